// `npm run build`: bundles src/ into dist/app.js (esbuild, minified, no source map) and copies
// index.html and app.css (minified) beside it; the wall's page (src/wall/) likewise into wall.js,
// wall.html and wall.css. Deterministic: the same sources give the same bytes.
// `node tools/build.mjs DIR` builds into DIR instead (tools/check_dist.mjs compares the two).
import { build } from 'esbuild';
import { copyFileSync, mkdirSync, readdirSync, rmSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const dist = process.argv[2] ? resolve(process.argv[2]) : join(root, 'dist');
mkdirSync(dist, { recursive: true });
for (const f of readdirSync(dist)) rmSync(join(dist, f), { recursive: true });

await build({
  entryPoints: [join(root, 'src/main.js')],
  outfile: join(dist, 'app.js'),
  bundle: true,
  format: 'iife',
  target: ['es2020', 'chrome90', 'firefox90', 'safari15'],
  minify: true,
  sourcemap: false,
  legalComments: 'eof',
  logLevel: 'warning',
});
// The wall's page (isowall wall --http): its own bundle and style.
await build({
  entryPoints: [join(root, 'src/wall/wall.js')],
  outfile: join(dist, 'wall.js'),
  bundle: true,
  format: 'iife',
  target: ['es2020', 'chrome90', 'firefox90', 'safari15'],
  minify: true,
  sourcemap: false,
  legalComments: 'eof',
  logLevel: 'warning',
});
await build({
  entryPoints: [join(root, 'src/wall/wall.css')],
  outfile: join(dist, 'wall.css'),
  minify: true,
  logLevel: 'warning',
});
await build({
  entryPoints: [join(root, 'src/app.css')],
  outfile: join(dist, 'app.css'),
  minify: true,
  logLevel: 'warning',
});
copyFileSync(join(root, 'src/index.html'), join(dist, 'index.html'));
copyFileSync(join(root, 'src/wall/wall.html'), join(dist, 'wall.html'));
console.log(`build: ${readdirSync(dist).sort().join(', ')} in ${dist}`);
