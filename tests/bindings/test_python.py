# SPDX-License-Identifier: Apache-2.0
"""The Python package (bindings/python) against the C API.

    test_python.py POSE_POSITIONS SOURCE_DIR SCRATCH RIG [CLIP MAP]

Imports `pose` as installed by `pip install ./bindings/python` (into
SCRATCH, offline), poses RIG as pose_positions (C) does and compares every
tissue's positions bit for bit; then errors, views, bounds and the bridge.
The libraries come from $POSE_LIBRARY_PATH (the build tree).
"""
import os
import shutil
import subprocess
import sys
import unittest

HELPER, SOURCE, SCRATCH, RIG = sys.argv[1:5]
CLIP, MAP = (sys.argv[5:7] + [None, None])[:2] if len(sys.argv) > 5 else (None, None)
TIME = 2.0

# Install the package as a user would, with no index: setuptools from the system.
# From a copy, as pip builds in the folder it is given.
target, copy = os.path.join(SCRATCH, "site"), os.path.join(SCRATCH, "python")
shutil.rmtree(copy, ignore_errors=True)
shutil.copytree(os.path.join(SOURCE, "bindings", "python"), copy,
                ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-index", "--upgrade", "--target", target, copy],
               check=True)
sys.path.insert(0, target)
import pose  # noqa: E402  (installed just above)


def c_positions():
    out = os.path.join(SCRATCH, "c_positions.bin")
    subprocess.run([HELPER, RIG, out] + ([CLIP, MAP, str(TIME)] if CLIP else []), check=True)
    with open(out, "rb") as f:
        return f.read()


class Bindings(unittest.TestCase):
    def test_installed_where_pip_put_it(self):
        self.assertTrue(pose.__file__.startswith(target), pose.__file__)
        self.assertEqual(pose.__version__, "0.2.0")
        self.assertEqual(pose.RIG_FORMAT_VERSION, 1)

    def test_positions_equal_the_c_api_bit_for_bit(self):
        with pose.Rig(RIG) as rig, pose.State(rig, method=pose.Method.DQS) as state:
            if CLIP:
                with pose.Bridge(CLIP, rig, map_path=MAP, play=pose.Play.MANUAL) as clip:
                    frame = clip.pose_at(TIME, state)
                    self.assertTrue(frame.fresh)
                    self.assertGreater(frame.joints, 10)
            state.set_joint_euler(rig.joint_count // 2, (10, 40, 0))
            state.apply()
            ours = b"".join(bytes(memoryview(state.positions(t)).cast("B")) for t in range(rig.tissue_count))
            rest = b"".join(bytes(memoryview(rig.rest_positions(t)).cast("B")) for t in range(rig.tissue_count))
        theirs = c_positions()
        self.assertEqual(len(ours), len(theirs))
        self.assertNotEqual(ours, rest)  # the pose moved something
        self.assertTrue(ours == theirs, "positions differ from the C API's")

    def test_views_are_the_states_memory(self):
        with pose.Rig(RIG) as rig, pose.State(rig) as state:
            skin = state.positions(0)
            before = bytes(memoryview(skin).cast("B"))
            self.assertEqual(before, bytes(memoryview(rig.rest_positions(0)).cast("B")))
            with self.assertRaises((ValueError, TypeError)):
                skin[0, 0] = 1.0  # read-only
            state.set_joint_euler(rig.joint_count // 2, (0, 60, 0))
            state.apply()
            # No copy: the same view now holds the posed positions.
            self.assertNotEqual(bytes(memoryview(skin).cast("B")), before)
            self.assertEqual(len(skin), rig.tissue(0).vertex_count)
            lo, hi = state.bounds(0)
            flat = memoryview(skin).cast("B").cast("f").tolist()
            for k in range(3):
                self.assertEqual(lo[k], min(flat[k::3]))
                self.assertEqual(hi[k], max(flat[k::3]))
            self.assertEqual(len(state.normals(0)), len(skin))

    def test_errors_carry_pose_last_error(self):
        with self.assertRaises(pose.PoseError) as caught:
            pose.Rig(os.path.join(SCRATCH, "missing.rig"))
        self.assertEqual(caught.exception.status, pose.Status.IO)
        self.assertIn("missing.rig", caught.exception.message)
        with pose.Rig(RIG) as rig, pose.State(rig) as state:
            with self.assertRaises(pose.PoseError) as caught:
                state.set_joint_euler("no_such_joint", (0, 0, 0))
            self.assertEqual(caught.exception.status, pose.Status.NOT_FOUND)
            with self.assertRaises(pose.PoseError) as caught:
                state.set_joint_euler(10 ** 6, (0, 0, 0))
            self.assertEqual(caught.exception.status, pose.Status.INVALID_ARGUMENT)
            self.assertIn("1000000", caught.exception.message)
            # Past a limit: the request is clamped, not refused, and True says so.
            limited = next(j for j in rig.joints if j.limit_flags & 2)
            self.assertTrue(state.set_joint_euler(limited.index, (0, limited.limit_max_deg[1] + 20, 0)))
            self.assertIn("clamped", pose.last_error())
        self.assertIsNone(rig._handle)  # the context manager closed it

    def test_fem_and_dynamics(self):
        with pose.Rig(RIG) as rig, pose.State(rig) as state:
            joint = rig.joint_count // 2
            state.set_joint_euler(joint, (0, 40, 0))
            if not rig.has_fem:  # the synthetic bar
                with self.assertRaises(pose.PoseError) as caught:
                    state.step(1 / 120)
                self.assertEqual(caught.exception.status, pose.Status.UNSUPPORTED)
                return
            state.method = pose.Method.FEM
            self.assertEqual(state.method, pose.Method.FEM)
            state.apply()
            fem = state.fem_stats()
            self.assertGreater(fem["outer_iterations"], 0)
            self.assertLess(fem["residual"], 1.0)
            with self.assertRaises(TypeError):
                state.set_dynamics(no_such_option=1)
            with self.assertRaises(pose.PoseError) as caught:
                state.set_dynamics(tolerance=2.0)
            self.assertEqual(caught.exception.status, pose.Status.INVALID_ARGUMENT)
            state.set_dynamics(gravity=(0.0, 0.0, 0.0), cg_iterations=40)
            state.reset_dynamics()
            state.set_joint_euler(joint, (0, 60, 0))
            for _ in range(6):
                state.step(1 / 120)
            stats = state.dynamics_stats()
            self.assertAlmostEqual(stats["time"], 6 / 120, places=9)
            self.assertGreater(stats["islands"], 0)
            self.assertGreater(stats["kinetic_energy"], 0.0)  # the joint's step set the tissue moving
            flat = memoryview(state.positions(0)).cast("B").cast("f").tolist()
            self.assertTrue(all(abs(v) < 1e3 for v in flat))

            # couplings: nodes near a bone tied to it, then removed
            bone = next(t for t in rig.tissues if t.kind == pose.TissueKind.BONE and t.joint >= 0)
            nodes = rig.fem_nodes_near(bone.joint, 0.05)
            self.assertGreater(len(nodes), 0)
            self.assertEqual(nodes, sorted(set(nodes)))
            with pose.State(rig) as at_rest:
                rest = memoryview(at_rest.tet_positions()).cast("B").cast("f").tolist()
            tied = [(n, bone.joint, 100.0, rest[3 * n:3 * n + 3]) for n in nodes[:8]]
            state.set_fem_couplings(tied)
            self.assertEqual(state.fem_coupling_count(), len(tied))
            with self.assertRaises(pose.PoseError) as caught:
                state.set_fem_couplings([(nodes[0], bone.joint, -1.0, (0.0, 0.0, 0.0))])
            self.assertEqual(caught.exception.status, pose.Status.INVALID_ARGUMENT)
            self.assertEqual(state.fem_coupling_count(), len(tied))  # unchanged by the refused call
            state.step(1 / 120)
            state.set_fem_couplings([])
            self.assertEqual(state.fem_coupling_count(), 0)
            self.assertIsInstance(rig.fem_couplings(), list)

            # soft-soft couplings: node pairs and a point of three nodes, then removed
            soft = [(nodes[0], [nodes[1]], [1.0], 50.0), (nodes[2], [nodes[3], nodes[4]], [0.5, 0.5], 50.0)]
            state.set_fem_soft_couplings(soft)
            self.assertEqual(state.fem_soft_coupling_count(), 2)
            with self.assertRaises(pose.PoseError) as caught:
                state.set_fem_soft_couplings([(nodes[0], [nodes[1]], [0.5], 50.0)])  # weights sum to 0.5
            self.assertEqual(caught.exception.status, pose.Status.INVALID_ARGUMENT)
            self.assertEqual(state.fem_soft_coupling_count(), 2)
            state.step(1 / 120)
            self.assertGreater(state.dynamics_stats()["islands"], 0)
            state.set_fem_soft_couplings([])
            self.assertEqual(state.fem_soft_coupling_count(), 0)
            self.assertIsInstance(rig.fem_soft_couplings(), list)

    @unittest.skipUnless(CLIP, "no clip given (the bridge is not built)")
    def test_bridge_plays_the_clip(self):
        with pose.Rig(RIG) as rig, pose.State(rig) as state, \
                pose.Bridge(CLIP, rig, map_path=MAP, play=pose.Play.AS_FAST_AS_POSSIBLE, end_s=1.0) as br:
            self.assertTrue(br.wait(20000))
            br.apply(state)
            status = br.status()
            self.assertEqual(status["state"], "ended")
            self.assertEqual(status["kind"], "bvh")
            self.assertGreaterEqual(status["media_s"], 0.95)
        with self.assertRaises(TypeError):
            pose.Bridge(CLIP, None, no_such_option=1)

    @unittest.skipUnless(CLIP, "no clip given (the bridge is not built)")
    def test_example_writes_its_csv(self):
        out = os.path.join(SCRATCH, "skin.csv")
        example = os.path.join(SOURCE, "bindings", "python", "examples", "bvh_displacement.py")
        env = dict(os.environ, PYTHONPATH=target)
        subprocess.run([sys.executable, example, RIG, CLIP, MAP, out, "0.5"], check=True, env=env)
        with open(out) as f:
            rows = f.read().splitlines()
        self.assertEqual(rows[0], "time_s,max_displacement,mean_displacement")
        self.assertEqual(len(rows), 1 + 15)
        first, last = [list(map(float, r.split(","))) for r in (rows[1], rows[-1])]
        self.assertAlmostEqual(last[0], 14 / 30, places=3)
        self.assertGreater(first[1], 0.0)
        self.assertNotEqual(first[1:], last[1:])  # the body moved between the clip's frames


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
