// The page's input as script lines, as the control window makes them (master/control_input.h):
// a drag orbits at kOrbitDegPerPx degrees per mosaic pixel (a right drag or a shift drag pans, in
// mosaic sizes), a wheel step or a pinch zooms, so the page, the control window and a script
// drive the wall alike. Pure: the caller converts screen pixels to mosaic pixels.
import { formatValue } from '../ui.js';

export const kOrbitDegPerPx = 0.5;
export const kZoomStep = 1.25;

// Six significant digits, no trailing zeros: "-30", "0.125".
export function num(v) {
  const s = formatValue(v);
  return s === '-0' ? '0' : s;
}

export function orbitLine(dx, dy) {
  return `orbit ${num(-dx * kOrbitDegPerPx)} ${num(-dy * kOrbitDegPerPx)}`;
}

export function panLine(dx, dy, mosaicWidth, mosaicHeight) {
  return `pan ${num(-dx / Math.max(mosaicWidth, 1))} ${num(dy / Math.max(mosaicHeight, 1))}`;
}

// Wheel steps (negative: towards the user, closer) as one zoom line.
export function zoomLine(steps) {
  return `zoom ${num(kZoomStep ** -steps)}`;
}

export function pinchLine(startDistance, endDistance) {
  return `zoom ${num(endDistance / Math.max(startDistance, 1))}`;
}

export function isoLine(v) {
  return `iso ${num(v)}`;
}

// The script line that shows time step n of a series.
export function timeLine(n) {
  return `time ${Math.round(n)}`;
}

// The script line for several surfaces typed as `iso` takes them ("40:skin:0.3 105:bone"), or
// null when nothing is typed; the wall checks each.
export function surfacesLine(text) {
  const words = String(text).trim().split(/\s+/).filter((w) => w.length > 0);
  return words.length > 0 ? `iso ${words.join(' ')}` : null;
}

// The clip line of the page's axis menu and slider: one plane keeping what lies below `at` on
// `axis` ('x', 'y' or 'z'), or none.
export function clipLine(axis, at) {
  return axis ? `clip ${axis}<${num(at)}` : 'clip off';
}

// The axis and place of a clip the page can show (one axis plane kept below, "x<99"), or null.
export function axisClip(text) {
  const m = /^([xyz])<(-?[0-9.]+(?:e[-+]?[0-9]+)?)$/.exec(text ?? '');
  return m ? { axis: m[1], at: Number(m[2]) } : null;
}

// A drag's motion in mosaic pixels, cut into lines no more often than the caller flushes.
export class Drag {
  constructor(kind) {
    this.kind = kind;  // 'orbit' | 'pan'
    this.dx = 0;
    this.dy = 0;
  }

  move(dx, dy) {
    this.dx += dx;
    this.dy += dy;
  }

  // The line for the motion since the last flush, or null when there was none.
  flush(mosaicWidth, mosaicHeight) {
    if (this.dx === 0 && this.dy === 0) return null;
    const line = this.kind === 'orbit' ? orbitLine(this.dx, this.dy) : panLine(this.dx, this.dy, mosaicWidth, mosaicHeight);
    this.dx = 0;
    this.dy = 0;
    return line;
  }
}
