// The cached-group slots a visible message names (remote/slot_list.h). Two forms, the encoder
// picks the smaller (a tie goes to the bitmap):
//   form 0, bitmap: bit count u32 n (the highest slot + 1), then ceil(n/8) bytes, bit i = slot i,
//           least significant bit first; bits >= n in the last byte are zero;
//   form 1, deltas: count u32 k, then k unsigned LEB128 varints: the first slot, then each gap
//           (>= 1); a varint takes at most 5 bytes and holds less than 2^32.
// Only the encoder's bytes decode (the smaller form, n = highest slot + 1, shortest varints), so a
// set has one encoding, as in the C++.

export const kMaxVisibleKeys = 1 << 20;
export const kMaxVarintBytes = 5;
export const SlotForm = { bitmap: 0, deltas: 1 };

export function putVarint(w, v) {
  v = v >>> 0;
  while (v >= 0x80) {
    w.u8((v & 0x7f) | 0x80);
    v >>>= 7;
  }
  w.u8(v);
}

export function varintBytes(v) {
  v = v >>> 0;
  if (v === 0) return 1;
  const bitWidth = 32 - Math.clz32(v);
  return Math.floor((bitWidth + 6) / 7);
}

export function getVarint(r, field) {
  let v = 0;
  for (let i = 0; i < kMaxVarintBytes; ++i) {
    if (r.remaining() === 0) r.fail(`${field}: the varint runs past the end of the message`);
    const byte = r.u8();
    v += (byte & 0x7f) * 2 ** (7 * i);
    if (!(byte & 0x80)) {
      if (i > 0 && byte === 0)
        r.fail(`${field}: varint of ${i + 1} bytes ends in a zero byte, expected the shortest form`);
      if (v > 0xffffffff) r.fail(`${field}: varint ${v}, expected less than 2^32`);
      return v;
    }
  }
  r.fail(`${field}: varint longer than ${kMaxVarintBytes} bytes`);
}

export function bitmapFormBytes(slots) {
  const n = slots.length === 0 ? 0 : slots[slots.length - 1] + 1;
  return 1 + 4 + Math.ceil(n / 8);
}

export function deltasFormBytes(slots) {
  let bytes = 1 + 4;
  for (let i = 0; i < slots.length; ++i) bytes += varintBytes(i === 0 ? slots[0] : slots[i] - slots[i - 1]);
  return bytes;
}

export function smallerForm(slots) {
  return bitmapFormBytes(slots) <= deltasFormBytes(slots) ? SlotForm.bitmap : SlotForm.deltas;
}

// `slots` strictly ascending, each below kMaxVisibleKeys.
export function putSlots(w, slots) {
  const form = smallerForm(slots);
  w.u8(form);
  if (form === SlotForm.deltas) {
    w.u32(slots.length);
    for (let i = 0; i < slots.length; ++i) putVarint(w, i === 0 ? slots[0] : slots[i] - slots[i - 1]);
    return;
  }
  const n = slots.length === 0 ? 0 : slots[slots.length - 1] + 1;
  w.u32(n);
  const bits = new Uint8Array(Math.ceil(n / 8));
  for (const s of slots) bits[s >> 3] |= 1 << (s & 7);
  w.raw(bits);
}

function getBitmap(r) {
  const n = r.u32();
  if (n > kMaxVisibleKeys) r.fail(`slots: bit count ${n}, expected at most ${kMaxVisibleKeys}`);
  const bytes = Math.ceil(n / 8);
  if (bytes > r.remaining())
    r.fail(`slots: a bitmap of ${n} bits takes ${bytes} bytes, ${r.remaining()} left`);
  const slots = [];
  for (let b = 0; b < bytes; ++b) {
    const byte = r.u8();
    for (let bit = 0; bit < 8; ++bit) {
      if (!((byte >> bit) & 1)) continue;
      const slot = b * 8 + bit;
      if (slot >= n)
        r.fail(`slots: bit ${slot} is set, expected none at or past the bit count ${n}`);
      slots.push(slot);
    }
  }
  if (n > 0 && (slots.length === 0 || slots[slots.length - 1] !== n - 1))
    r.fail(`slots: bit count ${n} but bit ${n - 1} is clear, expected the highest slot + 1`);
  return slots;
}

function getDeltas(r) {
  const k = r.u32();
  if (k > r.remaining()) r.fail(`slots: count ${k} is larger than the ${r.remaining()} bytes left`);
  const slots = [];
  let slot = 0;
  for (let i = 0; i < k; ++i) {
    const field = `slots[${i}]`;
    const v = getVarint(r, field);
    if (i > 0 && v === 0) r.fail(`${field}: gap 0, expected at least 1`);
    slot = i === 0 ? v : slot + v;
    if (slot >= kMaxVisibleKeys) r.fail(`${field}: slot ${slot}, expected less than ${kMaxVisibleKeys}`);
    slots.push(slot);
  }
  return slots;
}

export function getSlots(r) {
  const form = r.u8();
  let slots;
  if (form === SlotForm.bitmap) slots = getBitmap(r);
  else if (form === SlotForm.deltas) slots = getDeltas(r);
  else r.fail(`form: expected 0 (bitmap) or 1 (deltas), got ${form}`);
  if (smallerForm(slots) !== form)
    r.fail(`form: ${form}, but the slots take ${bitmapFormBytes(slots)} bytes as a bitmap and ` +
      `${deltasFormBytes(slots)} as deltas: expected the smaller (a tie: the bitmap)`);
  return slots;
}
