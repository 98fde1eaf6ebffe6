// The wall's page end to end (isowall wall --http): a 2x2 wall under mpirun, steered
// from two pages in headless Chromium through playwright-core.
//   1. The first page's mosaic, once the first frame is done, equals what the wall's own full-size
//      mosaic (a snapshot the page asks for) gives through the tiles' preview path
//      (isowall_test_page_mosaic), within the wall tests' thresholds.
//   2. A drag, a wheel step and an isovalue typed on the page become script lines the wall prints;
//      a second page sees who steers, is refused while it does not, takes over and steers; the
//      first page is refused after. Both pages end on the same picture.
//   3. The wall ended from the page; its mosaic equals that of the script the printed lines make.
//   4. Over https with a token and --measure: the page and its WebSocket (wss), the emulated time
//      to the wall's C = 99% on the page, a wrong token refused; an address off loopback without
//      TLS refused with one line.
//   5. A time series of 8 steps: the page's Time slider shows a step, its Play button plays round
//      and round and pauses, each as the script line the wall prints.
//   ISOWALL_BIN=build/bin/isowall ISOWALL_PAGE_MOSAIC=build/tests/isowall_test_page_mosaic \
//     ISOWALL_OUT=out node test/e2e_wall.mjs
import { chromium } from 'playwright-core';
import { execFileSync, spawnSync } from 'node:child_process';
import { mkdirSync, writeFileSync, rmSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { WallRun, mpiEnv } from './wall_run.mjs';

const bin = process.env.ISOWALL_BIN;
const tool = process.env.ISOWALL_PAGE_MOSAIC;
const out = process.env.ISOWALL_OUT;
if (!bin || !tool || !out) {
  console.error('e2e_wall: set ISOWALL_BIN, ISOWALL_PAGE_MOSAIC and ISOWALL_OUT');
  process.exit(2);
}
const root = join(dirname(fileURLToPath(import.meta.url)), '../..');
const wallFile = join(root, 'walls/2x2-bezels.toml');
const compare = join(root, 'web/test/compare_images.py');
rmSync(out, { recursive: true, force: true });
mkdirSync(out, { recursive: true });
const failures = [];
const started = Date.now();
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} [${((Date.now() - started) / 1000).toFixed(1)} s] ${what}`);
  if (!ok) failures.push(what);
}
// The wall tests' thresholds: mask IoU >= 0.999 and 99.9% of the pixels both cover within 2/255.
function same(a, b, what) {
  const r = spawnSync('/usr/bin/python3', [compare, a, b, '--min-iou', '0.999', '--min-within2', '0.999'], { encoding: 'utf8' });
  check(r.status === 0, `${what}: ${r.stdout.trim().replace(/\n/g, '; ')}`);
}
function savePng(dataUrl, path) {
  writeFileSync(path, Buffer.from(dataUrl.replace(/^data:image\/png;base64,/, ''), 'base64'));
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox'],
});
const wallArgs = ['--wall', wallFile, '--timeout', '300'];

// What a page knows; waits poll it.
const stateOf = (page) => page.evaluate(() => {
  const w = window.isowallWall;
  return { state: w.state, you: w.you, errors: w.errors.slice(), log: w.log.slice(), mosaics: w.mosaics, mosaic_frame: w.mosaic_frame, connected: w.connected };
});
async function until(page, pred, what, timeoutS = 180) {
  const end = Date.now() + timeoutS * 1000;
  for (;;) {
    const s = await stateOf(page);
    if (pred(s)) return s;
    if (Date.now() > end) throw new Error(`page: no ${what} within ${timeoutS} s: ${JSON.stringify(s.state)}`);
    await new Promise((r) => setTimeout(r, 100));
  }
}
// The frame the page last heard of is done and its pictures have stopped changing for 1.5 s.
async function settled(page, what) {
  let s = await until(page, (x) => x.state && x.state.done && x.mosaic_frame === x.state.frame, `${what} done`);
  for (let quiet = 0; quiet < 15;) {
    await new Promise((r) => setTimeout(r, 100));
    const t = await stateOf(page);
    quiet = t.mosaics === s.mosaics && t.state.frame === s.state.frame ? quiet + 1 : 0;
    s = t;
  }
  return s;
}

let wall = null;
try {
  // 1-3: steered over plain http on loopback.
  wall = new WallRun(bin, 5, [...wallArgs, '--http', '0', '--out', join(out, 'wall.png')]);
  const url = (await wall.waitFor(/http: page at (http:\/\/\S+)/))[1];
  const context = await browser.newContext({ viewport: { width: 1100, height: 800 }, deviceScaleFactor: 1 });
  const a = await context.newPage();
  await a.goto(`${url}?confirm=0`);
  let sa = await settled(a, 'the first frame');
  check(sa.you === 'page 1', `the first page is ${sa.you}`);
  const welcome = await a.evaluate(() => window.isowallWall.welcome);
  check(welcome.tiles.length === 4, `the page knows the wall's 4 tiles: ${welcome.width}x${welcome.height}`);
  await a.click('#snapshot');
  await wall.waitFor(/snapshot: \S*page-001\.png/);
  savePng(await a.evaluate(() => window.isowallWall.snapshot()), join(out, 'page_first.png'));
  execFileSync(tool, [wallFile, join(out, 'page-001.png'), join(out, 'expected_first.png')]);
  same(join(out, 'page_first.png'), join(out, 'expected_first.png'), "the page's mosaic against the wall's previews");

  // 2: a drag, a wheel step and an isovalue on the first page.
  const box = await a.locator('#mosaic').boundingBox();
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  await a.mouse.move(cx, cy);
  await a.mouse.down();
  await a.mouse.move(cx + 60, cy, { steps: 6 });
  await a.mouse.up();
  await wall.waitFor(/^page 1: orbit \S+ \S+$/m);
  await a.mouse.wheel(0, -100);
  await wall.waitFor(/^page 1: zoom \S+$/m);
  await a.fill('#iso-number', '52.2');
  await a.press('#iso-number', 'Enter');
  await wall.waitFor(/^page 1: iso 52.2$/m);
  sa = await until(a, (x) => x.log.length >= 4, 'four lines in the log');
  check(sa.log.slice(-3).every((l) => l.who === 'page 1' && !l.error), `page 1's lines ran: ${sa.log.map((l) => l.line).join('; ')}`);
  // The clip menu: an axis cuts the volume at its middle, and the state the wall sends back
  // shows it; off takes it away.
  await a.selectOption('#clip-axis', 'x');
  await wall.waitFor(/^page 1: clip x<\d+$/m);
  sa = await until(a, (x) => /^x<\d+$/.test(x.state.clip), 'the clip in the state');
  await a.selectOption('#clip-axis', '');
  await wall.waitFor(/^page 1: clip off$/m);
  // Several surfaces typed in: the wall draws both and the state lists them; one value again
  // goes back to one plain surface.
  await a.fill('#surfaces', '80:skin:0.3 160:bone');
  await a.press('#surfaces', 'Enter');
  await wall.waitFor(/^page 1: iso 80:skin:0.3 160:bone$/m);
  sa = await until(a, (x) => x.state.surfaces.length === 2, 'two surfaces in the state');
  check(sa.state.surfaces[0] === '80:#b17a65:0.3', `the first surface reads ${sa.state.surfaces[0]}`);
  // The phantom is one volume: no time controls.
  check(sa.state.steps === 0 && await a.isHidden('label.time'), 'no time controls without a series');

  // A second page watches, sees page 1 steer, is refused, takes over and steers.
  const b = await context.newPage();
  await b.goto(`${url}?confirm=0`);
  let sb = await until(b, (x) => x.state && x.mosaics > 0, 'a mosaic on the second page');
  check(sb.you === 'page 2' && sb.state.steering === 'page 1', `page 2 sees ${sb.state.steering} steer`);
  check((await b.textContent('#steering')) === 'page 1 steers', `page 2 reads "${await b.textContent('#steering')}"`);
  const bbox = await b.locator('#mosaic').boundingBox();
  await b.mouse.move(bbox.x + bbox.width / 2, bbox.y + bbox.height / 2);
  await b.mouse.wheel(0, -100);
  sb = await until(b, (x) => x.errors.length > 0, 'a refusal on page 2');
  check(/page 1 steers/.test(sb.errors[0]), `page 2 refused: ${sb.errors[0]}`);
  await b.click('#take');
  await wall.waitFor(/^http: page 2 steers$/m);
  sa = await until(a, (x) => x.state.steering === 'page 2', 'page 2 steering, seen on page 1');
  check(true, 'page 1 sees page 2 take over');
  const [bx, by] = [bbox.x + bbox.width / 2, bbox.y + bbox.height / 2];
  await b.mouse.move(bx, by);
  await b.mouse.down();
  await b.mouse.move(bx - 40, by + 20, { steps: 4 });
  await b.mouse.up();
  await wall.waitFor(/^page 2: orbit \S+ \S+$/m);
  sa = await until(a, (x) => x.log.some((l) => l.who === 'page 2'), "page 2's line in page 1's log");
  check(true, "page 1's log shows page 2's command");
  await a.mouse.move(cx, cy);
  await a.mouse.wheel(0, 100);
  sa = await until(a, (x) => x.errors.length > 0, 'a refusal on page 1');
  check(/page 2 steers/.test(sa.errors[0]), `page 1 refused after the take-over: ${sa.errors[0]}`);

  // Both pages end on the same picture.
  sb = await settled(b, 'the last frame');
  sa = await settled(a, 'the last frame (page 1)');
  savePng(await a.evaluate(() => window.isowallWall.snapshot()), join(out, 'page1_last.png'));
  savePng(await b.evaluate(() => window.isowallWall.snapshot()), join(out, 'page2_last.png'));
  // The operator's guide shows this page (docs/wall.md: wall_page.png).
  await a.screenshot({ path: join(out, 'wall_page.png') });
  same(join(out, 'page1_last.png'), join(out, 'page2_last.png'), 'both pages show the same mosaic');
  await b.click('#quit');
  const code = await wall.exit(120);
  check(code === 0, `the wall ended from the page: exit ${code}`);
  writeFileSync(join(out, 'wall.log'), wall.text);

  // 3: the same lines as a script.
  const lines = [...wall.text.matchAll(/^page \d+: (.+)$/gm)].map((m) => m[1]).filter((l) => l !== 'quit' && !l.startsWith('snapshot'));
  writeFileSync(join(out, 'replay.txt'), `${lines.join('\n')}\nwait done\nquit\n`);
  console.log(`replaying: ${lines.join('; ')}`);
  const replay = new WallRun(bin, 5, [...wallArgs, '--script', join(out, 'replay.txt'), '--out', join(out, 'replay.png')]);
  check((await replay.exit(300)) === 0, `the script of the page's lines ran: ${replay.tail()}`);
  same(join(out, 'wall.png'), join(out, 'replay.png'), "the steered wall against the script of its lines");
  await context.close();

  // 4: TLS and a token; an address off loopback without TLS.
  const cert = join(out, 'tls.crt');
  const key = join(out, 'tls.key');
  execFileSync('openssl', ['req', '-x509', '-newkey', 'ec', '-pkeyopt', 'ec_paramgen_curve:prime256v1',
    '-nodes', '-days', '1', '-subj', '/CN=localhost', '-addext', 'subjectAltName=DNS:localhost,IP:127.0.0.1',
    '-keyout', key, '-out', cert], { stdio: 'ignore' });
  // With --measure: the page also shows the emulated time to the wall's C = 99%.
  wall = new WallRun(bin, 5, [...wallArgs, '--http', '0', '--token', 't0k3n', '--tls-cert', cert, '--tls-key', key,
    '--measure', '--out', join(out, 'tls_wall.png')]);
  const tlsUrl = (await wall.waitFor(/http: page at (https:\/\/\S+)/))[1];
  check(/http: TLS certificate: .*localhost/.test(wall.text), 'the wall prints its certificate');
  const tls = await browser.newContext({ ignoreHTTPSErrors: true, viewport: { width: 1100, height: 800 } });
  const wrong = await tls.newPage();
  await wrong.goto(`${tlsUrl}?token=nope`);
  const sw = await until(wrong, (x) => x.errors.length > 0, 'a refusal of the wrong token');
  check(/wrong token/.test(sw.errors[0]), `a wrong token: ${sw.errors[0]}`);
  const p = await tls.newPage();
  const sockets = [];
  p.on('websocket', (ws) => sockets.push(ws.url()));
  await p.goto(`${tlsUrl}?token=t0k3n&confirm=0`);
  const sp = await settled(p, 'the first frame over TLS');
  check(sp.mosaics > 0 && (await p.evaluate(() => location.protocol)) === 'https:', `the page over https shows the wall (${sp.mosaics} mosaics)`);
  check(sockets.length > 0 && sockets.every((u) => u.startsWith('wss://')), `its WebSocket: ${sockets.join(', ')}`);
  const measured = await until(p, (x) => x.state.c99_s >= 0, 'the emulated time to C = 99%', 60);
  check(measured.state.c99_s > 0 && measured.state.c99_s <= measured.state.emulated_s + 1e-9,
    `--measure: C = 99% at ${measured.state.c99_s.toFixed(3)} s emulated, makespan ${measured.state.emulated_s.toFixed(3)} s; ` +
    `the page reads "${await p.textContent('#s-c99')}"`);
  await p.click('#quit');
  check((await wall.exit(120)) === 0, 'the TLS wall ended from the page');
  await tls.close();
  wall = null;

  // 5: a time series (8 numbered volumes of a ball moving along x, written here).
  const series = join(out, 'series');
  mkdirSync(series, { recursive: true });
  for (let t = 0; t < 8; ++t) {
    const n = 32, voxels = Buffer.alloc(n * n * n);
    for (let z = 0; z < n; ++z) for (let y = 0; y < n; ++y) for (let x = 0; x < n; ++x) {
      const d = Math.hypot(x - 8 - 2 * t, y - 16, z - 16);
      voxels[(z * n + y) * n + x] = Math.max(0, Math.min(255, Math.round(255 - 25 * d)));
    }
    const name = join(series, `ball_${String(t).padStart(2, '0')}.nrrd`);
    writeFileSync(name, Buffer.concat([Buffer.from(`NRRD0004\ntype: uint8\ndimension: 3\nsizes: ${n} ${n} ${n}\nencoding: raw\n\n`), voxels]));
  }
  wall = new WallRun(bin, 5, [...wallArgs, '-v', join(series, 'ball_%02d.nrrd'), '--iso', '128', '--http', '0',
    '--out', join(out, 'series_wall.png')]);
  const seriesUrl = (await wall.waitFor(/http: page at (http:\/\/\S+)/))[1];
  const seriesContext = await browser.newContext({ viewport: { width: 1300, height: 800 } });
  const t = await seriesContext.newPage();
  await t.goto(`${seriesUrl}?confirm=0`);
  let st = await until(t, (x) => x.state && x.state.steps === 8 && x.state.done, 'the series\' first frame');
  check(!(await t.isHidden('label.time')) && st.state.step === 0, 'the time controls show step 0 of 8');
  await t.locator('#time-step').fill('5');
  await wall.waitFor(/^page \d+: time 5$/m);
  st = await until(t, (x) => x.state.step === 5 && x.state.done, 'step 5 shown');
  check((await t.textContent('#time-value')) === '5/8', `the slider's step: ${await t.textContent('#time-value')}`);
  await t.click('#play');
  await wall.waitFor(/^page \d+: play loop$/m);
  st = await until(t, (x) => x.state.playing && x.state.step !== 5, 'the series playing');
  check((await t.textContent('#play')) === 'Pause', `playing, at step ${st.state.step}`);
  await t.click('#play');
  await wall.waitFor(/^page \d+: pause$/m);
  st = await until(t, (x) => !x.state.playing, 'the series paused');
  check((await t.textContent('#play')) === 'Play', `paused at step ${st.state.step}`);
  await t.click('#quit');
  check((await wall.exit(120)) === 0, 'the series wall ended from the page');
  await seriesContext.close();
  wall = null;

  const open = spawnSync('timeout', ['120', 'mpirun', '--oversubscribe', '-np', '5', bin, 'wall', ...wallArgs,
    '--http', '0', '--http-listen', '0.0.0.0', '--out', join(out, 'never.png')], { env: mpiEnv, encoding: 'utf8' });
  const errs = open.stderr.split('\n').filter((l) => l.startsWith('isowall: error'));
  check(open.status !== 0 && errs.length === 1 && /not loopback\) needs TLS/.test(errs[0]),
    `--http-listen 0.0.0.0 without TLS: exit ${open.status}, ${errs.join(' | ')}`);
} catch (e) {
  check(false, e.message);
} finally {
  if (wall && wall.exited === null) wall.proc.kill('SIGKILL');
  await browser.close();
}
if (failures.length) {
  console.error(`e2e_wall: ${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('e2e_wall: all checks pass');
