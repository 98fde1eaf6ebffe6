// Visible slots (remote/slot_list.h): both forms, the encoder's choice, and the refusal of every
// non-canonical form.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { Reader, Writer } from '../src/wire.js';
import { putSlots, getSlots, smallerForm, SlotForm, bitmapFormBytes, deltasFormBytes, varintBytes, putVarint, getVarint } from '../src/slot_list.js';

const encode = (slots) => { const w = new Writer(); putSlots(w, slots); return w.take(); };
const decode = (bytes) => { const r = new Reader(bytes, 'visible message'); const s = getSlots(r); r.finish(); return s; };

test('round trips, in the smaller form', () => {
  const sets = [[], [0], [7], [0, 1, 2, 5, 7, 11], [1000000], [3, 500, 70000, 1048575],
    Array.from({ length: 300 }, (_, i) => 2 * i), [0, 127, 128, 16511, 16512]];
  for (const s of sets) {
    const b = encode(s);
    assert.deepEqual(decode(b), s);
    const form = smallerForm(s);
    assert.equal(b[0], form);
    assert.equal(b.length, form === SlotForm.bitmap ? bitmapFormBytes(s) : deltasFormBytes(s));
  }
  assert.equal(encode([0, 1, 2, 5, 7, 11])[0], SlotForm.bitmap);
  assert.equal(encode([1000000])[0], SlotForm.deltas);
  // The seed's bitmap: form 0, n = 12, bits 0,1,2,5,7 | 11.
  assert.deepEqual(Array.from(encode([0, 1, 2, 5, 7, 11])), [0, 12, 0, 0, 0, 0xa7, 0x08]);
  // A tie goes to the bitmap: [] is 5 bytes either way.
  assert.equal(encode([])[0], SlotForm.bitmap);
});

test('varints: LEB128, shortest form only', () => {
  for (const v of [0, 1, 127, 128, 16383, 16384, 2 ** 32 - 1]) {
    const w = new Writer();
    putVarint(w, v);
    const b = w.take();
    assert.equal(b.length, varintBytes(v));
    assert.equal(getVarint(new Reader(b, 'm'), 'f'), v);
  }
  assert.throws(() => getVarint(new Reader(new Uint8Array([0x80, 0x00]), 'm'), 'slots[0]'),
    /m: slots\[0\]: varint of 2 bytes ends in a zero byte, expected the shortest form/);
  assert.throws(() => getVarint(new Reader(new Uint8Array([0xff, 0xff, 0xff, 0xff, 0x1f]), 'm'), 'f'), /varint 8589934591, expected less than 2\^32/);
  assert.throws(() => getVarint(new Reader(new Uint8Array([0x80, 0x80, 0x80, 0x80, 0x80, 0x01]), 'm'), 'f'), /varint longer than 5 bytes/);
  assert.throws(() => getVarint(new Reader(new Uint8Array([0x80]), 'm'), 'f'), /the varint runs past the end of the message/);
});

test('non-canonical forms are refused', () => {
  const u32 = (v) => [v & 0xff, (v >> 8) & 0xff, (v >> 16) & 0xff, v >>> 24];
  const cases = [
    [[2, ...u32(0)], /form: expected 0 \(bitmap\) or 1 \(deltas\), got 2/],
    // bit count past the highest slot + 1
    [[0, ...u32(9), 0x01, 0x00], /bit count 9 but bit 8 is clear, expected the highest slot \+ 1/],
    // a bit at or past n in the last byte
    [[0, ...u32(3), 0x0c], /bit 3 is set, expected none at or past the bit count 3/],
    // deltas where the bitmap is smaller
    [[1, ...u32(2), 0, 1], /form: 1, but the slots take 6 bytes as a bitmap and 7 as deltas: expected the smaller/],
    // a bitmap where the deltas are smaller
    [[0, ...u32(65), ...new Array(8).fill(0), 0x01], /form: 0, but the slots take 14 bytes as a bitmap and 6 as deltas/],
    [[1, ...u32(2), 100, 0], /slots\[1\]: gap 0, expected at least 1/],
    [[1, ...u32(1), 0x80, 0x80, 0x40], /slots\[0\]: slot 1048576, expected less than 1048576/],
    [[1, ...u32(50), 1], /slots: count 50 is larger than the 1 bytes left/],
    [[0, ...u32(2000000)], /slots: bit count 2000000, expected at most 1048576/],
    [[0, ...u32(64), 1], /slots: a bitmap of 64 bits takes 8 bytes, 1 left/],
  ];
  for (const [bytes, re] of cases) assert.throws(() => decode(new Uint8Array(bytes)), re, JSON.stringify(bytes));
});
