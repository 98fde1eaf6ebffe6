// Development bridge (issue 13): what `isowall serve --http` will do, in node, in front of a plain
// `isowall serve` TCP server. Serves web/dist/ and /datasets, and relays each binary WebSocket
// message of /ws to a TCP connection to the server, and the TCP stream back cut into frames by
// their 12-byte headers, one frame per WebSocket message. For development and tests only.
//
//   node tools/bridge.mjs --connect 127.0.0.1:7878 [--port 0] [--datasets phantom,head] [--token T]
//   node tools/bridge.mjs --spawn /work/build-h13p/master/isowall [--port 0] -- [serve options]
//
// Prints "bridge: page at http://127.0.0.1:PORT/ (WebSocket /ws)" once listening.
import { createServer } from 'node:http';
import { connect as tcpConnect } from 'node:net';
import { spawn } from 'node:child_process';
import { readFileSync, readdirSync } from 'node:fs';
import { dirname, join, extname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { WebSocketServer } from 'ws';
import { FrameSplitter, decodeHeader, kHeaderBytes } from '../src/protocol.js';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const args = process.argv.slice(2);
const opt = { port: 0, datasets: 'phantom', token: '', connect: '', spawn: '', serveArgs: [] };
for (let i = 0; i < args.length; ++i) {
  const a = args[i];
  if (a === '--') { opt.serveArgs = args.slice(i + 1); break; }
  const key = a.replace(/^--/, '');
  if (!(key in opt) || i + 1 >= args.length) {
    console.error(`bridge: unknown option or missing value: ${a}`);
    process.exit(2);
  }
  opt[key] = args[++i];
}

const types = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.css': 'text/css',
  '.png': 'image/png', '.svg': 'image/svg+xml', '.json': 'application/json', '.map': 'application/json' };

async function serverAddress() {
  if (opt.connect) {
    const m = /^(.*):(\d+)$/.exec(opt.connect);
    if (!m) throw new Error(`--connect ${opt.connect}: expected HOST:PORT`);
    return { host: m[1], port: +m[2] };
  }
  if (!opt.spawn) throw new Error('give --connect HOST:PORT or --spawn ISOWALL');
  const extra = [...opt.serveArgs];
  if (opt.token && !extra.includes('--token')) extra.push('--token', opt.token);
  const child = spawn(opt.spawn, ['serve', '--port', '0', ...extra], { stdio: ['ignore', 'pipe', 'inherit'] });
  process.on('exit', () => child.kill());
  for (const sig of ['SIGINT', 'SIGTERM']) process.on(sig, () => process.exit(0));
  child.on('exit', (code) => { console.error(`bridge: isowall serve exited (${code})`); process.exit(1); });
  return new Promise((resolve) => {
    let text = '';
    child.stdout.on('data', (d) => {
      process.stdout.write(`serve| ${d}`);
      text += d;
      const m = /(?:port|:)\s*(\d{2,5})\b/.exec(text);
      const m2 = /(\d+\.\d+\.\d+\.\d+):(\d+)/.exec(text);
      if (m2) resolve({ host: m2[1], port: +m2[2] });
      else if (m && /listen/i.test(text)) resolve({ host: '127.0.0.1', port: +m[1] });
    });
  });
}

const target = await serverAddress();
const names = opt.datasets.split(',').filter(Boolean);

const http = createServer((req, res) => {
  const url = new URL(req.url, 'http://x');
  const send = (code, type, body) => {
    res.writeHead(code, { 'Content-Type': type, 'Cache-Control': 'no-store' });
    res.end(body);
  };
  if (req.method !== 'GET') return send(405, 'text/plain', 'method not allowed\n');
  if (url.pathname === '/datasets') {
    if (opt.token && url.searchParams.get('token') !== opt.token)
      return send(403, 'application/json', JSON.stringify({ error: 'wrong token' }));
    return send(200, 'application/json', JSON.stringify({ datasets: names, token_required: !!opt.token }));
  }
  const file = url.pathname === '/' ? 'index.html' : url.pathname.slice(1);
  if (!readdirSync(join(root, 'dist')).includes(file)) return send(404, 'text/plain', 'not found\n');
  send(200, types[extname(file)] ?? 'application/octet-stream', readFileSync(join(root, 'dist', file)));
});

const wss = new WebSocketServer({ noServer: true, maxPayload: 64 * 1024 * 1024 + kHeaderBytes });
http.on('upgrade', (req, socket, head) => {
  const url = new URL(req.url, 'http://x');
  const origin = req.headers.origin;
  if (url.pathname !== '/ws' || (origin && origin !== `http://${req.headers.host}`)) {
    socket.end('HTTP/1.1 403 Forbidden\r\n\r\n');
    return;
  }
  wss.handleUpgrade(req, socket, head, (ws) => relay(ws));
});

function relay(ws) {
  const tcp = tcpConnect(target.port, target.host);
  const pending = [];
  let open = false;
  const splitter = new FrameSplitter();
  tcp.on('connect', () => {
    open = true;
    for (const b of pending) tcp.write(b);
    pending.length = 0;
  });
  tcp.on('data', (chunk) => {
    let frames;
    try {
      frames = splitter.push(new Uint8Array(chunk.buffer, chunk.byteOffset, chunk.length));
    } catch (e) {
      console.error(`bridge: server stream: ${e.message}`);
      ws.close(1011);
      tcp.destroy();
      return;
    }
    for (const f of frames) ws.send(f, { binary: true });
  });
  tcp.on('close', () => ws.close(1000));
  tcp.on('error', (e) => { console.error(`bridge: tcp: ${e.message}`); ws.close(1011); });
  ws.on('message', (data, isBinary) => {
    const b = new Uint8Array(data);
    // One whole frame a message, as the real server demands.
    let ok = isBinary && b.length >= kHeaderBytes;
    if (ok) {
      try { ok = decodeHeader(b.subarray(0, kHeaderBytes)).payloadBytes === b.length - kHeaderBytes; } catch { ok = false; }
    }
    if (!ok) {
      console.error('bridge: a WebSocket message that is not one frame; closing');
      ws.close(1002);
      tcp.destroy();
      return;
    }
    if (tcp.destroyed || tcp.writableEnded) return;
    if (open) tcp.write(b); else pending.push(b);
  });
  ws.on('close', () => tcp.end());
}

http.listen(+opt.port, '127.0.0.1', () => {
  console.log(`bridge: page at http://127.0.0.1:${http.address().port}/ (WebSocket /ws) -> ${target.host}:${target.port}`);
});
