// The group codec against the C++ seed corpus (fuzz/corpus/group_codec): every encoding of the
// same group decodes to the same triangles, with the same winding, up to the compact encodings'
// documented reordering (vertices, triangles, first corner), dropped unused vertices and
// quantisation (positions within the box's extent / 65535 per axis; normals within 0.01 degree).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, readdirSync } from 'node:fs';
import { decodeGroup, encodingOf, ready, zstdFrameContentSize, octDecode } from '../src/group_codec.js';

await ready;
const dir = new URL('../../fuzz/corpus/group_codec/', import.meta.url);
const regressions = new URL('../../fuzz/regressions/group_codec/', import.meta.url);
const read = (d, n) => new Uint8Array(readFileSync(new URL(n, d)));
const encodings = ['vertices', 'indexed', 'compact', 'compact_zstd'];

function triangles(g) {
  const out = [];
  for (let t = 0; t < g.indices.length / 3; ++t) {
    const corner = (k) => {
      const i = g.indices[3 * t + k];
      return { p: Array.from(g.positions.subarray(3 * i, 3 * i + 3)), n: Array.from(g.normals.subarray(3 * i, 3 * i + 3)) };
    };
    out.push([corner(0), corner(1), corner(2)]);
  }
  return out;
}

const angleDeg = (a, b) => {
  const la = Math.hypot(...a), lb = Math.hypot(...b);
  const c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
  return Math.acos(Math.min(1, Math.max(-1, c))) * 180 / Math.PI;
};

// Every triangle of `got` matches a distinct triangle of `want` under a rotation of its corners.
function sameTriangles(got, want, posTol, normalTolDeg, what) {
  assert.equal(got.length, want.length, `${what}: triangle count`);
  const used = new Array(want.length).fill(false);
  for (const t of got) {
    let found = -1;
    for (let j = 0; j < want.length && found < 0; ++j) {
      if (used[j]) continue;
      for (let rot = 0; rot < 3; ++rot) {
        const ok = [0, 1, 2].every((k) => {
          const a = t[k], b = want[j][(k + rot) % 3];
          return a.p.every((v, ax) => Math.abs(v - b.p[ax]) <= posTol[ax]) && angleDeg(a.n, b.n) <= normalTolDeg;
        });
        if (ok) { found = j; break; }
      }
    }
    assert.ok(found >= 0, `${what}: triangle ${JSON.stringify(t.map((c) => c.p))} has no match`);
    used[found] = true;
  }
}

for (const shape of ['tetrahedron', 'grid', 'empty']) {
  test(`${shape}: all four encodings decode to the same triangles`, () => {
    const groups = Object.fromEntries(encodings.map((e) => [e, decodeGroup(read(dir, `${e}-${shape}`))]));
    encodings.forEach((e, i) => assert.equal(encodingOf(read(dir, `${e}-${shape}`)), i));
    const ref = groups.indexed;
    for (const e of encodings) {
      const g = groups[e];
      assert.deepEqual([g.id, g.seed, g.level, g.iso, g.refinement], [ref.id, ref.seed, ref.level, ref.iso, ref.refinement], `${e} header`);
      for (const v of [...g.positions, ...g.normals]) assert.ok(Number.isFinite(v));
      for (const i of g.indices) assert.ok(i < g.positions.length / 3);
    }
    const want = triangles(ref);
    // vertices: the same floats, corner by corner, in order.
    assert.deepEqual(triangles(groups.vertices), want, 'vertices');
    // compact: the box of the used vertices over 65535 steps, half a step plus float rounding.
    const used = new Set(ref.indices);
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const i of used) for (let a = 0; a < 3; ++a) {
      lo[a] = Math.min(lo[a], ref.positions[3 * i + a]);
      hi[a] = Math.max(hi[a], ref.positions[3 * i + a]);
    }
    const tol = lo.map((l, a) => (hi[a] - l) / 65535 * 0.5 + 1e-5 * Math.max(1, Math.abs(hi[a]), Math.abs(l)));
    for (const e of ['compact', 'compact_zstd']) {
      sameTriangles(triangles(groups[e]), want, tol, 0.01 + 1e-3, e);
      assert.equal(groups[e].positions.length / 3, used.size, `${e}: unused vertices dropped`);
    }
    assert.deepEqual(groups.compact_zstd, groups.compact, 'compact+zstd is compact');
  });
}

// libmeshoptimizer 0.18 (Debian's, the server's) writes index codec version 0 by default (header
// byte 0xe0); the npm decoder (meshoptimizer 1.3) reads versions 0 and 1.
test('the index codec is meshoptimizer\'s version 0 (what libmeshoptimizer 0.18 writes)', () => {
  const b = read(dir, 'compact-tetrahedron');
  // version, encoding, header 29, V and T 8, box 24, positions 6V, normals 4V, size u32.
  const v = 4;
  const at = 2 + 29 + 8 + 24 + 10 * v;
  const size = new DataView(b.buffer).getUint32(at, true);
  assert.equal(at + 4 + size, b.length);
  assert.equal(b[at + 4], 0xe0);
});

test('zstd frame content size', () => {
  const b = read(dir, 'compact_zstd-grid');
  const size = Number(new DataView(b.buffer).getBigUint64(2, true));
  assert.equal(zstdFrameContentSize(b.subarray(10)), size);
  assert.equal(zstdFrameContentSize(new Uint8Array([1, 2, 3, 4, 5])), -1);
});

test('octahedral normals decode to unit vectors', () => {
  const out = new Float32Array(3);
  for (const [x, y] of [[0, 32767], [32767, 0], [-32768, -32768], [12345, -20000], [0, 0]]) {
    octDecode(x, y, out, 0);
    assert.ok(Math.abs(Math.hypot(...out) - 1) < 1e-6, `${x},${y}: ${out}`);
  }
  octDecode(0, 0, out, 0);
  assert.deepEqual(Array.from(out), [0, 0, 1]);
});

test('every truncation and trailing byte is an error naming the group', () => {
  for (const name of readdirSync(dir)) {
    const b = read(dir, name);
    for (let n = 0; n < b.length; ++n) assert.throws(() => decodeGroup(b.subarray(0, n)), /^WireError: group: /, `${name} cut at ${n}`);
    // A compact_zstd frame runs to the end, so a byte past it is the frame's; a cells body as it
    // is (packing 0, every seed's) is whole.
    if (!name.startsWith('compact_zstd'))
      assert.throws(() => decodeGroup(new Uint8Array([...b, 0])), /group: 1 trailing bytes/, name);
    if (name.startsWith('cells')) {
      assert.equal(b[31], 0, `${name}: a range-coded body goes as it is`);
      const c = b.slice();
      c[31] = 2;
      assert.throws(() => decodeGroup(c), /group: cells packing: expected 0 \(as it is\) or 1 \(zstd\), got 2/, name);
    }
  }
});

test('fields are checked and named', () => {
  const b = read(dir, 'indexed-tetrahedron');
  const patch = (at, v) => { const c = b.slice(); c[at] = v; return c; };
  assert.throws(() => decodeGroup(patch(0, 2)), /group: version 2, expected 3/);
  assert.throws(() => decodeGroup(patch(1, 5)), /group: encoding: expected 0..4, got 5/);
  assert.throws(() => decodeGroup(patch(2 + 16, 31)), /group: level: expected 0..30, got 31/);
  assert.throws(() => decodeGroup(patch(2 + 28, 2)), /group: refinement: expected 0 or 1, got 2/);
  // the first index (after V, T, 4 positions and 4 normals): 9 >= 4 vertices
  assert.throws(() => decodeGroup(patch(2 + 29 + 8 + 96, 9)), /group: index 9 >= vertex count 4/);
  // a NaN position
  const nan = b.slice();
  new DataView(nan.buffer).setFloat32(2 + 29 + 8, NaN, true);
  assert.throws(() => decodeGroup(nan), /group: position 0: expected a finite number, got NaN/);
  const z = read(dir, 'compact_zstd-grid');
  const claim = z.slice();
  claim[2] += 1;
  assert.throws(() => decodeGroup(claim), /group: zstd: the frame's content size is not the \d+ bytes claimed/);
});

test('the C++ fuzz regressions decode as the C++ does', () => {
  for (const name of readdirSync(regressions)) {
    const b = read(regressions, name);
    let g = null;
    try { g = decodeGroup(b); } catch (e) { assert.match(String(e), /^WireError: group: /); continue; }
    for (const v of g.positions) assert.ok(Number.isFinite(v), name);
  }
});

test('a compact group whose indices are in index codec version 1 decodes too', async () => {
  // Should the server's libmeshoptimizer move to version 1 (the default of newer releases),
  // the page still reads it: the tetrahedron's indices re-coded by the npm encoder (version 1).
  const { MeshoptEncoder } = await import('meshoptimizer/encoder');
  await MeshoptEncoder.ready;
  const b = read(dir, 'compact-tetrahedron');
  const g = decodeGroup(b);
  const at = 2 + 29 + 8 + 24 + 10 * 4;
  const coded = MeshoptEncoder.encodeIndexBuffer(new Uint8Array(g.indices.buffer.slice(0)), g.indices.length, 4);
  assert.equal(coded[0], 0xe1);
  const out = new Uint8Array(at + 4 + coded.length);
  out.set(b.subarray(0, at));
  new DataView(out.buffer).setUint32(at, coded.length, true);
  out.set(coded, at + 4);
  assert.deepEqual(decodeGroup(out), g);
});
