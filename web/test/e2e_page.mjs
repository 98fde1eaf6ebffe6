// End-to-end check of the page in headless Chromium (WebGL2 through SwiftShader), against a
// running `isowall serve --http` (tools/run_e2e.sh starts one):
//   ISOWALL_PAGE_URL=http://127.0.0.1:PORT/ ISOWALL_OUT=out/e2e node test/e2e_page.mjs
// Opens ?dataset=phantom&size=800x600&iso=ISO, waits for the frame, saves the canvas; moves the
// isovalue slider (a real input event) and waits for that request's frame; drags on the canvas and
// waits for the new view's frame, saving it too. Writes views.json: the views to draw with
// `isowall render` (web/test/compare_images.py compares them). Exits 1 on any failed check.
import { chromium } from 'playwright-core';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';

const base = process.env.ISOWALL_PAGE_URL;
const out = process.env.ISOWALL_OUT;
if (!base || !out) {
  console.error('e2e_page: set ISOWALL_PAGE_URL (the page) and ISOWALL_OUT (a folder)');
  // Also under `node --test test/`: a check that did not run is not an "ok" (npm test and
  // web_unit run test/*.test.mjs only; CTest's web_page_e2e runs this file with its page).
  process.exit(2);
}
const iso = Number(process.env.ISOWALL_ISO ?? 50);
const iso2 = Number(process.env.ISOWALL_ISO2 ?? 80);
const timeoutMs = Number(process.env.ISOWALL_TIMEOUT_MS ?? 180000);
mkdirSync(out, { recursive: true });

const failures = [];
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
const page = await browser.newPage({ viewport: { width: 1100, height: 800 }, deviceScaleFactor: 1, acceptDownloads: true });
const logs = [];
page.on('console', (m) => logs.push(`${m.type()}: ${m.text()}`));
page.on('pageerror', (e) => logs.push(`pageerror: ${e.message}`));

const state = () => page.evaluate(() => {
  const w = window.isowall;
  return w && JSON.parse(JSON.stringify({ ...w, stats: w.stats }));
});

async function savePng(name) {
  const url = await page.evaluate(() => window.isowall.snapshot());
  const file = join(out, name);
  writeFileSync(file, Buffer.from(url.replace(/^data:image\/png;base64,/, ''), 'base64'));
  return file;
}

// Waits for the frame of request `id` (or the last request sent) to be complete.
async function waitDone(id) {
  await page.waitForFunction((want) => {
    const w = window.isowall;
    if (!w) return false;
    if (w.state === 'error') return true;
    const target = want ?? w.request_id;
    return w.state === 'done' && w.done_request_id === target && w.request_id === target;
  }, id ?? null, { timeout: timeoutMs, polling: 50 });
  return state();
}

try {
  const url = new URL(base);
  url.search = `?dataset=phantom&size=800x600&iso=${iso}${process.env.ISOWALL_EXTRA ?? ""}`;
  const t0 = Date.now();
  await page.goto(url.href);
  // A snapshot while refining, when the first groups have been drawn.
  let mid = null;
  try {
    await page.waitForFunction(() => window.isowall && window.isowall.stats.groups >= 3 && window.isowall.state === 'refining',
      null, { timeout: timeoutMs, polling: 10 });
    mid = await savePng('front_mid.png');
  } catch { /* the frame may finish first */ }
  let s = await waitDone();
  check(s.state === 'done', `front view: state done (${s.state}${s.error ? `: ${s.error}` : ''}) after ${Date.now() - t0} ms`);
  check(s.error === '', `front view: no error line (${JSON.stringify(s.error)})`);
  check(s.dataset === 'phantom' && s.range.length === 2 && s.range[0] <= s.range[1], `range from ready: [${s.range}]`);
  check(s.view.width === 800 && s.view.height === 600, `view size 800x600 (${s.view.width}x${s.view.height})`);
  const canvas = await page.evaluate(() => {
    const c = document.getElementById('view');
    return { w: c.width, h: c.height, cssW: c.getBoundingClientRect().width, cssH: c.getBoundingClientRect().height };
  });
  check(canvas.w === 800 && canvas.h === 600 && canvas.cssW === 800 && canvas.cssH === 600, `canvas 800x600 device pixels (${JSON.stringify(canvas)})`);
  check(s.stats.groups > 0 && s.stats.triangles > 0 && s.stats.first_group_ms !== null && s.stats.frame_ms !== null,
    `front view stats ${JSON.stringify(s.stats)}`);
  check(s.requests.length === 1 && s.requests[0].iso === iso, `one request (lod ${s.requests[0].lod}, cache ${s.requests[0].cache})`);
  // Without an encoding in the URL the server chooses (cells or compact+zstd per group).
  const chosen = process.env.ISOWALL_EXTRA?.includes('encoding=') ? null : 255;
  check(chosen === null || s.encoding === chosen, `hello encoding ${s.encoding} (255: the server's choice)`);
  const front = { ...s.view, stats: s.stats, png: await savePng('front.png'), mid_png: mid };

  // The snapshot button downloads the canvas as a PNG of the canvas's size.
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.locator('#snapshot').click()]);
  const shot = join(out, 'snapshot_button.png');
  await download.saveAs(shot);
  const head = readFileSync(shot);
  const pngSize = head.length >= 24 && head.readUInt32BE(0) === 0x89504e47 ? [head.readUInt32BE(16), head.readUInt32BE(20)] : null;
  check(pngSize && pngSize[0] === 800 && pngSize[1] === 600 && /\.png$/.test(download.suggestedFilename()),
    `snapshot button: ${download.suggestedFilename()}, PNG ${pngSize ? pngSize.join('x') : 'not a PNG'}`);

  // The slider: a real input event on the range input.
  const before = s.request_id;
  await page.locator('#iso-slider').fill(String(iso2));
  await page.waitForFunction((b) => window.isowall.request_id > b, before, { timeout: 10000 });
  s = await waitDone();
  const sent = s.requests.filter((r) => r.id > before);
  check(sent.length >= 1 && sent.every((r) => r.iso === iso2), `slider: request(s) ${sent.map((r) => r.id)} with iso ${iso2}`);
  check(s.state === 'done' && s.done_request_id === s.request_id && s.view.iso === iso2, `slider: frame ${s.done_request_id} done at iso ${s.view.iso}`);
  const isoView = { ...s.view, stats: s.stats, png: await savePng('iso2.png') };

  // Back to the first isovalue through the number field (the cache holds its groups? a new
  // generation: the server decides) and then drag.
  const box = await page.locator('#view').boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const yaw0 = s.view.yaw, pitch0 = s.view.pitch, beforeDrag = s.request_id;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  for (let i = 1; i <= 10; ++i) await page.mouse.move(cx + 8 * i, cy + 3 * i);
  await page.mouse.up();
  s = await waitDone();
  check(s.view.yaw !== yaw0 && s.view.pitch !== pitch0, `drag: yaw ${yaw0} -> ${s.view.yaw}, pitch ${pitch0} -> ${s.view.pitch}`);
  const last = s.requests[s.requests.length - 1];
  check(s.request_id > beforeDrag && last.yaw === s.view.yaw && last.pitch === s.view.pitch && s.done_request_id === last.id,
    `drag: request ${last.id} with the new yaw/pitch completed (${s.request_id - beforeDrag} request(s) sent while dragging)`);
  const dragged = { ...s.view, stats: s.stats, png: await savePng('dragged.png') };

  // The wheel zooms in.
  const zoom0 = s.view.zoom, beforeWheel = s.request_id;
  await page.mouse.move(cx, cy);
  await page.mouse.wheel(0, -240);
  await page.waitForFunction((b) => window.isowall.request_id > b, beforeWheel, { timeout: 10000 });
  s = await waitDone();
  check(s.view.zoom > zoom0 && s.requests[s.requests.length - 1].zoom === s.view.zoom, `wheel: zoom ${zoom0} -> ${s.view.zoom}, frame ${s.done_request_id} done`);
  const zoomed = { ...s.view, stats: s.stats, png: await savePng('zoomed.png') };

  // A value outside the range: a readable message, nothing sent.
  const n = s.request_id;
  await page.locator('#iso-number').fill(String(s.range[1] + 1000));
  await page.locator('#iso-number').press('Enter');
  await page.waitForTimeout(300);
  s = await state();
  check(s.request_id === n && /outside/.test(s.error), `bad isovalue not sent: "${s.error}"`);
  const shown = await page.locator('#message').textContent();
  check(shown === s.error, 'bad isovalue message shown on the page');

  // The volume picker: no volume, then the phantom again (a new connection, a new cache).
  await page.locator('#dataset').selectOption('');
  s = await state();
  check(s.state === 'idle', `picker: no volume -> state ${s.state}`);
  const beforePick = s.request_id;
  await page.locator('#dataset').selectOption('phantom');
  await page.waitForFunction((b) => window.isowall.request_id > b, beforePick, { timeout: 20000 });
  s = await waitDone();
  check(s.state === 'done' && s.dataset === 'phantom' && s.stats.named === 0 && s.stats.groups > 0,
    `picker: phantom again, frame ${s.done_request_id} done (${s.stats.groups} groups, ${s.stats.named} named)`);

  // On run_e2e.sh's 20 Mbit/s link the server's choice is cells for most groups: the page's cells
  // decoder drew some of these frames' groups.
  const cellsGroups = [front, isoView, dragged, zoomed].reduce((n, v) => n + v.stats.cells, 0);
  check(chosen === null || cellsGroups > 0, `cells groups decoded and drawn: ${cellsGroups} of ` +
    `${[front, isoView, dragged, zoomed].reduce((n, v) => n + v.stats.groups, 0)}`);

  writeFileSync(join(out, 'views.json'), JSON.stringify({ dataset: 'phantom', front, iso2: isoView, dragged, zoomed }, null, 2));
  console.log(`e2e_page: wrote ${join(out, 'views.json')}`);
} catch (e) {
  failures.push(String(e && e.stack || e));
  console.error(e);
  try { console.error(JSON.stringify(await state())); } catch { /* page gone */ }
} finally {
  if (logs.length) writeFileSync(join(out, 'console.log'), logs.join('\n') + '\n');
  await browser.close();
}
if (failures.length) {
  console.error(`e2e_page: ${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('e2e_page: all checks passed');
