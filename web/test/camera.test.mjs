// The camera against numbers printed by the C++ (data/camera_probe.cpp, built against
// core/camera.cpp; its output is data/cameras_cpp.json).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { frontFullView, orbit, zoom, fitDepthRange, frustum, viewMatrix, projectionMatrix, cameraProblem,
  validUp, normalMatrix, viewCamera } from '../src/camera.js';

const cases = JSON.parse(readFileSync(new URL('./data/cameras_cpp.json', import.meta.url)));

// Relative to the magnitude (float32 has 24 bits; a few ulps of drift through the chain).
function close(actual, expected, what, rel = 2e-6) {
  assert.equal(actual.length, expected.length, what);
  const scale = Math.max(1, ...expected.map(Math.abs));
  for (let i = 0; i < expected.length; ++i)
    assert.ok(Math.abs(actual[i] - expected[i]) <= rel * scale,
      `${what}[${i}]: ${actual[i]} vs the C++ ${expected[i]}`);
}

for (const k of cases) {
  test(`camera ${k.w}x${k.h} box [${k.min}]..[${k.max}] orbit ${k.yaw} ${k.pitch} zoom ${k.zoom} ${k.proj ? 'ortho' : 'persp'}`, () => {
    const bounds = { min: k.min, max: k.max };
    const aspect = Math.fround(k.w / k.h);
    let c = frontFullView(bounds, aspect, k.proj);
    close(c.eye, k.front_eye, 'front eye');
    close([c.near_z, c.far_z, c.ortho_height], [k.front_near, k.front_far, k.front_ortho], 'front near/far/ortho');
    c = orbit(c, k.yaw, k.pitch);
    close(c.eye, k.orbit_eye, 'orbit eye');
    close(c.up, k.orbit_up, 'orbit up');
    c = fitDepthRange(zoom(c, k.zoom), bounds);
    close(c.eye, k.eye, 'eye');
    close(c.target, k.target, 'target');
    close(c.up, k.up, 'up');
    close([c.near_z, c.far_z, c.ortho_height], [k.near, k.far, k.ortho], 'near/far/ortho');
    const f = frustum(c, aspect);
    close([f.left, f.right, f.bottom, f.top, f.near_z, f.far_z], k.frustum, 'frustum');
    close(Array.from(viewMatrix(c)), k.view, 'view matrix', 1e-5);
    close(Array.from(projectionMatrix(f)), k.projection, 'projection matrix', 1e-5);
    assert.equal(cameraProblem(c), k.problem);
    if (k.proj === 0) {
      // viewCamera is the same chain, from the image size.
      const v = viewCamera(bounds, k.w, k.h, k.yaw, k.pitch, k.zoom);
      close(v.camera.eye, k.eye, 'viewCamera eye');
    }
  });
}

test('front view of the unit box, by hand', () => {
  // aspect 1: tan(15 deg) = 0.267949; half = 0.5; dist = max(0.5/t + 0.5) * 1.04 = 2.4606
  const c = frontFullView({ min: [0, 0, 0], max: [1, 1, 1] }, 1);
  assert.deepEqual(c.target, [0.5, 0.5, 0.5]);
  assert.ok(Math.abs(c.eye[1] - (0.5 - (0.5 / Math.tan(Math.PI / 12) + 0.5) * 1.04)) < 1e-5, `eye ${c.eye}`);
  assert.equal(c.eye[0], 0.5);
  assert.equal(c.eye[2], 0.5);
});

test('valid_up: falls back along the view direction', () => {
  assert.deepEqual(validUp([0, 1, 0], [0, 0, 1]), [0, 0, 1]);
  assert.deepEqual(validUp([0, 0, 1], [0, 0, 1]), [0, 1, 0]);
  assert.deepEqual(validUp([1, 0, 0], [1, 0, 0]), [0, 0, 1]);
  assert.deepEqual(validUp([1, 0, 0], [0, 0, 0]), [0, 0, 1]);
});

test('camera_problem: same point, far away, finite', () => {
  const base = { eye: [0, 0, 0], target: [0, 0, 0], up: [0, 0, 1], projection: 0, fovy_deg: 30, ortho_height: 2 };
  assert.equal(cameraProblem(base), 'the eye and the target are the same point');
  assert.match(cameraProblem({ ...base, eye: [2e9, 0, 0] }), /from the origin; expected at most/);
  assert.equal(cameraProblem({ ...base, eye: [NaN, 0, 0] }), 'the eye or the target is not a finite point');
  assert.equal(cameraProblem({ ...base, eye: [1, 0, 0] }), '');
});

test('normal matrix of a rotation is the rotation', () => {
  const c = orbit(frontFullView({ min: [0, 0, 0], max: [10, 20, 30] }, 1.5), 33, -20);
  const v = viewMatrix(c);
  const n = normalMatrix(v);
  const m3 = [v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]];
  close(Array.from(n), m3, 'normal matrix', 1e-6);
});

test('the front view of a turned volume is the patient\'s front, and the identity changes nothing', async () => {
  const { frontFullView, frontFullViewOf } = await import('../src/camera.js');
  const b = { min: [0, 0, 0], max: [100, 200, 50] };
  assert.deepEqual(frontFullViewOf(b, [[1, 0, 0], [0, 1, 0], [0, 0, 1]], 1.5), frontFullView(b, 1.5));
  // The volume's y runs toward the patient's feet (-z) and its z toward the back (+y): the eye
  // looks along the volume's z (the patient's +y), and the volume's -y is up.
  const c = frontFullViewOf(b, [[1, 0, 0], [0, 0, -1], [0, 1, 0]], 1.5);
  const d = [0, 1, 2].map((a) => c.target[a] - c.eye[a]);
  assert.ok(d[2] > 0 && Math.abs(d[0]) < 1e-3 && Math.abs(d[1]) < 1e-3, `view direction ${d}`);
  assert.ok(c.up[1] < -0.999, `up ${c.up}`);
});
