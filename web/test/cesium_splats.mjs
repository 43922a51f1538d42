// CesiumJS draws an `amgsplat export --tiles --splat-codec spz` tileset as Gaussian splats (docs/web.md
// "Cesium and SPZ"): opens web/test/cesium_splats.html in headless Chromium on DIR/tileset.json with
// the camera of `amgsplat render --view AZ,EL`, waits until every tile has loaded and the drawn
// image has settled (Cesium sorts and uploads the splats over a few frames), writes the canvas as
// PNG and fails on any error (a tile that did not load, a render error, a page or console error)
// or when the canvas shows no splats.
//   node web/test/cesium_splats.mjs DIR OUT.png [--view AZ,EL] [--size WxH] [--bg R,G,B] [--min-fg F]
//        [--timeout S] [--chromium PATH]
// Prints one JSON line {loaded, failed, errors, fg, ...}; fg is the fraction of pixels off the
// background. Exit 1 on an error or fg < min-fg (default 0.02), 2 on usage errors.
import fs from 'node:fs';
import path from 'node:path';
import { launchChromium, parseArgs, watchPage } from './browser.mjs';
import { serve } from '../serve.mjs';

const usage = 'usage: node web/test/cesium_splats.mjs DIR OUT.png [--view AZ,EL] [--size WxH] [--bg R,G,B] ' +
  '[--min-fg F] [--timeout S] [--chromium PATH]';

async function main() {
  let o;
  try {
    o = parseArgs(process.argv.slice(2),
      { view: '30,20', size: '256x256', bg: '255,255,255', 'min-fg': '0.02', timeout: '300' }, 2, 'DIR and OUT.png');
  } catch (e) {
    console.error(`cesium_splats: ${e.message}\n${usage}`);
    process.exit(2);
  }
  const [dir, out] = o.pos;
  if (!fs.existsSync(path.join(dir, 'tileset.json'))) {
    console.error(`cesium_splats: cannot read '${path.join(dir, 'tileset.json')}'`);
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
    const q = new URLSearchParams({ tileset: '/model/tileset.json', view: o.view, bg: o.bg });
    if (process.env.ASP_WEB_DEBUG) q.set('boxes', '1');
    await page.goto(`http://127.0.0.1:${port}/test/cesium_splats.html?${q}`, { waitUntil: 'load' });
    await page.waitForFunction('window.amgsplatCesium && (window.amgsplatCesium.ready || window.amgsplatCesium.errors.length)',
      { timeout: 1000 * Number(o.timeout) });
    // the fraction of canvas pixels off the background, polled until two readings 1 s apart agree
    // (Cesium builds the splat textures and sorts them in a worker after the tiles load)
    const bg = o.bg.split(',').map(Number);
    const fgOf = () => page.evaluate((bgc) => {
      const c = document.querySelector('#cesium canvas');
      const t = document.createElement('canvas');
      [t.width, t.height] = [c.width, c.height];
      const x = t.getContext('2d');
      x.drawImage(c, 0, 0);
      const d = x.getImageData(0, 0, t.width, t.height).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4)
        if (Math.abs(d[i] - bgc[0]) + Math.abs(d[i + 1] - bgc[1]) + Math.abs(d[i + 2] - bgc[2]) > 24) n++;
      return n / (t.width * t.height);
    }, bg);
    let fg = -1, prev = -2;
    const deadline = Date.now() + 1000 * Number(o.timeout);
    const failed = () => page.evaluate(() => window.amgsplatCesium.errors.length > 0);
    while (Date.now() < deadline && !(fg > 0 && Math.abs(fg - prev) < 0.002) && !errors.length && !(await failed())) {
      await new Promise((r) => setTimeout(r, 1000));
      [prev, fg] = [fg, await fgOf()];
    }
    const s = await page.evaluate(() => window.amgsplatCesium);
    errors.push(...s.errors);
    await page.screenshot({ path: out });
    console.log(JSON.stringify({ output: out, loaded: s.loaded, failed: s.failed, errors: errors.length,
      fg: +fg.toFixed(4), ...s.info }));
    if (errors.length || !(s.loaded > 0) || !(fg >= Number(o['min-fg']))) {
      code = 1;
      console.error(`cesium_splats: ${errors.length} errors, ${s.loaded} tiles loaded, ${(100 * fg).toFixed(2)}% ` +
        `of the canvas drawn (at least ${100 * Number(o['min-fg'])}% expected)`);
      for (const e of errors) console.error(`  ${e}`);
    }
  } catch (e) {
    console.error(`cesium_splats: ${e.message}`);
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
  console.error(`cesium_splats: ${e.message}`);
  process.exit(1);
});
