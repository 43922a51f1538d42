// The world-space size of the exported Gaussians as a glTF viewer computes it (issue 32): loads a
// compact GLB (KHR_mesh_quantization: the node's scale s, the box's side, undoes the normalized
// 16-bit positions) and the plain
// GLB of the same points with three.js's own GLTFLoader (its meshopt decoder), and for sampled
// splats of the compact file compares world sigma = exp(SCALE) * the node's world scale, and the
// world rotation, with those of the nearest plain splat. KHR_gaussian_splatting attributes live in
// the node's local space like POSITION, so a SCALE in world units would come out s times too small.
// An SPZ file (--splat-codec spz) is read as the page reads it (web/spz.js decodes it first); its
// 8-bit quantisation needs looser bounds (ln sigma in 1/16 steps: 3.2 %; 8-bit quaternions).
//   node web/test/splat_scale.mjs COMPACT.glb PLAIN.glb [SAMPLES [SIGMA_TOL [ANGLE_DEG]]]
// prints one JSON line; exit 1 on a failed check. Defaults: 200 samples, 1 %, 1 degree.
import { readFile } from 'node:fs/promises';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/examples/jsm/libs/meshopt_decoder.module.js';
import { spzToPlainGlb } from '../spz.js';

if (typeof globalThis.self === 'undefined') globalThis.self = globalThis;

// every splat of the file: world centre, world sigma (3), world rotation quaternion
async function splats(file) {
  const bytes = await readFile(file);
  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);
  const buffer = await spzToPlainGlb(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength));
  const gltf = await loader.parseAsync(buffer, '');
  gltf.scene.updateMatrixWorld(true);
  const out = [];
  let nodeScale = 1;
  gltf.scene.traverse((o) => {
    const g = o.geometry;
    if (!o.isPoints || !g.attributes['khr_gaussian_splatting:scale']) return;
    const P = g.attributes.position, S = g.attributes['khr_gaussian_splatting:scale'];
    const R = g.attributes['khr_gaussian_splatting:rotation'];
    const pos = new THREE.Vector3(), scl = new THREE.Vector3(), rot = new THREE.Quaternion();
    o.matrixWorld.decompose(pos, rot, scl);
    nodeScale = scl.x;
    for (let i = 0; i < P.count; i++) {
      const q = new THREE.Quaternion(R.getX(i), R.getY(i), R.getZ(i), R.getW(i)).normalize().premultiply(rot);
      out.push({
        c: new THREE.Vector3().fromBufferAttribute(P, i).applyMatrix4(o.matrixWorld),
        sigma: [Math.exp(S.getX(i)) * scl.x, Math.exp(S.getY(i)) * scl.y, Math.exp(S.getZ(i)) * scl.z],
        q,
      });
    }
  });
  return { out, nodeScale };
}

const [compactFile, plainFile, samplesArg, sigmaArg, angleArg] = process.argv.slice(2);
const sigmaTol = Number(sigmaArg || 0.01), angleTol = Number(angleArg || 1);
if (!compactFile || !plainFile) {
  console.error('usage: node web/test/splat_scale.mjs COMPACT.glb PLAIN.glb [SAMPLES]');
  process.exit(2);
}
const compact = await splats(compactFile), plain = await splats(plainFile);
const samples = Math.min(Number(samplesArg || 200), compact.out.length);
let worstSigma = 0, worstAngle = 0, worstDist = 0;
const ratios = [];
for (let k = 0; k < samples; k++) {
  const a = compact.out[Math.floor((k * compact.out.length) / samples)];
  let best = null, bd = Infinity;
  for (const b of plain.out) {
    const d = a.c.distanceToSquared(b.c);
    if (d < bd) [bd, best] = [d, b];
  }
  worstDist = Math.max(worstDist, Math.sqrt(bd));
  for (let j = 0; j < 2; j++) { // the ellipse's axes (the normal's sigma is 1/100 of the smaller)
    const r = a.sigma[j] / best.sigma[j];
    ratios.push(r);
    worstSigma = Math.max(worstSigma, Math.abs(Math.log(r)));
  }
  // a Gaussian is unchanged by a half turn about its own axes (SPZ stores the turn with the largest w)
  const turns = [[0, 0, 0, 1], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]].map((t) => new THREE.Quaternion(...t));
  worstAngle = Math.max(worstAngle, Math.min(...turns.map((t) => a.q.clone().multiply(t).angleTo(best.q))));
}
ratios.sort((x, y) => x - y);
const r = {
  compact: compactFile, plain: plainFile, splats: [compact.out.length, plain.out.length], samples,
  node_scale: [compact.nodeScale, plain.nodeScale], median_sigma_ratio: +ratios[ratios.length >> 1].toFixed(5),
  worst_sigma_error: +(Math.exp(worstSigma) - 1).toFixed(5), worst_angle_deg: +((worstAngle * 180) / Math.PI).toFixed(3),
  worst_centre_distance: worstDist,
};
const checks = [
  ['the same splats in both', compact.out.length === plain.out.length && samples > 0],
  // the compact node must carry a real scale (the bunny's side, 0.15), or the comparison proves nothing
  ['the compact node scales its 16-bit positions', Math.abs(Math.log(compact.nodeScale)) > 0.5 && plain.nodeScale === 1],
  // the exponential filter keeps 12 mantissa bits (0.03 %); 1 % leaves room, and a SCALE in world
  // units (the bug) is off by the node scale
  [`world sigma within ${100 * sigmaTol} % of the plain file`, worstSigma < Math.log(1 + sigmaTol)],
  // 12-bit quaternion filter: about 0.05 degrees
  [`world rotation within ${angleTol} degrees`, worstAngle < (angleTol * Math.PI) / 180],
];
r.failed = checks.filter(([, ok]) => !ok).map(([name]) => name);
console.log(JSON.stringify(r));
process.exit(r.failed.length ? 1 : 0);
