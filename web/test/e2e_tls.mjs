// The page over TLS, end to end in headless Chromium: starts its own
// `isowall serve --http 0 --tls-cert --tls-key` with a certificate made here with `openssl`, then
// checks that the page loads over https, that its WebSocket is wss, that the front view completes
// and saves it (ISOWALL_OUT/tls_front.png: tools/run_e2e.sh compares it with `isowall render`'s),
// and that plain http on the TLS port gets no page.
//   ISOWALL_BIN=build/bin/isowall ISOWALL_OUT=out/e2e node test/e2e_tls.mjs
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import { mkdirSync, writeFileSync } from 'node:fs';
import http from 'node:http';
import { join } from 'node:path';
import { startServe } from './serve.mjs';

const bin = process.env.ISOWALL_BIN;
const out = process.env.ISOWALL_OUT;
if (!bin || !out) {
  console.error('e2e_tls: set ISOWALL_BIN (the isowall program) and ISOWALL_OUT (a folder)');
  process.exit(2);
}
mkdirSync(out, { recursive: true });
const failures = [];
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
}

const cert = join(out, 'tls.crt');
const key = join(out, 'tls.key');
execFileSync('openssl', ['req', '-x509', '-newkey', 'ec', '-pkeyopt', 'ec_paramgen_curve:prime256v1',
  '-nodes', '-days', '1', '-subj', '/CN=localhost', '-addext', 'subjectAltName=DNS:localhost,IP:127.0.0.1',
  '-keyout', key, '-out', cert], { stdio: 'ignore' });

const served = await startServe(bin, ['--tls-cert', cert, '--tls-key', key]);
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  check(served.url.startsWith('https://'), `serve prints an https page: ${served.url}`);
  // The test's certificate is self-signed: this browser context accepts it, as a user would
  // after checking it (or after installing it as an authority).
  const context = await browser.newContext({ ignoreHTTPSErrors: true, viewport: { width: 1100, height: 800 }, deviceScaleFactor: 1 });
  const page = await context.newPage();
  const sockets = [];
  page.on('websocket', (ws) => sockets.push(ws.url()));
  await page.goto(`${served.url}?dataset=phantom&size=800x600&iso=50`);
  await page.waitForFunction(() => {
    const w = window.isowall;
    return w && (w.state === 'error' || (w.state === 'done' && w.done_request_id === w.request_id));
  }, null, { timeout: 180000, polling: 50 });
  const s = await page.evaluate(() => ({ state: window.isowall.state, error: window.isowall.error, protocol: location.protocol }));
  check(s.protocol === 'https:', `the page's protocol: ${s.protocol}`);
  check(s.state === 'done' && s.error === '', `front view over TLS: ${s.state}${s.error ? `: ${s.error}` : ''}`);
  check(sockets.length > 0 && sockets.every((u) => u.startsWith('wss://')), `WebSocket over wss: ${sockets.join(', ')}`);
  const url = await page.evaluate(() => window.isowall.snapshot());
  writeFileSync(join(out, 'tls_front.png'), Buffer.from(url.replace(/^data:image\/png;base64,/, ''), 'base64'));
  // Plain http on the TLS port: no page (the TLS handshake fails and the connection closes).
  const port = new URL(served.url).port;
  const plain = await new Promise((resolve) => {
    const req = http.get({ host: '127.0.0.1', port, path: '/', timeout: 10000 }, (res) => resolve(`status ${res.statusCode}`));
    req.on('error', (e) => resolve(`error ${e.code ?? e.message}`));
    req.on('timeout', () => { req.destroy(); resolve('timeout'); });
  });
  check(plain.startsWith('error'), `plain http on the TLS port gets no page: ${plain}`);
} finally {
  await browser.close();
  served.proc.kill('SIGINT');
}
if (failures.length) {
  console.error(`e2e_tls: ${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('e2e_tls: all checks pass');
