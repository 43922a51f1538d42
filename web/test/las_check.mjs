// Independent LAS reader check: parses FILE.las with @loaders.gl/las (not amgsplat's reader)
// and prints what it found as one JSON line: count, world bounds (double), the first and last
// colours as 8-bit RGBA, the first and last intensity and classification, the version and format.
// usage: node web/test/las_check.mjs FILE.las     (exit 3 when loaders.gl cannot read the file)
import { readFile } from 'node:fs/promises';
import { dirname, join } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { parse } from '@loaders.gl/core';
import { LAZRsLoader } from '@loaders.gl/las';

// The laz-rs (Rust, WebAssembly) loader of @loaders.gl/las 4.5 reads LAS 1.0-1.4 and formats 0-10;
// the default laz-perf one stops at 1.3. Its wasm is fetched by URL, which Node's fetch cannot do for
// file: URLs, so it is initialised here from the file's bytes.
const lasDir = dirname(fileURLToPath(import.meta.resolve('@loaders.gl/las')));
const wasmDir = join(lasDir, 'libs', 'laz-rs-wasm');
const initWasm = (await import(pathToFileURL(join(wasmDir, 'laz_rs_wasm.js')).href)).default;
await initWasm({ module_or_path: await readFile(join(wasmDir, 'laz_rs_wasm_bg.wasm')) });

const path = process.argv[2];
if (!path) {
  console.error('usage: node web/test/las_check.mjs FILE.las');
  process.exit(2);
}
const bytes = await readFile(path);
let mesh;
try {
  // fp64: world coordinates in double, as amgsplat's origin + offset; colorDepth 'auto': the high byte
  // when a value exceeds 255, as amgsplat's reader does (docs/las.md)
  mesh = await parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), LAZRsLoader, {
    worker: false,
    las: { fp64: true, colorDepth: 'auto', shape: 'mesh' },
  });
} catch (e) {
  console.log(JSON.stringify({ error: String(e && e.message ? e.message : e) }));
  process.exit(3);
}
const pos = mesh.attributes.POSITION.value;
const n = pos.length / 3;
const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
for (let i = 0; i < n; i++)
  for (let k = 0; k < 3; k++) {
    const v = pos[3 * i + k];
    if (v < min[k]) min[k] = v;
    if (v > max[k]) max[k] = v;
  }
const col = mesh.attributes.COLOR_0 ? mesh.attributes.COLOR_0.value : null;
const rgba = (i) => (col && n ? Array.from(col.slice(4 * i, 4 * i + 4)) : null);
const first = (name, i) => (mesh.attributes[name] && n ? mesh.attributes[name].value[i] : null);
const hdr = mesh.loaderData || {};
console.log(JSON.stringify({
  count: n,
  header_count: hdr.pointsCount ?? null,
  format: hdr.pointsFormatId ?? null,
  version: hdr.versionAsString ?? null,
  min, max,
  first_color: rgba(0), last_color: rgba(n - 1),
  first_position: n ? Array.from(pos.slice(0, 3)) : null,
  last_position: n ? Array.from(pos.slice(3 * (n - 1), 3 * n)) : null,
  intensity: [first('intensity', 0), first('intensity', n - 1)],
  classification: [first('classification', 0), first('classification', n - 1)],
}));
