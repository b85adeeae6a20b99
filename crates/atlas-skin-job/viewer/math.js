// Small column-major 4x4 matrix, 3-vector and quaternion (x, y, z, w) math.

const mat4 = {
  identity: () => new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]),
  multiply(a, b, out = new Float32Array(16)) {
    for (let c = 0; c < 4; c++) {
      for (let r = 0; r < 4; r++) {
        out[c * 4 + r] = a[r] * b[c * 4] + a[4 + r] * b[c * 4 + 1] + a[8 + r] * b[c * 4 + 2] + a[12 + r] * b[c * 4 + 3];
      }
    }
    return out;
  },
  fromTrs(t, q, s) {
    const [x, y, z, w] = q;
    return new Float32Array([
      (1 - 2 * (y * y + z * z)) * s[0], 2 * (x * y + z * w) * s[0], 2 * (x * z - y * w) * s[0], 0,
      2 * (x * y - z * w) * s[1], (1 - 2 * (x * x + z * z)) * s[1], 2 * (y * z + x * w) * s[1], 0,
      2 * (x * z + y * w) * s[2], 2 * (y * z - x * w) * s[2], (1 - 2 * (x * x + y * y)) * s[2], 0,
      t[0], t[1], t[2], 1,
    ]);
  },
  perspective(fovY, aspect, near, far) {
    const f = 1 / Math.tan(fovY / 2);
    const m = new Float32Array(16);
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (far + near) / (near - far);
    m[11] = -1;
    m[14] = (2 * far * near) / (near - far);
    return m;
  },
  lookAt(eye, target, up) {
    const z = vec3.normalize(vec3.sub(eye, target));
    const x = vec3.normalize(vec3.cross(up, z));
    const y = vec3.cross(z, x);
    return new Float32Array([
      x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -vec3.dot(x, eye), -vec3.dot(y, eye), -vec3.dot(z, eye), 1,
    ]);
  },
  columnLengths: (m) => [0, 1, 2].map((c) => Math.hypot(m[c * 4], m[c * 4 + 1], m[c * 4 + 2]) || 1),
  transformPoint: (m, p) => [
    m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12],
    m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13],
    m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14],
  ],
};
const vec3 = {
  sub: (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]],
  dot: (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2],
  cross: (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]],
  normalize(a) {
    const l = Math.hypot(a[0], a[1], a[2]) || 1;
    return [a[0] / l, a[1] / l, a[2] / l];
  },
};
const quat = {
  multiply: (a, b) => [
    a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
    a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
    a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
    a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
  ],
  normalize(q) {
    const l = Math.hypot(q[0], q[1], q[2], q[3]) || 1;
    return [q[0] / l, q[1] / l, q[2] / l, q[3] / l];
  },
  axisAngle(axis, radians) {
    const s = Math.sin(radians / 2);
    return [axis[0] * s, axis[1] * s, axis[2] * s, Math.cos(radians / 2)];
  },
  conjugate: (q) => [-q[0], -q[1], -q[2], q[3]],
  // v rotated by the unit quaternion q = (u, w): v + w t + u × t with t = 2 u × v.
  rotate(q, v) {
    const u = [q[0], q[1], q[2]];
    const t = vec3.cross(u, v).map((c) => 2 * c);
    const ut = vec3.cross(u, t);
    return [0, 1, 2].map((c) => v[c] + q[3] * t[c] + ut[c]);
  },
  // The joint sliders' angles [x, y, z] (degrees) as the rotation Rz(z) Ry(y) Rx(x).
  fromEulerDegrees(degrees) {
    const toRad = Math.PI / 180;
    return [[0, 0, 1], [0, 1, 0], [1, 0, 0]]
      .map((axis, k) => quat.axisAngle(axis, degrees[2 - k] * toRad))
      .reduce((a, b) => quat.multiply(a, b));
  },
  // Inverse of fromEulerDegrees: with R = Rz(z) Ry(y) Rx(x), R20 = -sin y, R21 / R22 = tan x
  // and R10 / R00 = tan z; at y = ±90° only x ∓ z is defined: z = 0, x = atan2(-R12, R11).
  // Angles in (-180°, 180°], y in [-90°, 90°].
  toEulerDegrees(q) {
    const [x, y, z, w] = q;
    const toDeg = 180 / Math.PI;
    const sinY = Math.max(-1, Math.min(1, -2 * (x * z - y * w)));
    if (Math.abs(sinY) > 1 - 1e-9) {
      return [Math.atan2(-2 * (y * z - x * w), 1 - 2 * (x * x + z * z)) * toDeg, Math.asin(sinY) * toDeg, 0];
    }
    return [
      Math.atan2(2 * (y * z + x * w), 1 - 2 * (x * x + y * y)) * toDeg,
      Math.asin(sinY) * toDeg,
      Math.atan2(2 * (x * y + z * w), 1 - 2 * (y * y + z * z)) * toDeg,
    ];
  },
  slerp(a, b, t) {
    let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    const sign = d < 0 ? -1 : 1;
    d = Math.abs(d);
    let wa = 1 - t;
    let wb = t;
    if (d < 0.9995) {
      const angle = Math.acos(d);
      wa = Math.sin(wa * angle) / Math.sin(angle);
      wb = Math.sin(wb * angle) / Math.sin(angle);
    }
    wb *= sign;
    return quat.normalize([0, 1, 2, 3].map((i) => wa * a[i] + wb * b[i]));
  },
  // Rotation part of a column-major 4x4 whose 3x3 columns have lengths `scale`.
  fromMatrix(m, scale) {
    const e = (r, c) => m[c * 4 + r] / scale[c];
    const trace = e(0, 0) + e(1, 1) + e(2, 2);
    let q;
    if (trace > 0) {
      const s = 0.5 / Math.sqrt(trace + 1);
      q = [(e(2, 1) - e(1, 2)) * s, (e(0, 2) - e(2, 0)) * s, (e(1, 0) - e(0, 1)) * s, 0.25 / s];
    } else if (e(0, 0) > e(1, 1) && e(0, 0) > e(2, 2)) {
      const s = 2 * Math.sqrt(1 + e(0, 0) - e(1, 1) - e(2, 2));
      q = [0.25 * s, (e(0, 1) + e(1, 0)) / s, (e(0, 2) + e(2, 0)) / s, (e(2, 1) - e(1, 2)) / s];
    } else if (e(1, 1) > e(2, 2)) {
      const s = 2 * Math.sqrt(1 + e(1, 1) - e(0, 0) - e(2, 2));
      q = [(e(0, 1) + e(1, 0)) / s, 0.25 * s, (e(1, 2) + e(2, 1)) / s, (e(0, 2) - e(2, 0)) / s];
    } else {
      const s = 2 * Math.sqrt(1 + e(2, 2) - e(0, 0) - e(1, 1));
      q = [(e(0, 2) + e(2, 0)) / s, (e(1, 2) + e(2, 1)) / s, 0.25 * s, (e(1, 0) - e(0, 1)) / s];
    }
    return quat.normalize(q);
  },
};
