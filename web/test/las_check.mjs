// Independent LAS reader check: parses FILE.las with @loaders.gl/las (not amgsplat's reader)
// and prints what it found as one JSON line: count, world bounds (double), the first and last
// colours as 8-bit RGBA, the first and last intensity and classification, the version and format.
// usage: node web/test/las_check.mjs FILE.las     (exit 3 when loaders.gl cannot read the file)
import { readFile } from 'node:fs/promises';
import { parse } from '@loaders.gl/core';
import { LASLoader } from '@loaders.gl/las';

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
  mesh = await parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), LASLoader, {
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
