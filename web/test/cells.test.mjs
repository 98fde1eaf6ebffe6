// The cells encoding in the page (src/cells.js: remote/cell_codec.cpp in WebAssembly) against the
// C++ decoder: test/data/cells_groups.bin holds groups the C++ encoded, in cells and compact+zstd,
// with the mesh decode_group gave for the cells bytes (test/data/cells_probe.cpp wrote it; the
// README says how to write it again). The page must give that mesh to the bit, and fail on
// malformed bytes with a WireError naming the group, as the C++ does, never trap or hang.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, readdirSync } from 'node:fs';
import { decodeGroup, encodingOf, encodingName, helloEncoding, kAdaptiveEncoding, ready } from '../src/group_codec.js';
import { decodeCellBody } from '../src/cells.js';
import { readCellsGroups } from './cells_groups.mjs';
import { warmGroups } from '../src/cells_warm.js';

await ready;
const groups = readCellsGroups(new URL('data/cells_groups.bin', import.meta.url));
const bodyDir = new URL('../../fuzz/corpus/cell_body/', import.meta.url);
// A cell_body seed: the isovalue (f64), then the body (fuzz/fuzz_cell_body.cpp).
const seeds = readdirSync(bodyDir).sort().map((name) => {
  const b = new Uint8Array(readFileSync(new URL(name, bodyDir)));
  return { name, iso: new DataView(b.buffer).getFloat64(0, true), body: b.subarray(8) };
});
const cellsGroups = groups.filter((g) => encodingOf(g.cells) === 4);

const bytesOf = (a) => Buffer.from(a.buffer, a.byteOffset, a.byteLength);
function assertSameMesh(got, want, what) {
  assert.equal(got.indices.length, want.indices.length, `${what}: index count`);
  assert.equal(got.positions.length, want.positions.length, `${what}: vertex count`);
  assert.ok(got.positions instanceof Float32Array && got.normals instanceof Float32Array && got.indices instanceof Uint32Array,
    `${what}: the renderer's array types`);
  for (const field of ['positions', 'normals', 'indices']) {
    if (bytesOf(got[field]).equals(bytesOf(want[field]))) continue;
    const i = got[field].findIndex((v, k) => !Object.is(v, want[field][k]));
    assert.fail(`${what}: ${field}[${i}] is ${got[field][i]}, the C++ decoder gave ${want[field][i]}`);
  }
}

// What the renderer can draw: a normal a position, indices below the vertex count, all finite.
function assertDrawable(m, what) {
  assert.equal(m.positions.length, m.normals.length, what);
  assert.equal(m.indices.length % 3, 0, what);
  const v = m.positions.length / 3;
  for (const i of m.indices) if (i >= v) assert.fail(`${what}: index ${i} >= ${v} vertices`);
  for (const x of m.positions) if (!Number.isFinite(x)) assert.fail(`${what}: position ${x}`);
  for (const x of m.normals) if (!Number.isFinite(x)) assert.fail(`${what}: normal ${x}`);
}

// Runs decode(bytes): it must throw a WireError naming the group, or give a drawable mesh.
function failsOrDraws(decode, bytes, what) {
  let m;
  try {
    m = decode(bytes);
  } catch (e) {
    assert.match(String(e), /^WireError: group: /, what);
    assert.doesNotMatch(String(e), /the decoder failed/, `${what}: the WebAssembly trapped`);
    return false;
  }
  assertDrawable(m, what);
  return true;
}

// A fixed-seed generator (mulberry32), so a failing mutation is the same on every run.
function random(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = Math.imul(a ^ (a >>> 15), 1 | a);
    t = (t + Math.imul(t ^ (t >>> 7), 61 | t)) ^ t;
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

test('the groups cover every voxel type, coarse passes and refinements', () => {
  const names = groups.map((g) => g.name);
  for (const type of ['u8', 'i8', 'u16', 'i16', 'u32', 'i32', 'f32', 'f64'])
    assert.ok(names.includes(`${type}-cells`), `${type}-cells`);
  for (const g of groups.filter((g) => /level2|refinement/.test(g.name) && !g.name.startsWith('corpus')))
    assert.ok(g.cells[1] === 3 || g.cells[1] === 4, g.name);
  assert.ok(cellsGroups.some((g) => g.name.endsWith('-level2')), 'a coarse pass as cells (normals from its faces)');
  assert.ok(cellsGroups.length >= 20, `${cellsGroups.length} groups as cells`);
});

test('cells groups decode to the C++ decoder\'s mesh, bit for bit', () => {
  for (const g of groups) {
    const d = decodeGroup(g.cells, g.exact.length ? g.exact : null);
    assert.equal(d.stepped ?? false, g.exact.length > 0, g.name);
    assert.ok(Number.isFinite(d.iso) && d.seed.length === 3, g.name);
    assertSameMesh(d, g.mesh, `${g.name} (${encodingName(encodingOf(g.cells))})`);
  }
});

test('a group whose gradients came to a step gives the server\'s vertices first, and its mesh with the exact values', () => {
  const stepped = groups.filter((g) => g.exact.length > 0);
  assert.ok(stepped.some((g) => g.name.startsWith('u16')) && stepped.some((g) => g.name.startsWith('cthead')),
    stepped.map((g) => g.name).join(', '));
  for (const g of stepped) {
    const first = decodeGroup(g.cells);
    assert.equal(first.stepped, true, g.name);
    assert.deepEqual(first.positions, g.mesh.positions, `${g.name}: the vertices stay`);
    assert.deepEqual(first.indices, g.mesh.indices, g.name);
    assert.notDeepEqual(first.normals, g.mesh.normals, `${g.name}: the normals moved`);
    // Every cut and a byte over, as the C++ (ExactBitsReader) names them.
    for (const n of [0, 1, g.exact.length - 1])
      assert.throws(() => decodeGroup(g.cells, g.exact.subarray(0, n)), /^WireError: group: exact values: \d+ bytes of exact values, expected/, `${g.name} cut to ${n}`);
    assert.throws(() => decodeGroup(g.cells, new Uint8Array([...g.exact, 0])), /^WireError: group: exact values:/, g.name);
    assert.throws(() => decodeGroup(g.compact, g.exact), /^WireError: group: exact values: only a cells group takes them/, g.name);
  }
  const exact = groups.find((g) => g.name === 'u8-cells');
  assert.throws(() => decodeGroup(exact.cells, new Uint8Array(1)), /^WireError: group: exact values: the body has no values to make exact/);
});

test('compact+zstd of the same groups has as many triangles', () => {
  for (const g of groups) {
    const c = decodeGroup(g.compact);
    assert.equal(encodingOf(g.compact), 3, g.name);
    assert.equal(c.indices.length, g.mesh.indices.length, g.name);
    const d = decodeGroup(g.cells);
    assert.deepEqual([c.id, c.seed, c.level, c.iso, c.refinement], [d.id, d.seed, d.level, d.iso, d.refinement], g.name);
  }
});

test('the seed corpus\'s cell bodies decode to their groups\' meshes', () => {
  assert.deepEqual(seeds.map((s) => s.name), ['phantom-cells', 'phantom-level2', 'phantom-refinement']);
  for (const s of seeds) {
    const g = groups.find((x) => x.name === `corpus-cells-${s.name}`);
    assertSameMesh(decodeCellBody(s.body, s.iso), g.mesh, s.name);
  }
});

test('the warm-up groups are the seed corpus\'s, as the C++ encodes them now, and decode as cells', () => {
  const corpus = new URL('../../fuzz/corpus/group_codec/', import.meta.url);
  for (const [i, name] of ['cells-phantom-cells', 'cells-phantom-level2'].entries()) {
    assert.ok(bytesOf(warmGroups[i]).equals(readFileSync(new URL(name, corpus))),
      `${name}: src/cells_warm.js is stale (web/wasm/refresh.sh makes it again)`);
    assert.equal(encodingOf(warmGroups[i]), 4, name);
    assertSameMesh(decodeGroup(warmGroups[i]), groups.find((x) => x.name === `corpus-${name}`).mesh, name);
  }
});

test('every truncation of a cells body fails naming the group, and so does a trailing byte', () => {
  for (const s of seeds) {
    for (let n = 0; n < s.body.length; ++n)
      assert.throws(() => decodeCellBody(s.body.subarray(0, n), s.iso), /^WireError: group: /, `${s.name} cut at ${n}`);
    assert.throws(() => decodeCellBody(new Uint8Array([...s.body, 0]), s.iso), /^WireError: group: 1 trailing bytes$/, s.name);
  }
});

test('every truncation of every cells group fails naming the group', () => {
  for (const g of cellsGroups)
    for (let n = 0; n < g.cells.length; ++n)
      assert.throws(() => decodeGroup(g.cells.subarray(0, n)), /^WireError: group: /, `${g.name} cut at ${n}`);
});

test('a cells body\'s fields are checked and named as the C++ names them', () => {
  const s = seeds[0];
  const patch = (at, ...values) => { const b = s.body.slice(); b.set(values, at); return b; };
  const fails = (b, re) => assert.throws(() => decodeCellBody(b, s.iso), re);
  // type u8, dims 3 x i32 (from 1), spacing 3 x f32 (from 13), normals u8 (25), bucket count (26)
  fails(patch(0, 8), /^WireError: group: voxel type: expected 0..7, got 8$/);
  fails(patch(1, 1, 0, 0, 0), /^WireError: group: volume dims: expected 2..1048576, got 1$/);
  fails(patch(5, 0, 0, 0, 0x80), /^WireError: group: volume dims: expected 2..1048576, got -2147483648$/);
  fails(patch(13, 0, 0, 0x80, 0xbf), /^WireError: group: spacing: expected a positive finite number, got -1.000000$/);
  fails(patch(17, 0, 0, 0xc0, 0x7f), /^WireError: group: spacing: expected a positive finite number, got nan$/);
  fails(patch(25, 2), /^WireError: group: normals: expected 0 \(gradients\) or 1 \(faces\), got 2$/);
  fails(patch(26, 0), /^WireError: group: /);
});

test('seeded byte mutations give a WireError naming the group or a drawable mesh, never a trap', () => {
  const next = random(34);
  const pick = (n) => Math.floor(next() * n);
  let failed = 0, decoded = 0;
  const mutate = (b) => {
    const c = b.slice();
    for (let k = 1 + pick(3); k > 0; --k) c[pick(c.length)] = pick(256);
    return c;
  };
  for (const s of seeds)
    for (let i = 0; i < 400; ++i)
      failsOrDraws((b) => decodeCellBody(b, s.iso), mutate(s.body), `${s.name} mutation ${i}`) ? ++decoded : ++failed;
  for (const g of cellsGroups.slice(0, 8))
    for (let i = 0; i < 100; ++i)
      failsOrDraws(decodeGroup, mutate(g.cells), `${g.name} mutation ${i}`) ? ++decoded : ++failed;
  assert.ok(failed > 0 && decoded > 0, `${failed} failed, ${decoded} decoded`);
  // The module is as it was: a good body still gives the C++ mesh.
  const g = groups.find((x) => x.name === 'corpus-cells-phantom-cells');
  assertSameMesh(decodeCellBody(seeds[0].body, seeds[0].iso), g.mesh, 'after the mutations');
});

test('the hello\'s encoding from the URL: a codec, auto by name or 255, nothing else', () => {
  assert.equal(kAdaptiveEncoding, 255);
  assert.equal(helloEncoding('auto'), 255);
  assert.equal(helloEncoding('255'), 255);
  ['vertices', 'indexed', 'compact', 'compact-zstd', 'cells'].forEach((n, i) => {
    assert.equal(helloEncoding(n), i);
    assert.equal(helloEncoding(String(i)), i);
  });
  for (const bad of ['5', '-1', '3.0', ' 3', 'compact+zstd', 'AUTO', '254', ''])
    assert.equal(helloEncoding(bad), null, JSON.stringify(bad));
  assert.equal(encodingName(4), 'cells');
  assert.equal(encodingName(255), 'auto');
});

test('a browser that cannot run the cells decoder still decodes the other encodings', async () => {
  // WebAssembly.instantiate refuses emscripten's cells module alone (its imports name
  // emscripten_resize_heap), as a browser without WebAssembly exceptions would refuse it to compile.
  const script = `
    const instantiate = WebAssembly.instantiate;
    WebAssembly.instantiate = (b, imports) => imports?.env?.emscripten_resize_heap
      ? Promise.reject(new Error('no exception handling')) : instantiate(b, imports);
    const { ready, cellsProblem, decodeGroup } = await import(${JSON.stringify(new URL('../src/group_codec.js', import.meta.url).href)});
    const { readFileSync } = await import('node:fs');
    const read = (n) => new Uint8Array(readFileSync(new URL('../../fuzz/corpus/group_codec/' + n, ${JSON.stringify(import.meta.url)})));
    await ready;
    let cells;
    try { decodeGroup(read('cells-phantom-cells')); } catch (e) { cells = String(e); }
    console.log(JSON.stringify({ problem: cellsProblem(), cells, compact: decodeGroup(read('compact_zstd-grid')).indices.length }));`;
  const { execFileSync } = await import('node:child_process');
  const out = JSON.parse(execFileSync(process.execPath, ['--input-type=module', '-e', script], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] }));
  assert.match(out.problem, /^the cells decoder \(WebAssembly\) did not start: .*no exception handling/);
  assert.match(out.cells, /^WireError: group: cells: the cells decoder \(WebAssembly\) did not start/);
  assert.equal(out.compact, 54);
});
