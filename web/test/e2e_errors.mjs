// The page's error lines, end to end: starts its own `isowall serve --http 0 --token`, then
// checks in headless Chromium: a missing token, an unknown dataset, the server going away, WebGL2
// missing, a window-filling canvas, device pixel ratio 2 and touch.
//   ISOWALL_BIN=/work/build-h13p/master/isowall node test/e2e_errors.mjs
import { chromium } from 'playwright-core';
import { startServe } from './serve.mjs';

const bin = process.env.ISOWALL_BIN;
if (!bin) {
  console.error('e2e_errors: set ISOWALL_BIN (the isowall program)');
  process.exit(2);  // never an "ok" for a check that did not run, under node --test too
}
const token = 'secret';
const served = await startServe(bin, ['--token', token]);
const base = served.url;
const server = served.proc;

const failures = [];
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
}
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
const settle = (page, pred, arg) => page.waitForFunction(pred, arg, { timeout: 120000, polling: 50 })
  .then(() => page.evaluate(() => ({ state: window.isowall.state, error: window.isowall.error, shown: document.getElementById('message').textContent })));

try {
  let page = await browser.newPage();
  await page.goto(`${base}?dataset=phantom&size=200x150`);
  let s = await settle(page, () => window.isowall.state === 'error');
  check(/token/i.test(s.error) && s.shown === s.error, `no token: "${s.error}"`);

  await page.goto(`${base}?dataset=nosuch&token=${token}&size=200x150`);
  s = await settle(page, () => window.isowall.state === 'error' || /unknown/.test(window.isowall.error));
  check(/unknown dataset/i.test(s.error), `unknown dataset: "${s.error}"`);

  await page.goto(`${base}?dataset=phantom&token=${token}`);
  s = await settle(page, () => window.isowall.state === 'done' || window.isowall.state === 'error');
  const dims = await page.evaluate(() => {
    const c = document.getElementById('view'), st = document.getElementById('stage');
    return { w: c.width, h: c.height, sw: Math.round(st.clientWidth * devicePixelRatio), sh: Math.round(st.clientHeight * devicePixelRatio), view: window.isowall.view };
  });
  check(s.state === 'done' && dims.w === dims.sw && dims.h === dims.sh && dims.view.width === dims.w,
    `window-filling canvas ${dims.w}x${dims.h} (stage ${dims.sw}x${dims.sh}), state ${s.state} ${s.error}`);
  const datasets = await page.evaluate(() => [...document.querySelectorAll('#dataset option')].map((o) => o.value));
  check(datasets.includes('phantom'), `volume picker: ${JSON.stringify(datasets)}`);

  // devicePixelRatio 2 and touch: size= is device pixels; one finger orbits, two pinch.
  const ctx = await browser.newContext({ deviceScaleFactor: 2, hasTouch: true, viewport: { width: 900, height: 700 } });
  const tpage = await ctx.newPage();
  await tpage.goto(`${base}?dataset=phantom&token=${token}&size=400x300`);
  s = await settle(tpage, () => window.isowall.state === 'done' || window.isowall.state === 'error');
  const c2 = await tpage.evaluate(() => {
    const c = document.getElementById('view');
    const r = c.getBoundingClientRect();
    return { w: c.width, h: c.height, cssW: r.width, cssH: r.height, x: r.x, y: r.y };
  });
  check(s.state === 'done' && c2.w === 400 && c2.h === 300 && c2.cssW === 200 && c2.cssH === 150,
    `dpr 2, size=400x300: canvas ${c2.w}x${c2.h}, CSS ${c2.cssW}x${c2.cssH}`);
  const cdp = await ctx.newCDPSession(tpage);
  const cx = c2.x + 100, cy = c2.y + 75;
  const touch = (type, points) => cdp.send('Input.dispatchTouchEvent', { type, touchPoints: points.map(([x, y], id) => ({ x, y, id })) });
  let before = await tpage.evaluate(() => ({ ...window.isowall.view }));
  await touch('touchStart', [[cx, cy]]);
  for (let i = 1; i <= 5; ++i) await touch('touchMove', [[cx - 6 * i, cy]]);
  await touch('touchEnd', []);
  s = await settle(tpage, (y) => window.isowall.view.yaw !== y && window.isowall.state === 'done' &&
    window.isowall.done_request_id === window.isowall.request_id, before.yaw);
  let after = await tpage.evaluate(() => ({ ...window.isowall.view }));
  check(after.yaw > before.yaw && after.zoom === before.zoom, `one finger: yaw ${before.yaw} -> ${after.yaw}`);
  before = after;
  await touch('touchStart', [[cx - 20, cy], [cx + 20, cy]]);
  for (let i = 1; i <= 5; ++i) await touch('touchMove', [[cx - 20 - 6 * i, cy], [cx + 20 + 6 * i, cy]]);
  await touch('touchEnd', []);
  s = await settle(tpage, (z) => window.isowall.view.zoom !== z && window.isowall.state === 'done' &&
    window.isowall.done_request_id === window.isowall.request_id, before.zoom);
  after = await tpage.evaluate(() => ({ ...window.isowall.view }));
  check(after.zoom > before.zoom, `pinch out: zoom ${before.zoom} -> ${after.zoom} (yaw ${before.yaw} -> ${after.yaw})`);
  await ctx.close();

  const page2 = await browser.newPage();
  await page2.addInitScript(() => {
    const orig = HTMLCanvasElement.prototype.getContext;
    HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
      return kind === 'webgl2' ? null : orig.call(this, kind, ...rest);
    };
  });
  await page2.goto(`${base}?dataset=phantom&token=${token}`);
  await page2.waitForFunction(() => window.isowall && window.isowall.state === 'error', null, { timeout: 10000 }).catch(() => {});
  s = await page2.evaluate(() => ({ state: window.isowall?.state, error: window.isowall?.error })).catch((e) => ({ error: String(e) }));
  check(s.state === 'error' && /WebGL2/.test(s.error), `WebGL2 missing: "${s.error}"`);
  server.kill('SIGINT');
  s = await settle(page, () => window.isowall.state === 'error');
  check(/server gone/.test(s.error), `server gone: "${s.error}"`);

} catch (e) {
  failures.push(String(e));
  console.error(e);
} finally {
  await browser.close();
  server.kill('SIGINT');
}
if (failures.length) {
  console.error(`e2e_errors: ${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('e2e_errors: all checks passed');
