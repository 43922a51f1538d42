// CesiumJS reads an `amgsplat export --tiles` tileset (docs/web.md): opens web/cesium.html in
// headless Chromium on DIR/tileset.json, waits until Cesium3DTileset has loaded every tile the view
// needs, and fails on any error: a tile that did not load, a render error, a page error or an error
// on the console.
//   node web/test/cesium.mjs DIR [--size WxH] [--sse PX] [--png OUT.png] [--timeout S] [--chromium PATH]
// Prints one JSON line {loaded, failed, ...}. Exit 1 on an error, 2 on usage errors.
import fs from 'node:fs';
import path from 'node:path';
import { launchChromium, parseArgs, watchPage } from './browser.mjs';
import { serve } from '../serve.mjs';

const usage = 'usage: node web/test/cesium.mjs DIR [--size WxH] [--sse PX] [--png OUT.png] [--timeout S] [--chromium PATH]';

async function main() {
  let o;
  try {
    o = parseArgs(process.argv.slice(2), { size: '320x240', sse: '2', png: null, timeout: '300' }, 1, 'DIR');
  } catch (e) {
    console.error(`cesium: ${e.message}\n${usage}`);
    process.exit(2);
  }
  const dir = o.pos[0];
  if (!fs.existsSync(path.join(dir, 'tileset.json'))) {
    console.error(`cesium: cannot read '${path.join(dir, 'tileset.json')}'`);
    process.exit(1);
  }
  const [w, h] = o.size.split('x').map(Number);
  const server = await serve(path.resolve(dir));
  const { browser, userDir } = await launchChromium(o.chromium, o.timeout);
  let code = 0;
  const errors = [], logs = [];
  try {
    const page = await browser.newPage();
    watchPage(page, errors, logs);
    await page.setViewport({ width: w, height: h, deviceScaleFactor: 1 });
    const { port } = server.address();
    const q = new URLSearchParams({ tileset: '/model/tileset.json', sse: o.sse });
    await page.goto(`http://127.0.0.1:${port}/cesium.html?${q}`, { waitUntil: 'load' });
    await page.waitForFunction('window.amgsplatCesium && (window.amgsplatCesium.ready || window.amgsplatCesium.errors.length)',
      { timeout: 1000 * Number(o.timeout) });
    const s = await page.evaluate(() => window.amgsplatCesium);
    errors.push(...s.errors);
    if (o.png) await page.screenshot({ path: o.png });
    console.log(JSON.stringify({ loaded: s.loaded, failed: s.failed, errors: errors.length, ...s.info }));
    if (errors.length || !(s.loaded > 0)) {
      code = 1;
      console.error(`cesium: ${errors.length} errors, ${s.loaded} tiles loaded`);
      for (const e of errors) console.error(`  ${e}`);
    }
  } catch (e) {
    console.error(`cesium: ${e.message}`);
    for (const e2 of errors) console.error(`  ${e2}`);
    code = 1;
  } finally {
    if (process.env.ASP_WEB_DEBUG) for (const l of logs) console.error(`  ${l}`);
    await browser.close();
    server.close();
    fs.rmSync(userDir, { recursive: true, force: true });
  }
  process.exit(code);
}

main().catch((e) => {
  console.error(`cesium: ${e.message}`);
  process.exit(1);
});
