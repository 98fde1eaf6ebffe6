// The ClientFrames rules (remote/client_frames.cpp) with a recording renderer and fake meshes.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { ClientFrames, RemoteError } from '../src/frames.js';
import { frontFullView, fitDepthRange, frustum } from '../src/camera.js';
import { kGroupCodecVersion } from '../src/group_codec.js';

class Recorder {
  constructor() { this.ops = []; this.live = null; }
  resize(w, h) { this.ops.push(`resize ${w}x${h}`); }
  clear() { this.ops.push('clear'); }
  clearDepth() { this.ops.push('depth'); }
  draw(mesh) { this.ops.push(`draw ${mesh.name}`); }
  collect(live) { this.live = live; }
}

const bounds = { min: [0, 0, 0], max: [10, 10, 10] };
function request(id, cache = true) {
  const c = fitDepthRange(frontFullView(bounds, 1), bounds);
  return { request_id: id, view: { camera: c, frustum: frustum(c, 1), width: 4, height: 4, iso: 1 }, lod: 1, cached_groups: cache };
}
// A group message whose "encoded" bytes are the mesh itself (the decoder is replaced).
function group(id, name, level, { gen = 0, late = false, tris = 1 } = {}) {
  return { request_id: id, key: { seed: [0, 0, 0], level, iso: 1, refinement: false }, draw_from_next_frame: late, cache_gen: gen,
    encoded: { name, indices: new Uint32Array(3 * tris) } };
}
function make() {
  const r = new Recorder();
  let t = 0;
  const f = new ClientFrames(r, () => (t += 1), (m) => m.encoded);
  return { r, f };
}

test('progressive LOD: a depth clear when a finer level begins, coarser groups skipped, redraw at the end', () => {
  const { r, f } = make();
  f.begin(request(1));
  f.handle('group', group(1, 'a2', 2, { tris: 2 }), 100);
  f.handle('group', group(1, 'b2', 2), 100);
  f.handle('group', group(1, 'c1', 1), 100);
  f.handle('group', group(1, 'd2', 2), 100);  // coarser than what shows: not drawn
  f.handle('group', group(1, 'e0', 0), 100);
  f.handle('group', group(1, 'f0', 0), 100);
  f.handle('group', group(1, 'g1', 1), 100);  // coarser: skipped
  assert.equal(f.handle('end_of_frame', { request_id: 1 }, 50), true);
  assert.deepEqual(r.ops, ['resize 4x4', 'clear', 'draw a2', 'draw b2', 'depth', 'draw c1', 'depth', 'draw e0', 'draw f0',
    'clear', 'draw e0', 'draw f0']);
  assert.deepEqual({ ...f.stats, first_group_ms: 0, frame_ms: 0, decode_ms: 0, draw_ms: 0, gl_wait_ms: 0 },
    { bytes: 750, groups: 7, cells: 0, named: 0, triangles: 6, first_group_ms: 0, frame_ms: 0, decode_ms: 0, draw_ms: 0, gl_wait_ms: 0,
      cells_decode_ms: 0, cells_triangles: 0 });
  assert.ok(f.stats.first_group_ms > 0 && f.stats.frame_ms > f.stats.first_group_ms);
});

test('no coarse group: no redraw; late groups cached but not drawn', () => {
  const { r, f } = make();
  f.begin(request(1));
  f.handle('group', group(1, 'a0', 0, { gen: 1 }), 10);
  f.handle('group', group(1, 'late', 1, { gen: 1, late: true }), 10);
  f.handle('end_of_frame', { request_id: 1 }, 10);
  assert.deepEqual(r.ops, ['resize 4x4', 'clear', 'draw a0']);
  assert.equal(f.cache.length, 2);
  assert.equal(f.stats.groups, 2);
});

test('visible: cached groups by slot, coarse first; generations; stale messages only fill the cache', () => {
  const { r, f } = make();
  f.begin(request(1));
  f.handle('group', group(1, 's0', 0, { gen: 1 }), 10);
  f.handle('group', group(1, 's1', 2, { gen: 1 }), 10);
  f.handle('end_of_frame', { request_id: 1 }, 10);
  f.begin(request(2));
  // A group of request 1 arriving late, with the generation: cached (slot 2), not drawn.
  f.handle('group', group(1, 's2', 1, { gen: 1 }), 10);
  f.handle('visible', { request_id: 1, slots: [0] }, 10);  // an older request's: ignored
  r.ops = [];
  f.handle('visible', { request_id: 2, slots: [0, 1, 2] }, 20);
  assert.deepEqual(r.ops, ['draw s1', 'depth', 'draw s2', 'depth', 'draw s0']);
  assert.equal(f.stats.named, 3);
  assert.equal(f.stats.bytes, 20);
  assert.throws(() => f.handle('visible', { request_id: 2, slots: [3] }, 5),
    /visible message: slots: the server named a group the client does not hold \(slot 3 of 3\)/);
  // A new generation drops the cache.
  f.handle('group', group(2, 'n0', 0, { gen: 2 }), 10);
  assert.deepEqual(f.cache.map((c) => c.mesh.name), ['n0']);
  assert.equal(f.cacheGen, 2);
  // Requests that do not cache keep the cache.
  f.begin(request(3, false));
  f.handle('group', group(3, 'u0', 0), 10);
  assert.deepEqual(f.cache.map((c) => c.mesh.name), ['n0']);
  f.handle('end_of_frame', { request_id: 3 }, 10);
  // The frames' end-of-frame redraw keeps groups of the frame alive on the GPU; dropped ones go.
  f.begin(request(4));
  assert.ok([...r.live].every((m) => m.name === 'n0'));
});

test('an end of frame of another request does not end this one; errors throw', () => {
  const { f } = make();
  f.begin(request(5));
  assert.equal(f.handle('end_of_frame', { request_id: 4 }, 10), false);
  assert.equal(f.handle('ready', {}, 10), false);
  assert.throws(() => f.handle('error', { code: 3, text: 'wrong token' }, 10), (e) => e instanceof RemoteError && e.code === 3 && e.message === 'wrong token');
});

test('a group whose encoded key is another group is refused', async () => {
  const { decodeMesh } = await import('../src/frames.js');
  const { readFileSync } = await import('node:fs');
  const { ready } = await import('../src/group_codec.js');
  await ready;
  const encoded = new Uint8Array(readFileSync(new URL('../../fuzz/corpus/group_codec/compact_zstd-tetrahedron', import.meta.url)));
  const key = { seed: [4, -5, 6], level: 0, iso: 105.5, refinement: false };
  assert.equal(decodeMesh({ key, encoded }).indices.length, 12);
  assert.throws(() => decodeMesh({ key: { ...key, level: 1 }, encoded }), /group message: key: the encoded group is another group/);
});

test('decode reports: triangles and seconds per encoding, at most every 50 ms, cells groups counted', () => {
  const r = new Recorder();
  let t = 0;
  // A clock that moves 2 ms for each reading: each decode takes 2 ms.
  const f = new ClientFrames(r, () => (t += 2), (m) => m.mesh);
  const g = (e, tris, gen = 0, id = 1) => ({ request_id: id, key: { seed: [0, 0, 0], level: 0, iso: 1, refinement: false },
    draw_from_next_frame: false, cache_gen: gen, encoded: new Uint8Array([kGroupCodecVersion, e]), mesh: { name: `e${e}`, indices: new Uint32Array(3 * tris) } });
  assert.equal(f.decodeReport(0), null, 'nothing decoded');
  f.begin(request(1));
  f.handle('group', g(4, 10), 10);
  f.handle('group', g(3, 5), 10);
  f.handle('group', g(4, 2), 10);
  f.handle('group', g(3, 1, 7, 99), 10);  // another request's, cached: decoded, so it counts
  assert.equal(f.stats.cells, 2);
  assert.deepEqual(f.decodeReport(1000), { entries: [{ encoding: 3, triangles: 6, seconds: 0.004 }, { encoding: 4, triangles: 12, seconds: 0.004 }] });
  f.handle('group', g(4, 1), 10);
  assert.equal(f.decodeReport(1049), null, 'within 50 ms of the last report');
  assert.deepEqual(f.decodeReport(1050), { entries: [{ encoding: 4, triangles: 1, seconds: 0.002 }] });
  assert.equal(f.decodeReport(2000), null, 'nothing decoded since');
});

// A stepped cells group (remote/cell_codec.h) as the fake decoder sees it: the first decode gives
// the stepped mesh, the one with the exact message's bits its exact mesh.
function steppedFrames() {
  const r = new Recorder();
  let t = 0;
  const decode = (m, exact) => (exact ? { name: `${m.encoded.name}!`, indices: m.encoded.indices } : m.encoded);
  return { r, f: new ClientFrames(r, () => (t += 1), decode) };
}
function stepped(id, name, seed, gen = 0) {
  const g = group(id, name, 0, { gen });
  g.key.seed = [seed, 0, 0];
  g.encoded.stepped = true;
  return g;
}
const exact = (id, seed) => ({ request_id: id, key: { seed: [seed, 0, 0], level: 0, iso: 1, refinement: false }, bits: new Uint8Array(1) });

test('exact values: each replaces its stepped group, and the frame ends on the exact groups alone', () => {
  const { r, f } = steppedFrames();
  f.begin(request(1, false));
  f.handle('group', stepped(1, 'a', 1), 100);
  f.handle('group', group(1, 'b', 0), 100);
  f.handle('group', stepped(1, 'c', 3), 100);
  f.handle('exact', exact(1, 3), 10);
  f.handle('exact', exact(1, 1), 10);
  assert.equal(f.handle('end_of_frame', { request_id: 1 }, 50), true);
  assert.deepEqual(r.ops, ['resize 4x4', 'clear', 'draw a', 'draw b', 'draw c', 'draw c!', 'draw a!',
    'clear', 'draw a!', 'draw b', 'draw c!']);
  assert.equal(f.stats.bytes, 370);
  assert.equal(f.stats.triangles, 3, 'an exact mesh is not counted again');
});

test('exact values: for no awaiting group, missing at the end, or for a group to cache are errors', () => {
  let { f } = steppedFrames();
  f.begin(request(1, false));
  assert.throws(() => f.handle('exact', exact(1, 1), 10), /exact message: key: no group of the request awaits exact values/);
  f.handle('group', stepped(1, 'a', 1), 100);
  f.handle('exact', exact(2, 1), 10);  // another request's: dropped
  assert.throws(() => f.handle('end_of_frame', { request_id: 1 }, 10), /end of frame message: 1 groups of the request never got their exact values/);
  ({ f } = steppedFrames());
  f.begin(request(1));
  assert.throws(() => f.handle('group', stepped(1, 'a', 1, 1), 100), /group message: a group to cache came with its values to a step/);
});
