// Fails when the committed src/cells_wasm.js is not what web/wasm/build.sh makes of the C++ now:
// the page would then decode cells bodies by another version of remote/cell_codec.cpp than the
// server encodes them with (the build is deterministic: the same sources give the same bytes).
// Without emcc it can tell nothing: it says so and exits 77 (CTest's SKIP_RETURN_CODE).
//   node tools/check_wasm.mjs            (CTest: web_wasm_fresh)
import { execFileSync, spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
if (spawnSync('sh', ['-c', 'command -v emcc'], { stdio: 'ignore' }).status !== 0) {
  console.log('check_wasm: skipped: emcc not found (apt-get install emscripten), so src/cells_wasm.js cannot be rebuilt here');
  process.exit(77);
}
const fresh = mkdtempSync(join(tmpdir(), 'isowall-wasm-'));
try {
  const out = join(fresh, 'cells_wasm.js');
  try {
    execFileSync('bash', [join(root, 'wasm/build.sh'), out], { stdio: 'pipe' });
  } catch (e) {
    console.error(`check_wasm: wasm/build.sh failed:\n${String(e.stderr).trim().split('\n').slice(-5).join('\n')}`);
    process.exit(1);
  }
  if (!readFileSync(out).equals(readFileSync(join(root, 'src/cells_wasm.js')))) {
    console.error('check_wasm: src/cells_wasm.js differs from a fresh build of the C++: run web/wasm/refresh.sh ' +
      '(the decoder, the test groups, dist/), then npm test in web/, and commit what it wrote');
    process.exit(1);
  }
  console.log('check_wasm: src/cells_wasm.js is what web/wasm/build.sh makes of the C++ now');
} finally {
  rmSync(fresh, { recursive: true, force: true });
}
