// The wall page's pure parts (src/wall/): gestures as the control window's script lines
// (master/control_input.h), and the mosaic message (master/wall_page.h: encode_mosaic).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { Drag, num, orbitLine, panLine, zoomLine, pinchLine, isoLine, surfacesLine, timeLine, clipLine, axisClip } from '../src/wall/gestures.js';
import { ready, isMosaic, mosaicHeader, decodeMosaic } from '../src/wall/mosaic.js';
import { readFileSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

test('gestures become the control window\'s lines', () => {
  assert.equal(orbitLine(60, 0), 'orbit -30 0');
  assert.equal(orbitLine(-10, 4), 'orbit 5 -2');
  assert.equal(panLine(32, 24, 320, 240), 'pan -0.1 0.1');
  assert.equal(zoomLine(-1), 'zoom 1.25');
  assert.equal(zoomLine(1), 'zoom 0.8');
  assert.equal(zoomLine(-2), 'zoom 1.5625');
  assert.equal(pinchLine(100, 150), 'zoom 1.5');
  assert.equal(isoLine(52.2), 'iso 52.2');
  assert.equal(surfacesLine('  40:skin:0.3   105:bone '), 'iso 40:skin:0.3 105:bone');
  assert.equal(surfacesLine('   '), null);
  assert.equal(timeLine(3), 'time 3');
  assert.equal(clipLine('x', 99), 'clip x<99');
  assert.equal(clipLine('', 5), 'clip off');
  assert.deepEqual(axisClip('z<83.5'), { axis: 'z', at: 83.5 });
  assert.equal(axisClip('x>10'), null);
  assert.equal(axisClip('x<10 y<4'), null);
  assert.equal(axisClip(''), null);
  assert.equal(num(1 / 3), '0.333333');
  assert.equal(num(-0), '0');
});

test('a drag adds up however its motion is cut', () => {
  const d = new Drag('orbit');
  assert.equal(d.flush(320, 240), null);
  for (let i = 0; i < 6; ++i) d.move(10, 0);
  assert.equal(d.flush(320, 240), 'orbit -30 0');
  assert.equal(d.flush(320, 240), null);
  const p = new Drag('pan');
  p.move(16, -12);
  assert.equal(p.flush(320, 240), 'pan -0.05 -0.05');
});

// A mosaic the C++ side made (test/data/mosaic_64x24.bin, frame 42): control_test's
// WallPage.TheMosaicRoundTripsAndMalformedOnesThrow checks that it decodes there to its picture.
test('the mosaic message decodes, and malformed ones throw', async () => {
  await ready;
  const here = dirname(fileURLToPath(import.meta.url));
  const bytes = new Uint8Array(readFileSync(join(here, 'data/mosaic_64x24.bin')));
  assert.ok(isMosaic(bytes));
  const m = decodeMosaic(bytes);
  assert.deepEqual([m.width, m.height, m.frame], [64, 24, 42]);
  assert.equal(m.rgba.length, 64 * 24 * 4);
  // The top-left pixel is the bezel's grey frame (master/control_view.h: kControlBezel 96).
  assert.deepEqual([...m.rgba.subarray(0, 4)], [96, 96, 96, 255]);
  for (const cut of [0, 3, 10, 19, 21, bytes.length - 1]) {
    assert.throws(() => decodeMosaic(bytes.subarray(0, cut)), /mosaic|zstd|size|Error/i, `cut ${cut}`);
  }
  const wide = bytes.slice();
  wide[4] = 0xff; wide[5] = 0xff;
  assert.throws(() => mosaicHeader(wide), /size/);
  assert.ok(!isMosaic(new TextEncoder().encode('{"type":"state"}')));
});
