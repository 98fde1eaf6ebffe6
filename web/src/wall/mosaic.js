// The wall's mosaic as the master sends it (master/wall_page.h: encode_mosaic): "IWM1", width and
// height (u32), the frame (u64), little-endian, then the RGB pixels as one zstd frame.
import { ZSTDDecoder } from 'zstddec';

const zstd = new ZSTDDecoder();
export const ready = zstd.init();
const kHeader = 20;
const kMaxSide = 4096;

// Whether a binary message from the master is a mosaic (the others are JSON, starting with '{').
export function isMosaic(bytes) {
  return bytes.length >= 4 && bytes[0] === 0x49 && bytes[1] === 0x57 && bytes[2] === 0x4d && bytes[3] === 0x31;
}

// The header alone; throws on a malformed one.
export function mosaicHeader(bytes) {
  if (bytes.length < kHeader || !isMosaic(bytes)) throw new Error('mosaic: not an IWM1 message');
  const v = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const width = v.getUint32(4, true), height = v.getUint32(8, true);
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide) {
    throw new Error(`mosaic: size ${width}x${height}`);
  }
  const frame = Number(v.getBigUint64(12, true));
  return { width, height, frame };
}

// { width, height, frame, rgba } (Uint8ClampedArray for an ImageData); `decode` is zstd's,
// replaceable for tests. Throws on anything malformed.
export function decodeMosaic(bytes, decode = (src, size) => zstd.decode(src, size)) {
  const h = mosaicHeader(bytes);
  const n = h.width * h.height;
  const rgb = decode(bytes.subarray(kHeader), n * 3);
  if (rgb.length !== n * 3) throw new Error('mosaic: the pixels are not width x height x 3 bytes');
  const rgba = new Uint8ClampedArray(n * 4);
  for (let i = 0, j = 0; i < n; ++i, j += 3) {
    rgba[i * 4] = rgb[j];
    rgba[i * 4 + 1] = rgb[j + 1];
    rgba[i * 4 + 2] = rgb[j + 2];
    rgba[i * 4 + 3] = 255;
  }
  return { ...h, rgba };
}
