// The remote-viewing protocol (remote/view_framing.h, remote/view_protocol.h): a 12-byte header
// (magic "IWVP", u16 version 1, u16 type, u32 payload length, little-endian), then the payload: a
// layout version byte, then the fields. Every message has its encoder above its decoder. Decoders
// check every value (finite numbers, ranges, bounded printable text, no trailing bytes) and throw
// an Error naming the message and the field, as the C++ decoders do.
import { Reader, Writer, WireError } from './wire.js';
import { getSlots, putSlots } from './slot_list.js';
import { cameraProblem } from './camera.js';

export const MsgType = {
  hello: 1, ready: 2, request: 3, group: 4, visible: 5, end_of_frame: 6, error: 7, bye: 8, session: 9,
  decode_rate: 10, exact: 11,
};
export const kLastMsgType = 11;
const typeNames = Object.fromEntries(Object.entries(MsgType).map(([k, v]) => [v, k]));
export function typeName(type) {
  return typeNames[type] ?? 'unknown';
}

export const ErrorCode = {
  malformed: 1, unsupported_version: 2, bad_token: 3, unknown_dataset: 4, too_large: 5, internal: 6, session: 7,
};
export const kLastErrorCode = 7;

export const kProtocolVersion = 1;
export const kHeaderBytes = 12;
export const kDefaultMaxPayloadBytes = 64 * 1024 * 1024;
export const kMaxDatasetNameBytes = 256;
export const kMaxTokenBytes = 256;
export const kMaxErrorTextBytes = 256;
export const kMaxSessionNameBytes = 64;
export const kMaxPeerNameBytes = 128;
export const kMaxGroupBytes = 32 * 1024 * 1024;
export const kMaxGroupLevel = 30;
export const kMaxImageSide = 32768;
// decode_rate: one entry at most per group codec (GroupEncoding's count).
export const kDecodeRateEncodings = 5;
// A request's progressive LOD (remote/view_protocol.h LodSchedule): never, always, or where the
// server forecasts that the coarse passes bring C = 90% sooner (the page's default).
export const LodSchedule = { off: 0, on: 1, chosen: 2 };
const MAGIC = [0x49, 0x57, 0x56, 0x50];

// hello: 1 with neither a shared session nor takes_exact, 2 with a session (role and session
// name), 3 with takes_exact (role 0 without a session); all three decode.
const VERSION = {
  hello: 1, ready: 2, request: 2, group: 2, visible: 2, end_of_frame: 1, error: 1, bye: 1, session: 1, decode_rate: 1,
  exact: 1,
};

// ---- text ----------------------------------------------------------------------------------

function putText(w, s) {
  const b = new TextEncoder().encode(s);
  w.bytes(b);
}

function getText(r, field, maxBytes, mayBeEmpty) {
  const b = r.getBytes();
  if (b.length > maxBytes) r.fail(`${field}: ${b.length} bytes, expected at most ${maxBytes}`);
  if (b.length === 0 && !mayBeEmpty) r.fail(`${field}: expected a name, got none`);
  for (let i = 0; i < b.length; ++i)
    if (b[i] < 0x20 || b[i] > 0x7e) r.fail(`${field}: byte ${i} is ${b[i]}, expected printable ASCII (32..126)`);
  return String.fromCharCode(...b);
}

// Cuts to kMaxErrorTextBytes and replaces anything outside printable ASCII by '?' (make_error).
export function makeError(code, text) {
  let t = String(text).slice(0, kMaxErrorTextBytes);
  t = t.replace(/[^\x20-\x7e]/g, '?');
  return { code, text: t };
}

function getFlag(r, field) {
  const v = r.u8();
  if (v > 1) r.fail(`${field}: expected 0 or 1, got ${v}`);
  return v === 1;
}

function getIntIn(r, field, lo, hi) {
  const v = r.i32();
  if (v < lo || v > hi) r.fail(`${field}: expected ${lo}..${hi}, got ${v}`);
  return v;
}

// ---- frame view (wire/message_fields.cpp) -------------------------------------------------------

function getProjection(r, field) {
  const v = r.i32();
  if (v < 0 || v > 1) r.fail(`${field}: expected 0 (perspective) or 1 (orthographic), got ${v}`);
  return v;
}

function finiteVec3Group(r, field) {
  const v = r.vec3();
  if (!v.every(Number.isFinite)) r.fail(`${field}: expected finite numbers, got (${v.join(', ')})`);
  return v;
}

export function putFrameView(w, v) {
  const c = v.camera, fr = v.frustum;
  w.vec3(c.eye); w.vec3(c.target); w.vec3(c.up);
  w.i32(c.projection); w.f32(c.fovy_deg); w.f32(c.ortho_height); w.f32(c.near_z); w.f32(c.far_z);
  w.f32(fr.left); w.f32(fr.right); w.f32(fr.bottom); w.f32(fr.top); w.f32(fr.near_z); w.f32(fr.far_z);
  w.i32(fr.projection);
  w.i32(v.width); w.i32(v.height);
  w.f64(v.iso);
}

export function getFrameView(r) {
  const camera = {};
  camera.eye = finiteVec3Group(r, 'camera.eye');
  camera.target = finiteVec3Group(r, 'camera.target');
  camera.up = finiteVec3Group(r, 'camera.up');
  camera.projection = getProjection(r, 'camera.projection');
  camera.fovy_deg = r.finiteF32('camera.fovy_deg');
  camera.ortho_height = r.finiteF32('camera.ortho_height');
  camera.near_z = r.finiteF32('camera.near_z');
  camera.far_z = r.finiteF32('camera.far_z');
  const frustum = {};
  for (const k of ['left', 'right', 'bottom', 'top', 'near_z', 'far_z']) frustum[k] = r.finiteF32(`frustum.${k}`);
  frustum.projection = getProjection(r, 'frustum.projection');
  const width = getIntIn(r, 'view.width', 1, kMaxImageSide);
  const height = getIntIn(r, 'view.height', 1, kMaxImageSide);
  const iso = r.finiteF64('view.iso');
  return { camera, frustum, width, height, iso };
}

// ---- group key -------------------------------------------------------------------------------

function putGroupKey(w, k) {
  w.i32(k.seed[0]); w.i32(k.seed[1]); w.i32(k.seed[2]); w.i32(k.level);
  w.f64(k.iso);
  w.u8(k.refinement ? 1 : 0);
}

function getGroupKey(r) {
  const names = ['seed.x', 'seed.y', 'seed.z', 'level'];
  const ints = [];
  for (let i = 0; i < 4; ++i) {
    const v = r.i32();
    const hi = i === 3 ? kMaxGroupLevel : 2147483647;
    if (v < 0 || v > hi) r.fail(`key.${names[i]}: expected 0..${hi}, got ${v}`);
    ints.push(v);
  }
  const iso = r.f64();
  if (!Number.isFinite(iso)) r.fail(`key.iso: expected a finite number, got ${iso}`);
  const refinement = r.u8();
  if (refinement > 1) r.fail(`key.refinement: expected 0 or 1, got ${refinement}`);
  return { seed: ints.slice(0, 3), level: ints[3], iso, refinement: refinement === 1 };
}

// ---- the messages ----------------------------------------------------------------------------

const encoders = {
  hello(m) {
    const version = m.takes_exact ? 3 : m.role ? 2 : VERSION.hello;
    const w = new Writer(version);
    w.u16(m.protocol_version ?? 1);
    putText(w, m.dataset);
    putText(w, m.token ?? '');
    w.u8(m.encoding ?? 0);
    if (version >= 2) {
      w.u8(m.role ?? 0);
      putText(w, m.session ?? '');
    }
    if (version >= 3) w.u8(1);
    return w.take();
  },
  session(m) {
    const w = new Writer(VERSION.session);
    putText(w, m.session);
    putText(w, m.presenter);
    w.u32(m.members);
    return w.take();
  },
  ready(m) {
    const w = new Writer(VERSION.ready);
    w.vec3(m.bounds.min); w.vec3(m.bounds.max);
    w.f64(m.value_min); w.f64(m.value_max);
    for (const d of m.dims) w.i32(d);
    w.vec3(m.spacing);
    for (const col of m.axes ?? [[1, 0, 0], [0, 1, 0], [0, 0, 1]]) w.vec3(col);
    return w.take();
  },
  request(m) {
    const w = new Writer(VERSION.request);
    w.u64(m.request_id);
    putFrameView(w, m.view);
    w.u8(m.lod);
    w.u8(m.cached_groups ? 1 : 0);
    return w.take();
  },
  group(m) {
    const w = new Writer(VERSION.group);
    w.u64(m.request_id);
    putGroupKey(w, m.key);
    w.u8(m.draw_from_next_frame ? 1 : 0);
    w.u64(m.cache_gen);
    w.bytes(m.encoded);
    return w.take();
  },
  // A cells group's exact values (remote/cell_exact.h) after its group message stepped them.
  exact(m) {
    const w = new Writer(VERSION.exact);
    w.u64(m.request_id);
    putGroupKey(w, m.key);
    w.bytes(m.bits);
    return w.take();
  },
  visible(m) {
    const w = new Writer(VERSION.visible);
    w.u64(m.request_id);
    putSlots(w, m.slots);
    return w.take();
  },
  // What decoding groups cost the client since its last report, per encoding: entries
  // { encoding, triangles, seconds }, ascending by encoding (a client of the adaptive server sends it).
  decode_rate(m) {
    const w = new Writer(VERSION.decode_rate);
    w.u8(m.entries.length);
    for (const e of m.entries) {
      w.u8(e.encoding);
      w.u64(e.triangles);
      w.f64(e.seconds);
    }
    return w.take();
  },
  end_of_frame(m) {
    const w = new Writer(VERSION.end_of_frame);
    for (const k of ['request_id', 'rays', 'groups', 'triangles', 'bytes']) w.u64(m[k]);
    return w.take();
  },
  error(m) {
    const w = new Writer(VERSION.error);
    w.u16(m.code);
    putText(w, m.text);
    return w.take();
  },
  bye() {
    return new Writer(VERSION.bye).take();
  },
};

const decoders = {
  hello(r, version) {
    const m = {};
    m.protocol_version = r.u16();
    m.dataset = getText(r, 'dataset', kMaxDatasetNameBytes, false);
    m.token = getText(r, 'token', kMaxTokenBytes, true);
    m.encoding = r.u8();
    if (version >= 2) {
      // Version 2 has a role; version 3 may have none (0), and then no session name.
      m.role = r.u8();
      const least = version === 2 ? 1 : 0;
      if (m.role < least || m.role > 2)
        r.fail(`role: ${m.role}, expected ${least === 0 ? '0 (none), ' : ''}1 (presenter) or 2 (follower)`);
      m.session = getText(r, 'session', kMaxSessionNameBytes, m.role === 0);
      if (m.role === 0 && m.session !== '') r.fail('session: a name without a role');
    }
    if (version >= 3) {
      // Version 3 exists to say 1: a hello without it is version 1 or 2, one encoding per hello.
      m.takes_exact = getFlag(r, 'takes_exact');
      if (!m.takes_exact) r.fail('takes_exact: 0 in a version 3 hello, which is sent only with 1');
    }
    return m;
  },
  session(r) {
    const m = {};
    m.session = getText(r, 'session', kMaxSessionNameBytes, false);
    m.presenter = getText(r, 'presenter', kMaxPeerNameBytes, true);
    m.members = r.u32();
    return m;
  },
  ready(r) {
    const m = {};
    const min = r.finiteVec3('bounds.min');
    const max = r.finiteVec3('bounds.max');
    m.bounds = { min, max };
    if (min.some((v, a) => v > max[a])) r.fail('bounds: expected min <= max on every axis');
    m.value_min = r.finiteF64('value_min');
    m.value_max = r.finiteF64('value_max');
    if (m.value_min > m.value_max) r.fail('value_max: expected >= value_min');
    m.dims = ['dims.x', 'dims.y', 'dims.z'].map((n) => getIntIn(r, n, 1, 2147483647));
    m.spacing = r.finiteVec3('spacing');
    if (!m.spacing.every((s) => s > 0)) r.fail('spacing: expected positive numbers');
    // The volume's axes in patient space: unit columns making a rotation (version 2).
    m.axes = ['axes.x', 'axes.y', 'axes.z'].map((n) => {
      const col = r.finiteVec3(n);
      if (Math.abs(Math.hypot(...col) - 1) > 1e-3) r.fail(`${n}: expected a unit vector`);
      return col;
    });
    const [a, b, c] = m.axes;
    const det = a[0] * (b[1] * c[2] - b[2] * c[1]) - b[0] * (a[1] * c[2] - a[2] * c[1]) +
      c[0] * (a[1] * b[2] - a[2] * b[1]);
    if (Math.abs(det - 1) > 1e-2) r.fail('axes: expected a rotation (orthogonal unit columns, determinant 1)');
    return m;
  },
  request(r) {
    const m = {};
    m.request_id = r.u64('request_id');
    m.view = getFrameView(r);
    const problem = cameraProblem(m.view.camera);
    if (problem) r.fail(`view.camera: ${problem}`);
    m.lod = r.u8();
    if (m.lod > LodSchedule.chosen) r.fail(`lod: expected 0 (off), 1 (on) or 2 (the server chooses), got ${m.lod}`);
    m.cached_groups = getFlag(r, 'cached_groups');
    return m;
  },
  group(r) {
    const m = {};
    m.request_id = r.u64('request_id');
    m.key = getGroupKey(r);
    m.draw_from_next_frame = getFlag(r, 'draw_from_next_frame');
    m.cache_gen = r.u64('cache_gen');
    const encoded = r.getBytes();
    if (encoded.length > kMaxGroupBytes) r.fail(`encoded: ${encoded.length} bytes, expected at most ${kMaxGroupBytes}`);
    m.encoded = encoded;
    return m;
  },
  exact(r) {
    const m = {};
    m.request_id = r.u64('request_id');
    m.key = getGroupKey(r);
    const bits = r.getBytes();
    if (bits.length > kMaxGroupBytes) r.fail(`bits: ${bits.length} bytes, expected at most ${kMaxGroupBytes}`);
    m.bits = bits;
    return m;
  },
  visible(r) {
    const m = {};
    m.request_id = r.u64('request_id');
    m.slots = getSlots(r);
    return m;
  },
  end_of_frame(r) {
    const m = {};
    for (const k of ['request_id', 'rays', 'groups', 'triangles', 'bytes']) m[k] = r.u64(k);
    return m;
  },
  error(r) {
    const m = {};
    const code = r.u16();
    if (code < 1 || code > kLastErrorCode) r.fail(`code: expected 1..${kLastErrorCode}, got ${code}`);
    m.code = code;
    m.text = getText(r, 'text', kMaxErrorTextBytes, true);
    return m;
  },
  bye() {
    return {};
  },
  decode_rate(r) {
    const count = r.u8();
    if (count > kDecodeRateEncodings) r.fail(`entries: ${count}, expected at most ${kDecodeRateEncodings}`);
    const entries = [];
    for (let i = 0; i < count; ++i) {
      const encoding = r.u8();
      if (encoding > kDecodeRateEncodings - 1)
        r.fail(`entries.encoding: ${encoding}, expected at most ${kDecodeRateEncodings - 1}`);
      if (entries.length && encoding <= entries[entries.length - 1].encoding)
        r.fail(`entries.encoding: ${encoding} after ${entries[entries.length - 1].encoding}, expected ascending`);
      const triangles = r.u64('entries.triangles');
      const seconds = r.finiteF64('entries.seconds');
      if (seconds < 0) r.fail(`entries.seconds: ${seconds}, expected >= 0`);
      entries.push({ encoding, triangles, seconds });
    }
    return { entries };
  },
};

// The payload of a message of `type` (a MsgType number).
export function encodePayload(type, m) {
  const name = typeNames[type];
  if (!name) throw new WireError(`view protocol: unknown message type ${type}`);
  return encoders[name](m);
}

export function decodePayload(type, payload) {
  const name = typeNames[type];
  if (!name) throw new WireError(`view protocol: unknown message type ${type}`);
  // A hello is read in the layout its version byte names (1..3), as the C++ does; another fails on 3.
  const version = name !== 'hello' ? VERSION[name] : payload.length > 0 && payload[0] >= 1 && payload[0] <= 3 ? payload[0] : 3;
  const r = new Reader(payload, `${name} message`, version);
  const m = decoders[name](r, version);
  r.finish();
  return m;
}

function headerError(why) {
  throw new WireError(`view protocol header: ${why}`);
}

const hex = (b) => Array.from(b, (x) => x.toString(16).padStart(2, '0')).join(' ');

// The header's 12 bytes, checked.
export function decodeHeader(bytes, maxPayloadBytes = kDefaultMaxPayloadBytes) {
  if (bytes.length < kHeaderBytes) headerError(`truncated: ${bytes.length} bytes, expected ${kHeaderBytes}`);
  const magic = bytes.subarray(0, 4);
  if (!MAGIC.every((b, i) => magic[i] === b)) headerError(`magic: expected 49 57 56 50 ("IWVP"), got ${hex(magic)}`);
  const dv = new DataView(bytes.buffer, bytes.byteOffset, kHeaderBytes);
  const version = dv.getUint16(4, true);
  if (version !== kProtocolVersion) headerError(`version: expected ${kProtocolVersion}, got ${version}`);
  const type = dv.getUint16(6, true);
  if (type < 1 || type > kLastMsgType) headerError(`type: expected 1..${kLastMsgType}, got ${type}`);
  const payloadBytes = dv.getUint32(8, true);
  if (payloadBytes > maxPayloadBytes)
    headerError(`length: ${payloadBytes} bytes is over the limit of ${maxPayloadBytes} (${typeNames[type]} message)`);
  return { version, type, payloadBytes };
}

// Header and payload of one message, ready to send.
export function encodeFrame(type, m) {
  const payload = encodePayload(type, m);
  const out = new Uint8Array(kHeaderBytes + payload.length);
  out.set(MAGIC, 0);
  const dv = new DataView(out.buffer);
  dv.setUint16(4, kProtocolVersion, true);
  dv.setUint16(6, type, true);
  dv.setUint32(8, payload.length, true);
  out.set(payload, kHeaderBytes);
  return out;
}

// Exactly one whole frame (one WebSocket message): { type, name, msg }.
export function decodeFrame(bytes, maxPayloadBytes = kDefaultMaxPayloadBytes) {
  bytes = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
  const h = decodeHeader(bytes, maxPayloadBytes);
  if (bytes.length !== kHeaderBytes + h.payloadBytes)
    headerError(`length: the header says ${h.payloadBytes} payload bytes, the frame holds ${bytes.length - kHeaderBytes}`);
  const msg = decodePayload(h.type, bytes.subarray(kHeaderBytes));
  return { type: h.type, name: typeNames[h.type], msg };
}

// Splits a byte stream into whole frames (for the tests): feed chunks, get frames.
export class FrameSplitter {
  constructor(maxPayloadBytes = kDefaultMaxPayloadBytes) {
    this.max = maxPayloadBytes;
    this.chunks = [];
    this.held = 0;
  }
  push(chunk) {
    this.chunks.push(chunk);
    this.held += chunk.length;
    const out = [];
    for (;;) {
      if (this.held < kHeaderBytes) break;
      const all = this.concat();
      const h = decodeHeader(all.subarray(0, kHeaderBytes), this.max);
      const total = kHeaderBytes + h.payloadBytes;
      if (all.length < total) break;
      out.push(all.slice(0, total));
      const rest = all.subarray(total);
      this.chunks = rest.length ? [rest] : [];
      this.held = rest.length;
    }
    return out;
  }
  concat() {
    if (this.chunks.length === 1) return this.chunks[0];
    const all = new Uint8Array(this.held);
    let o = 0;
    for (const c of this.chunks) { all.set(c, o); o += c.length; }
    this.chunks = [all];
    return all;
  }
}
