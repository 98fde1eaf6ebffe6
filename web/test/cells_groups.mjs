// Reads the groups test/data/cells_probe.cpp writes (its header comment has the layout): each as
// the C++ encoded it in cells (or what a coarse pass fell back to) and in compact+zstd, with the
// mesh the C++ decoder gave for the cells bytes (with the exact bits of its ExactMsg, when its
// gradients went to a step).
import { readFileSync } from 'node:fs';

export function readCellsGroups(file) {
  const b = new Uint8Array(readFileSync(file));
  const dv = new DataView(b.buffer, b.byteOffset, b.byteLength);
  let p = 0;
  const u32 = () => { const v = dv.getUint32(p, true); p += 4; return v; };
  const take = (n) => { const s = b.slice(p, p + n); p += n; return s; };
  const bytes = () => take(u32());
  const groups = [];
  for (let n = u32(); n > 0; --n) {
    const name = new TextDecoder().decode(bytes());
    const cells = bytes(), compact = bytes(), exact = bytes();
    const v = u32(), i = u32();
    const positions = new Float32Array(take(12 * v).buffer);
    const normals = new Float32Array(take(12 * v).buffer);
    const indices = new Uint32Array(take(4 * i).buffer);
    groups.push({ name, cells, compact, exact, mesh: { positions, normals, indices } });
  }
  if (p !== b.length) throw new Error(`${file}: ${b.length - p} bytes after the last group`);
  return groups;
}
