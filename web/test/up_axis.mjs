// The up axis of an exported scan as three.js sees it (issue 29): loads each GLB with three.js's own
// GLTFLoader (with its meshopt decoder), takes every vertex of every mesh and point set through its
// node's world matrix (what any three.js page draws), and checks that the z-up site of
// tests/cli/up_axis.sh (60 x 40 m of ground, a 2 x 2 m tower 16 m tall) stands on glTF's +y: y is
// the box's shortest side, the median vertex lies low in y (ground down, not upside down), only the
// narrow tower reaches the top 40% of y, and the scene's extras.amgsplat.toSource takes the
// vertices back to the scan's z-up elevations (about 100 m).
//   node web/test/up_axis.mjs FILE.glb...      prints one JSON line per file; exit 1 on a failed check
import { readFile } from 'node:fs/promises';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/examples/jsm/libs/meshopt_decoder.module.js';

// textures are not needed for positions, and Node has no DOM to decode the PNGs: an empty texture
THREE.TextureLoader.prototype.load = function (url, onLoad) {
  const texture = new THREE.Texture();
  queueMicrotask(() => onLoad && onLoad(texture));
  return texture;
};
if (typeof globalThis.self === 'undefined') globalThis.self = globalThis;

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = await readFile(file);
  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);
  const gltf = await loader.parseAsync(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), '');
  const scene = gltf.scene;
  scene.updateMatrixWorld(true);
  const pts = [];
  scene.traverse((o) => {
    if (!(o.isMesh || o.isPoints)) return;
    const p = o.geometry.attributes.position, v = new THREE.Vector3();
    for (let i = 0; i < p.count; i++) pts.push(v.fromBufferAttribute(p, i).applyMatrix4(o.matrixWorld).clone());
  });
  const box = new THREE.Box3().setFromPoints(pts), size = box.getSize(new THREE.Vector3());
  const h = size.y, ys = pts.map((q) => q.y).sort((a, b) => a - b);
  const median = (ys[ys.length >> 1] - box.min.y) / h; // where the ground lies in the y range
  const upper = pts.filter((q) => q.y > box.min.y + 0.6 * h);
  const ub = new THREE.Box3().setFromPoints(upper), us = ub.getSize(new THREE.Vector3());
  const extras = scene.userData.amgsplat || {};
  const back = new THREE.Matrix4().fromArray(extras.toSource || new THREE.Matrix4().toArray());
  const src = new THREE.Box3().setFromPoints(pts.map((q) => q.clone().applyMatrix4(back)));
  const r = {
    file, vertices: pts.length, size: size.toArray().map((x) => +x.toFixed(2)), median_y: +median.toFixed(3),
    upper: upper.length, upper_size: us.toArray().map((x) => +x.toFixed(2)), sourceUp: extras.sourceUp,
    source_z: [+src.min.z.toFixed(2), +src.max.z.toFixed(2)],
    crs: gltf.parser.json.asset.extras?.amgsplat?.crs ? Object.keys(gltf.parser.json.asset.extras.amgsplat.crs) : null,
  };
  const checks = [
    ['the flat site lies in x-z: y its shortest side', h < 0.6 * size.z && size.z < size.x],
    ['the ground low in y, not upside down', median < 0.35],
    ['only the narrow tower in the top 40% of y', upper.length > 0 && us.x < 0.2 * size.x && us.z < 0.2 * size.z],
    ['toSource gives back the z-up elevations', extras.sourceUp === 'z' && src.min.z > 90 && src.max.z < 125 &&
      Math.abs(src.max.z - src.min.z - h) < 1e-3 * h],
  ];
  r.failed = checks.filter(([, ok]) => !ok).map(([name]) => name);
  if (r.failed.length) failed = true;
  console.log(JSON.stringify(r));
}
process.exit(failed ? 1 : 0);
