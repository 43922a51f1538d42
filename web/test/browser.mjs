// What the page tests (screenshot.mjs, tiles.mjs, cesium.mjs, cesium_splats.mjs) share: their command line and headless
// Chromium started as this machine runs it (no sandbox as root, no GPU: WebGL through SwiftShader,
// no background networking on a closed network).
import fs from 'node:fs';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

// --key value options over defaults (every key must be one of them), then exactly npos positional
// arguments (expected: what to say when they are not); --size must read WxH.
export function parseArgs(argv, defaults, npos, expected) {
  const o = { ...defaults, chromium: process.env.CHROMIUM || '/usr/bin/chromium', pos: [] };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a.startsWith('--')) {
      const key = a.slice(2);
      if (!(key in o) || key === 'pos' || i + 1 >= argv.length) throw new Error(`unknown option or missing value: ${a}`);
      o[key] = argv[++i];
    } else o.pos.push(a);
  }
  if (o.pos.length !== npos) throw new Error(`expected ${expected}`);
  if (!/^\d+x\d+$/.test(o.size)) throw new Error(`--size expects WxH, got '${o.size}'`);
  return o;
}

// { browser, userDir }: the browser on a fresh profile (remove userDir after browser.close());
// timeoutSeconds, where given, bounds the protocol calls (waitForFunction's polls run under it).
export async function launchChromium(executablePath, timeoutSeconds) {
  const userDir = fs.mkdtempSync(path.join(process.env.TMPDIR || '/tmp', 'amgsplat-chromium-'));
  const browser = await puppeteer.launch({
    executablePath,
    headless: true,
    ...(timeoutSeconds ? { protocolTimeout: 1000 * Number(timeoutSeconds) + 60000 } : {}),
    userDataDir: userDir,
    args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  return { browser, userDir };
}

// The errors a page shows (console errors, uncaught exceptions, failed requests, HTTP >= 400) into
// errors, every console line into logs: the Cesium checks fail on any of the first.
export function watchPage(page, errors, logs) {
  page.on('console', (m) => {
    logs.push(`${m.type()}: ${m.text()}`);
    if (m.type() === 'error') errors.push(`console: ${m.text()}`);
  });
  page.on('pageerror', (e) => errors.push(`pageerror: ${e.message}`));
  page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()}: ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    if (r.status() >= 400) errors.push(`HTTP ${r.status()}: ${r.url()}`);
  });
}
