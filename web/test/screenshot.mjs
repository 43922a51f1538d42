// Screenshot of the web viewer in headless Chromium (docs/web.md):
//   node web/test/screenshot.mjs FILE.glb OUT.png [--view AZ,EL[,DIST]] [--size WxH] [--bg R,G,B]
//        [--method normalized|blend-all|gltf] [--light off|head] [--points splats|points] [--level NAME]
//        [--chromium PATH]
// Serves web/ and FILE's directory over a throwaway web/serve.mjs server on 127.0.0.1, opens index.html with the URL
// parameters, waits until the viewer reports ready, and writes the canvas as PNG. Exit 1 when the
// page reports an error (printed), 2 on usage errors.
import fs from 'node:fs';
import path from 'node:path';
import { launchChromium, parseArgs } from './browser.mjs';
import { serve } from '../serve.mjs';

const usage = 'usage: node web/test/screenshot.mjs FILE.glb OUT.png [--view AZ,EL[,DIST]] [--size WxH] ' +
  '[--bg R,G,B] [--method M] [--light off|head] [--points splats|points] [--level NAME] [--chromium PATH]';

async function main() {
  let o;
  try {
    o = parseArgs(process.argv.slice(2),
      { view: '30,20', size: '256x256', bg: '255,255,255', method: 'normalized', light: 'off', level: null, points: 'splats' },
      2, 'FILE.glb and OUT.png');
  } catch (e) {
    console.error(`screenshot: ${e.message}\n${usage}`);
    process.exit(2);
  }
  const [file, out] = o.pos;
  if (!fs.existsSync(file)) {
    console.error(`screenshot: cannot read '${file}'`);
    process.exit(1);
  }
  const [w, h] = o.size.split('x').map(Number);
  const server = await serve(path.resolve(path.dirname(file)));
  const { browser, userDir } = await launchChromium(o.chromium);
  let code = 0;
  try {
    const page = await browser.newPage();
    const logs = [];
    page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
    page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));
    await page.setViewport({ width: w, height: h, deviceScaleFactor: 1 });
    const q = new URLSearchParams({ file: `/model/${path.basename(file)}`, view: o.view, size: o.size, bg: o.bg,
      method: o.method, light: o.light, points: o.points, ui: '0' });
    if (o.level) q.set('level', o.level);
    const { port } = server.address();
    await page.goto(`http://127.0.0.1:${port}/index.html?${q}`, { waitUntil: 'load' });
    await page.waitForFunction('window.amgsplatViewer && window.amgsplatViewer.ready', { timeout: 60000 });
    const state = await page.evaluate(() => ({ error: window.amgsplatViewer.error, info: window.amgsplatViewer.info }));
    if (state.error) {
      console.error(`screenshot: the viewer failed: ${state.error}`);
      for (const l of logs) console.error(`  ${l}`);
      code = 1;
    } else {
      // the canvas's own pixels (preserveDrawingBuffer), as 8-bit RGBA PNG like amgsplat's images
      const url = await page.evaluate(() => document.querySelector('canvas').toDataURL('image/png'));
      fs.writeFileSync(out, Buffer.from(url.slice(url.indexOf(',') + 1), 'base64'));
      console.log(JSON.stringify({ output: out, size: [w, h], ...state.info }));
      if (process.env.ASP_WEB_DEBUG) for (const l of logs) console.error(`  ${l}`);
    }
  } finally {
    await browser.close();
    server.close();
    fs.rmSync(userDir, { recursive: true, force: true });
  }
  process.exit(code);
}

main().catch((e) => {
  console.error(`screenshot: ${e.message}`);
  process.exit(1);
});
