// `npm run build`: bundles src/ into dist/app.js (esbuild, minified, no source map) and copies
// index.html and app.css (minified) beside it; the wall's page (src/wall/) likewise into wall.js,
// wall.html and wall.css. Deterministic: the same sources give the same bytes.
// `node tools/build.mjs DIR` builds into DIR instead (tools/check_dist.mjs compares the two).
import { build } from 'esbuild';
import {
  copyFileSync, existsSync, mkdirSync, readFileSync, readdirSync, rmSync, writeFileSync,
} from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { kShadersModule, shadersModule } from './shaders.mjs';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const dist = process.argv[2] ? resolve(process.argv[2]) : join(root, 'dist');
mkdirSync(dist, { recursive: true });
for (const f of readdirSync(dist)) rmSync(join(dist, f), { recursive: true });

// A page's script, bundled and minified, and its style.
async function bundle(entry, out) {
  await build({
    entryPoints: [join(root, entry)],
    outfile: join(dist, out),
    bundle: true,
    format: 'iife',
    target: ['es2020', 'chrome90', 'firefox90', 'safari15'],
    minify: true,
    sourcemap: false,
    legalComments: 'eof',
    logLevel: 'warning',
    // src/cells_wasm.js (emscripten's ES module) reads import.meta.url to find its .wasm file; its
    // WebAssembly is inlined, so the empty import.meta of a script is no loss.
    logOverride: { 'empty-import-meta': 'silent' },
  });
}
async function style(entry, out) {
  await build({ entryPoints: [join(root, entry)], outfile: join(dist, out), minify: true, logLevel: 'warning' });
}

// The shaders first: src/shaders.js is made from render/shaders/ (tools/shaders.mjs).
const shaders = shadersModule();
if (!existsSync(kShadersModule) || readFileSync(kShadersModule, 'utf8') !== shaders) {
  writeFileSync(kShadersModule, shaders);
}
await bundle('src/main.js', 'app.js');
await style('src/app.css', 'app.css');
// The wall's page (isowall wall --http).
await bundle('src/wall/wall.js', 'wall.js');
await style('src/wall/wall.css', 'wall.css');
copyFileSync(join(root, 'src/index.html'), join(dist, 'index.html'));
copyFileSync(join(root, 'src/wall/wall.html'), join(dist, 'wall.html'));
console.log(`build: ${readdirSync(dist).sort().join(', ')} in ${dist}`);
