// Decoding of the five group encodings of remote/group_codec.h:
//   0 vertices      three separate float32 vertices (position + normal) a triangle
//   1 indexed       float32 positions and normals, uint16 indices (uint32 past 65536 vertices)
//   2 compact       positions quantised to 16 bits in a box, octahedral snorm16 normals,
//                   indices through meshoptimizer's index codec
//   3 compact_zstd  the whole compact message in one zstd frame
//   4 cells         the units and voxel values marching cubes triangulates, as they are or in one
//                   zstd frame (cells.js: the server's C++ decoder in WebAssembly)
// Bytes: [version u8 = 3][encoding u8][header: id u32, seed 3 x i32, level i32, iso f64,
// refinement u8][body]; compact_zstd has no header of its own: after the encoding byte come the
// u64 size of the compact message, then the frame holding it; a cells body follows a packing
// byte: 0, the body as it is, to the end; 1, its u64 size, then a frame holding it. Decoding is
// for hostile input: every count is checked against the limits and the bytes left before anything
// is allocated, indices against the vertex count, floats must be finite; anything else throws an
// Error "group: <field>: <why>".
//
// A decoded group: { id, seed: [x, y, z], level, iso, refinement, positions: Float32Array(3V),
// normals: Float32Array(3V), indices: Uint32Array(3T) }.
import { ZSTDDecoder } from 'zstddec';
import { MeshoptDecoder } from 'meshoptimizer/decoder';
import { ByteReader } from './wire.js';
import { ready as cellsReady, decodeCellBody, cellsProblem } from './cells.js';
import { warmGroups } from './cells_warm.js';
export { cellsProblem };

export const GroupEncoding = { vertices: 0, indexed: 1, compact: 2, compact_zstd: 3, cells: 4 };
// The hello's encoding for "the server chooses per group" between cells and compact+zstd
// (remote/encoding_choice.h); not a codec's id.
export const kAdaptiveEncoding = 255;
export const kGroupCodecVersion = 3;  // 3: remote/group_codec.h
export const kMaxNarrowIndexedVertices = 65536;
export const kMaxGroupTriangles = 1 << 22;
export const kMaxGroupVertices = 3 * kMaxGroupTriangles;
export const kMaxZstdExpansion = 64;
const kMaxLevel = 30;
const kMaxCompactBytes = kMaxGroupVertices * 10 + kMaxGroupTriangles * 16 + 256;
// The largest cells body (group_codec.cpp): every voxel of the largest box (kMaxCellBoxVoxels,
// cell_codec.h) as a float64, and the units' gaps.
const kMaxCellBytes = (1 << 24) * 8 + kMaxGroupTriangles * 10 + 256;
const WHAT = 'group';
const f = Math.fround;

// The decoders are WebAssembly: await this once before decoding a group. meshoptimizer's for
// compact indices; zstd is the reference decoder (zstddec): 7-10x faster than a decoder in
// JavaScript on the head's groups (fzstd: 65-135 ms a frame against 9-53 ms, in node); cells.js's.
// Once they are, the cells decoder runs on two small groups: the engine compiles a WebAssembly
// function when it is first called, which put 30-35 ms on the first cells group in node (8 ms
// after the warm-up, against 4.5 once warm: web/tools/bench_decode.mjs's groups, in order).
const zstd = new ZSTDDecoder();
export const ready = Promise.all([MeshoptDecoder.ready, zstd.init(), cellsReady]).then(warmCells);

function warmCells() {
  if (cellsProblem()) return;
  for (const bytes of warmGroups) {
    try {
      decodeGroup(bytes);
    } catch (e) {
      console.warn(`isowall: the cells decoder's warm-up group failed: ${e.message}`);
    }
  }
}

export function encodingName(e) {
  if (e === kAdaptiveEncoding) return 'auto';
  return ['vertices', 'indexed', 'compact', 'compact+zstd', 'cells'][e] ?? 'unknown';
}

// The encoding a hello asks for, from a URL's text: a codec's id (0..4) or name as `isowall view
// --encoding` takes it (compact-zstd for compact+zstd), or auto / 255 (kAdaptiveEncoding);
// null for anything else.
export function helloEncoding(text) {
  if (text === 'auto' || text === String(kAdaptiveEncoding)) return kAdaptiveEncoding;
  if (/^[0-4]$/.test(text)) return Number(text);
  const e = ['vertices', 'indexed', 'compact', 'compact-zstd', 'cells'].indexOf(text);
  return e >= 0 ? e : null;
}

function getHeader(r) {
  const g = {};
  g.id = r.u32();
  g.seed = [r.i32(), r.i32(), r.i32()];
  g.level = r.i32();
  if (g.level < 0 || g.level > kMaxLevel) r.fail(`level: expected 0..${kMaxLevel}, got ${g.level}`);
  g.iso = r.f64();
  if (!Number.isFinite(g.iso)) r.fail(`iso: expected a finite number, got ${g.iso}`);
  const refinement = r.u8();
  if (refinement > 1) r.fail(`refinement: expected 0 or 1, got ${refinement}`);
  g.refinement = refinement === 1;
  return g;
}

function getCount(r, limit, field) {
  const n = r.u32();
  if (n > limit) r.fail(`${field} ${n} over the limit ${limit}`);
  return n;
}

// n float32 triples, each finite.
function getFiniteVec3s(r, n, field) {
  const bytes = r.span(n * 12);
  const out = new Float32Array(n * 3);
  new Uint8Array(out.buffer).set(bytes);
  for (let i = 0; i < out.length; ++i)
    if (!Number.isFinite(out[i])) r.fail(`${field} ${Math.floor(i / 3)}: expected a finite number, got ${out[i]}`);
  return out;
}

function getVertices(r) {
  const triangles = getCount(r, kMaxGroupTriangles, 'triangle count');
  r.needElements(triangles, 3 * 2 * 12, 'triangles');
  const n = 3 * triangles;
  const positions = getFiniteVec3s(r, n, 'position');
  const normals = getFiniteVec3s(r, n, 'normal');
  const indices = new Uint32Array(n);
  for (let i = 0; i < n; ++i) indices[i] = i;
  return { positions, normals, indices };
}

function getIndexed(r) {
  const vertices = getCount(r, kMaxGroupVertices, 'vertex count');
  const triangles = getCount(r, kMaxGroupTriangles, 'triangle count');
  r.needElements(vertices, 2 * 12, 'vertices');
  const positions = getFiniteVec3s(r, vertices, 'position');
  const normals = getFiniteVec3s(r, vertices, 'normal');
  const n = 3 * triangles;
  const indices = new Uint32Array(n);
  if (vertices <= kMaxNarrowIndexedVertices) {
    r.needElements(triangles, 3 * 2, 'triangles');
    const b = r.span(2 * n);
    const dv = new DataView(b.buffer, b.byteOffset, b.byteLength);
    for (let i = 0; i < n; ++i) indices[i] = dv.getUint16(2 * i, true);
  } else {
    r.needElements(triangles, 3 * 4, 'triangles');
    const b = r.span(4 * n);
    const dv = new DataView(b.buffer, b.byteOffset, b.byteLength);
    for (let i = 0; i < n; ++i) indices[i] = dv.getUint32(4 * i, true);
  }
  for (let i = 0; i < n; ++i)
    if (indices[i] >= vertices) r.fail(`index ${indices[i]} >= vertex count ${vertices}`);
  return { positions, normals, indices };
}

// Little-endian 16-bit values of `bytes` as a typed array: a view when the host is little-endian
// (every browser's is) and the bytes are aligned, else a copy.
const kLittleEndian = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;
function u16s(bytes) {
  if (!kLittleEndian) {
    const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    return Uint16Array.from({ length: bytes.length >> 1 }, (_, i) => dv.getUint16(2 * i, true));
  }
  const b = bytes.byteOffset % 2 ? bytes.slice() : bytes;
  return new Uint16Array(b.buffer, b.byteOffset, b.length >> 1);
}
function i16s(bytes) {
  const u = u16s(bytes);
  return new Int16Array(u.buffer, u.byteOffset, u.length);
}

// oct_decode of remote/compact_mesh.cpp, in float32.
function fromSnorm16(v) {
  return Math.max(f(v / 32767), -1);
}
export function octDecode(cx, cy, out, o) {
  let x = fromSnorm16(cx), y = fromSnorm16(cy);
  const z = f(f(1 - Math.abs(x)) - Math.abs(y));
  const t = Math.max(-z, 0);
  x = f(x >= 0 ? x - t : x + t);
  y = f(y >= 0 ? y - t : y + t);
  const inv = f(1 / f(Math.sqrt(f(f(f(x * x) + f(y * y)) + f(z * z)))));
  out[o] = f(x * inv);
  out[o + 1] = f(y * inv);
  out[o + 2] = f(z * inv);
}

function getCompact(r) {
  const vertexCount = r.u32();
  const triangleCount = r.u32();
  if (vertexCount > kMaxGroupVertices) r.fail(`vertex count ${vertexCount} over the limit ${kMaxGroupVertices}`);
  if (triangleCount > kMaxGroupTriangles) r.fail(`triangle count ${triangleCount} over the limit ${kMaxGroupTriangles}`);
  r.needElements(vertexCount, 10, 'vertices');
  // The box: finite, min <= max, a finite extent (in float).
  const lo = [r.f32(), r.f32(), r.f32()];
  const hi = [r.f32(), r.f32(), r.f32()];
  for (let a = 0; a < 3; ++a)
    if (!Number.isFinite(lo[a]) || !Number.isFinite(hi[a]) || !Number.isFinite(f(hi[a] - lo[a])) || lo[a] > hi[a])
      r.fail(`box: expected finite min <= max, got axis ${a} [${lo[a]}, ${hi[a]}]`);
  const step = [0, 1, 2].map((a) => (hi[a] - lo[a]) / 65535);  // in double, as the C++
  const q = u16s(r.span(6 * vertexCount));
  const positions = new Float32Array(3 * vertexCount);
  for (let a = 0; a < 3; ++a) {
    const base = lo[a], s = step[a], top = hi[a];
    for (let i = a; i < 3 * vertexCount; i += 3) positions[i] = Math.min(f(base + q[i] * s), top);
  }
  const n = i16s(r.span(4 * vertexCount));
  const normals = new Float32Array(3 * vertexCount);
  for (let i = 0; i < vertexCount; ++i) octDecode(n[2 * i], n[2 * i + 1], normals, 3 * i);
  const size = r.u32();
  const coded = r.span(size);
  let indices = new Uint32Array(0);
  if (triangleCount === 0) {
    if (size !== 0) r.fail(`indices: ${size} bytes for no triangle`);
  } else {
    if (triangleCount > size) r.fail(`indices: ${triangleCount} triangles in ${size} coded bytes`);
    indices = new Uint32Array(3 * triangleCount);
    try {
      MeshoptDecoder.decodeIndexBuffer(new Uint8Array(indices.buffer), indices.length, 4, coded);
    } catch (e) {
      r.fail(`indices: meshopt_decodeIndexBuffer failed (${e.message})`);
    }
    for (let i = 0; i < indices.length; ++i)
      if (indices[i] >= vertexCount) r.fail(`indices: index ${indices[i]} >= vertex count ${vertexCount}`);
  }
  return { positions, normals, indices };
}

// ZSTD_getFrameContentSize: the frame header's content size, or -1 when it has none / is bad.
export function zstdFrameContentSize(b) {
  if (b.length < 5 || b[0] !== 0x28 || b[1] !== 0xb5 || b[2] !== 0x2f || b[3] !== 0xfd) return -1;
  const fhd = b[4];
  const fcsFlag = fhd >> 6, single = (fhd >> 5) & 1, dictFlag = fhd & 3;
  if (fhd & 0x08) return -1;  // reserved bit
  let p = 5 + (single ? 0 : 1) + [0, 1, 2, 4][dictFlag];
  const fcsBytes = fcsFlag === 0 ? (single ? 1 : 0) : [0, 2, 4, 8][fcsFlag];
  if (fcsBytes === 0) return -1;
  if (b.length < p + fcsBytes) return -1;
  let v = 0;
  for (let i = fcsBytes - 1; i >= 0; --i) v = v * 256 + b[p + i];
  return fcsBytes === 2 ? v + 256 : v;
}

// The message inside the frame; its size is checked against `limit`, the frame's own claim and the
// expansion cap before anything is allocated.
function getZstd(r, limit) {
  const lo = r.u32(), hi = r.u32();
  const size = hi * 4294967296 + lo;
  const frame = r.span(r.remaining());
  if (size > limit || size > frame.length * kMaxZstdExpansion)
    r.fail(`zstd: ${size} bytes claimed from a frame of ${frame.length}`);
  if (zstdFrameContentSize(frame) !== size) r.fail(`zstd: the frame's content size is not the ${size} bytes claimed`);
  let out;
  try {
    out = zstd.decode(frame, size);
  } catch (e) {
    r.fail(`zstd: ${e.message}`);
  }
  // ZSTD_decompress's error codes come back as negative sizes, so a frame that does not decode
  // gives fewer bytes than claimed.
  if (out.length !== size) r.fail(`zstd: the frame does not decode to the ${size} bytes claimed`);
  return out;
}

// The encoding named by encoded bytes (their second byte), checked.
export function encodingOf(bytes) {
  const r = new ByteReader(bytes, WHAT);
  const version = r.u8();
  if (version !== kGroupCodecVersion) r.fail(`version ${version}, expected ${kGroupCodecVersion}`);
  const e = r.u8();
  if (e > GroupEncoding.cells) r.fail(`encoding: expected 0..4, got ${e}`);
  return e;
}

// exact: a cells group's exact values (an exact message's bits), or null. A cells group's result
// says whether its gradients' voxels came to a step (`stepped`: exact values are to follow).
export function decodeGroup(bytes, exact = null) {
  const encoding = encodingOf(bytes);
  const r = new ByteReader(bytes.subarray(2), WHAT);
  if (exact && encoding !== GroupEncoding.cells) r.fail('exact values: only a cells group takes them');
  if (encoding === GroupEncoding.compact_zstd) {
    const compact = getZstd(r, kMaxCompactBytes);
    const inner = encodingOf(compact);
    if (inner !== GroupEncoding.compact)
      r.fail(`zstd: the frame holds a ${encodingName(inner)} group, expected compact`);
    return decodeGroup(compact);
  }
  const g = getHeader(r);
  if (encoding === GroupEncoding.cells) {
    const packing = r.u8();
    if (packing > 1) r.fail(`cells packing: expected 0 (as it is) or 1 (zstd), got ${packing}`);
    const body = packing === 1 ? getZstd(r, kMaxCellBytes) : r.span(r.remaining());
    return Object.assign(g, decodeCellBody(body, g.iso, exact));
  }
  const mesh = encoding === GroupEncoding.vertices ? getVertices(r)
    : encoding === GroupEncoding.indexed ? getIndexed(r) : getCompact(r);
  r.finish();
  return Object.assign(g, mesh);
}

export function triangleCount(g) {
  return g.indices.length / 3;
}
