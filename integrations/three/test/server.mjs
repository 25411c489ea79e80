// A small static file server on 127.0.0.1 for the browser tests (WebGL and WebGPU need a
// page served over http from a secure-context origin; 127.0.0.1 is one).
//
//   /pkg/...            integrations/three/src (the package)
//   /test/...           integrations/three/test
//   /three/NAME/...     integrations/three/node_modules/NAME (three = newest, three-r160 = oldest
//                       for WebGLRenderer, three-r171 = oldest for WebGPURenderer)
//   /tables/...         tables/baked (the default table set)
//   /samples/...        ../shared/gltf-samples (Khronos glTF samples; not in the repository)
//   /page/NAME.html     an empty page whose import map points `three` at node_modules/NAME
//   /export/NAME.QUANTITY.json  the sidecar `nacre export` wrote (test/export/, committed)
//   /export/NAME.QUANTITY.raw   the raw texture: the level-0 bytes of tables/baked/NAME.QUANTITY.ktx2,
//                       which are the bytes `nacre export` writes (crates/cli/tests/three_fixture.rs
//                       checks both), so the 1.3 MB file need not be committed
import { createServer } from 'node:http';
import { readFile, stat } from 'node:fs/promises';
import { extname, join, normalize, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = fileURLToPath(new URL('.', import.meta.url));
export const packageRoot = normalize(join(here, '..'));
export const repoRoot = normalize(join(packageRoot, '..', '..'));
// ../shared beside the repository (DATA.md), or NACRE_SHARED where it lives elsewhere.
export const sharedRoot = process.env.NACRE_SHARED ?? normalize(join(repoRoot, '..', 'shared'));
export const samplesRoot = join(sharedRoot, 'gltf-samples');

const roots = {
  pkg: join(packageRoot, 'src'),
  test: join(packageRoot, 'test'),
  three: join(packageRoot, 'node_modules'),
  tables: join(repoRoot, 'tables', 'baked'),
  export: join(packageRoot, 'test', 'export'),
  samples: samplesRoot,
};

const types = {
  '.js': 'text/javascript',
  '.mjs': 'text/javascript',
  '.json': 'application/json',
  '.html': 'text/html',
  '.glb': 'model/gltf-binary',
  '.gltf': 'model/gltf+json',
  '.bin': 'application/octet-stream',
  '.ktx2': 'image/ktx2',
  '.png': 'image/png',
  '.jpg': 'image/jpeg',
  '.jpeg': 'image/jpeg',
};

function page(threeName) {
  return `<!doctype html>
<html><head><meta charset="utf-8"><title>nacre three.js test (${threeName})</title>
<script type="importmap">{"imports": {
  "three": "/three/${threeName}/build/three.module.js",
  "three/addons/": "/three/${threeName}/examples/jsm/",
  "three/webgpu": "/three/${threeName}/build/three.webgpu.js",
  "three/tsl": "/three/${threeName}/build/three.tsl.js",
  "@nacre/three": "/pkg/index.js",
  "@nacre/three/webgpu": "/pkg/webgpu.js"
}}</script>
<style>body { margin: 0; background: #000 }</style>
</head><body></body></html>`;
}

/** Starts the server on an ephemeral port of 127.0.0.1; resolves to {url, close}. */
export function startServer() {
  const server = createServer(async (req, res) => {
    try {
      const path = decodeURIComponent(new URL(req.url, 'http://127.0.0.1').pathname);
      if (path === '/favicon.ico') {
        res.writeHead(204).end();
        return;
      }
      const pageMatch = /^\/page\/([\w.-]+)\.html$/.exec(path);
      if (pageMatch) {
        res.writeHead(200, { 'content-type': 'text/html' });
        res.end(page(pageMatch[1]));
        return;
      }
      const rawMatch = /^\/export\/([\w-]+\.(?:reflectance|transmittance))\.raw$/.exec(path);
      if (rawMatch) {
        const ktx2 = await readFile(join(roots.tables, `${rawMatch[1]}.ktx2`));
        const view = new DataView(ktx2.buffer, ktx2.byteOffset, ktx2.byteLength);
        const offset = Number(view.getBigUint64(80, true));
        const length = Number(view.getBigUint64(88, true));
        res.writeHead(200, { 'content-type': 'application/octet-stream' });
        res.end(ktx2.subarray(offset, offset + length));
        return;
      }
      const [, root, ...rest] = path.split('/');
      const base = roots[root];
      const file = base && normalize(join(base, ...rest));
      if (!file || !(file === base || file.startsWith(base + sep)) || !(await stat(file)).isFile()) {
        res.writeHead(404).end();
        return;
      }
      res.writeHead(200, { 'content-type': types[extname(file)] ?? 'application/octet-stream' });
      res.end(await readFile(file));
    } catch {
      res.writeHead(404).end();
    }
  });
  return new Promise((resolve) => {
    server.listen(0, '127.0.0.1', () => {
      const { port } = server.address();
      resolve({ url: `http://127.0.0.1:${port}`, close: () => new Promise((r) => server.close(r)) });
    });
  });
}
