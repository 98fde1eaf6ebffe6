// The byte format of every message (wire/wire.h): a version byte first, then explicit
// little-endian fields. A Reader never trusts a length: every count is checked against the bytes
// left before anything is allocated, and every failure throws an Error "<what>: <why>", as the
// C++ WireError does.

export class WireError extends Error {
  constructor(message) {
    super(message);
    this.name = 'WireError';
  }
}

const TWO_32 = 4294967296;

export class Writer {
  constructor(version) {
    this.buf = new Uint8Array(64);
    this.view = new DataView(this.buf.buffer);
    this.len = 0;
    if (version !== undefined) this.u8(version);
  }
  reserve(n) {
    if (this.len + n <= this.buf.length) return;
    let cap = this.buf.length * 2;
    while (cap < this.len + n) cap *= 2;
    const b = new Uint8Array(cap);
    b.set(this.buf.subarray(0, this.len));
    this.buf = b;
    this.view = new DataView(b.buffer);
  }
  u8(v) { this.reserve(1); this.view.setUint8(this.len, v); this.len += 1; }
  u16(v) { this.reserve(2); this.view.setUint16(this.len, v, true); this.len += 2; }
  u32(v) { this.reserve(4); this.view.setUint32(this.len, v >>> 0, true); this.len += 4; }
  i32(v) { this.reserve(4); this.view.setInt32(this.len, v, true); this.len += 4; }
  // A u64 held in a Number (exact up to 2^53).
  u64(v) {
    if (!Number.isSafeInteger(v) || v < 0) throw new RangeError(`u64 ${v}: expected 0..2^53-1`);
    this.u32(v % TWO_32);
    this.u32(Math.floor(v / TWO_32));
  }
  f32(v) { this.reserve(4); this.view.setFloat32(this.len, v, true); this.len += 4; }
  f64(v) { this.reserve(8); this.view.setFloat64(this.len, v, true); this.len += 8; }
  vec3(v) { this.f32(v[0]); this.f32(v[1]); this.f32(v[2]); }
  raw(bytes) { this.reserve(bytes.length); this.buf.set(bytes, this.len); this.len += bytes.length; }
  // A length (u64) then the bytes.
  bytes(b) { this.u64(b.length); this.raw(b); }
  string(s) { this.bytes(new TextEncoder().encode(s)); }
  take() { return this.buf.slice(0, this.len); }
}

export class Reader {
  // `what` names the message in errors ("group message"). With `version` given, the first byte
  // must be it (MessageReader); without, no version byte is read (ByteReader).
  constructor(bytes, what, version) {
    this.bytes = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
    this.view = new DataView(this.bytes.buffer, this.bytes.byteOffset, this.bytes.byteLength);
    this.pos = 0;
    this.what = what;
    if (version !== undefined) {
      const found = this.u8();
      if (found !== version) this.fail(`version ${found}, expected ${version}`);
    }
  }
  fail(why) { throw new WireError(`${this.what}: ${why}`); }
  remaining() { return this.bytes.length - this.pos; }
  need(n) {
    if (n > this.remaining()) this.fail('truncated');
  }
  u8() { this.need(1); return this.view.getUint8(this.pos++); }
  u16() { this.need(2); const v = this.view.getUint16(this.pos, true); this.pos += 2; return v; }
  u32() { this.need(4); const v = this.view.getUint32(this.pos, true); this.pos += 4; return v; }
  i16() { this.need(2); const v = this.view.getInt16(this.pos, true); this.pos += 2; return v; }
  i32() { this.need(4); const v = this.view.getInt32(this.pos, true); this.pos += 4; return v; }
  // A u64 as a Number; one past 2^53 cannot be held exactly and is refused.
  u64(field = 'u64') {
    const lo = this.u32(), hi = this.u32();
    if (hi >= 0x200000) this.fail(`${field}: ${BigInt(hi) * 4294967296n + BigInt(lo)} is over 2^53`);
    return hi * TWO_32 + lo;
  }
  f32() { this.need(4); const v = this.view.getFloat32(this.pos, true); this.pos += 4; return v; }
  f64() { this.need(8); const v = this.view.getFloat64(this.pos, true); this.pos += 8; return v; }
  vec3() { return [this.f32(), this.f32(), this.f32()]; }
  finiteF32(field) {
    const v = this.f32();
    if (!Number.isFinite(v)) this.fail(`${field}: expected a finite number, got ${v}`);
    return v;
  }
  finiteF64(field) {
    const v = this.f64();
    if (!Number.isFinite(v)) this.fail(`${field}: expected a finite number, got ${v}`);
    return v;
  }
  finiteVec3(field) {
    return [this.finiteF32(`${field}.x`), this.finiteF32(`${field}.y`), this.finiteF32(`${field}.z`)];
  }
  // The next n bytes, not copied.
  span(n) {
    this.need(n);
    const s = this.bytes.subarray(this.pos, this.pos + n);
    this.pos += n;
    return s;
  }
  // A length (u64) then that many bytes, the length checked against the message first.
  getBytes() {
    const lo = this.u32(), hi = this.u32();
    const n = hi * TWO_32 + lo;
    if (n > this.remaining()) this.fail(`length ${hi ? BigInt(hi) * 4294967296n + BigInt(lo) : lo} is longer than the message`);
    return this.span(n);
  }
  finish() {
    if (this.remaining() !== 0) this.fail(`${this.remaining()} trailing bytes`);
  }
}

// The group codec's reader (remote/byte_io.h): no version byte, and a short read says how short.
export class ByteReader extends Reader {
  constructor(bytes, what) {
    super(bytes, what);
  }
  need(n) {
    if (n > this.remaining()) this.fail(`truncated: ${n} bytes wanted, ${this.remaining()} left`);
  }
  // `count` elements of `bytesEach` must fit in what is left: call before allocating them.
  needElements(count, bytesEach, field) {
    if (count > Math.floor(this.remaining() / bytesEach))
      this.fail(`${field}: ${count} elements are longer than the bytes left (${this.remaining()})`);
  }
}
