// The page's group decoding speed, in triangles a second, for cells (the C++ decoder in
// WebAssembly, after zstddec) and compact+zstd, on the same groups in one process:
//   node tools/bench_decode.mjs [GROUPS] [--runs N]
// GROUPS: a file of test/data/cells_probe.cpp (default test/data/cells_groups.bin, small groups);
// for one frame's groups, as isowall_bench_codec decodes them natively:
//   cells_probe frame /tmp/frame.bin && node tools/bench_decode.mjs /tmp/frame.bin
// (the probe prints the C++ decoder's figures on the same groups). Prints the best of N runs
// (default 5); checks once, outside the timing, that every cells group gave the C++ mesh.
import { decodeGroup, ready } from '../src/group_codec.js';
import { readCellsGroups } from '../test/cells_groups.mjs';

function usage(text) {
  console.error(`bench_decode: ${text}\nusage: node tools/bench_decode.mjs [GROUPS] [--runs N]`);
  process.exit(2);
}

let file = new URL('../test/data/cells_groups.bin', import.meta.url);
let runs = 5;
const args = process.argv.slice(2);
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--runs') {
    runs = Number(args[++i]);
    if (!Number.isInteger(runs) || runs < 1) usage(`--runs: expected a positive integer, got ${args[i]}`);
  } else if (args[i].startsWith('-')) usage(`unknown option ${args[i]}`);
  else file = args[i];
}

await ready;
const groups = readCellsGroups(file);
const same = (a, b) => a.length === b.length && Buffer.compare(Buffer.from(a.buffer, a.byteOffset, a.byteLength),
  Buffer.from(b.buffer, b.byteOffset, b.byteLength)) === 0;
let triangles = 0, cellsBytes = 0, compactBytes = 0, notCells = 0;
// A stepped group's mesh is the one its exact bits give (test/data/cells_probe.cpp), and the
// timing decodes it so too: what the page does once the exact message comes.
const exactOf = (g) => (g.exact.length > 0 ? g.exact : null);
for (const g of groups) {
  const d = decodeGroup(g.cells, exactOf(g));
  if (!same(d.positions, g.mesh.positions) || !same(d.normals, g.mesh.normals) || !same(d.indices, g.mesh.indices)) {
    console.error(`bench_decode: ${g.name}: the page's mesh is not the C++ decoder's`);
    process.exit(1);
  }
  triangles += g.mesh.indices.length / 3;
  cellsBytes += g.cells.length;
  compactBytes += g.compact.length;
  if (g.cells[1] !== 4) ++notCells;
}

// The best of `runs` passes over every group's bytes, in seconds.
function best(which) {
  let bestS = Infinity, kept = 0;
  for (let run = 0; run < runs; ++run) {
    const t0 = performance.now();
    for (const g of groups) kept += decodeGroup(g[which], which === 'cells' ? exactOf(g) : null).indices.length;
    bestS = Math.min(bestS, (performance.now() - t0) / 1e3);
  }
  if (kept === 0 && triangles > 0) throw new Error('nothing decoded');
  return bestS;
}

const cellsS = best('cells'), compactS = best('compact');
console.log(`bench_decode: ${groups.length} groups (${notCells} not as cells: coarse passes), ${triangles} triangles, ` +
  `from ${file instanceof URL ? file.pathname : file}; node ${process.versions.node}, best of ${runs}`);
console.log('| encoding | bytes | bytes/triangle | decode ms | Mtri/s |\n|---|---:|---:|---:|---:|');
for (const [name, bytes, s] of [['cells', cellsBytes, cellsS], ['compact+zstd', compactBytes, compactS]])
  console.log(`| ${name} | ${bytes} | ${(bytes / triangles).toFixed(2)} | ${(s * 1e3).toFixed(2)} | ${(triangles / s / 1e6).toFixed(2)} |`);
console.log(`cells decodes at ${(compactS / cellsS).toFixed(3)}x compact+zstd's speed`);
