// The drawing rules of remote/client_frames.{h,cpp} (the dissertation's section 4.1.4), for the
// page: the messages of a request go in, the frame is drawn as they arrive.
//   - groups are drawn as they arrive, each decoded once; with progressive LOD the depth buffer
//     is cleared when a finer level begins, so the finer surface covers the coarser one;
//   - a group coarser than what the frame already shows is not drawn, nor one sent with
//     draw_from_next_frame; both are cached when they carry a cache generation;
//   - a visible message names cached groups by slot: the client must hold each (a protocol error
//     if not) and draws them coarse levels first;
//   - at the end of a frame that drew any coarse group, the frame is drawn again from its
//     full-resolution groups alone, so the final image equals the image without LOD;
//   - a cells group whose gradients' voxels came to a step is drawn as it comes; its exact message
//     (before the frame's end) decodes it again exact, and the frame's end draws the exact groups
//     alone; an exact message for no awaiting group, a frame that ends with one still stepped, and
//     a stepped group to cache are protocol errors.
// The cache follows the server's stream, not the client's requests: a group with a cache
// generation (of any request) is appended to the cache; one of another generation first drops
// the cache. A group's slot is its index in the generation. The cache is kept while requests do
// not cache.
import { decodeGroup, triangleCount, GroupEncoding } from './group_codec.js';
import { WireError } from './wire.js';
import { viewMatrix, projectionMatrix } from './camera.js';

// The server's error message, as an exception.
export class RemoteError extends Error {
  constructor(code, text) {
    super(text);
    this.name = 'RemoteError';
    this.code = code;
  }
}

function sameKey(g, k) {
  return g.seed[0] === k.seed[0] && g.seed[1] === k.seed[1] && g.seed[2] === k.seed[2] &&
    g.level === k.level && g.iso === k.iso && g.refinement === k.refinement;
}

// `exact`: the group's exact values (an exact message's bits), or null.
export function decodeMesh(m, exact = null) {
  const g = decodeGroup(m.encoded, exact);
  if (!sameKey(g, m.key)) throw new WireError('group message: key: the encoded group is another group');
  return g;
}

export function emptyStats() {
  // Where a frame's time goes: main-thread time decoding groups and issuing GL calls, and waiting
  // in finish() for the GL to draw what was issued (at the first group and the end of the frame).
  // cells: of the groups, those in the cells encoding (the adaptive server's choice);
  // cells_decode_ms, cells_triangles: their share of decode_ms (both decodings of a stepped group)
  // and of the triangles decoded.
  return { bytes: 0, groups: 0, cells: 0, named: 0, triangles: 0, first_group_ms: null, frame_ms: null,
           decode_ms: 0, draw_ms: 0, gl_wait_ms: 0, cells_decode_ms: 0, cells_triangles: 0 };
}

// How often decodeReport gives what decoding cost (ClientFrames::kReportEveryS).
export const kReportEveryMs = 50;

export class ClientFrames {
  // renderer: clear(), clearDepth(), draw(mesh, view, projection), resize(w, h), collect(live).
  // now: a clock in milliseconds (performance.now()).
  constructor(renderer, now = () => performance.now(), decode = decodeMesh) {
    this.renderer = renderer;
    this.now = now;
    this.decode = decode;
    this.request = null;
    this.active = false;
    this.startMs = 0;
    this.stats = emptyStats();
    this.drawLevel = 1 << 30;  // the finest level drawn in this frame so far
    this.drewCoarse = false;
    this.drewAny = false;
    this.finals = [];  // full-resolution groups of the frame
    this.stepped = [];
    this.replaced = false;
    this.cache = [];   // { mesh, level }; index = slot in generation cacheGen
    this.cacheGen = 0;
    this.lastEnd = null;
    // Decoded since the last report, by encoding id: { triangles, ms } (decodeReport).
    this.decoded = new Map();
    this.lastReportMs = -Infinity;
  }

  // A request was sent: a new frame of its view (the previous one is abandoned).
  begin(request) {
    this.request = request;
    this.active = true;
    this.startMs = this.now();
    this.stats = emptyStats();
    this.drawLevel = 1 << 30;
    this.drewCoarse = false;
    this.drewAny = false;
    this.finals = [];
    this.stepped = [];  // { key, encoded, finalIndex }: groups awaiting their exact values
    this.replaced = false;
    this.viewM = viewMatrix(request.view.camera);
    this.projM = projectionMatrix(request.view.frustum);
    this.renderer.resize(request.view.width, request.view.height);
    this.renderer.clear();
    this.collect();
  }

  collect() {
    const live = new Set(this.cache.map((c) => c.mesh));
    for (const m of this.finals) live.add(m);
    this.renderer.collect?.(live);
  }

  draw(mesh, level) {
    if (level > this.drawLevel) return;  // coarser than what shows: cached, drawn next frame
    if (level < this.drawLevel && this.drewAny) this.renderer.clearDepth();
    this.drawLevel = level;
    this.drewCoarse = this.drewCoarse || level > 0;
    const t0 = this.now();
    this.renderer.draw(mesh, this.viewM, this.projM);
    this.drewAny = true;
    if (level === 0) this.finals.push(mesh);
    this.stats.triangles += triangleCount(mesh);
    this.stats.draw_ms += this.now() - t0;
    if (this.stats.first_group_ms === null) this.stats.first_group_ms = this.finish();
  }

  handleGroup(g, wireBytes) {
    const current = this.active && g.request_id === this.request.request_id;
    if (!current && g.cache_gen === 0) return;
    const t0 = this.now();
    const mesh = this.decode(g);
    const ms = this.now() - t0;
    this.stats.decode_ms += ms;
    // decode checked the encoding byte.
    const e = g.encoded[1];
    const d = this.decoded.get(e) ?? { triangles: 0, ms: 0 };
    d.triangles += triangleCount(mesh);
    d.ms += ms;
    this.decoded.set(e, d);
    if (g.cache_gen !== 0) {
      if (g.cache_gen !== this.cacheGen) {
        this.cache = [];
        this.cacheGen = g.cache_gen;
        this.collect();
      }
      this.cache.push({ mesh, level: g.key.level });
    }
    if (mesh.stepped && g.cache_gen !== 0)
      throw new WireError('group message: a group to cache came with its values to a step');
    if (!current) return;
    this.stats.bytes += wireBytes;
    ++this.stats.groups;
    if (e === GroupEncoding.cells) {
      ++this.stats.cells;
      this.stats.cells_decode_ms += ms;
      this.stats.cells_triangles += triangleCount(mesh);
    }
    const before = this.finals.length;
    if (!g.draw_from_next_frame) this.draw(mesh, g.key.level);
    if (mesh.stepped)
      this.stepped.push({ key: g.key, encoded: g.encoded, finalIndex: this.finals.length > before ? before : -1 });
  }

  handleExact(x, wireBytes) {
    if (!this.active || x.request_id !== this.request.request_id) return;
    const at = this.stepped.findIndex((s) => sameKey(s.key, x.key));
    if (at < 0) throw new WireError('exact message: key: no group of the request awaits exact values');
    const s = this.stepped[at];
    this.stepped.splice(at, 1);
    const t0 = this.now();
    const mesh = this.decode({ key: s.key, encoded: s.encoded }, x.bits);
    const ms = this.now() - t0;
    this.stats.decode_ms += ms;
    this.stats.cells_decode_ms += ms;
    // The second decoding of a cells group is the client's work too (its triangles were counted).
    const d = this.decoded.get(GroupEncoding.cells) ?? { triangles: 0, ms: 0 };
    d.ms += ms;
    this.decoded.set(GroupEncoding.cells, d);
    this.stats.bytes += wireBytes;
    if (s.finalIndex < 0) return;
    this.finals[s.finalIndex] = mesh;
    // Over the stepped surface, which lies within a hair of it: the frame's end draws the
    // full-resolution groups again alone.
    const t1 = this.now();
    this.renderer.draw(mesh, this.viewM, this.projM);
    this.stats.draw_ms += this.now() - t1;
    this.replaced = true;
  }

  handleVisible(v, wireBytes) {
    if (!this.active || v.request_id !== this.request.request_id) return;
    this.stats.bytes += wireBytes;
    const named = [];
    for (const slot of v.slots) {
      if (slot >= this.cache.length)
        throw new WireError('visible message: slots: the server named a group the client does not ' +
          `hold (slot ${slot} of ${this.cache.length})`);
      named.push(this.cache[slot]);
    }
    // Coarse first (a stable sort): draw() skips a group coarser than what the frame shows.
    named.sort((a, b) => b.level - a.level);
    for (const c of named) {
      ++this.stats.named;
      this.draw(c.mesh, c.level);
    }
  }

  // What decoding groups cost since the last report, as a decode_rate message (the adaptive server
  // weighs it, remote/encoding_choice.h), once kReportEveryMs has passed since that report (at
  // `nowMs`) and something was decoded; null otherwise.
  decodeReport(nowMs) {
    if (nowMs - this.lastReportMs < kReportEveryMs) return null;
    const entries = [...this.decoded].filter(([, d]) => d.triangles > 0).sort(([a], [b]) => a - b)
      .map(([encoding, d]) => ({ encoding, triangles: d.triangles, seconds: d.ms / 1e3 }));
    this.decoded.clear();
    if (entries.length === 0) return null;
    this.lastReportMs = nowMs;
    return { entries };
  }

  // A decoded frame { name, msg } of `wireBytes` bytes. True when it ended the current frame.
  // Throws for a group that does not decode or names an unknown cached group, and RemoteError
  // for an error message.
  handle(name, m, wireBytes) {
    if (name === 'error') throw new RemoteError(m.code, m.text);
    if (name === 'group') {
      this.handleGroup(m, wireBytes);
      return false;
    }
    if (name === 'visible') {
      this.handleVisible(m, wireBytes);
      return false;
    }
    if (name === 'exact') {
      this.handleExact(m, wireBytes);
      return false;
    }
    if (name === 'end_of_frame') {
      if (!this.active || m.request_id !== this.request.request_id) return false;
      this.stats.bytes += wireBytes;
      this.finishFrame(m);
      return true;
    }
    return false;  // ready, hello, request, bye: not part of a frame
  }

  // Waits for the GL to draw what was issued (a time taken before would be a time the pixels are
  // only queued), then gives the time since the request.
  finish() {
    const t0 = this.now();
    this.renderer.finish?.();
    const t1 = this.now();
    this.stats.gl_wait_ms += t1 - t0;
    return t1 - this.startMs;
  }

  finishFrame(end) {
    if (this.stepped.length > 0)
      throw new WireError(`end of frame message: ${this.stepped.length} groups of the request never got their exact values`);
    if (this.drewCoarse || this.replaced) {
      // The full-resolution groups alone: no coarse surface outside the fine one stays.
      this.renderer.clear();
      for (const mesh of this.finals) this.renderer.draw(mesh, this.viewM, this.projM);
    }
    this.stats.frame_ms = this.finish();
    this.active = false;
    this.lastEnd = end;
  }
}
