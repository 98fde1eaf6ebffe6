// The camera of core/camera.cpp, in float32 arithmetic as glm does it (every operation
// rounded with Math.fround), so a view built here is the view `isowall render` builds:
// front_full_view(bounds, aspect), orbit(yaw, pitch), zoom(f), fit_depth_range(bounds), and
// frustum(aspect). Vectors are [x, y, z]; matrices are column-major Float32Arrays of 16 (as GL
// and glm store them).

const f = Math.fround;
export const Projection = { perspective: 0, orthographic: 1 };

const add = (a, b) => [f(a[0] + b[0]), f(a[1] + b[1]), f(a[2] + b[2])];
const sub = (a, b) => [f(a[0] - b[0]), f(a[1] - b[1]), f(a[2] - b[2])];
const scale = (a, s) => [f(a[0] * s), f(a[1] * s), f(a[2] * s)];
const divide = (a, s) => [f(a[0] / s), f(a[1] / s), f(a[2] / s)];
const neg = (a) => [-a[0], -a[1], -a[2]];
const dot = (a, b) => f(f(f(a[0] * b[0]) + f(a[1] * b[1])) + f(a[2] * b[2]));
const cross = (a, b) => [
  f(f(a[1] * b[2]) - f(b[1] * a[2])),
  f(f(a[2] * b[0]) - f(b[2] * a[0])),
  f(f(a[0] * b[1]) - f(b[0] * a[1])),
];
const length = (a) => f(Math.sqrt(dot(a, a)));
// glm::normalize: v * inversesqrt(dot(v, v)).
const normalize = (a) => scale(a, f(1 / f(Math.sqrt(dot(a, a)))));
const radians = (deg) => f(f(deg) * f(0.01745329251994329576923690768489));
const isFiniteVec = (v) => v.every(Number.isFinite);

export const vec3 = { add, sub, scale, dot, cross, length, normalize };

export function boxCenter(b) {
  return scale(add(b.min, b.max), f(0.5));
}
export function boxExtent(b) {
  return sub(b.max, b.min);
}

export function defaultCamera() {
  return {
    eye: [0, 0, 10], target: [0, 0, 0], up: [0, 1, 0],
    projection: Projection.perspective,
    fovy_deg: 30, ortho_height: 2, near_z: f(0.1), far_z: 100,
  };
}

function copyCamera(c) {
  return { ...c, eye: [...c.eye], target: [...c.target], up: [...c.up] };
}

// The up vector a view uses (valid_up): `up` unless nearly parallel to `forward`.
export function validUp(forward, up) {
  const fl = length(forward), ul = length(up);
  if (fl > 0 && ul > 0 && length(cross(divide(forward, fl), divide(up, ul))) >= f(1e-3)) return up;
  if (!(fl > 0) || Math.abs(f(forward[2] / fl)) < f(0.9)) return [0, 0, 1];
  return [0, 1, 0];
}

export function fitDepthRange(c, bounds) {
  const out = copyCamera(c);
  const radius = f(f(0.5) * length(boxExtent(bounds)));
  const d = length(sub(boxCenter(bounds), c.eye));
  out.near_z = Math.max(f(d - f(radius * f(1.05))), f(radius * f(0.01)));
  out.far_z = f(d + f(radius * f(1.05)));
  return out;
}

export function frontFullView(bounds, aspect, projection = Projection.perspective) {
  aspect = f(aspect);
  const c = defaultCamera();
  c.projection = projection;
  c.target = boxCenter(bounds);
  c.up = [0, 0, 1];
  const half = scale(boxExtent(bounds), f(0.5));
  const tanY = f(Math.tan(f(radians(c.fovy_deg) * f(0.5))));
  const tanX = f(tanY * aspect);
  let dist = 0, orthoHalfH = 0;
  for (const sy of [-1, 1]) {
    const depthOffset = f(sy * half[1]);
    dist = Math.max(dist, f(f(half[0] / tanX) - depthOffset), f(f(half[2] / tanY) - depthOffset));
    orthoHalfH = Math.max(orthoHalfH, half[2], f(half[0] / aspect));
  }
  dist = Math.max(f(dist * f(1.04)), f(f(half[1] * f(1.1)) + f(1e-3)));
  c.eye = sub(c.target, [0, dist, 0]);
  c.ortho_height = f(f(2 * orthoHalfH) * f(1.04));
  return fitDepthRange(c, bounds);
}

// glm::rotate(v, angle, normal) (gtx/rotate_vector): mat3(rotate(mat4(1), angle, normal)) * v.
function rotate(v, angle, normal) {
  const c = f(Math.cos(angle)), s = f(Math.sin(angle));
  const axis = normalize(normal);
  const temp = scale(axis, f(1 - c));
  const R = [
    [f(c + f(temp[0] * axis[0])), f(f(temp[0] * axis[1]) + f(s * axis[2])), f(f(temp[0] * axis[2]) - f(s * axis[1]))],
    [f(f(temp[1] * axis[0]) - f(s * axis[2])), f(c + f(temp[1] * axis[1])), f(f(temp[1] * axis[2]) + f(s * axis[0]))],
    [f(f(temp[2] * axis[0]) + f(s * axis[1])), f(f(temp[2] * axis[1]) - f(s * axis[0])), f(c + f(temp[2] * axis[2]))],
  ];
  const out = [0, 0, 0];
  for (let i = 0; i < 3; ++i) out[i] = f(f(f(R[0][i] * v[0]) + f(R[1][i] * v[1])) + f(R[2][i] * v[2]));
  return out;
}

// std::fmod(deg, 360.0) in double, then glm::radians in double, then to float.
function orbitRadians(deg) {
  const r = deg % 360;
  return f(r * (Math.PI / 180));
}

export function orbit(c, yawDeg, pitchDeg) {
  const out = copyCamera(c);
  let offset = sub(c.eye, c.target);
  const up = normalize(validUp(neg(offset), c.up));
  offset = rotate(offset, orbitRadians(yawDeg), up);
  const right = normalize(cross(neg(offset), up));
  offset = rotate(offset, orbitRadians(pitchDeg), right);
  out.eye = add(c.target, offset);
  out.up = normalize(cross(right, neg(offset)));
  return out;
}

export function zoom(c, factor) {
  const out = copyCamera(c);
  factor = f(factor);
  if (c.projection === Projection.perspective) out.eye = add(c.target, divide(sub(c.eye, c.target), factor));
  else out.ortho_height = f(c.ortho_height / factor);
  return out;
}

export function frustum(c, aspect) {
  aspect = f(aspect);
  const halfH = c.projection === Projection.perspective
    ? f(c.near_z * f(Math.tan(f(radians(c.fovy_deg) * f(0.5)))))
    : f(c.ortho_height * f(0.5));
  const right = f(halfH * aspect);
  return {
    left: -right, right, bottom: -halfH, top: halfH,
    near_z: c.near_z, far_z: c.far_z, projection: c.projection,
  };
}

// What `isowall render --orbit YAW PITCH --zoom F` draws, for an image of width x height.
const IDENTITY = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];

// frame_rotation: a rotation from the columns of `m` (Gram-Schmidt; the identity when x is zero
// or parallel to y).
export function frameRotation(m) {
  const x = m[0];
  const y = sub(m[1], scale(x, f(dot(m[1], x) / Math.max(dot(x, x), 1e-30))));
  if (!(length(x) > 1e-6) || !(length(y) > 1e-6)) return IDENTITY;
  const nx = normalize(x), ny = normalize(y);
  return [nx, ny, cross(nx, ny)];
}

const isIdentity = (r) => r.every((col, c) => col.every((v, i) => v === (c === i ? 1 : 0)));
// r * v and its transpose, r given as columns.
const toPatient = (r, v) => add(add(scale(r[0], v[0]), scale(r[1], v[1])), scale(r[2], v[2]));
const fromPatient = (r, v) => [dot(r[0], v), dot(r[1], v), dot(r[2], v)];

// front_full_view(bounds, axes, aspect): the patient's front for a volume whose axes (columns, in
// patient LPS space) the server's ready message names.
export function frontFullViewOf(bounds, axes, aspect, projection = Projection.perspective) {
  const r = frameRotation(axes ?? IDENTITY);
  if (isIdentity(r)) return frontFullView(bounds, aspect, projection);
  const centre = boxCenter(bounds);
  const patient = { min: [Infinity, Infinity, Infinity], max: [-Infinity, -Infinity, -Infinity] };
  for (let i = 0; i < 8; ++i) {
    const corner = [0, 1, 2].map((a) => ((i >> a) & 1 ? bounds.max[a] : bounds.min[a]));
    const p = toPatient(r, sub(corner, centre));
    for (let a = 0; a < 3; ++a) {
      patient.min[a] = Math.min(patient.min[a], p[a]);
      patient.max[a] = Math.max(patient.max[a], p[a]);
    }
  }
  const p = frontFullView(patient, aspect, projection);
  const pc = boxCenter(patient);
  const c = copyCamera(p);
  c.target = add(centre, fromPatient(r, sub(p.target, pc)));
  c.eye = add(centre, fromPatient(r, sub(p.eye, pc)));
  c.up = fromPatient(r, p.up);
  return fitDepthRange(c, bounds);
}

export function viewCamera(bounds, width, height, yaw, pitch, zoomFactor, axes = IDENTITY) {
  const aspect = f(f(width) / f(height));
  let cam = frontFullViewOf(bounds, axes, aspect);
  cam = orbit(cam, yaw, pitch);
  cam = zoom(cam, zoomFactor);
  cam = fitDepthRange(cam, bounds);
  return { camera: cam, frustum: frustum(cam, aspect) };
}

// glm::lookAt (right-handed).
export function viewMatrix(c) {
  const up = validUp(sub(c.target, c.eye), c.up);
  const fw = normalize(sub(c.target, c.eye));
  const s = normalize(cross(fw, up));
  const u = cross(s, fw);
  const m = new Float32Array(16);
  m[0] = s[0]; m[4] = s[1]; m[8] = s[2];
  m[1] = u[0]; m[5] = u[1]; m[9] = u[2];
  m[2] = -fw[0]; m[6] = -fw[1]; m[10] = -fw[2];
  m[12] = -dot(s, c.eye); m[13] = -dot(u, c.eye); m[14] = dot(fw, c.eye);
  m[15] = 1;
  return m;
}

// Frustum::matrix: glm::frustum or glm::ortho (right-handed, depth -1..1).
export function projectionMatrix(fr) {
  const m = new Float32Array(16);
  const { left: l, right: r, bottom: b, top: t, near_z: n, far_z: fa } = fr;
  if (fr.projection === Projection.perspective) {
    m[0] = f(f(2 * n) / f(r - l));
    m[5] = f(f(2 * n) / f(t - b));
    m[8] = f(f(r + l) / f(r - l));
    m[9] = f(f(t + b) / f(t - b));
    m[10] = f(-f(fa + n) / f(fa - n));
    m[11] = -1;
    m[14] = f(-f(f(2 * fa) * n) / f(fa - n));
  } else {
    m[0] = f(2 / f(r - l));
    m[5] = f(2 / f(t - b));
    m[10] = f(-2 / f(fa - n));
    m[12] = f(-f(r + l) / f(r - l));
    m[13] = f(-f(t + b) / f(t - b));
    m[14] = f(-f(fa + n) / f(fa - n));
    m[15] = 1;
  }
  return m;
}

// transpose(inverse(mat3(view))), column-major 9 floats.
export function normalMatrix(view) {
  const a = [view[0], view[1], view[2], view[4], view[5], view[6], view[8], view[9], view[10]];
  // a[c*3 + r]: column c, row r.
  const m = (r, c) => a[c * 3 + r];
  const det = m(0, 0) * (m(1, 1) * m(2, 2) - m(2, 1) * m(1, 2)) -
    m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0)) +
    m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
  const inv = (r, c) => {
    // cofactor(c, r) / det gives inverse(r, c).
    const rows = [0, 1, 2].filter((i) => i !== c), cols = [0, 1, 2].filter((i) => i !== r);
    const minor = m(rows[0], cols[0]) * m(rows[1], cols[1]) - m(rows[0], cols[1]) * m(rows[1], cols[0]);
    return ((r + c) % 2 ? -minor : minor) / det;
  };
  const out = new Float32Array(9);
  // transpose(inverse): out(r, c) = inverse(c, r).
  for (let c = 0; c < 3; ++c) for (let r = 0; r < 3; ++r) out[c * 3 + r] = inv(c, r);
  return out;
}

const kMaxReach = 1e9;
const kMinSeparation = 1e-4;
const fmt = (v) => String(Number(v.toPrecision(6)));

export function eyeTargetProblem(eye, target) {
  if (!isFiniteVec(eye) || !isFiniteVec(target)) return 'the eye or the target is not a finite point';
  const len = (v) => Math.hypot(v[0], v[1], v[2]);
  const scl = Math.max(1, length(eye), length(target));
  const apart = len([eye[0] - target[0], eye[1] - target[1], eye[2] - target[2]]);
  if (apart < kMinSeparation * scl)
    return apart === 0 ? 'the eye and the target are the same point'
      : `the eye and the target are ${fmt(apart)} apart; expected at least ${fmt(kMinSeparation * scl)} at this distance from the origin`;
  return '';
}

// Why the camera cannot be drawn, or '' (camera_problem).
export function cameraProblem(c) {
  if (!isFiniteVec(c.up) || !Number.isFinite(c.fovy_deg) || !Number.isFinite(c.ortho_height))
    return 'the view is not finite';
  const p = eyeTargetProblem(c.eye, c.target);
  if (p) return p;
  const reach = Math.max(length(c.eye), length(c.target));
  if (reach > kMaxReach) return `the view would be ${fmt(reach)} from the origin; expected at most ${fmt(kMaxReach)}`;
  const scl = Math.max(1, length(c.target));
  if (c.projection === Projection.orthographic &&
      (c.ortho_height < kMinSeparation * scl || c.ortho_height > kMaxReach))
    return `the view would be ${fmt(c.ortho_height)} high; expected ${fmt(kMinSeparation * scl)} to ${fmt(kMaxReach)}`;
  return '';
}
