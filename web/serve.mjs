// A tiny static server for the viewer (docs/web.md): web/ at /, a model directory at /model/.
//   node web/serve.mjs [--port N] [DIR]      then open http://localhost:N/?file=/model/X.glb
// Listens on 127.0.0.1 only. web/test/screenshot.mjs uses the same server on a free port.
// Sends Content-Length, answers single byte ranges (Range: bytes=A-B, 206) and allows any origin
// (CORS), as a tileset's server should (docs/web.md); server.bytesServed counts the body bytes sent
// from DIR (what the tileset tests compare with the page's own count).
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const webRoot = path.dirname(fileURLToPath(import.meta.url));

const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.glb': 'model/gltf-binary',
  '.gltf': 'model/gltf+json', '.bin': 'application/octet-stream', '.png': 'image/png', '.json': 'application/json' };

// Resolves with the listening server; port 0 picks a free one (server.address().port).
export function serve(modelDir, port = 0) {
  const server = http.createServer((req, res) => {
    let url;
    try {
      url = decodeURIComponent(new URL(req.url, 'http://localhost').pathname);
    } catch {
      res.writeHead(400).end('bad request');
      return;
    }
    const [root, rel] = url.startsWith('/model/') ? [modelDir, url.slice(7)] : [webRoot, url.slice(1) || 'index.html'];
    const file = path.resolve(root, rel);
    // nothing outside the two roots, nothing but regular files
    if (!file.startsWith(root + path.sep) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
      res.writeHead(404).end('not found');
      return;
    }
    const size = fs.statSync(file).size;
    const head = { 'content-type': types[path.extname(file)] || 'application/octet-stream',
      'access-control-allow-origin': '*', 'accept-ranges': 'bytes' };
    let start = 0, end = size - 1, code = 200;
    const range = /^bytes=(\d*)-(\d*)$/.exec(req.headers.range || '');
    if (range && (range[1] || range[2])) {
      start = range[1] ? Number(range[1]) : Math.max(0, size - Number(range[2]));
      end = range[1] && range[2] ? Math.min(Number(range[2]), size - 1) : size - 1;
      if (start > end || start >= size) {
        res.writeHead(416, { 'content-range': `bytes */${size}` }).end();
        return;
      }
      code = 206;
      head['content-range'] = `bytes ${start}-${end}/${size}`;
    }
    head['content-length'] = String(size === 0 ? 0 : end - start + 1);
    res.writeHead(code, head);
    if (root === modelDir) server.bytesServed += size === 0 ? 0 : end - start + 1;
    if (size === 0) res.end();
    else fs.createReadStream(file, { start, end }).pipe(res);
  });
  server.bytesServed = 0;
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(port, '127.0.0.1', () => resolve(server));
  });
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  let port = 8000, dir = process.cwd();
  for (let i = 0; i < args.length; i++) {
    if (args[i] === '--port' && i + 1 < args.length) port = Number(args[++i]);
    else if (!args[i].startsWith('--')) dir = args[i];
    else {
      console.error('usage: node web/serve.mjs [--port N] [DIR]');
      process.exit(2);
    }
  }
  const server = await serve(path.resolve(dir), port);
  console.log(`viewer: http://localhost:${server.address().port}/  models from ${path.resolve(dir)} at /model/ ` +
    `(e.g. http://localhost:${server.address().port}/?file=/model/NAME.glb)`);
}
