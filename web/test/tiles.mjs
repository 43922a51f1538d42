// The streamed tileset in headless Chromium (docs/web.md): opens the viewer on DIR/tileset.json
// from `amgsplat export --tiles`, saves the first frame and the picture once refinement has
// settled, and prints what was fetched for each:
//   node web/test/tiles.mjs DIR OUT_PREFIX [--view AZ,EL[,DIST]] [--size WxH] [--bg R,G,B]
//        [--light off|head] [--error PX] [--point-budget N] [--timeout S] [--chromium PATH]
// writes OUT_PREFIX_first.png and OUT_PREFIX_refined.png; prints one JSON line: tileset_bytes (every
// file under DIR), first_frame {bytes (the page's count), server_bytes (the server's, read when the
// page reported its first frame, before it requests more), requests, ms}, refined {bytes, requests, tiles, points,
// error_target}. Exit 1 when the page reports an error or does not settle in time, 2 on usage errors.
import fs from 'node:fs';
import path from 'node:path';
import { launchChromium, parseArgs } from './browser.mjs';
import { serve } from '../serve.mjs';

const usage = 'usage: node web/test/tiles.mjs DIR OUT_PREFIX [--view AZ,EL[,DIST]] [--size WxH] [--bg R,G,B] ' +
  '[--light off|head] [--error PX] [--point-budget N] [--timeout S] [--chromium PATH]';

function dirBytes(dir) {
  let n = 0;
  for (const e of fs.readdirSync(dir, { withFileTypes: true }))
    n += e.isDirectory() ? dirBytes(path.join(dir, e.name)) : fs.statSync(path.join(dir, e.name)).size;
  return n;
}

function savePng(url, file) {
  fs.writeFileSync(file, Buffer.from(url.slice(url.indexOf(',') + 1), 'base64'));
}

async function main() {
  let o;
  try {
    o = parseArgs(process.argv.slice(2),
      { view: '30,20', size: '256x256', bg: '255,255,255', light: 'off', error: null, 'point-budget': null, timeout: '300' },
      2, 'DIR and OUT_PREFIX');
  } catch (e) {
    console.error(`tiles: ${e.message}\n${usage}`);
    process.exit(2);
  }
  const [dir, out] = o.pos;
  if (!fs.existsSync(path.join(dir, 'tileset.json'))) {
    console.error(`tiles: cannot read '${path.join(dir, 'tileset.json')}'`);
    process.exit(1);
  }
  const [w, h] = o.size.split('x').map(Number);
  const server = await serve(path.resolve(dir));
  const { browser, userDir } = await launchChromium(o.chromium, o.timeout);
  let code = 0;
  const logs = [];
  try {
    const page = await browser.newPage();
    page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
    page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));
    await page.setViewport({ width: w, height: h, deviceScaleFactor: 1 });
    const q = new URLSearchParams({ tileset: '/model/tileset.json', view: o.view, size: o.size, bg: o.bg, light: o.light,
      ui: '0' });
    if (o.error) q.set('error', o.error);
    if (o['point-budget']) q.set('point-budget', o['point-budget']);
    const { port } = server.address();
    const timeout = 1000 * Number(o.timeout);
    // the page calls this at its first frame and holds refinement until it returns: the server's
    // count is then exactly what the first frame cost
    let serverBytes = null;
    await page.exposeFunction('amgsplatOnFirstFrame', () => {
      serverBytes = server.bytesServed;
    });
    await page.goto(`http://127.0.0.1:${port}/index.html?${q}`, { waitUntil: 'load' });
    await page.waitForFunction('window.amgsplatViewer && window.amgsplatViewer.ready', { timeout });
    const first = await page.evaluate(() => ({ error: window.amgsplatViewer.error, firstFrame: window.amgsplatViewer.firstFrame,
      image: window.amgsplatViewer.firstFrameImage }));
    if (first.error) throw new Error(`the viewer failed: ${first.error}`);
    savePng(first.image, `${out}_first.png`);
    await page.waitForFunction('window.amgsplatViewer.settled || window.amgsplatViewer.error', { timeout });
    const state = await page.evaluate(() => ({ error: window.amgsplatViewer.error, info: window.amgsplatViewer.info }));
    if (state.error) throw new Error(`the viewer failed: ${state.error}`);
    savePng(await page.evaluate(() => document.querySelector('canvas').toDataURL('image/png')), `${out}_refined.png`);
    const i = state.info;
    console.log(JSON.stringify({ tileset_bytes: dirBytes(dir),
      first_frame: { ...first.firstFrame, server_bytes: serverBytes },
      refined: { bytes: i.bytes, server_bytes: server.bytesServed, requests: i.requests, tiles: i.visibleTiles,
        points: i.points, error_target: i.errorTarget },
      total: i.total, images: [`${out}_first.png`, `${out}_refined.png`] }));
  } catch (e) {
    console.error(`tiles: ${e.message}`);
    for (const l of logs) console.error(`  ${l}`);
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
  console.error(`tiles: ${e.message}`);
  process.exit(1);
});
