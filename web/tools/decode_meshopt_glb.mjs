// Decodes a binary glTF whose views are compressed with EXT_meshopt_compression (what `isowall
// extract --compress meshopt` writes) through meshoptimizer's own decoder (npm's meshoptimizer,
// the one three.js and glTF-Transform use), and writes the same mesh as a plain binary glTF, so
// the Khronos validator, which does not know the extension, can check what a viewer would draw.
// Prints one JSON line: the views decoded and the bytes before and after. Exit status 1 on a
// file it cannot take apart.
//
//   node web/tools/decode_meshopt_glb.mjs IN.glb OUT.glb
import fs from 'node:fs';
import { MeshoptDecoder } from 'meshoptimizer';

const [input, output] = process.argv.slice(2);
if (!input || !output) {
  console.error('usage: decode_meshopt_glb.mjs IN.glb OUT.glb');
  process.exit(2);
}

function fail(why) {
  console.error(`decode_meshopt_glb: ${input}: ${why}`);
  process.exit(1);
}

const bytes = new Uint8Array(fs.readFileSync(input));
const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
if (bytes.length < 20 || view.getUint32(0, true) !== 0x46546c67) fail('not a binary glTF');
const jsonLength = view.getUint32(12, true);
const doc = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
const binAt = 20 + jsonLength;
const bin = binAt + 8 <= bytes.length
  ? bytes.subarray(binAt + 8, binAt + 8 + view.getUint32(binAt, true)) : new Uint8Array(0);

await MeshoptDecoder.ready;
const fallback = (doc.buffers ?? []).findIndex((b) => b.extensions?.EXT_meshopt_compression?.fallback);
if (fallback < 0) fail('no fallback buffer: not compressed with EXT_meshopt_compression');
const plain = new Uint8Array(doc.buffers[fallback].byteLength);
let decoded = 0;
for (const bv of doc.bufferViews ?? []) {
  const ext = bv.extensions?.EXT_meshopt_compression;
  if (!ext) fail('a view without EXT_meshopt_compression');
  if (ext.buffer !== 0) fail('a compressed view outside the file\'s own buffer');
  const source = bin.subarray(ext.byteOffset ?? 0, (ext.byteOffset ?? 0) + ext.byteLength);
  const target = new Uint8Array(ext.count * ext.byteStride);
  MeshoptDecoder.decodeGltfBuffer(target, ext.count, ext.byteStride, source, ext.mode, ext.filter ?? 'NONE');
  plain.set(target, bv.byteOffset ?? 0);
  delete bv.extensions;
  bv.buffer = 0;
  decoded += 1;
}
doc.buffers = [{ byteLength: plain.length }];
delete doc.extensionsUsed;
delete doc.extensionsRequired;

const pad = (n) => (4 - (n % 4)) % 4;
const json = new TextEncoder().encode(JSON.stringify(doc));
const jsonChunk = new Uint8Array(json.length + pad(json.length)).fill(0x20);
jsonChunk.set(json);
const binChunk = new Uint8Array(plain.length + pad(plain.length));
binChunk.set(plain);
const out = new Uint8Array(12 + 8 + jsonChunk.length + 8 + binChunk.length);
const o = new DataView(out.buffer);
o.setUint32(0, 0x46546c67, true);
o.setUint32(4, 2, true);
o.setUint32(8, out.length, true);
o.setUint32(12, jsonChunk.length, true);
o.setUint32(16, 0x4e4f534a, true);
out.set(jsonChunk, 20);
o.setUint32(20 + jsonChunk.length, binChunk.length, true);
o.setUint32(24 + jsonChunk.length, 0x004e4942, true);
out.set(binChunk, 28 + jsonChunk.length);
fs.writeFileSync(output, out);
console.log(JSON.stringify({ file: input, views: decoded, compressed: bytes.length, plain: out.length }));
