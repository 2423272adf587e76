// SPDX-License-Identifier: Apache-2.0
// A console host of Pose.cs, as a Unity script would use it: load a rig, take
// a clip's pose at a time through the bridge, bend one joint, pose, and write
// every tissue's positions (float32, tissue after tissue) so a test can
// compare them with the C API's (tests/python/pose_positions.c does the same).
//   mcs -out:sample.exe Pose.cs examples/Sample.cs && mono sample.exe RIG OUT [CLIP MAP TIME]
using System;
using System.IO;

class Sample
{
    static int Main(string[] args)
    {
        if (args.Length != 2 && args.Length != 5) {
            Console.Error.WriteLine("usage: sample.exe RIG OUT [CLIP MAP TIME]");
            return 2;
        }
        try {
            using (var rig = new Pose.Rig(args[0]))
            using (var state = new Pose.State(rig, 0, Pose.Method.DQS)) {
                if (args.Length == 5) {
                    var options = new Pose.BridgeOptions { MapPath = args[3], Play = Pose.Play.Manual };
                    using (var clip = new Pose.Bridge(args[2], rig, options)) {
                        Pose.BridgeFrame f = clip.PoseAt(double.Parse(args[4], System.Globalization.CultureInfo.InvariantCulture), state);
                        Console.WriteLine("{0}: {1} joints at {2:F3} s ({3})", args[2], f.Joints, f.MediaS,
                                          clip.Status().Kind);
                    }
                }
                int joint = rig.JointCount / 2;
                bool clamped = state.SetJointEuler(joint, 10, 40, 0);
                state.Apply();
                using (var file = new BinaryWriter(File.Create(args[1]))) {
                    for (int t = 0; t < rig.TissueCount; t++)
                        foreach (float v in state.Positions(t))
                            file.Write(v);
                }
                float[] lo = new float[3], hi = new float[3];
                state.Bounds(-1, lo, hi);
                Pose.Transform w = state.JointWorld(joint);
                Console.WriteLine("{0}: {1} joints, {2} tissues, format {3}; {4} bent{5}, now at ({6:F3}, {7:F3}, {8:F3}); "
                                  + "posed height {9:F3}", args[0], rig.JointCount, rig.TissueCount, rig.FormatVersion,
                                  rig.Joint(joint).Name, clamped ? " (clamped)" : "", w.Translation[0],
                                  w.Translation[1], w.Translation[2], hi[2] - lo[2]);
                // Soft tissue that swings after the joint: a host's fixed 120 Hz loop.
                if (rig.HasFem) {
                    Pose.DynamicsOptions dyn = Pose.DynamicsOptions.Defaults();
                    dyn.CgIterations = 40;
                    state.SetDynamics(dyn);
                    state.SetJointEuler(joint, 10, 60, 0);
                    for (int i = 0; i < 6; i++)
                        state.Step(1.0 / 120);
                    Pose.DynamicsStats s = state.DynamicsStats();
                    Console.WriteLine("dynamics: 6 steps, {0:F4} s simulated, {1} islands, kinetic energy {2:E2} J",
                                      s.Time, s.Islands, s.KineticEnergy);
                    if (!TieNearBone(rig, state))
                        return 1;
                } else {
                    Console.WriteLine("dynamics: unsupported (the rig has no fem section)");
                }
            }
        } catch (Pose.PoseException e) {
            Console.Error.WriteLine("sample: " + e.Message);
            return 1;
        }
        return 0;
    }

    // Couplings: the first 8 nodes within 5 cm of a bone tied to it at their rest positions, the count
    // read back, a refused call leaving them, a step, and their removal.
    static bool TieNearBone(Pose.Rig rig, Pose.State state)
    {
        int bone = -1;
        for (int t = 0; t < rig.TissueCount && bone < 0; t++)
            if (rig.Tissue(t).Kind == Pose.TissueKind.Bone && rig.Tissue(t).Joint >= 0)
                bone = t;
        if (bone < 0) {
            Console.WriteLine("couplings: no bone tissue");
            return true;
        }
        int joint = rig.Tissue(bone).Joint;
        uint[] nodes = rig.FemNodesNear(joint, 0.05f);
        if (nodes.Length == 0) {
            Console.Error.WriteLine("sample: no simulation node within 5 cm of " + rig.Joint(joint).Name);
            return false;
        }
        float[] rest;
        using (var atRest = new Pose.State(rig))
            rest = atRest.TetPositions();
        var tied = new Pose.FemCoupling[Math.Min(8, nodes.Length)];
        for (int i = 0; i < tied.Length; i++) {
            uint n = nodes[i];
            tied[i] = new Pose.FemCoupling { Node = n, Joint = joint, Stiffness = 100,
                                             Anchor = new[] { rest[3 * n], rest[3 * n + 1], rest[3 * n + 2] } };
        }
        state.SetFemCouplings(tied);
        int count = state.FemCouplingCount;
        var refused = new Pose.FemCoupling { Node = nodes[0], Joint = joint, Stiffness = -1, Anchor = new float[3] };
        try {
            state.SetFemCouplings(new[] { refused });
            Console.Error.WriteLine("sample: a negative stiffness was accepted");
            return false;
        } catch (Pose.PoseException e) {
            if (e.Status != Pose.Status.InvalidArgument || state.FemCouplingCount != count) {
                Console.Error.WriteLine("sample: the refused coupling left {0} of {1} ({2})", state.FemCouplingCount,
                                        count, e.Message);
                return false;
            }
        }
        state.Step(1.0 / 120);
        state.SetFemCouplings(new Pose.FemCoupling[0]);
        Console.WriteLine("couplings: {0} of {1} nodes near {2} tied, {3} in effect, {4} after removal; "
                          + "the rig has {5}", tied.Length, nodes.Length, rig.Joint(joint).Name, count,
                          state.FemCouplingCount, rig.FemCouplings().Length);
        if (count != tied.Length || state.FemCouplingCount != 0 || nodes.Length < 2)
            return false;
        // Soft-soft: the first two of those nodes tied to each other, read back, removed.
        state.SetFemSoftCouplings(new[] { Pose.FemSoftCoupling.Pair(nodes[0], nodes[1], 50) });
        int soft = state.FemSoftCouplingCount;
        state.Step(1.0 / 120);
        state.SetFemSoftCouplings(new Pose.FemSoftCoupling[0]);
        Console.WriteLine("soft couplings: {0} in effect, {1} after removal; the rig has {2}", soft,
                          state.FemSoftCouplingCount, rig.FemSoftCouplings().Length);
        return soft == 1 && state.FemSoftCouplingCount == 0;
    }
}
