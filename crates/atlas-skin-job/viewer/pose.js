// The pose: sampled animations, world matrices with the user's joint rotations, the
// skinning palette, the skin's joint tree and the rest pose's bounds.

// The node's own transform before the user's rotation: its matrix or its (animated) T R S.
const baseTransform = (node) => node.matrix || mat4.fromTrs(node.pose.t, node.pose.r, node.pose.s);

// local = (matrix | T R S) * R_user, R_user = Rz Ry Rx of the joint's slider angles (degrees).
function updateWorld(scene) {
  for (const i of scene.order) {
    const node = scene.nodes[i];
    const base = baseTransform(node);
    let local = base;
    if (node.user[0] || node.user[1] || node.user[2]) {
      local = mat4.multiply(base, mat4.fromTrs([0, 0, 0], quat.fromEulerDegrees(node.user), [1, 1, 1]));
    }
    node.world = node.parent >= 0 ? mat4.multiply(scene.nodes[node.parent].world, local) : local;
  }
}

// The value of an animation channel at `time` (seconds), held before the first key and
// after the last.
function sampleChannel(channel, time) {
  const { times, values, width, interpolation, path } = channel;
  const cubic = interpolation === 'CUBICSPLINE';
  const stride = cubic ? 3 * width : width;
  const value = (k, part = 1) => Array.from(values.subarray(k * stride + (cubic ? part * width : 0), k * stride + (cubic ? part * width : 0) + width));
  const last = times.length - 1;
  if (time <= times[0] || last === 0) return value(0);
  if (time >= times[last]) return value(last);
  let lo = 0;
  let hi = last;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (times[mid] <= time) lo = mid;
    else hi = mid;
  }
  const dt = times[hi] - times[lo];
  const t = dt > 0 ? (time - times[lo]) / dt : 0;
  if (interpolation === 'STEP') return value(lo);
  if (cubic) {
    // Hermite spline (glTF 2.0 Appendix C): in-tangent a, value v, out-tangent b per key.
    const t2 = t * t;
    const t3 = t2 * t;
    const v0 = value(lo, 1);
    const b0 = value(lo, 2);
    const v1 = value(hi, 1);
    const a1 = value(hi, 0);
    const out = v0.map((_, c) => (2 * t3 - 3 * t2 + 1) * v0[c] + (t3 - 2 * t2 + t) * dt * b0[c] + (-2 * t3 + 3 * t2) * v1[c] + (t3 - t2) * dt * a1[c]);
    return path === 'rotation' ? quat.normalize(out) : out;
  }
  const a = value(lo);
  const b = value(hi);
  return path === 'rotation' ? quat.slerp(a, b, t) : a.map((x, c) => x + (b[c] - x) * t);
}

// Every node's T R S: its rest values, overridden by the animation's channels at `time`.
function applyAnimation(scene, animation, time) {
  scene.nodes.forEach((node) => (node.pose = { t: node.rest.t, r: node.rest.r, s: node.rest.s }));
  if (!animation) return;
  for (const channel of animation.channels) {
    const node = scene.nodes[channel.node];
    if (node) node.pose[channel.path[0]] = sampleChannel(channel, time);
  }
}

// Palette rows (see skinning.glsl): M_j, its dual quaternion and its column lengths.
function updatePalette(scene, skin) {
  skin.joints.forEach((nodeIndex, j) => {
    const m = mat4.multiply(scene.nodes[nodeIndex].world, skin.inverseBind(j));
    const scale = mat4.columnLengths(m);
    const real = quat.fromMatrix(m, scale);
    const dual = quat.multiply([m[12], m[13], m[14], 0], real).map((x) => 0.5 * x);
    const row = skin.palette.subarray(j * 28, j * 28 + 28);
    row.set(m, 0);
    row.set(real, 16);
    row.set(dual, 20);
    row.set([scale[0], scale[1], scale[2], 0], 24);
  });
}

// The skin's joint tree: each joint's parent joint (-1 for a root), its child joints and the
// bones [joint, parent].
function jointTree(scene, skin) {
  const parentJoint = skin.joints.map((n) => skin.joints.indexOf(scene.nodes[n].parent));
  const bones = parentJoint.map((p, j) => [j, p]).filter(([, p]) => p >= 0);
  const childJoints = parentJoint.map(() => []);
  bones.forEach(([j, p]) => childJoints[p].push(j));
  return { parentJoint, bones, childJoints };
}

// Bounds {lo, hi} of every mesh in the rest pose, skinned on the CPU (linear blend skinning).
function restPoseBounds(scene, items) {
  updateWorld(scene);
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (const item of items) {
    updatePalette(scene, item.skin);
    for (let v = 0; v < item.vertexCount; v++) {
      const p = [0, 0, 0];
      const position = item.positions.subarray(v * 3, v * 3 + 3);
      for (let k = 0; k < 4; k++) {
        const w = item.weights0 ? item.weights0[v * 4 + k] : k === 0 ? 1 : 0;
        if (w <= 0) continue;
        const j = item.weights0 ? item.joints0[v * 4 + k] : 0;
        const q = mat4.transformPoint(item.skin.palette.subarray(j * 28, j * 28 + 16), position);
        for (let c = 0; c < 3; c++) p[c] += w * q[c];
      }
      for (let c = 0; c < 3; c++) {
        lo[c] = Math.min(lo[c], p[c]);
        hi[c] = Math.max(hi[c], p[c]);
      }
    }
  }
  return { lo, hi };
}
