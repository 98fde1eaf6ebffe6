// The protocol against the C++ seed corpus (fuzz/corpus/view_protocol: every message with every
// field set, as payloads and as frames) and round trips of what the page encodes.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, readdirSync } from 'node:fs';
import { MsgType, encodePayload, decodePayload, encodeFrame, decodeFrame, decodeHeader, FrameSplitter, makeError } from '../src/protocol.js';
import { frontFullView, fitDepthRange, frustum } from '../src/camera.js';

const corpus = new URL('../../fuzz/corpus/view_protocol/', import.meta.url);
const regressions = new URL('../../fuzz/regressions/view_protocol/', import.meta.url);
const read = (dir, name) => new Uint8Array(readFileSync(new URL(name, dir)));

test('corpus payloads decode, and encode back to their bytes', () => {
  const names = readdirSync(corpus).filter((n) => n.startsWith('payload-'));
  assert.equal(names.length, 11);
  for (const name of names) {
    const b = read(corpus, name);
    assert.equal(b[0] % 2, 0, name);
    const type = b[1] | (b[2] << 8);
    const payload = b.subarray(3);
    const m = decodePayload(type, payload);
    assert.deepEqual(encodePayload(type, m), payload, `${name}: encode(decode(payload)) == payload`);
  }
});

test('corpus frames decode, and frame back to their bytes', () => {
  for (const name of readdirSync(corpus).filter((n) => n.startsWith('stream-') && n !== 'stream-all')) {
    const b = read(corpus, name);
    const frame = b.subarray(2);
    const { type, name: kind, msg } = decodeFrame(frame);
    assert.equal(`stream-${kind}`, name);
    assert.deepEqual(encodeFrame(type, msg), frame, name);
  }
});

test('corpus values are the seeds\' (fuzz/view_protocol_seeds.cpp)', () => {
  const msg = (n) => decodeFrame(read(corpus, `stream-${n}`).subarray(2)).msg;
  assert.deepEqual(msg('hello'), { protocol_version: 1, dataset: 'ct_head', token: 's3cret', encoding: 2 });
  const r = msg('ready');
  assert.deepEqual([r.bounds, r.value_min, r.value_max, r.dims, r.spacing, r.axes],
    [{ min: [0, 0, 0], max: [1, 2, 3] }, -1024, 3071, [256, 256, 113], [1, 1, 2],
      [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]]);
  const q = msg('request');
  assert.equal(q.request_id, 3);
  assert.deepEqual(q.view.camera.eye, [1, -40, 3]);
  assert.equal(q.view.frustum.left, -0.5);
  assert.deepEqual([q.view.width, q.view.height, q.view.iso, q.lod, q.cached_groups], [8, 6, 105.5, 2, true]);
  const g = msg('group');
  assert.deepEqual([g.request_id, g.key, g.draw_from_next_frame, g.cache_gen, Array.from(g.encoded)],
    [3, { seed: [4, 5, 6], level: 2, iso: 105.5, refinement: true }, true, 3, [1, 2, 3]]);
  assert.deepEqual(msg('visible'), { request_id: 3, slots: [0, 1, 2, 5, 7, 11] });
  assert.deepEqual(msg('end_of_frame'), { request_id: 3, rays: 480000, groups: 120, triangles: 90000, bytes: 2400000 });
  assert.deepEqual(msg('error'), { code: 3, text: 'wrong token' });
  assert.deepEqual(msg('bye'), {});
  assert.deepEqual(msg('session'), { session: 'class 3b', presenter: '10.0.0.7:51234', members: 12 });
  assert.deepEqual(msg('decode_rate'), { entries: [{ encoding: 3, triangles: 120000, seconds: 0.0125 },
    { encoding: 4, triangles: 30000, seconds: 0.01 }] });
  const x = msg('exact');
  assert.deepEqual([x.request_id, x.key, Array.from(x.bits)],
    [3, { seed: [4, 5, 6], level: 2, iso: 105.5, refinement: true }, [0x5a, 0x81]]);
});

test('stream-all splits into its eleven frames, whatever the chunks', () => {
  const stream = read(corpus, 'stream-all').subarray(2);
  for (const chunk of [1, 5, 13, 1000]) {
    const s = new FrameSplitter();
    const frames = [];
    for (let i = 0; i < stream.length; i += chunk) frames.push(...s.push(stream.subarray(i, i + chunk)));
    assert.deepEqual(frames.map((f) => decodeFrame(f).name),
      ['hello', 'ready', 'request', 'group', 'visible', 'end_of_frame', 'error', 'bye', 'session', 'decode_rate', 'exact'],
      `chunks of ${chunk}`);
  }
});

test('the non-canonical visible regression is refused, naming the field', () => {
  const b = read(regressions, 'stream-visible-noncanonical-form');
  // As the C++ FrameParser: each frame is decoded as soon as it is whole; the first error ends it.
  const splitter = new FrameSplitter();
  const names = [];
  assert.throws(() => {
    for (let i = 2; i < b.length; ++i) for (const f of splitter.push(b.subarray(i, i + 1))) names.push(decodeFrame(f).name);
  }, /^WireError: visible message: slots: bit count 12 but bit 11 is clear/);
  assert.deepEqual(names, ['hello', 'ready', 'request', 'group']);
});

function sampleRequest() {
  const bounds = { min: [0, 0, 0], max: [199, 183, 167] };
  const c = fitDepthRange(frontFullView(bounds, 4 / 3), bounds);
  return { request_id: 41, view: { camera: c, frustum: frustum(c, 4 / 3), width: 800, height: 600, iso: 50.25 },
    lod: 2, cached_groups: false };
}

test('round trips of what the page sends: hello, request, decode_rate, bye', () => {
  for (const [type, m] of [
    [MsgType.hello, { protocol_version: 1, dataset: 'phantom', token: 'tok en', encoding: 3 }],
    [MsgType.hello, { protocol_version: 1, dataset: 'head', token: '', encoding: 0 }],
    [MsgType.hello, { protocol_version: 1, dataset: 'head', token: '', encoding: 255 }],
    [MsgType.decode_rate, { entries: [] }],
    [MsgType.decode_rate, { entries: [{ encoding: 0, triangles: 1, seconds: 0 }, { encoding: 4, triangles: 2 ** 40, seconds: 1.5e-3 }] }],
    [MsgType.request, sampleRequest()],
    [MsgType.bye, {}],
  ]) {
    const f = encodeFrame(type, m);
    assert.equal(f.length, 12 + new DataView(f.buffer).getUint32(8, true));
    assert.deepEqual(decodeFrame(f).msg, m);
  }
  // A request is 1 + 8 + (9 + 3 + 4) * 4 + 7 * 4 + 8 + 8 + 2 bytes: as the C++'s seed (114 - 3).
  assert.equal(encodePayload(MsgType.request, sampleRequest()).length, 111);
});

test('a hello that takes exact values is version 3, with or without a role, as the C++ writes it', () => {
  const mine = { protocol_version: 1, dataset: 'head', token: '', encoding: 255, takes_exact: true };
  const p = encodePayload(MsgType.hello, mine);
  assert.equal(p[0], 3);
  assert.deepEqual(decodePayload(MsgType.hello, p), { ...mine, role: 0, session: '' });
  const presenter = { ...mine, role: 1, session: 'class 3b' };
  assert.deepEqual(decodePayload(MsgType.hello, encodePayload(MsgType.hello, presenter)), presenter);
  const flag = encodePayload(MsgType.hello, mine);
  flag[flag.length - 1] = 2;
  assert.throws(() => decodePayload(MsgType.hello, flag), /^WireError: hello message: takes_exact: expected 0 or 1, got 2$/);
  flag[flag.length - 1] = 0;  // would encode back as version 1: one encoding per hello
  assert.throws(() => decodePayload(MsgType.hello, flag), /^WireError: hello message: takes_exact: 0 in a version 3 hello/);
  const named = encodePayload(MsgType.hello, { ...mine, session: 'x' });
  assert.throws(() => decodePayload(MsgType.hello, named), /^WireError: hello message: session: a name without a role$/);
});

test('decoders name the message and the field', () => {
  const hello = encodePayload(MsgType.hello, { protocol_version: 1, dataset: 'phantom', token: '', encoding: 3 });
  assert.throws(() => decodePayload(MsgType.hello, hello.subarray(0, 5)), /^WireError: hello message: truncated$/);
  assert.throws(() => decodePayload(MsgType.hello, new Uint8Array([...hello, 0])), /hello message: 1 trailing bytes/);
  assert.throws(() => decodePayload(MsgType.hello, new Uint8Array([4, ...hello.subarray(1)])), /hello message: version 4, expected 3/);
  const empty = encodePayload(MsgType.hello, { protocol_version: 1, dataset: 'x', token: '', encoding: 3 });
  empty[11] = 0x07;  // the dataset's one byte
  assert.throws(() => decodePayload(MsgType.hello, empty), /hello message: dataset: byte 0 is 7, expected printable ASCII/);
  const req = encodePayload(MsgType.request, sampleRequest());
  const bad = req.slice();
  bad[bad.length - 1] = 2;
  assert.throws(() => decodePayload(MsgType.request, bad), /request message: cached_groups: expected 0 or 1, got 2/);
  const lod = req.slice();
  lod[lod.length - 2] = 3;
  assert.throws(() => decodePayload(MsgType.request, lod), /request message: lod: expected 0 \(off\), 1 \(on\) or 2 \(the server chooses\), got 3/);
  const v1 = req.slice();
  v1[0] = 1;  // the version byte: a request of version 1 had the lod byte as a flag
  assert.throws(() => decodePayload(MsgType.request, v1), /request message: version 1, expected 2/);
  const same = sampleRequest();
  same.view.camera.eye = [...same.view.camera.target];
  assert.throws(() => decodePayload(MsgType.request, encodePayload(MsgType.request, same)),
    /request message: view.camera: the eye and the target are the same point/);
  const err = encodePayload(MsgType.error, { code: 3, text: 'x' });
  err[1] = 9;
  assert.throws(() => decodePayload(MsgType.error, err), /error message: code: expected 1..7, got 9/);
  const ready = encodePayload(MsgType.ready, { bounds: { min: [0, 0, 0], max: [1, 1, 1] }, value_min: 5, value_max: 1, dims: [2, 2, 2], spacing: [1, 1, 1] });
  assert.throws(() => decodePayload(MsgType.ready, ready), /ready message: value_max: expected >= value_min/);
  const mirrored = encodePayload(MsgType.ready, { bounds: { min: [0, 0, 0], max: [1, 1, 1] }, value_min: 0, value_max: 1, dims: [2, 2, 2], spacing: [1, 1, 1], axes: [[-1, 0, 0], [0, 1, 0], [0, 0, 1]] });
  assert.throws(() => decodePayload(MsgType.ready, mirrored), /ready message: axes: expected a rotation/);
  const rate = (entries) => encodePayload(MsgType.decode_rate, { entries });
  const one = { encoding: 4, triangles: 10, seconds: 0.5 };
  assert.throws(() => decodePayload(MsgType.decode_rate, rate(Array(6).fill(one))), /^WireError: decode_rate message: entries: 6, expected at most 5$/);
  assert.throws(() => decodePayload(MsgType.decode_rate, rate([{ ...one, encoding: 5 }])), /decode_rate message: entries.encoding: 5, expected at most 4/);
  assert.throws(() => decodePayload(MsgType.decode_rate, rate([one, { ...one, encoding: 3 }])), /entries.encoding: 3 after 4, expected ascending/);
  assert.throws(() => decodePayload(MsgType.decode_rate, rate([{ ...one, seconds: -1 }])), /entries.seconds: -1, expected >= 0/);
  assert.throws(() => decodePayload(MsgType.decode_rate, rate([{ ...one, seconds: NaN }])), /entries.seconds: expected a finite number, got NaN/);
  assert.throws(() => decodePayload(12, new Uint8Array([1])), /view protocol: unknown message type 12/);
});

test('headers are checked before the payload', () => {
  const f = encodeFrame(MsgType.bye, {});
  const h = (patch) => { const b = f.slice(); patch(b); return b; };
  assert.throws(() => decodeHeader(h((b) => { b[0] = 0x58; })), /view protocol header: magic: expected 49 57 56 50 \("IWVP"\), got 58 57 56 50/);
  assert.throws(() => decodeHeader(h((b) => { b[4] = 2; })), /header: version: expected 1, got 2/);
  assert.throws(() => decodeHeader(h((b) => { b[6] = 12; })), /header: type: expected 1..11, got 12/);
  assert.throws(() => decodeHeader(h((b) => { b[11] = 0x10; })), /header: length: 268435457 bytes is over the limit of 67108864 \(bye message\)/);
  assert.throws(() => decodeFrame(new Uint8Array([...f, 0])), /header: length: the header says 1 payload bytes, the frame holds 2/);
});

test('make_error: printable and bounded', () => {
  const e = makeError(3, 'bad\ntoken é' + 'x'.repeat(300));
  assert.equal(e.text.length, 256);
  assert.ok(e.text.startsWith('bad?token ?'));
});
