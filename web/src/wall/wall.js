// The wall's page (isowall wall --http, app/wall_http.h): shows the live mosaic of the tiles'
// previews and turns drags, wheel steps, pinches and the isovalue slider into script lines the
// master runs (master/wall_page.h). One page steers at a time; the others watch and may take over.
// window.isowallWall is kept up to date for tests.
import { ready as mosaicReady, isMosaic, decodeMosaic } from './mosaic.js';
import { Drag, zoomLine, pinchLine, isoLine, surfacesLine, timeLine, clipLine, axisClip, num } from './gestures.js';
import { showMessage as show } from '../ui.js';

const $ = (id) => document.getElementById(id);
const el = {
  wallName: $('wall-name'), slider: $('iso-slider'), number: $('iso-number'), surfaces: $('surfaces'), timeBox: document.querySelector('label.time'), timeStep: $('time-step'), timeValue: $('time-value'), play: $('play'),
  rangeMin: $('range-min'), rangeMax: $('range-max'), snapshot: $('snapshot'),
  steering: $('steering'), take: $('take'), quit: $('quit'), message: $('message'),
  canvas: $('mosaic'), frameState: $('frame-state'), frame: $('s-frame'), wall: $('s-wall'),
  emulated: $('s-emulated'), c99: $('s-c99'), balance: $('s-balance'), jobs: $('s-jobs'), migrated: $('s-migrated'),
  pages: $('s-pages'), dark: $('s-dark'), log: $('log'),
  legendLabel: $('s-legend-label'), legendLo: $('s-legend-lo'), legendHi: $('s-legend-hi'), legendBar: $('s-legend-bar'),
  clipAxis: $('clip-axis'), clipAt: $('clip-at'), clipValue: $('clip-value'),
};
const ctx = el.canvas.getContext('2d');
const kFlushMs = 100;  // a drag or a wheel sends at most this often
const kLogLines = 200;

const api = {
  connected: false,
  you: '',
  welcome: null,
  state: null,
  log: [],      // {who, line, error} of every command the wall ran or refused
  errors: [],   // what only this page was told
  mosaics: 0,   // mosaics drawn
  mosaic_frame: -1,
  sent: [],     // lines this page sent
  snapshot() {
    return el.canvas.toDataURL('image/png');
  },
};
window.isowallWall = api;

function showMessage(text, kind = 'error') {
  show(el, text, kind);
}

const params = new URLSearchParams(location.search);
const ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
ws.binaryType = 'arraybuffer';

function send(obj) {
  if (ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(obj));
}

function run(line) {
  api.sent.push(line);
  send({ run: line });
}

ws.onopen = async () => {
  await mosaicReady;
  send({ hello: params.get('token') ?? '' });
};
ws.onclose = (e) => {
  api.connected = false;
  showMessage(`disconnected from the wall${e.reason ? `: ${e.reason}` : ''} (reload to reconnect)`);
  for (const b of [el.snapshot, el.take, el.quit, el.slider, el.number, el.clipAxis, el.clipAt]) b.disabled = true;
  el.steering.textContent = 'disconnected';
};

ws.onmessage = (e) => {
  const bytes = new Uint8Array(e.data);
  if (isMosaic(bytes)) {
    drawMosaic(bytes);
    return;
  }
  let m;
  try {
    m = JSON.parse(new TextDecoder().decode(bytes));
  } catch (err) {
    showMessage(`a message from the wall that is not JSON: ${err.message}`);
    return;
  }
  if (m.type === 'welcome') welcome(m);
  else if (m.type === 'state') showState(m);
  else if (m.type === 'ran') logLine(m);
  else if (m.type === 'error') {
    api.errors.push(m.text);
    showMessage(m.text);
  }
};

function drawMosaic(bytes) {
  let m;
  try {
    m = decodeMosaic(bytes);
  } catch (err) {
    showMessage(err.message);
    return;
  }
  if (el.canvas.width !== m.width || el.canvas.height !== m.height) {
    el.canvas.width = m.width;
    el.canvas.height = m.height;
  }
  ctx.putImageData(new ImageData(m.rgba, m.width, m.height), 0, 0);
  api.mosaics += 1;
  api.mosaic_frame = m.frame;
}

function welcome(m) {
  api.connected = true;
  api.you = m.you;
  api.welcome = m;
  el.wallName.textContent = `${m.wall} - you are ${m.you}`;
  el.canvas.width = m.width;
  el.canvas.height = m.height;
  for (const b of [el.snapshot, el.take, el.quit]) b.disabled = false;
  showMessage('');
}

let sliderHeld = false;

function showState(s) {
  const first = api.state === null;
  api.state = s;
  if (first || s.value_min !== Number(el.slider.min) || s.value_max !== Number(el.slider.max)) {
    el.slider.min = s.value_min;
    el.slider.max = s.value_max;
    el.slider.step = (s.value_max - s.value_min) / 1000 || 'any';
    el.rangeMin.textContent = num(s.value_min);
    el.rangeMax.textContent = num(s.value_max);
    el.slider.disabled = false;
    el.number.disabled = false;
  }
  if (!sliderHeld && document.activeElement !== el.number) {
    el.slider.value = s.iso;
    el.number.value = num(s.iso);
  }
  showClip(s);
  el.surfaces.disabled = false;
  showTime(s);
  if (document.activeElement !== el.surfaces) el.surfaces.value = (s.surfaces ?? []).join(' ');
  const you = s.steering === api.you;
  el.steering.textContent = you ? 'you steer' : s.steering ? `${s.steering} steers` : 'nobody steers: any input takes the wall';
  el.steering.className = you ? 'you' : '';
  el.take.disabled = you;
  el.frameState.textContent = s.done ? 'done' : 'running';
  el.frame.textContent = String(s.frame);
  el.wall.textContent = `${s.frame_s.toFixed(2)} s`;
  el.emulated.textContent = `${s.emulated_s.toFixed(3)} s`;
  // Known once the frame is complete, and only when the wall measures (--measure).
  el.c99.textContent = s.c99_s >= 0 ? `${s.c99_s.toFixed(3)} s` : '-';
  el.balance.textContent = s.balance.toFixed(2);
  el.jobs.textContent = `${s.jobs_done}/${s.jobs}`;
  el.migrated.textContent = String(s.migrated);
  el.pages.textContent = s.pages.join(', ');
  // Screens whose tile rank is lost: the other ranks draw them into this mosaic, the wall's own
  // display stays dark.
  const legend = s.legend;
  el.legendLabel.parentElement.hidden = !legend;
  if (legend) {
    el.legendLabel.textContent = legend.label;
    el.legendLo.textContent = num(legend.lo);
    el.legendHi.textContent = num(legend.hi);
    el.legendBar.style.background = `linear-gradient(to right, ${legend.stops.join(', ')})`;
  }
  const dark = s.dark || [];
  el.dark.parentElement.hidden = dark.length === 0;
  el.dark.textContent = dark.join('; ');
}

function logLine(m) {
  api.log.push(m);
  const li = document.createElement('li');
  li.textContent = `${m.who}: ${m.line}${m.error ? `  (refused: ${m.error})` : ''}`;
  if (m.error) li.className = 'refused';
  el.log.appendChild(li);
  while (el.log.children.length > kLogLines) el.log.removeChild(el.log.firstChild);
  el.log.scrollTop = el.log.scrollHeight;
  if (m.who === api.you && m.error) showMessage(m.error);
}

// Screen pixels to mosaic pixels (the canvas is scaled to fit the page).
function toMosaic(dx, dy) {
  const r = el.canvas.getBoundingClientRect();
  return [dx * el.canvas.width / Math.max(r.width, 1), dy * el.canvas.height / Math.max(r.height, 1)];
}

// Pointers: one drags (orbit; right button or shift: pan), two pinch (zoom).
const pointers = new Map();
let drag = null, pinchStart = 0, pinchNow = 0, wheelSteps = 0, flushTimer = null;

function flush() {
  flushTimer = null;
  if (drag) {
    const line = drag.flush(el.canvas.width, el.canvas.height);
    if (line) run(line);
  }
  if (wheelSteps !== 0) {
    run(zoomLine(wheelSteps));
    wheelSteps = 0;
  }
}

function flushSoon() {
  if (flushTimer === null) flushTimer = setTimeout(flush, kFlushMs);
}

function distance() {
  const [a, b] = [...pointers.values()];
  return Math.hypot(a.x - b.x, a.y - b.y);
}

el.canvas.addEventListener('contextmenu', (e) => e.preventDefault());
el.canvas.addEventListener('pointerdown', (e) => {
  el.canvas.setPointerCapture(e.pointerId);
  pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
  if (pointers.size === 1) {
    drag = new Drag(e.button === 2 || e.shiftKey ? 'pan' : 'orbit');
  } else if (pointers.size === 2) {
    flush();
    drag = null;
    pinchStart = pinchNow = distance();
  }
});
el.canvas.addEventListener('pointermove', (e) => {
  const p = pointers.get(e.pointerId);
  if (!p) return;
  const [dx, dy] = toMosaic(e.clientX - p.x, e.clientY - p.y);
  p.x = e.clientX;
  p.y = e.clientY;
  if (pointers.size === 2) {
    pinchNow = distance();
  } else if (drag) {
    drag.move(dx, dy);
    flushSoon();
  }
});
function pointerEnd(e) {
  if (!pointers.has(e.pointerId)) return;
  if (pointers.size === 2 && pinchStart > 0 && Math.abs(pinchNow - pinchStart) > 2) {
    run(pinchLine(pinchStart, pinchNow));
    pinchStart = 0;
  }
  pointers.delete(e.pointerId);
  if (pointers.size === 0) {
    if (flushTimer !== null) clearTimeout(flushTimer);
    flush();
    drag = null;
  }
}
el.canvas.addEventListener('pointerup', pointerEnd);
el.canvas.addEventListener('pointercancel', pointerEnd);
el.canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  if (e.deltaY !== 0) wheelSteps += Math.sign(e.deltaY);
  flushSoon();
}, { passive: false });

function setIso(v) {
  if (!api.state) return;
  if (!Number.isFinite(v) || v < api.state.value_min || v > api.state.value_max) {
    showMessage(`isovalue ${v}: outside the volume's range [${num(api.state.value_min)}, ${num(api.state.value_max)}]`);
    return;
  }
  run(isoLine(v));
}
el.slider.addEventListener('input', () => {
  sliderHeld = true;
  el.number.value = num(Number(el.slider.value));
});
el.slider.addEventListener('change', () => {
  sliderHeld = false;
  setIso(Number(el.slider.value));
});
el.number.addEventListener('keydown', (e) => {
  if (e.key === 'Enter') setIso(Number(el.number.value));
});
// A time series: the slider shows the step (unless held), the button plays round and round or
// pauses.
let timeHeld = false;
function showTime(s) {
  el.timeBox.hidden = !(s.steps > 0);
  if (!(s.steps > 0)) return;
  el.timeStep.max = s.steps - 1;
  if (!timeHeld) el.timeStep.value = s.step;
  el.timeValue.textContent = `${s.step}/${s.steps}`;
  el.play.textContent = s.playing ? 'Pause' : 'Play';
}
el.timeStep.addEventListener('input', () => { timeHeld = true; });
el.timeStep.addEventListener('change', () => {
  timeHeld = false;
  run(timeLine(Number(el.timeStep.value)));
});
el.play.addEventListener('click', () => run(api.state?.playing ? 'pause' : 'play loop'));
el.surfaces.addEventListener('keydown', (e) => {
  if (e.key !== 'Enter') return;
  const line = surfacesLine(el.surfaces.value);
  if (line) run(line);
  el.surfaces.blur();
});
// The clip menu and slider show the wall's clip when it is one axis plane (a script or the control
// window may have set others: the menu then says "other" until the page sets its own).
let clipHeld = false;
function showClip(s) {
  el.clipAxis.disabled = false;
  el.clipAt.disabled = false;
  if (clipHeld) return;
  const c = axisClip(s.clip);
  const other = s.clip && !c;
  let opt = el.clipAxis.querySelector('option[value="other"]');
  if (other && !opt) {
    opt = new Option('other', 'other');
    el.clipAxis.add(opt);
  }
  if (opt && !other) opt.remove();
  el.clipAxis.value = c ? c.axis : other ? 'other' : '';
  el.clipValue.textContent = s.clip || 'none';
  if (c) setClipRange(c.axis, c.at);
}
function setClipRange(axis, at) {
  const dims = api.state?.dims ?? [1, 1, 1];
  el.clipAt.max = Math.max(0, dims['xyz'.indexOf(axis)] - 1);
  if (at !== undefined) el.clipAt.value = at;
}
function sendClip() {
  const axis = el.clipAxis.value === 'other' ? '' : el.clipAxis.value;
  run(clipLine(axis, Number(el.clipAt.value)));
}
el.clipAxis.addEventListener('change', () => {
  // A new axis starts at its middle.
  const axis = el.clipAxis.value;
  if (axis && axis !== 'other') setClipRange(axis, Math.floor((Number(el.clipAt.max)) / 2));
  sendClip();
});
el.clipAt.addEventListener('input', () => {
  clipHeld = true;
  el.clipValue.textContent = `${el.clipAxis.value}<${el.clipAt.value}`;
});
el.clipAt.addEventListener('change', () => {
  clipHeld = false;
  if (el.clipAxis.value && el.clipAxis.value !== 'other') sendClip();
});
el.snapshot.addEventListener('click', () => send({ snapshot: true }));
el.take.addEventListener('click', () => send({ take: true }));
el.quit.addEventListener('click', () => {
  if (params.get('confirm') === '0' || window.confirm('End the wall run for everyone?')) run('quit');
});
