// The body of the `cells` group encoding (remote/cell_codec.h): the units and voxel values a group
// was triangulated from. The decoder is the server's own C++ (remote/cell_codec.cpp, with
// web/wasm/cells_wasm.cpp as its C API) compiled to WebAssembly by web/wasm/build.sh, so the page
// runs the project's marching cubes and gets the server's triangles and normals to the bit.
import createCellsModule from './cells_wasm.js';
import { WireError } from './wire.js';

let wasm = null;
let failure = null;
// Settles once the module is compiled, or could not be: a browser without WebAssembly exceptions
// (before Chrome 95, Firefox 100, Safari 15.2) cannot run it, and the page then asks for
// compact+zstd, which does not need it (cellsProblem).
export const ready = createCellsModule().then((m) => { wasm = m; }, (e) => { failure = e; });

// Why this browser cannot decode cells bodies, or null when it can (after `ready`).
export function cellsProblem() {
  if (wasm) return null;
  return `the cells decoder (WebAssembly) did not start: ${failure?.message ?? 'not yet loaded'}`;
}

// The mesh of a cells body (the bytes inside the group's zstd frame) at `iso`, as
// { positions: Float32Array(3V), normals: Float32Array(3V), indices: Uint32Array(3T), stepped }.
// With `exact` (an exact message's bits), the mesh of its gradients' exact values; `stepped` says
// whether the body had them to a step. Throws a WireError with the C++ decoder's message
// ("group: <field>: <why>") for a malformed body or exact values that do not fit it.
export function decodeCellBody(body, iso, exact = null) {
  if (!wasm) throw new WireError(`group: cells: ${cellsProblem()}`);
  const bits = exact ?? new Uint8Array(0);
  const at = wasm._cells_alloc(body.length + bits.length);
  if (at === 0 && body.length + bits.length > 0)
    throw new WireError(`group: cells: no memory for a body of ${body.length + bits.length} bytes`);
  // A trap (a bug, never a malformed body: those are WireErrors the C API catches) leaves the
  // module's stack pointer where it stopped; restoring it keeps the module usable.
  const stack = wasm.stackSave();
  let status;
  try {
    wasm.HEAPU8.set(body, at);
    wasm.HEAPU8.set(bits, at + body.length);
    status = wasm._cells_decode(at, body.length, iso, at + body.length, bits.length, exact ? 1 : 0);
  } catch (e) {
    wasm.stackRestore(stack);
    throw new WireError(`group: cells: the decoder failed (${e.message})`);
  } finally {
    wasm._cells_free(at);
  }
  if (status !== 0) throw new WireError(wasm.UTF8ToString(wasm._cells_error()));
  // Copies: the next decode reuses the memory, and growing it detaches every view.
  const v = wasm._cells_vertex_count(), n = wasm._cells_index_count();
  const f32 = (p, count) => new Float32Array(wasm.HEAPU8.buffer, p, count).slice();
  return {
    positions: f32(wasm._cells_positions(), 3 * v),
    normals: f32(wasm._cells_normals(), 3 * v),
    indices: new Uint32Array(wasm.HEAPU8.buffer, wasm._cells_indices(), n).slice(),
    stepped: wasm._cells_stepped() !== 0,
  };
}
