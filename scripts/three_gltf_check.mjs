// Plays an mprog .glb with three.js (GLTFLoader, AnimationMixer) in Node and compares the
// joints with the positions they were written from.
//
//   npm install --prefix DIR three@0.187.0
//   THREE_MODULES=DIR/node_modules node scripts/three_gltf_check.mjs IN.glb EXPECTED.npy N0,N1,…,N21 [--tol 0.01]
//
// IN.glb: a file mprog wrote for one person (its own skeleton, or a user's character with
// --rig). EXPECTED.npy: float32 [frames, 22, 3], metres, Y up. The names are the 22 nodes
// in HumanML3D order. The script loads the file, plays its first animation with an
// AnimationMixer at each key's time, updates the scene's world matrices and reads each
// named node's world position. Prints "three_gltf_check: OK|FAIL max error E m (frames F,
// skinned meshes S)" and exits non-zero on failure.
import { readFileSync } from "node:fs";
import { pathToFileURL } from "node:url";

// three.js from $THREE_MODULES (a node_modules folder), else wherever Node finds it.
const modules = process.env.THREE_MODULES;
const from = (path) =>
  modules ? new URL(path, pathToFileURL(`${modules}/`)).href : path.replace(/^three\/build\/three\.module\.js$/, "three");
const THREE = await import(from("three/build/three.module.js"));
const { GLTFLoader } = await import(from("three/examples/jsm/loaders/GLTFLoader.js"));

const [glbPath, npyPath, namesArg, ...rest] = process.argv.slice(2);
if (!namesArg) {
  console.error("usage: three_gltf_check.mjs IN.glb EXPECTED.npy N0,…,N21 [--tol T]");
  process.exit(2);
}
const tol = rest[0] === "--tol" ? Number(rest[1]) : 0.01;
const names = namesArg.split(",");

function readNpy(path) {
  const b = readFileSync(path);
  const major = b[6];
  const headerLen = major === 1 ? b.readUInt16LE(8) : b.readUInt32LE(8);
  const start = (major === 1 ? 10 : 12) + headerLen;
  const header = b.subarray(major === 1 ? 10 : 12, start).toString("latin1");
  if (!header.includes("'<f4'")) throw new Error(`${path}: not little-endian float32`);
  const shape = header.match(/\(([^)]*)\)/)[1].split(",").filter((s) => s.trim()).map(Number);
  const data = new Float32Array(b.buffer.slice(b.byteOffset + start, b.byteOffset + b.length));
  return { shape, data };
}

const bytes = readFileSync(glbPath);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length);
const gltf = await new GLTFLoader().parseAsync(buffer, "");
const scene = gltf.scene;
const clip = gltf.animations[0];
if (!clip) throw new Error("the file has no animation");
const mixer = new THREE.AnimationMixer(scene);
// Played once and held at the end: a looping action wraps its last key to the first.
const action = mixer.clipAction(clip);
action.setLoop(THREE.LoopOnce, 1);
action.clampWhenFinished = true;
action.play();
const nodes = names.map((n) => {
  const o = scene.getObjectByName(THREE.PropertyBinding.sanitizeNodeName(n));
  if (!o) throw new Error(`no node ${n}`);
  return o;
});
let skinned = 0;
scene.traverse((o) => { if (o.isSkinnedMesh) skinned += 1; });
const { shape, data } = readNpy(npyPath);
const frames = shape[0];
const times = clip.tracks[0].times;
let worst = 0;
const p = new THREE.Vector3();
for (let f = 0; f < frames; f++) {
  mixer.setTime(times[Math.min(f, times.length - 1)]);
  scene.updateMatrixWorld(true);
  nodes.forEach((node, j) => {
    node.getWorldPosition(p);
    const k = (f * 22 + j) * 3;
    const d = Math.hypot(p.x - data[k], p.y - data[k + 1], p.z - data[k + 2]);
    worst = Math.max(worst, d);
  });
}
const ok = worst <= tol && skinned > 0;
console.log(`three_gltf_check: ${ok ? "OK" : "FAIL"} max error ${worst.toExponential(3)} m (frames ${frames}, skinned meshes ${skinned}, three.js r${THREE.REVISION})`);
process.exit(ok ? 0 : 1);
