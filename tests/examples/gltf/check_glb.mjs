// SPDX-License-Identifier: Apache-2.0
// Loads pose-export's animated session (.glb) with three.js's GLTFLoader, as
// a web page would, and checks it plays: the skinned meshes, their joints,
// the animation's length, and that the skin posed by three.js at a sample
// time lies where pose-export put it (a static .glb of the same pose).
// usage: node check_glb.mjs SESSION.glb MESHES JOINTS SECONDS [POSED.glb AT_S MESH MAX_MEAN_M]
import { readFileSync } from 'node:fs';
import { AnimationMixer, Vector3 } from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

const [file, meshes, joints, seconds, posedFile, atS, meshName, maxMean] = process.argv.slice(2);

function load(path) {
  const b = readFileSync(path);
  const ab = b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength);
  return new Promise((resolve, reject) => new GLTFLoader().parse(ab, '', resolve, reject));
}

function fail(msg) {
  console.error(`check_glb: ${msg}`);
  process.exit(1);
}

const gltf = await load(file);
const skinned = [];
gltf.scene.traverse((o) => { if (o.isSkinnedMesh) skinned.push(o); });
const bones = new Set();
for (const m of skinned) for (const b of m.skeleton.bones) bones.add(b.name);
const clip = gltf.animations[0];
const report = {
  skinned_meshes: skinned.length,
  joints: bones.size,
  animations: gltf.animations.length,
  duration_s: clip ? clip.duration : 0,
  tracks: clip ? clip.tracks.length : 0,
  vertices: skinned.reduce((n, m) => n + m.geometry.attributes.position.count, 0),
};
if (report.skinned_meshes !== Number(meshes)) fail(`${report.skinned_meshes} skinned meshes, expected ${meshes}`);
if (report.joints !== Number(joints)) fail(`${report.joints} joints, expected ${joints}`);
if (report.animations !== 1) fail(`${report.animations} animations, expected 1`);
if (Math.abs(report.duration_s - Number(seconds)) > 0.01) fail(`animation of ${report.duration_s} s, expected ${seconds}`);

if (posedFile) {
  // Play the clip to AT_S and compare the skinned mesh with the posed one.
  const mixer = new AnimationMixer(gltf.scene);
  mixer.clipAction(clip).play();
  mixer.setTime(Number(atS));
  gltf.scene.updateMatrixWorld(true);
  const posed = await load(posedFile);
  posed.scene.updateMatrixWorld(true);
  let ref = null;
  posed.scene.traverse((o) => { if (o.isMesh && o.name === meshName) ref = o; });
  const mesh = skinned.find((m) => m.name === meshName);
  if (!ref || !mesh) fail(`no mesh '${meshName}' in both files`);
  const n = mesh.geometry.attributes.position.count;
  const a = new Vector3(), b = new Vector3(), rest = new Vector3();
  let sum = 0, max = 0, moved = 0;
  for (let i = 0; i < n; i++) {
    mesh.getVertexPosition(i, a);
    a.applyMatrix4(mesh.matrixWorld);
    b.fromBufferAttribute(ref.geometry.attributes.position, i).applyMatrix4(ref.matrixWorld);
    rest.fromBufferAttribute(mesh.geometry.attributes.position, i);
    const d = a.distanceTo(b);
    sum += d;
    max = Math.max(max, d);
    moved = Math.max(moved, b.distanceTo(rest));
  }
  report.compare = { mesh: meshName, at_s: Number(atS), mean_m: sum / n, max_m: max, moved_m: moved };
  if (!(moved > 0.05)) fail(`the reference pose moved '${meshName}' only ${moved} m: nothing to compare`);
  if (!(sum / n <= Number(maxMean))) fail(`three.js poses '${meshName}' ${sum / n} m from pose-export on average (limit ${maxMean})`);
}
console.log(JSON.stringify(report));
