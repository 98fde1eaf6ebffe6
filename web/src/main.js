// The page: picks a volume, connects to `isowall serve --http` over its WebSocket (/ws, one frame
// of the TCP protocol per binary message), sends views and draws their groups as they arrive
// (frames.js), and keeps window.isowall up to date for tests and the bench (a contract
// they rely on).
import { MsgType, encodeFrame, decodeFrame, ErrorCode, LodSchedule } from './protocol.js';
import { ready as codecReady, helloEncoding, kAdaptiveEncoding, GroupEncoding, cellsProblem } from './group_codec.js';
import { viewCamera, cameraProblem } from './camera.js';
import { Renderer } from './renderer.js';
import { ClientFrames, RemoteError, emptyStats } from './frames.js';
import * as ui from './ui.js';

const params = new URLSearchParams(location.search);
const el = ui.elements();
const warnings = [];

function intParam(name, lo, hi, fallback) {
  const s = params.get(name);
  if (s === null || s === '') return fallback;
  const v = Number(s);
  if (!Number.isInteger(v) || v < lo || v > hi) {
    warnings.push(`URL parameter ${name}=${s}: expected an integer in ${lo}..${hi}`);
    return fallback;
  }
  return v;
}

function numberParam(name, fallback, ok = Number.isFinite, expected = 'a finite number') {
  const s = params.get(name);
  if (s === null || s === '') return fallback;
  const v = Number(s);
  if (!ok(v)) {
    warnings.push(`URL parameter ${name}=${s}: expected ${expected}`);
    return fallback;
  }
  return v;
}

function sizeParam() {
  const s = params.get('size');
  if (!s) return null;
  const m = /^(\d+)x(\d+)$/.exec(s);
  if (!m || +m[1] < 1 || +m[2] < 1 || +m[1] > 32768 || +m[2] > 32768) {
    warnings.push(`URL parameter size=${s}: expected WIDTHxHEIGHT, each 1..32768`);
    return null;
  }
  return [+m[1], +m[2]];
}

// How groups travel (the hello's encoding): by default the server chooses cells or compact+zstd
// per group, whichever its CPU and the link bring sooner (remote/encoding_choice.h).
function encodingParam() {
  const s = params.get('encoding');
  if (s === null || s === '') return kAdaptiveEncoding;
  const e = helloEncoding(s);
  if (e !== null) return e;
  warnings.push(`URL parameter encoding=${s}: expected auto, 0..4 or vertices, indexed, compact, compact-zstd, cells`);
  return kAdaptiveEncoding;
}

const fixedSize = sizeParam();
const settings = {
  lod: intParam('lod', 0, 2, LodSchedule.chosen),  // 0 off, 1 on, 2 the server chooses
  cache: intParam('cache', 0, 1, 1) === 1,
  encoding: encodingParam(),
};
const urlIso = numberParam('iso', null);
const kMinZoom = 1e-3, kMaxZoom = 1e3;

const api = {
  state: 'idle',
  error: '',
  dataset: '',
  range: [0, 0],
  encoding: settings.encoding,  // what the hello asks for: a codec's id, or 255 for the server's choice
  view: {
    yaw: numberParam('yaw', 0), pitch: numberParam('pitch', 0),
    zoom: numberParam('zoom', 1, (v) => v >= kMinZoom && v <= kMaxZoom, `a zoom in [${kMinZoom}, ${kMaxZoom}]`),
    iso: urlIso ?? 0, width: 0, height: 0,
  },
  request_id: 0,
  frames_done: 0,
  done_request_id: 0,
  stats: emptyStats(),
  requests: [],
  snapshot() {
    return el.canvas.toDataURL('image/png');
  },
};
window.isowall = api;

let renderer = null;
let frames = null;
let ws = null;
let session = 0;        // counts connections; a closed one's events are ignored
let readyMsg = null;
let dirty = false;      // the view changed since the last request
let countersDirty = true;

function setState(s) {
  api.state = s;
  countersDirty = true;
}

// An error that stops the session (or the page): state 'error' and one readable line.
function fail(text) {
  api.error = text;
  setState('error');
  ui.showMessage(el, text, 'error');
}

// A complaint that leaves the session as it is (a bad isovalue typed in).
function complain(text) {
  api.error = text;
  ui.showMessage(el, text, 'error');
}

function clearMessage() {
  api.error = '';
  ui.showMessage(el, '', 'info');
}

// ---- canvas size -------------------------------------------------------------------------------

function canvasSize() {
  const dpr = window.devicePixelRatio || 1;
  if (fixedSize) return fixedSize;
  const w = Math.max(1, Math.round(el.stage.clientWidth * dpr));
  const h = Math.max(1, Math.round(el.stage.clientHeight * dpr));
  return [w, h];
}

function layoutCanvas() {
  const dpr = window.devicePixelRatio || 1;
  const [w, h] = canvasSize();
  // CSS pixels so that one canvas pixel is one device pixel.
  el.canvas.style.width = `${w / dpr}px`;
  el.canvas.style.height = `${h / dpr}px`;
  return [w, h];
}

// ---- requests ----------------------------------------------------------------------------------

function sendFrame(type, msg) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return false;
  ws.send(encodeFrame(type, msg));
  return true;
}

function sendRequest() {
  dirty = false;
  if (!readyMsg || !ws || ws.readyState !== WebSocket.OPEN) return;
  const [width, height] = layoutCanvas();
  const v = api.view;
  const { camera, frustum } = viewCamera(readyMsg.bounds, width, height, v.yaw, v.pitch, v.zoom,
    readyMsg.axes);
  const problem = cameraProblem(camera);
  if (problem) {
    complain(`this view cannot be drawn: ${problem}`);
    return;
  }
  v.width = width;
  v.height = height;
  const id = api.request_id + 1;
  const request = {
    request_id: id,
    view: { camera, frustum, width, height, iso: v.iso },
    lod: settings.lod,
    cached_groups: settings.cache,
  };
  sendFrame(MsgType.request, request);
  api.request_id = id;
  api.requests.push({ id, iso: v.iso, yaw: v.yaw, pitch: v.pitch, zoom: v.zoom, lod: settings.lod, cache: settings.cache });
  frames.begin(request);
  api.stats = frames.stats;
  setState('refining');
}

// At most one request an animation frame, however many events changed the view.
function scheduleRequest() {
  dirty = true;
}

function tick() {
  if (dirty && readyMsg) sendRequest();
  if (countersDirty) {
    countersDirty = false;
    ui.showCounters(el, api);
  }
  requestAnimationFrame(tick);
}

// ---- the connection ----------------------------------------------------------------------------

function closeConnection() {
  if (!ws) return;
  const old = ws;
  ws = null;
  ++session;
  if (old.readyState === WebSocket.OPEN) {
    try { old.send(encodeFrame(MsgType.bye, {})); } catch { /* closing anyway */ }
  }
  old.close(1000);
}

function connect(name) {
  closeConnection();
  readyMsg = null;
  // A new connection is a new server session: its cache generations start afresh, so nothing of
  // the old cache may be named by slot.
  if (renderer) {
    renderer.collect(new Set());
    frames = new ClientFrames(renderer);
    api.stats = frames.stats;
  }
  api.dataset = name;
  api.range = [0, 0];
  api.frames_done = 0;
  el.slider.disabled = el.number.disabled = true;
  el.snapshot.disabled = true;
  if (!name) {
    setState('idle');
    return;
  }
  clearMessage();
  setState('connecting');
  const mine = ++session;
  const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
  let socket;
  try {
    socket = new WebSocket(`${proto}//${location.host}/ws`);
  } catch (e) {
    fail(`cannot open the WebSocket: ${e.message}`);
    return;
  }
  ws = socket;
  socket.binaryType = 'arraybuffer';
  let ended = false;  // an error or a bye came: the close that follows is expected
  socket.onopen = () => {
    if (mine !== session) return;
    // takes_exact: a cells group the page does not cache may come with its gradients to a step first.
    sendFrame(MsgType.hello, { protocol_version: 1, dataset: name, token: el.token.value, encoding: settings.encoding,
      takes_exact: true });
  };
  socket.onmessage = (ev) => {
    if (mine !== session) return;
    if (!(ev.data instanceof ArrayBuffer)) {
      ended = true;
      fail('protocol error: the server sent a text message');
      closeConnection();
      return;
    }
    const bytes = new Uint8Array(ev.data);
    try {
      const { name: kind, msg } = decodeFrame(bytes);
      onMessage(kind, msg, bytes.length);
    } catch (e) {
      ended = true;
      if (e instanceof RemoteError) fail(remoteErrorText(e));
      else fail(`protocol error: ${e.message}`);
      closeConnection();
    }
  };
  socket.onclose = (ev) => {
    if (mine !== session || ended) return;
    ws = null;
    fail(api.state === 'connecting' && !readyMsg
      ? `server gone: cannot connect to ${location.host} (WebSocket closed, code ${ev.code})`
      : `server gone: the connection closed unexpectedly (code ${ev.code})`);
  };
  socket.onerror = () => {};  // onclose follows and says it
  function onMessage(kind, msg, wireBytes) {
    if (kind === 'ready') return onReady(msg);
    if (kind === 'bye') {
      ended = true;
      fail('the server ended the session (bye)');
      closeConnection();
      return;
    }
    if (kind === 'error') throw new RemoteError(msg.code, msg.text);
    if (!frames) return;
    const done = frames.handle(kind, msg, wireBytes);
    // The server chooses the encodings: tell it what decoding costs here (view_client.cpp).
    if (settings.encoding === kAdaptiveEncoding) {
      const report = frames.decodeReport(performance.now());
      if (report) sendFrame(MsgType.decode_rate, report);
    }
    api.stats = frames.stats;
    countersDirty = true;
    if (done) {
      api.frames_done += 1;
      api.done_request_id = frames.lastEnd.request_id;
      setState('done');
    }
  }
}

function remoteErrorText(e) {
  const what = {
    [ErrorCode.bad_token]: 'wrong token',
    [ErrorCode.unknown_dataset]: 'unknown dataset',
    [ErrorCode.unsupported_version]: 'unsupported protocol version',
    [ErrorCode.malformed]: 'the server could not read a message',
    [ErrorCode.too_large]: 'a message was too large',
    [ErrorCode.internal]: 'the server failed',
  }[e.code] ?? 'server error';
  return e.message && e.message !== what ? `${what} (${e.message})` : what;
}

function defaultIso(r, name) {
  if (name === 'phantom' && 50 >= r.value_min && 50 <= r.value_max) return 50;
  return (r.value_min + r.value_max) / 2;
}

function onReady(r) {
  readyMsg = r;
  api.range = [r.value_min, r.value_max];
  let iso = urlIso ?? defaultIso(r, api.dataset);
  if (!(iso >= r.value_min && iso <= r.value_max)) {
    const fallback = defaultIso(r, api.dataset);
    complain(`isovalue ${ui.formatValue(iso)} is outside the value range ` +
      `[${ui.formatValue(r.value_min)}, ${ui.formatValue(r.value_max)}] of ${api.dataset}; drawing ${ui.formatValue(fallback)}`);
    iso = fallback;
  }
  api.view.iso = iso;
  ui.setRange(el, r.value_min, r.value_max, iso);
  el.snapshot.disabled = false;
  sendRequest();
}

// ---- the isovalue ------------------------------------------------------------------------------

function setIso(v, from) {
  if (!readyMsg) return;
  const [lo, hi] = api.range;
  if (!Number.isFinite(v) || v < lo || v > hi) {
    complain(`isovalue ${Number.isFinite(v) ? ui.formatValue(v) : `"${el.number.value}"`} is outside the ` +
      `value range [${ui.formatValue(lo)}, ${ui.formatValue(hi)}]; not sent`);
    return;
  }
  if (api.error) clearMessage();
  api.view.iso = v;
  if (from !== el.slider) el.slider.value = String(v);
  if (from !== el.number) el.number.value = ui.formatValue(v);
  scheduleRequest();
}

el.slider.addEventListener('input', () => setIso(Number(el.slider.value), el.slider));
el.number.addEventListener('change', () => setIso(el.number.value === '' ? NaN : Number(el.number.value), el.number));
el.number.addEventListener('keydown', (e) => {
  if (e.key === 'Enter') setIso(el.number.value === '' ? NaN : Number(el.number.value), el.number);
});

// ---- orbit and zoom (Pointer Events) -----------------------------------------------------------

const kDegPerPixel = 0.4;
const pointers = new Map();
let pinchDistance = 0;

function pinchSpan() {
  const [a, b] = [...pointers.values()];
  return Math.hypot(a.x - b.x, a.y - b.y);
}

function setZoom(z) {
  api.view.zoom = Math.round(Math.min(kMaxZoom, Math.max(kMinZoom, z)) * 1e6) / 1e6;
  scheduleRequest();
}

el.canvas.addEventListener('pointerdown', (e) => {
  el.canvas.setPointerCapture(e.pointerId);
  pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
  if (pointers.size === 2) pinchDistance = pinchSpan();
  e.preventDefault();
});

el.canvas.addEventListener('pointermove', (e) => {
  const p = pointers.get(e.pointerId);
  if (!p) return;
  const dx = e.clientX - p.x, dy = e.clientY - p.y;
  p.x = e.clientX;
  p.y = e.clientY;
  if (pointers.size === 1) {
    if (dx === 0 && dy === 0) return;
    const v = api.view;
    // Drag right turns the volume right; drag down tips its top towards the viewer.
    v.yaw -= dx * kDegPerPixel;
    if (v.yaw > 180) v.yaw -= 360;
    else if (v.yaw < -180) v.yaw += 360;
    v.yaw = Math.round(v.yaw * 1e6) / 1e6;  // no drift of sums of 0.4 (a readable angle)
    v.pitch = Math.round(Math.max(-89, Math.min(89, v.pitch - dy * kDegPerPixel)) * 1e6) / 1e6;
    scheduleRequest();
  } else if (pointers.size === 2) {
    const d = pinchSpan();
    if (pinchDistance > 0 && d > 0) setZoom(api.view.zoom * (d / pinchDistance));
    pinchDistance = d;
  }
});

function pointerEnd(e) {
  pointers.delete(e.pointerId);
  if (pointers.size === 2) pinchDistance = pinchSpan();
}
el.canvas.addEventListener('pointerup', pointerEnd);
el.canvas.addEventListener('pointercancel', pointerEnd);

el.canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  const lines = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
  setZoom(api.view.zoom * Math.exp(-e.deltaY * lines * 0.0015));
}, { passive: false });

// ---- the rest of the controls ------------------------------------------------------------------

el.lod.value = String(settings.lod);
el.cache.checked = settings.cache;
el.lod.addEventListener('change', () => { settings.lod = Number(el.lod.value); scheduleRequest(); });
el.cache.addEventListener('change', () => { settings.cache = el.cache.checked; scheduleRequest(); });

el.snapshot.addEventListener('click', () => {
  const a = document.createElement('a');
  a.href = api.snapshot();
  const v = api.view;
  a.download = `isowall-${api.dataset}-iso${ui.formatValue(v.iso)}-yaw${v.yaw.toFixed(0)}-pitch${v.pitch.toFixed(0)}.png`;
  document.body.appendChild(a);
  a.click();
  a.remove();
});

el.dataset.addEventListener('change', () => connect(el.dataset.value));

async function loadDatasets() {
  const token = el.token.value;
  let res;
  try {
    res = await fetch(`/datasets?token=${encodeURIComponent(token)}`, { cache: 'no-store' });
  } catch (e) {
    fail(`server gone: cannot load the volume list (${e.message})`);
    return;
  }
  let body = null;
  try { body = await res.json(); } catch { /* an error below says it */ }
  if (res.status === 403) {
    fail(body && body.error ? body.error : 'wrong token');
    el.tokenLabel.classList.add('wanted');
    return;
  }
  if (!res.ok || !body || !Array.isArray(body.datasets)) {
    fail(`cannot load the volume list: HTTP ${res.status}`);
    return;
  }
  ui.setDatasets(el, body.datasets.map(String), api.dataset);
  if (api.dataset && !body.datasets.includes(api.dataset) && api.state !== 'error')
    complain(`unknown dataset "${api.dataset}": the server offers ${body.datasets.join(', ') || 'none'}`);
}

el.token.addEventListener('change', () => {
  if (api.state === 'error') clearMessage();
  loadDatasets().then(() => { if (api.dataset && api.state === 'error') connect(api.dataset); });
});

window.addEventListener('resize', () => {
  if (!fixedSize) {
    layoutCanvas();
    scheduleRequest();
  }
});
window.addEventListener('beforeunload', () => closeConnection());

// ---- start -------------------------------------------------------------------------------------

async function start() {
  el.token.value = params.get('token') ?? '';
  const [w, h] = layoutCanvas();
  el.canvas.width = w;
  el.canvas.height = h;
  api.view.width = w;
  api.view.height = h;
  try {
    renderer = new Renderer(el.canvas);
  } catch (e) {
    fail(e.message);
    ui.showCounters(el, api);
    return;
  }
  renderer.clear();
  frames = new ClientFrames(renderer);
  requestAnimationFrame(tick);
  try {
    await codecReady;
  } catch (e) {
    fail(`cannot start the group decoders (WebAssembly): ${e.message}`);
    return;
  }
  // Without the cells decoder, groups come as compact+zstd: a server left to choose would send
  // cells too.
  const problem = cellsProblem();
  if (problem && (settings.encoding === kAdaptiveEncoding || settings.encoding === GroupEncoding.cells)) {
    warnings.push(`${problem}: groups come as compact+zstd`);
    settings.encoding = api.encoding = GroupEncoding.compact_zstd;
  }
  const name = params.get('dataset') ?? '';
  if (name) {
    api.dataset = name;
    ui.setDatasets(el, [], name);
    connect(name);
  }
  await loadDatasets();
  if (warnings.length && !api.error) complain(warnings.join('; '));
}

start();
