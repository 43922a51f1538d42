// Streaming a 3D Tiles 1.1 tileset from `amgsplat export --tiles` into the viewer (docs/web.md):
// 3d-tiles-renderer (npm, pinned in package.json) picks the tiles a view needs by screen-space
// error; each tile's points become the viewer's splats (Viewer.splatPasses), drawn with the same
// passes as a single GLB. The tileset's geometricError is a tile's largest splat diameter, so the
// error target is in pixels of splat diameter: the point hierarchy's tau (docs/hier.md).
//   coarse first: only the root tile is requested until it is on screen (the first frame);
//   error target: tiles refine until their splats project below `error` pixels;
//   point budget: while the visible tiles hold more splats than `point-budget`, the error target
//     grows (x1.25 a frame) and shrinks back once they hold under half of it;
//   while the camera moves the target is `move-factor` times larger (few loads), and the view
//     refines once it stops.
// Two kinds of tileset (docs/web.md): REPLACE tiles of an in-memory hierarchy carry
// KHR_gaussian_splatting ellipses, drawn by Viewer.splatPasses; ADD tiles of a streamed hierarchy
// (one tile a node, each point once) carry plain points and their disc radius in the mesh's
// extras.amgsplat.pointRadius, drawn here as camera-facing discs of that radius (discPasses) with
// the same two passes, as `amgsplat render` draws a streamed cut (asp_ooc_load's radii; docs/hier.md).
// window.amgsplatViewer: ready at the first frame (firstFrame: bytes and requests fetched by then),
// settled once nothing loads and the visible set has not changed for a while (stream: the totals).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { TilesRenderer } from '3d-tiles-renderer/three';
import { splatMaterials } from './viewer.js';
import { spzToPlainGlb } from './spz.js';

const STILL_MS = 300; // the camera counts as moving until this long after its last change
const SETTLE_FRAMES = 20; // frames without loads or visibility changes before `settled`

// A streamed tile's points as discs facing the eye (the disc renderer's normal u_eye - p,
// src/render/disc_renderer.c), in eye space: the splat passes' triangle around the unit circle,
// pass 1 pushed one radius away from the eye, pass 2 weighted as the splats are. The radius is the
// tile's, or in an octant of its node's cube (uCube) where a child tile is drawn, that child's
// (uRadii, refineRadii): asp_ooc_load sizes a point by the deepest loaded node that holds it, so
// a coarse tile's wide discs do not blur the finer tiles drawn over the same surface (ADD).
const discVertex = `
in vec3 position;
in vec3 center;
in vec4 splatColor;
uniform mat4 modelViewMatrix;
uniform mat4 projectionMatrix;
uniform float uEpsilon;
uniform float uRadii[8];
uniform vec3 uCube;
out vec2 vLocal;
out vec3 vColor;
void main() {
  vec2 q = position.xy * 1.05;
  int octant = (center.x > uCube.x ? 1 : 0) + (center.y > uCube.y ? 2 : 0) + (center.z > uCube.z ? 4 : 0);
  float r = uRadii[octant];
  vec3 c = (modelViewMatrix * vec4(center, 1.0)).xyz;
  vec3 n = dot(c, c) > 0.0 ? -normalize(c) : vec3(0.0, 0.0, 1.0);
  vec3 t = normalize(cross(n, abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
  vec3 b = cross(n, t);
  vec3 e = c + r * (q.x * t + q.y * b);
  if (uEpsilon > 0.0 && dot(e, e) > 0.0) e += uEpsilon * r * normalize(e);
  vLocal = q;
  vColor = splatColor.rgb;
  gl_Position = projectionMatrix * vec4(e, 1.0);
}`;

// the viewer's splat entry ({mesh, points, depth, accum, uniforms}, Viewer.render) for a points node
function discPasses(viewer, points, radius, cube) {
  const g = points.geometry, n = g.attributes.position.count, P = g.attributes.position, C = g.attributes.color;
  const at = new THREE.Vector3();
  points.updateMatrix();
  const centers = new Float32Array(3 * n), colors = new Float32Array(4 * n);
  for (let i = 0; i < n; i++) {
    centers.set(at.fromBufferAttribute(P, i).applyMatrix4(points.matrix).toArray(), 3 * i);
    colors.set(C ? [C.getX(i), C.getY(i), C.getZ(i), 1] : [0.578, 0.578, 0.578, 1], 4 * i);
  }
  const geo = new THREE.InstancedBufferGeometry();
  geo.setAttribute('position', new THREE.Float32BufferAttribute([-1.7320508, -1, 0, 1.7320508, -1, 0, 0, 2, 0], 3));
  geo.setAttribute('center', new THREE.InstancedBufferAttribute(centers, 3));
  geo.setAttribute('splatColor', new THREE.InstancedBufferAttribute(colors, 4));
  geo.instanceCount = n;
  const uniforms = { uEpsilon: { value: 1 }, uLit: { value: 0 }, uRadii: { value: new Array(8).fill(radius) },
    uCube: { value: new THREE.Vector3(...(cube || [0, 0, 0])) }, frontDepth: { value: viewer.front.depthTexture } };
  const { depth, accum } = splatMaterials(discVertex, uniforms);
  const mesh = new THREE.Mesh(geo, depth);
  mesh.frustumCulled = false;
  return { mesh, points, depth, accum, uniforms };
}

export class TileStream {
  constructor(viewer, opts, status) {
    this.viewer = viewer;
    this.opts = opts;
    this.status = status;
    this.bytes = 0; // response bytes fetched (tileset.json and tiles)
    this.requests = 0;
    this.scale = 1; // the point budget's factor on the error target
    this.lastMove = -Infinity;
    this.moving = false;
    this.dirty = true;
    this.still = 0;
    this.t0 = performance.now();
  }

  start() {
    const v = this.viewer, o = this.opts;
    const tiles = new TilesRenderer(o.tileset);
    this.tiles = tiles;
    const loader = new GLTFLoader(tiles.manager);
    loader.setMeshoptDecoder(MeshoptDecoder); // the tiles are compact GLBs (EXT_meshopt_compression)
    tiles.manager.addHandler(/\.(gltf|glb)$/g, loader);
    // every byte the stream fetches is counted here (the first-frame figure of the tests)
    tiles.fetchData = async (url, init) => {
      const res = await fetch(url, init);
      const body = await res.arrayBuffer();
      this.bytes += body.byteLength;
      this.requests++;
      // SPZ tiles (export --tiles --splat-codec spz, for CesiumJS) become the float Gaussians three
      // reads (spz.js), so one tileset serves Cesium and this page
      const out = res.ok && /\.glb$/.test(new URL(url, location.href).pathname) ? await spzToPlainGlb(body) : body;
      return new Response(out, { status: res.status, statusText: res.statusText, headers: res.headers });
    };
    tiles.registerPlugin({ name: 'amgsplat-splats', processTileModel: (scene) => this.prepare(scene) });
    tiles.maxDepth = 1; // coarse first: the root alone until it is shown
    tiles.errorTarget = o.errorTarget;
    v.scene = new THREE.Scene();
    v.scene.add(tiles.group);
    v.splats = [];
    v.prims = [];
    tiles.setCamera(v.camera);
    return new Promise((resolve, reject) => {
      this.fail = (e) => {
        this.status.error = String(e && e.message ? e.message : e);
        document.getElementById('status').textContent = `error: ${this.status.error}`;
        this.status.ready = true;
        reject(e);
      };
      this.firstFrame = resolve;
      tiles.addEventListener('load-error', (e) => this.fail(new Error(`cannot load '${e.url}': ${e.error?.message || e.error}`)));
      tiles.addEventListener('load-root-tileset', ({ tileset }) => this.root(tileset));
      tiles.addEventListener('tile-visibility-change', () => (this.dirty = true));
      tiles.addEventListener('load-model', () => (this.dirty = true));
      tiles.addEventListener('dispose-model', ({ scene }) => this.dispose(scene));
      v.controls.addEventListener('start', () => (this.moving = true));
      v.controls.addEventListener('end', () => {
        this.moving = false;
        this.lastMove = performance.now();
      });
      v.controls.addEventListener('change', () => {
        this.lastMove = performance.now();
        this.dirty = true;
      });
      const loop = () => {
        if (this.status.error) return;
        requestAnimationFrame(loop);
        try {
          this.frame();
        } catch (e) {
          this.fail(e);
        }
      };
      loop();
    });
  }

  // The tileset's frame: 3D Tiles is z up and turned the glTF content y-up to z-up; the group turns
  // it back and removes the origin (the root transform), so the page works in the hierarchy's local
  // y-up frame as it does for a single GLB, and frames the camera from extras.amgsplat.frame.
  root(tileset) {
    const v = this.viewer, tiles = this.tiles;
    const a = (tileset.extras && tileset.extras.amgsplat) || {};
    const origin = new THREE.Vector3(...(a.origin || [0, 0, 0]));
    tiles.group.rotation.x = -Math.PI / 2;
    tiles.group.position.copy(origin).negate();
    tiles.group.updateMatrixWorld(true);
    if (a.frame && a.frame.radius > 0) {
      v.frame = { center: new THREE.Vector3(...a.frame.center).sub(origin), radius: a.frame.radius };
    } else {
      const sphere = new THREE.Sphere();
      tiles.getBoundingSphere(sphere);
      v.frame = { center: sphere.center, radius: sphere.radius || 1 };
    }
    this.total = { tiles: a.tiles, points: a.points, splats: a.splats, bytes: a.bytes };
    v.fit();
  }

  // Each tile's points with KHR_gaussian_splatting attributes, or a disc radius, become splats beside
  // them; a .dps tile's textured quads (one level, export --tiles of a .dps) get the viewer's
  // primitive passes, blended by the page's method as a single GLB's levels are.
  prepare(scene) {
    const v = this.viewer, found = [], prims = [];
    let points = 0;
    scene.updateMatrixWorld(true);
    scene.traverse((o) => {
      if (o.isMesh && o.material && o.material.map) prims.push(v.primitivePasses(o));
    });
    v.prims.push(...prims);
    scene.traverse((o) => {
      if (!o.isPoints) return;
      points += o.geometry.attributes.position.count;
      o.material.size = this.opts.pointSize;
      if (o.geometry.attributes['khr_gaussian_splatting:rotation'] || o.userData.amgsplat?.pointRadius > 0) found.push(o);
    });
    let disc = null; // a streamed tile: its radius and node cube (refineRadii)
    const splats = found.map((p) => {
      if (p.geometry.attributes['khr_gaussian_splatting:rotation']) return v.splatPasses(p);
      const a = p.userData.amgsplat;
      disc = { radius: a.pointRadius, cube: a.cube };
      return discPasses(v, p, a.pointRadius, a.cube);
    }).map((sp) => {
      sp.points.parent.add(sp.mesh); // the centres hold the points' node transform (splatPasses)
      return sp;
    });
    for (const p of prims) points += p.count; // a primitive counts against the budget as a splat does
    scene.userData.amgsplat = { points, splats, disc, prims };
    v.splats.push(...splats);
  }

  dispose(scene) {
    const v = this.viewer, mine = scene.userData.amgsplat;
    if (!mine) return;
    v.splats = v.splats.filter((sp) => !mine.splats.includes(sp));
    v.prims = v.prims.filter((p) => !mine.prims.includes(p));
    for (const p of mine.prims) {
      p.depth.dispose();
      p.accum.dispose();
    }
    for (const sp of mine.splats) {
      sp.mesh.geometry.dispose();
      sp.depth.dispose();
      sp.accum.dispose();
    }
    this.dirty = true;
  }

  // Per streamed tile and octant of its node's cube, the disc radius of the child tile drawn there
  // (ADD: the parent's points in that octant lie among the child's denser ones), else the tile's own.
  refineRadii() {
    const shown = this.tiles.visibleTiles;
    for (const t of shown) {
      const mine = t.engineData.scene?.userData.amgsplat;
      if (!mine?.disc?.cube) continue;
      const c0 = mine.disc.cube, radii = new Array(8).fill(mine.disc.radius);
      for (const child of t.children) {
        const d = shown.has(child) && child.engineData.scene?.userData.amgsplat?.disc;
        if (!d?.cube) continue;
        const o = (d.cube[0] > c0[0] ? 1 : 0) + (d.cube[1] > c0[1] ? 2 : 0) + (d.cube[2] > c0[2] ? 4 : 0);
        radii[o] = Math.min(radii[o], d.radius);
      }
      for (const sp of mine.splats) if (sp.uniforms.uRadii) sp.uniforms.uRadii.value = radii;
    }
  }

  visiblePoints() {
    let n = 0;
    for (const t of this.tiles.visibleTiles) n += t.engineData.scene?.userData.amgsplat?.points || 0;
    return n;
  }

  frame() {
    const v = this.viewer, o = this.opts, tiles = this.tiles;
    const moving = this.moving || performance.now() - this.lastMove < STILL_MS;
    tiles.errorTarget = o.errorTarget * this.scale * (moving ? o.moveFactor : 1);
    v.camera.updateMatrixWorld();
    tiles.setResolutionFromRenderer(v.camera, v.renderer);
    tiles.update();
    if (this.dirty) this.refineRadii();
    const shown = this.visiblePoints();
    if (shown > o.pointBudget) this.scale *= 1.25;
    else if (shown < 0.5 * o.pointBudget && this.scale > 1) this.scale = Math.max(1, this.scale / 1.25);
    const loading = tiles.stats.queued + tiles.stats.downloading + tiles.stats.parsing > 0;
    if (this.dirty && v.frame) {
      v.render();
      this.dirty = false;
      this.still = 0;
      if (!this.status.firstFrame && tiles.visibleTiles.size > 0) {
        this.status.firstFrame = { bytes: this.bytes, requests: this.requests, ms: performance.now() - this.t0,
          points: shown };
        // the root is on screen: refine, once a test's hook (web/test/tiles.mjs reads its server's
        // byte count there) has seen that nothing more was requested
        Promise.resolve(window.amgsplatOnFirstFrame?.()).finally(() => (tiles.maxDepth = Infinity));
        this.status.ready = true;
        this.status.info = this.describe(shown);
        // the picture as first shown, for the tests (the stream goes on refining right away)
        this.status.firstFrameImage = v.renderer.domElement.toDataURL('image/png');
        this.firstFrame();
      }
    } else if (!loading && this.status.firstFrame && !moving) this.still++;
    else this.still = 0;
    const settled = this.still >= SETTLE_FRAMES;
    if (settled && !this.status.settled) this.status.info = this.describe(shown);
    this.status.settled = settled;
    document.getElementById('status').textContent = `${o.tileset}: ${tiles.visibleTiles.size} tiles, ${shown} ` +
      `splats shown, ${(this.bytes / 1e6).toFixed(2)} MB in ${this.requests} requests, error target ` +
      `${tiles.errorTarget.toFixed(2)} px${loading ? ', loading' : ''}`;
  }

  describe(shown) {
    return { tileset: this.opts.tileset, bytes: this.bytes, requests: this.requests, visibleTiles: this.tiles.visibleTiles.size,
      points: shown, errorTarget: this.tiles.errorTarget, total: this.total, frame: this.viewer.frame,
      firstFrame: this.status.firstFrame };
  }
}
