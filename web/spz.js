// SPZ-compressed Gaussian splats (KHR_gaussian_splatting_compression_spz_2, `amgsplat export
// --splat-codec spz`, docs/web.md "Cesium and SPZ") for the page: three.js's GLTFLoader does not
// know the extension, so spzToPlainGlb rewrites such a GLB before it parses it: every SPZ stream is
// gunzipped (the browser's DecompressionStream) and decoded to the float attributes the page's
// other exports carry (POSITION, NORMAL = the rotation's third axis, COLOR_0 linear,
// KHR_gaussian_splatting ROTATION, SCALE = ln sigma, OPACITY, SH_DEGREE_0_COEF_0), appended to the
// binary chunk; the extension leaves the primitive and the extension lists. SPZ version 2 as Niantic
// describes it (nianticlabs/spz README, the gzip layout): a 16-byte header (magic NGSP, version,
// count, SH degree, fractional bits, flags), then positions (24-bit fixed point), alphas, colours
// (SH DC * 0.15 * 255 + 127.5), scales ((ln sigma + 10) * 16) and rotations (x, y, z of the unit
// quaternion with w >= 0, q * 127.5 + 127.5).

const EXT = 'KHR_gaussian_splatting_compression_spz_2';
const SH_C0 = 0.28209479177387814;

async function gunzip(bytes) {
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

const srgbToLinear = (x) => (x <= 0.04045 ? x / 12.92 : Math.pow((x + 0.055) / 1.055, 2.4));

// The splats of one SPZ stream as float arrays; throws on what this decoder does not read.
export async function decodeSpz(gz) {
  const raw = await gunzip(gz);
  const dv = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
  if (raw.byteLength < 16 || dv.getUint32(0, true) !== 0x5053474e) throw new Error('SPZ: no NGSP header');
  const version = dv.getUint32(4, true), n = dv.getUint32(8, true), shDegree = raw[12], bits = raw[13];
  if (version !== 2) throw new Error(`SPZ: version ${version} (this page reads version 2, what amgsplat writes)`);
  const shDim = [0, 3, 8, 15][shDegree];
  if (shDim === undefined) throw new Error(`SPZ: SH degree ${shDegree}`);
  const need = 16 + n * (9 + 1 + 3 + 3 + 3 + 3 * shDim);
  if (raw.byteLength < need) throw new Error(`SPZ: ${raw.byteLength} bytes for ${n} splats, ${need} needed`);
  const pos = raw.subarray(16), alpha = pos.subarray(9 * n), color = alpha.subarray(n);
  const scale = color.subarray(3 * n), rot = scale.subarray(3 * n);
  const out = {
    count: n, positions: new Float32Array(3 * n), rotations: new Float32Array(4 * n), scales: new Float32Array(3 * n),
    opacities: new Float32Array(n), sh0: new Float32Array(3 * n),
  };
  const unit = 1 / (1 << bits);
  for (let i = 0; i < n; i++) {
    for (let k = 0; k < 3; k++) {
      const b = 9 * i + 3 * k;
      let v = pos[b] | (pos[b + 1] << 8) | (pos[b + 2] << 16);
      if (v & 0x800000) v -= 0x1000000; // 24-bit two's complement
      out.positions[3 * i + k] = v * unit;
      out.sh0[3 * i + k] = (color[3 * i + k] / 255 - 0.5) / 0.15;
      out.scales[3 * i + k] = scale[3 * i + k] / 16 - 10;
    }
    out.opacities[i] = alpha[i] / 255;
    const x = rot[3 * i] / 127.5 - 1, y = rot[3 * i + 1] / 127.5 - 1, z = rot[3 * i + 2] / 127.5 - 1;
    out.rotations.set([x, y, z, Math.sqrt(Math.max(0, 1 - x * x - y * y - z * z))], 4 * i);
  }
  return out;
}

// The GLB in buffer (ArrayBuffer) with its SPZ streams decoded, or buffer itself when it has none.
export async function spzToPlainGlb(buffer) {
  const dv = new DataView(buffer);
  if (buffer.byteLength < 20 || dv.getUint32(0, true) !== 0x46546c67) {
    // a .gltf (JSON): its streams lie in other files, which this rewrite does not fetch
    const text = new TextDecoder().decode(new Uint8Array(buffer, 0, Math.min(buffer.byteLength, 1 << 20)));
    if (text.includes(EXT)) throw new Error(`${EXT}: the page decodes SPZ in .glb files only (export to .glb)`);
    return buffer;
  }
  const jsonLength = dv.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 20, jsonLength)));
  if (!(json.extensionsUsed || []).includes(EXT)) return buffer;
  const binStart = 20 + jsonLength + 8;
  const bin = binStart <= buffer.byteLength ? new Uint8Array(buffer, binStart, dv.getUint32(20 + jsonLength, true)) : new Uint8Array(0);
  const pieces = [bin];
  let binLength = bin.byteLength;
  const append = (array, type, count, extra = {}) => { // a tightly packed float view and its accessor
    const pad = (4 - (binLength % 4)) % 4;
    if (pad) pieces.push(new Uint8Array(pad));
    binLength += pad;
    const bytes = new Uint8Array(array.buffer, array.byteOffset, array.byteLength);
    json.bufferViews.push({ buffer: 0, byteOffset: binLength, byteLength: bytes.byteLength, target: 34962 });
    pieces.push(bytes);
    binLength += bytes.byteLength;
    json.accessors.push({ bufferView: json.bufferViews.length - 1, componentType: 5126, count, type, ...extra });
    return json.accessors.length - 1;
  };
  for (const mesh of json.meshes || []) {
    for (const pr of mesh.primitives) {
      const k = pr.extensions?.KHR_gaussian_splatting;
      const spz = k?.extensions?.[EXT];
      if (!spz) continue;
      const view = json.bufferViews[spz.bufferView];
      const s = await decodeSpz(bin.subarray(view.byteOffset || 0, (view.byteOffset || 0) + view.byteLength));
      const n = s.count, normals = new Float32Array(3 * n), colors = new Float32Array(4 * n);
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      for (let i = 0; i < n; i++) {
        const [x, y, z, w] = s.rotations.subarray(4 * i, 4 * i + 4);
        // the Gaussian's flat axis: the rotation's third column (amgsplat's splat normal)
        normals.set([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], 3 * i);
        for (let c = 0; c < 3; c++) {
          const display = Math.min(Math.max(0.5 + SH_C0 * s.sh0[3 * i + c], 0), 1);
          colors[4 * i + c] = srgbToLinear(display); // glTF colours are linear
          lo[c] = Math.min(lo[c], s.positions[3 * i + c]);
          hi[c] = Math.max(hi[c], s.positions[3 * i + c]);
        }
        colors[4 * i + 3] = s.opacities[i];
      }
      // SPZ's SH DC uses its own scale; KHR_gaussian_splatting's SH0 is the same coefficient
      pr.attributes = {
        POSITION: append(s.positions, 'VEC3', n, { min: lo, max: hi }),
        NORMAL: append(normals, 'VEC3', n),
        COLOR_0: append(colors, 'VEC4', n),
        'KHR_gaussian_splatting:ROTATION': append(s.rotations, 'VEC4', n),
        'KHR_gaussian_splatting:SCALE': append(s.scales, 'VEC3', n),
        'KHR_gaussian_splatting:OPACITY': append(s.opacities, 'SCALAR', n),
        'KHR_gaussian_splatting:SH_DEGREE_0_COEF_0': append(s.sh0, 'VEC3', n),
      };
      delete k.extensions;
    }
  }
  for (const list of ['extensionsUsed', 'extensionsRequired']) {
    if (json[list]) json[list] = json[list].filter((e) => e !== EXT && !(list === 'extensionsRequired' && e === 'KHR_gaussian_splatting'));
  }
  json.buffers[0].byteLength = binLength;
  const jsonBytes = new TextEncoder().encode(JSON.stringify(json));
  const jsonPadded = (jsonBytes.byteLength + 3) & ~3, binPadded = (binLength + 3) & ~3;
  const out = new Uint8Array(12 + 8 + jsonPadded + 8 + binPadded);
  const o = new DataView(out.buffer);
  o.setUint32(0, 0x46546c67, true);
  o.setUint32(4, 2, true);
  o.setUint32(8, out.byteLength, true);
  o.setUint32(12, jsonPadded, true);
  o.setUint32(16, 0x4e4f534a, true); // JSON
  out.fill(0x20, 20, 20 + jsonPadded);
  out.set(jsonBytes, 20);
  o.setUint32(20 + jsonPadded, binPadded, true);
  o.setUint32(24 + jsonPadded, 0x004e4942, true); // BIN
  let at = 28 + jsonPadded;
  for (const p of pieces) {
    out.set(p, at);
    at += p.byteLength;
  }
  return out.buffer;
}
