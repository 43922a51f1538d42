// The amgsplat glTF viewer (docs/web.md): opens a GLB from `amgsplat export`, frames it as
// `amgsplat render` does (src/render/camera.c: the recorded frame sphere, fov 40, azimuth/elevation
// orbit, near/far from the sphere) and blends domain primitives as the renderer's methods do
// (docs/render-methods.md): "normalized" (Pajarola et al. 2003 5.3-5.4: front layer, window,
// division) or "blend-all" (additive), in linear light; points are drawn as three.js points.
// URL: ?file=URL&view=AZ,EL[,DIST]&size=WxH&bg=R,G,B&level=NAME&method=M&light=off|head&points=splats|points&ui=0
// A 3D Tiles tileset from `amgsplat export --tiles` streams instead (tileset=URL, tiles.js):
// ?tileset=URL&error=PX&point-budget=N&...
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
// EXT_meshopt_compression (amgsplat export's default for points, docs/cli/export.md): the decoder
// three ships (meshoptimizer's WebAssembly decoder, filters included)
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { TileStream } from './tiles.js';
import { spzToPlainGlb } from './spz.js';

const status = { ready: false, error: null, info: null };
window.amgsplatViewer = status;

function numbers(text, min, max, what) {
  const v = text.split(',').map(Number);
  if (v.length < min || v.length > max || v.some((x) => !Number.isFinite(x)))
    throw new Error(`${what}: expected ${min === max ? min : `${min} to ${max}`} numbers, got '${text}'`);
  return v;
}

function parseParams() {
  const p = new URLSearchParams(location.search);
  const o = {
    file: p.get('file'),
    tileset: p.get('tileset'),
    errorTarget: 1.5, // pixels: the projected splat diameter a tile may show (the hierarchy's tau)
    pointBudget: 4000000, // splats drawn at most; the error target grows until the visible tiles fit
    moveFactor: 4, // while the camera moves, the error target x this: coarse tiles while moving
    view: [30, 20, 0], // amgsplat render's default --view
    size: null,
    bg: [255, 255, 255], // amgsplat render's default --background
    level: p.get('level'),
    method: p.get('method') || 'normalized',
    light: p.get('light') === 'head',
    ui: p.get('ui') !== '0',
    pointSize: 1,
    points: p.get('points') || 'splats',
  };
  if (p.get('view')) o.view = numbers(p.get('view'), 2, 3, 'view').concat([0]).slice(0, 3);
  if (p.get('size')) {
    const m = /^(\d+)x(\d+)$/.exec(p.get('size'));
    if (!m || +m[1] < 1 || +m[2] < 1) throw new Error(`size: expected WxH, got '${p.get('size')}'`);
    o.size = [+m[1], +m[2]];
  }
  if (p.get('bg')) o.bg = numbers(p.get('bg'), 3, 3, 'bg');
  if (p.get('error')) o.errorTarget = numbers(p.get('error'), 1, 1, 'error')[0];
  if (p.get('point-budget')) o.pointBudget = numbers(p.get('point-budget'), 1, 1, 'point-budget')[0];
  if (p.get('move-factor')) o.moveFactor = numbers(p.get('move-factor'), 1, 1, 'move-factor')[0];
  if (!(o.errorTarget > 0) || !(o.pointBudget >= 1) || !(o.moveFactor >= 1))
    throw new Error('error, point-budget and move-factor: expected error > 0, point-budget >= 1, move-factor >= 1');
  if (o.file && o.tileset) throw new Error('file and tileset: give one of them');
  if (p.get('point-size')) o.pointSize = numbers(p.get('point-size'), 1, 1, 'point-size')[0];
  if (!['normalized', 'blend-all', 'gltf'].includes(o.method))
    throw new Error(`method: expected normalized, blend-all or gltf, got '${o.method}'`);
  if (!['splats', 'points'].includes(o.points))
    throw new Error(`points: expected splats or points, got '${o.points}'`);
  if (p.get('light') && !['off', 'head'].includes(p.get('light')))
    throw new Error(`light: expected off or head, got '${p.get('light')}'`);
  return o;
}

// ---- shaders (GLSL ES 3.0 through glslVersion GLSL3; RawShaderMaterial: no colour conversion) ----

const quadVertex = `
in vec3 position;
in vec3 normal;
in vec4 tangent;
in vec2 uv;
uniform mat4 modelViewMatrix;
uniform mat4 projectionMatrix;
uniform mat3 normalMatrix;
out vec2 vUv;
out vec3 vEye;
out vec3 vNormal;
out vec4 vTangent;
void main() {
  vec4 e = modelViewMatrix * vec4(position, 1.0);
  vUv = uv;
  vEye = e.xyz;
  vNormal = normalMatrix * normal;
  vTangent = vec4(normalMatrix * tangent.xyz, tangent.w);
  gl_Position = projectionMatrix * e;
}`;

// pass 1 of normalized: the depth of the front-most alpha-tested layer (alpha > alphaRef)
const depthFragment = `
precision highp float;
uniform sampler2D map;
uniform float alphaRef;
in vec2 vUv;
out vec4 color;
void main() {
  if (!(texture(map, vUv).a > alphaRef)) discard;
  color = vec4(1.0);
}`;

// pass 2: (colour x alpha, alpha) of what lies within the window behind the front layer
// (prim_shaders.c selected(), distances along the eye ray), or of everything (blend-all)
const accumFragment = `
precision highp float;
uniform sampler2D map;
uniform sampler2D normalMap;
uniform sampler2D frontDepth;
uniform mat4 projectionMatrix;
uniform int uSelect;
uniform int uLit;
uniform int hasNormalMap;
uniform float uWindow;
in vec2 vUv;
in vec3 vEye;
in vec3 vNormal;
in vec4 vTangent;
out vec4 color;
float eyeDistanceZ(float depth) {
  return projectionMatrix[3][2] / ((2.0 * depth - 1.0) + projectionMatrix[2][2]);
}
bool selected() {
  if (uSelect == 0) return true;
  float front = texelFetch(frontDepth, ivec2(gl_FragCoord.xy), 0).r;
  if (!(front < 1.0)) return false;
  float mine = -vEye.z, theirs = eyeDistanceZ(front);
  float along = (mine - theirs) * length(vEye) / max(mine, 1e-30);
  return along <= uWindow + 1e-5 * length(vEye);
}
vec3 shade(vec3 rgb) {
  if (uLit == 0) return rgb;
  // the renderers' headlight: colour (0.25 + 0.75 |n . l|), l towards the eye
  vec3 n = vNormal;
  if (hasNormalMap != 0) {
    vec3 m = texture(normalMap, vUv).xyz * 2.0 - 1.0;
    vec3 b = cross(vNormal, vTangent.xyz) * vTangent.w;
    n = vTangent.xyz * m.x + b * m.y + vNormal * m.z;
  }
  float lambert = dot(n, n) > 0.0 ? abs(normalize(n).z) : 1.0;
  return rgb * (0.25 + 0.75 * lambert);
}
void main() {
  vec4 t = texture(map, vUv);
  if (!(t.a > 0.0)) discard;
  if (!selected()) discard;
  color = vec4(shade(t.rgb) * t.a, t.a);
}`;

// Points with KHR_gaussian_splatting ellipses, drawn as amgsplat's splat renderer draws seed 001's
// (src/render/splat_renderer.c): per splat the triangle around its ellipse (grown 5%), the ellipse
// = 2 sigma of the Gaussian (export.md); pass 1 writes the depth pushed epsilon = 1 major
// semi-axis away from the eye (5.3, Fig. 15), pass 2 adds (psi c, psi) of what lies in front of it
// with psi(r) = exp(-6 (r / 1.5)^3) cut at the rim (4.2, eq. 12), flat headlight per splat.
const splatVertex = `
in vec3 position;
in vec3 center;
in vec3 axisU;
in vec3 axisV;
in vec3 splatNormal;
in vec4 splatColor;
uniform mat4 modelViewMatrix;
uniform mat4 projectionMatrix;
uniform float uEpsilon;
uniform int uLit;
out vec2 vLocal;
out vec3 vColor;
void main() {
  vec2 q = position.xy * 1.05;
  // in eye space (the eye at 0): the model matrix (a tile's transform; identity for a GLB) is
  // rigid, so this is the push along the eye ray of the splat renderer
  vec3 e = (modelViewMatrix * vec4(center + q.x * axisU + q.y * axisV, 1.0)).xyz;
  if (uEpsilon > 0.0 && dot(e, e) > 0.0) e += uEpsilon * length(mat3(modelViewMatrix) * axisU) * normalize(e);
  vLocal = q;
  vec3 n = mat3(modelViewMatrix) * splatNormal;
  float shade = dot(n, n) > 0.0 ? 0.25 + 0.75 * abs(normalize(n).z) : 1.0;
  vColor = splatColor.rgb * (uLit != 0 ? shade : 1.0);
  gl_Position = projectionMatrix * vec4(e, 1.0);
}`;

const splatDepthFragment = `
precision highp float;
in vec2 vLocal;
in vec3 vColor;
out vec4 color;
void main() {
  if (dot(vLocal, vLocal) > 1.0) discard;
  color = vec4(1.0);
}`;

const splatAccumFragment = `
precision highp float;
uniform sampler2D frontDepth;
in vec2 vLocal;
in vec3 vColor;
out vec4 color;
void main() {
  if (dot(vLocal, vLocal) > 1.0) discard;
  // the depth test of pass 2 (LEQUAL against the pushed depth), done by hand
  float front = texelFetch(frontDepth, ivec2(gl_FragCoord.xy), 0).r;
  if (gl_FragCoord.z > front) discard;
  float r = min(length(vLocal), 1.0);
  float w = exp(-6.0 * pow(r / 1.5, 3.0));
  color = vec4(w * vColor, w);
}`;

const resolveVertex = `
in vec3 position;
void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }`;

// normalized: colour / alpha where alpha > 0; blend-all: the clamped sum over the background
// (docs/render-methods.md), then linear light to sRGB for the canvas
const resolveFragment = `
precision highp float;
uniform sampler2D accum;
uniform int uNormalize;
uniform vec3 background;
out vec4 color;
vec3 toSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
void main() {
  vec4 acc = texelFetch(accum, ivec2(gl_FragCoord.xy), 0);
  vec3 c;
  if (uNormalize != 0)
    c = acc.a > 0.0 ? acc.rgb / acc.a : background;
  else
    c = clamp(acc.rgb, 0.0, 1.0) + (1.0 - clamp(acc.a, 0.0, 1.0)) * background;
  color = vec4(toSrgb(c), 1.0);
}`;

// the streamed tiles' discs blend with the splats' passes (tiles.js)
// The two splat passes over one instanced mesh (render's splat renderer, seed 001 sections 4-5):
// pass 1 writes the front depth pushed back by uEpsilon, pass 2 adds (psi c, psi) without depth
// test; vertexShader places each splat (its ellipse here, a disc facing the eye in tiles.js).
export function splatMaterials(vertexShader, uniforms) {
  const common = { glslVersion: THREE.GLSL3, vertexShader, side: THREE.DoubleSide };
  const depth = new THREE.RawShaderMaterial({ ...common, fragmentShader: splatDepthFragment, uniforms });
  const accum = new THREE.RawShaderMaterial({
    ...common, fragmentShader: splatAccumFragment, uniforms,
    blending: THREE.CustomBlending, blendEquation: THREE.AddEquation, blendSrc: THREE.OneFactor,
    blendDst: THREE.OneFactor, blendSrcAlpha: THREE.OneFactor, blendDstAlpha: THREE.OneFactor,
    depthTest: false, depthWrite: false,
  });
  return { depth, accum };
}

function srgbToLinear(c) {
  const x = c / 255;
  return x <= 0.04045 ? x / 12.92 : Math.pow((x + 0.055) / 1.055, 2.4);
}

// ---- the viewer ----

class Viewer {
  constructor(opts) {
    this.opts = opts;
    this.renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(opts.size ? 1 : window.devicePixelRatio);
    this.renderer.autoClear = false;
    document.body.appendChild(this.renderer.domElement);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    this.scene = new THREE.Scene();
    this.gltf = null;
    this.prims = [];
    this.splats = [];
    this.frame = null;
    this.resize();
    window.addEventListener('resize', () => {
      if (!this.opts.size) {
        this.resize();
        this.render();
      }
    });
  }

  resize() {
    const [w, h] = this.opts.size || [window.innerWidth, window.innerHeight];
    this.renderer.setSize(w, h);
    const pw = Math.floor(w * this.renderer.getPixelRatio()), ph = Math.floor(h * this.renderer.getPixelRatio());
    this.front?.dispose();
    this.accum?.dispose();
    const depthTexture = new THREE.DepthTexture(pw, ph, THREE.FloatType);
    this.front = new THREE.WebGLRenderTarget(pw, ph, { depthBuffer: true, depthTexture });
    // half float: blendable wherever WebGL2 renders to float (EXT_color_buffer_float)
    this.accum = new THREE.WebGLRenderTarget(pw, ph, { type: THREE.HalfFloatType, depthBuffer: false });
    if (this.resolveMaterial) this.resolveMaterial.uniforms.accum.value = this.accum.texture;
    for (const p of this.prims) p.accum.uniforms.frontDepth.value = this.front.depthTexture;
  }

  async open(buffer, name, resourcePath = '') {
    const loader = new GLTFLoader();
    loader.setMeshoptDecoder(MeshoptDecoder);
    // SPZ splats (export --splat-codec spz, for CesiumJS) decoded to the float attributes three reads
    if (buffer instanceof ArrayBuffer) buffer = await spzToPlainGlb(buffer);
    const gltf = await loader.parseAsync(buffer, resourcePath);
    this.gltf = gltf;
    // an unlit material (KHR_materials_unlit) becomes a MeshBasicMaterial, which drops the
    // normalTexture: fetch those textures here for the headlight (light=head)
    this.normalMaps = new Map();
    const defs = gltf.parser.json.materials || [];
    for (let i = 0; i < defs.length; i++)
      if (defs[i].normalTexture) {
        const t = await gltf.parser.getDependency('texture', defs[i].normalTexture.index);
        t.colorSpace = THREE.NoColorSpace; // data, not colour
        this.normalMaps.set(i, t);
      }
    const levels = document.getElementById('level');
    levels.replaceChildren(...gltf.scenes.map((s, i) => new Option(s.name || `scene ${i}`, i)));
    let index = gltf.scenes.indexOf(gltf.scene);
    if (this.opts.level) {
      index = gltf.scenes.findIndex((s) => s.name === this.opts.level);
      if (index < 0)
        throw new Error(`no level '${this.opts.level}' (the file holds ${gltf.scenes.map((s) => s.name).join(', ')})`);
    }
    levels.value = String(Math.max(index, 0));
    this.name = name;
    this.show(Math.max(index, 0));
    this.name = name;
    status.info = { file: name, scenes: gltf.scenes.map((s) => s.name), ...this.describe() };
  }

  describe() {
    let primitives = 0, points = 0;
    for (const p of this.prims) primitives += p.count;
    this.scene.traverse((o) => {
      if (o.isPoints) points += o.geometry.attributes.position.count;
    });
    return { primitives, points, frame: this.frame };
  }

  // Shows one glTF scene (one level) in the scene's local frame: the origin in the node
  // translations is removed, so float precision is that of the offsets (UTM-size models).
  show(index) {
    const src = this.gltf.scenes[index];
    const extras = src.userData.amgsplat || {};
    const origin = new THREE.Vector3(...(extras.origin || [0, 0, 0]));
    this.scene = new THREE.Scene();
    this.scene.add(src);
    src.traverse((o) => {
      if (o.parent === src) o.position.sub(origin);
    });
    src.updateMatrixWorld(true);
    this.prims = [];
    src.traverse((o) => {
      if (o.isMesh && o.material && o.material.map) this.prims.push(this.primitivePasses(o));
      if (o.isPoints) o.material.size = this.opts.pointSize;
    });
    this.splats = [];
    src.traverse((o) => {
      if (o.isPoints && o.geometry.attributes['khr_gaussian_splatting:rotation']) this.splats.push(this.splatPasses(o));
    });
    for (const sp of this.splats) src.add(sp.mesh);
    // a billboard cloud (simplify --billboards, issue 30) is drawn as its material says: alpha-tested
    // (MASK), depth-tested, never blended or normalised, whatever the method
    this.billboards = this.prims.some((p) => (p.mesh.userData.amgsplat || {}).billboards);
    if (extras.frame && extras.frame.radius > 0) {
      const c = new THREE.Vector3(...extras.frame.center).sub(origin);
      this.frame = { center: c, radius: extras.frame.radius };
    } else {
      const sphere = new THREE.Box3().setFromObject(src).getBoundingSphere(new THREE.Sphere());
      this.frame = { center: sphere.center, radius: sphere.radius || 1 };
    }
    this.fit();
    this.render();
    const d = this.describe();
    document.getElementById('status').textContent =
      `${this.name || ''} ${src.name || ''}: ${d.primitives} primitives, ${d.points} points`;
  }

  primitivePasses(mesh) {
    const gltfMaterial = mesh.material;
    const extras = mesh.userData.amgsplat || {};
    const map = gltfMaterial.map;
    // a tileset's tiles (tiles.js) come without this.gltf: their unlit materials keep no normal map
    const assoc = this.gltf && this.gltf.parser.associations.get(gltfMaterial);
    const normalMap = (assoc && this.normalMaps.get(assoc.materials)) || gltfMaterial.normalMap || null;
    const depth = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3,
      vertexShader: quadVertex,
      fragmentShader: depthFragment,
      uniforms: { map: { value: map }, alphaRef: { value: extras.alphaRef ?? 0.1 } },
      side: THREE.FrontSide, // back faces are left out of both passes (render-methods.md)
    });
    const accum = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3,
      vertexShader: quadVertex,
      fragmentShader: accumFragment,
      uniforms: {
        map: { value: map },
        normalMap: { value: normalMap || map },
        hasNormalMap: { value: normalMap ? 1 : 0 },
        frontDepth: { value: this.front.depthTexture },
        uSelect: { value: 1 },
        uLit: { value: 0 },
        uWindow: { value: extras.depthWindow ?? 0 },
      },
      blending: THREE.CustomBlending,
      blendEquation: THREE.AddEquation,
      blendSrc: THREE.OneFactor,
      blendDst: THREE.OneFactor,
      blendSrcAlpha: THREE.OneFactor,
      blendDstAlpha: THREE.OneFactor,
      depthTest: false,
      depthWrite: false,
      side: THREE.FrontSide,
    });
    return { mesh, gltf: gltfMaterial, depth, accum, count: mesh.geometry.index.count / 6 };
  }

  // The splats of a points node: per point its ellipse axes u a, v b from the Gaussian
  // (rotation columns x, y; semi-axes 2 sigma, export.md), colour (linear), normal. Attributes are
  // read through getX.. (which undo KHR_mesh_quantization's normalized integers); the centres and
  // the axes get the node's transform here (translation, and the scale that undoes the 16-bit
  // positions: SCALE is in the node's units, as every glTF attribute), as the splat shader works
  // in the scene's frame without a model matrix.
  splatPasses(points) {
    const g = points.geometry, n = g.attributes.position.count;
    const rot = g.attributes['khr_gaussian_splatting:rotation'], scale = g.attributes['khr_gaussian_splatting:scale'];
    const P = g.attributes.position, N = g.attributes.normal, at = new THREE.Vector3();
    points.updateMatrix();
    const linear = new THREE.Matrix3().setFromMatrix4(points.matrix), axis = new THREE.Vector3();
    const U = new Float32Array(3 * n), V = new Float32Array(3 * n), C = new Float32Array(4 * n);
    const centers = new Float32Array(3 * n), normals = new Float32Array(3 * n);
    for (let i = 0; i < n; i++) {
      centers.set(at.fromBufferAttribute(P, i).applyMatrix4(points.matrix).toArray(), 3 * i);
      if (N) normals.set([N.getX(i), N.getY(i), N.getZ(i)], 3 * i);
      const x = rot.getX(i), y = rot.getY(i), z = rot.getZ(i), w = rot.getW(i);
      const a = 2 * Math.exp(scale.getX(i)), b = 2 * Math.exp(scale.getY(i));
      axis.set((1 - 2 * (y * y + z * z)) * a, 2 * (x * y + w * z) * a, 2 * (x * z - w * y) * a);
      U.set(axis.applyMatrix3(linear).toArray(), 3 * i);
      axis.set(2 * (x * y - w * z) * b, (1 - 2 * (x * x + z * z)) * b, 2 * (y * z + w * x) * b);
      V.set(axis.applyMatrix3(linear).toArray(), 3 * i);
      const c = g.attributes.color;
      C.set(c ? [c.getX(i), c.getY(i), c.getZ(i), 1] : [0.578, 0.578, 0.578, 1], 4 * i);
    }
    const geo = new THREE.InstancedBufferGeometry();
    // the equilateral triangle around the unit circle (splat_renderer.c)
    geo.setAttribute('position', new THREE.Float32BufferAttribute([-1.7320508, -1, 0, 1.7320508, -1, 0, 0, 2, 0], 3));
    geo.setAttribute('center', new THREE.InstancedBufferAttribute(centers, 3));
    geo.setAttribute('axisU', new THREE.InstancedBufferAttribute(U, 3));
    geo.setAttribute('axisV', new THREE.InstancedBufferAttribute(V, 3));
    geo.setAttribute('splatNormal', new THREE.InstancedBufferAttribute(normals, 3));
    geo.setAttribute('splatColor', new THREE.InstancedBufferAttribute(C, 4));
    geo.instanceCount = n;
    const uniforms = { uEpsilon: { value: 1 }, uLit: { value: 0 },
      frontDepth: { value: this.front.depthTexture } };
    const { depth, accum } = splatMaterials(splatVertex, uniforms);
    const mesh = new THREE.Mesh(geo, depth);
    mesh.frustumCulled = false;
    // at the identity: the centres already hold the node's transform (the shader takes the model matrix of
    // whatever holds the mesh: a tile's transform in tiles.js)
    return { mesh, points, depth, accum, uniforms };
  }

  // asp_camera_fit + orbit_axes (src/render/camera.c), y up
  fit() {
    const [az, el, dist] = this.opts.view.map((x, i) => (i < 2 ? (x * Math.PI) / 180 : x));
    const { center, radius } = this.frame;
    const [w, h] = this.opts.size || [window.innerWidth, window.innerHeight];
    const aspect = w / h;
    const halfY = (0.5 * 40 * Math.PI) / 180;
    const halfX = Math.atan(Math.tan(halfY) * aspect);
    const d = dist > 0 ? dist * radius : radius / Math.sin(Math.min(halfX, halfY));
    const back = new THREE.Vector3(Math.cos(el) * Math.sin(az), Math.sin(el), Math.cos(el) * Math.cos(az));
    const up = new THREE.Vector3(-Math.sin(el) * Math.sin(az), Math.cos(el), -Math.sin(el) * Math.cos(az));
    this.camera.fov = 40;
    this.camera.aspect = aspect;
    this.camera.position.copy(center).addScaledVector(back, d);
    this.camera.up.copy(up);
    this.camera.lookAt(center);
    this.controls.target.copy(center);
    this.clip();
  }

  // asp_camera_clip_to_sphere: near/far around the frame sphere from the current eye
  clip() {
    const { center, radius } = this.frame;
    const d = this.camera.position.distanceTo(center);
    this.camera.near = Math.max(0.99 * (d - radius), 1e-3 * (d + radius));
    this.camera.far = 1.01 * (d + radius);
    if (!(this.camera.far > this.camera.near)) this.camera.far = 2 * this.camera.near;
    this.camera.updateProjectionMatrix();
  }

  render() {
    if (!this.frame) return;
    this.clip();
    const r = this.renderer, o = this.opts;
    const bg = new THREE.Color().setRGB(o.bg[0] / 255, o.bg[1] / 255, o.bg[2] / 255, THREE.SRGBColorSpace);
    const splatting = this.splats.length > 0 && o.points === 'splats';
    for (const sp of this.splats) {
      sp.mesh.visible = splatting;
      sp.points.visible = !splatting;
    }
    if (splatting) {
      this.scene.background = null;
      for (const sp of this.splats) {
        sp.uniforms.uLit.value = o.light ? 1 : 0;
        sp.uniforms.frontDepth.value = this.front.depthTexture;
        sp.uniforms.uEpsilon.value = 1;
        sp.mesh.material = sp.depth;
      }
      r.setRenderTarget(this.front);
      r.setClearColor(0x000000, 0);
      r.clear(true, true, false);
      r.render(this.scene, this.camera);
      for (const sp of this.splats) {
        sp.uniforms.uEpsilon.value = 0;
        sp.mesh.material = sp.accum;
      }
      r.setRenderTarget(this.accum);
      r.clear(true, false, false);
      r.render(this.scene, this.camera);
      this.resolve(true);
      return;
    }
    if (this.prims.length === 0 || o.method === 'gltf' || this.billboards) {
      for (const p of this.prims) p.mesh.material = p.gltf;
      this.scene.background = bg;
      r.setRenderTarget(null);
      r.clear();
      r.render(this.scene, this.camera);
      return;
    }
    this.scene.background = null;
    const normalized = o.method === 'normalized';
    if (normalized) {
      for (const p of this.prims) p.mesh.material = p.depth;
      r.setRenderTarget(this.front);
      r.setClearColor(0x000000, 0);
      r.clear(true, true, false);
      r.render(this.scene, this.camera);
    }
    for (const p of this.prims) {
      p.mesh.material = p.accum;
      p.accum.uniforms.uSelect.value = normalized ? 1 : 0;
      p.accum.uniforms.uLit.value = o.light ? 1 : 0;
      // blend-all: no culling, every face adds (thesis appendix C)
      p.accum.side = normalized ? THREE.FrontSide : THREE.DoubleSide;
    }
    r.setRenderTarget(this.accum);
    r.setClearColor(0x000000, 0);
    r.clear(true, false, false);
    r.render(this.scene, this.camera);
    this.resolve(normalized);
  }

  // the last pass of both: accumulated sums onto the background, in sRGB
  resolve(normalized) {
    const r = this.renderer, o = this.opts;
    if (!this.resolveMaterial) {
      this.resolveMaterial = new THREE.RawShaderMaterial({
        glslVersion: THREE.GLSL3,
        vertexShader: resolveVertex,
        fragmentShader: resolveFragment,
        uniforms: { accum: { value: this.accum.texture }, uNormalize: { value: 1 }, background: { value: new THREE.Vector3() } },
        depthTest: false,
        depthWrite: false,
      });
      this.quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), this.resolveMaterial);
      this.quad.frustumCulled = false;
      this.quadScene = new THREE.Scene();
      this.quadScene.add(this.quad);
      this.quadCamera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
    }
    this.resolveMaterial.uniforms.uNormalize.value = normalized ? 1 : 0;
    this.resolveMaterial.uniforms.background.value.set(...o.bg.map(srgbToLinear));
    r.setRenderTarget(null);
    r.clear();
    r.render(this.quadScene, this.quadCamera);
  }
}

async function fetchBytes(url) {
  const res = await fetch(url);
  if (!res.ok) throw new Error(`cannot fetch '${url}': HTTP ${res.status}`);
  return res.arrayBuffer();
}

function fail(e) {
  status.error = String(e && e.message ? e.message : e);
  document.getElementById('status').textContent = `error: ${status.error}`;
  console.error(e);
}

async function main() {
  const opts = parseParams();
  if (!opts.ui) document.getElementById('panel').classList.add('hidden');
  document.getElementById('method').value = opts.method;
  document.getElementById('light').checked = opts.light;
  const viewer = new Viewer(opts);
  window.amgsplatViewer.viewer = viewer;
  document.getElementById('method').onchange = (e) => {
    opts.method = e.target.value;
    viewer.render();
  };
  document.getElementById('light').onchange = (e) => {
    opts.light = e.target.checked;
    viewer.render();
  };
  document.getElementById('splats').checked = opts.points === 'splats';
  document.getElementById('splats').onchange = (e) => {
    opts.points = e.target.checked ? 'splats' : 'points';
    viewer.render();
  };
  document.getElementById('level').onchange = (e) => viewer.gltf && viewer.show(+e.target.value);
  const openFile = (file) =>
    file.arrayBuffer().then((b) => viewer.open(b, file.name)).catch(fail);
  document.getElementById('picker').onchange = (e) => e.target.files[0] && openFile(e.target.files[0]);
  const drop = document.getElementById('drop');
  window.addEventListener('dragover', (e) => {
    e.preventDefault();
    drop.classList.add('on');
  });
  window.addEventListener('dragleave', () => drop.classList.remove('on'));
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('on');
    if (e.dataTransfer.files[0]) openFile(e.dataTransfer.files[0]);
  });
  if (opts.tileset) {
    // streaming: ready at the first frame; window.amgsplatViewer.settled once refined (tiles.js)
    await new TileStream(viewer, opts, status).start();
  } else if (opts.file) {
    const base = opts.file.slice(0, opts.file.lastIndexOf('/') + 1);
    await viewer.open(await fetchBytes(opts.file), opts.file, base);
  }
  status.ready = true;
}

main().catch((e) => {
  fail(e);
  status.ready = true;
});
