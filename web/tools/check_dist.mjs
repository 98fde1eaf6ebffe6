// Fails when the committed dist/ is not what `npm run build` makes of src/ now: the server embeds
// dist/ at build time, so a change to src/ without a rebuild would ship the old page.
//   node tools/check_dist.mjs            (CTest: web_dist_fresh)
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const fresh = mkdtempSync(join(tmpdir(), 'isowall-dist-'));
try {
  execFileSync(process.execPath, [join(root, 'tools/build.mjs'), fresh], { stdio: 'pipe' });
  const want = readdirSync(fresh).sort(), have = readdirSync(join(root, 'dist')).sort();
  const problems = [];
  if (want.join() !== have.join()) problems.push(`files: dist/ has [${have}], a build makes [${want}]`);
  for (const f of want.filter((n) => have.includes(n)))
    if (!readFileSync(join(fresh, f)).equals(readFileSync(join(root, 'dist', f))))
      problems.push(`dist/${f} differs from a fresh build`);
  if (problems.length) {
    console.error(`check_dist: ${problems.join('; ')}: run \`npm run build\` in web/ and commit dist/`);
    process.exit(1);
  }
  console.log(`check_dist: dist/ (${want.join(', ')}) is what src/ builds to`);
} finally {
  rmSync(fresh, { recursive: true, force: true });
}
