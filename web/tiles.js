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
// window.amgsplatViewer: ready at the first frame (firstFrame: bytes and requests fetched by then),
// settled once nothing loads and the visible set has not changed for a while (stream: the totals).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { TilesRenderer } from '3d-tiles-renderer/three';

const STILL_MS = 300; // the camera counts as moving until this long after its last change
const SETTLE_FRAMES = 20; // frames without loads or visibility changes before `settled`

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
      return new Response(body, { status: res.status, statusText: res.statusText, headers: res.headers });
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

  // Each tile's points with KHR_gaussian_splatting attributes become splats beside them.
  prepare(scene) {
    const v = this.viewer, found = [];
    let points = 0;
    scene.updateMatrixWorld(true);
    scene.traverse((o) => {
      if (!o.isPoints) return;
      points += o.geometry.attributes.position.count;
      o.material.size = this.opts.pointSize;
      if (o.geometry.attributes['khr_gaussian_splatting:rotation']) found.push(o);
    });
    const splats = found.map((p) => {
      const sp = v.splatPasses(p);
      p.parent.add(sp.mesh); // the centres hold the points' node transform (splatPasses)
      return sp;
    });
    scene.userData.amgsplat = { points, splats };
    v.splats.push(...splats);
  }

  dispose(scene) {
    const v = this.viewer, mine = scene.userData.amgsplat;
    if (!mine) return;
    v.splats = v.splats.filter((sp) => !mine.splats.includes(sp));
    for (const sp of mine.splats) {
      sp.mesh.geometry.dispose();
      sp.depth.dispose();
      sp.accum.dispose();
    }
    this.dirty = true;
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
