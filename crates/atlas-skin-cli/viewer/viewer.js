// atlas-skin report viewer: a small WebGL2 viewer of one skinned glTF binary embedded in the
// page (base64), with the skinning report JSON beside it. No network access, no libraries.
//
// Report keys read (all optional): decomposition.joints[] {name, status, reason, perimeter,
// diameter, overlap*, point [x,y,z], normal [x,y,z], curve [[x,y,z], ...] (bind space)},
// decomposition.regions[] {joint, joints: [name...]}, decomposition.vertex_regions (region
// index or null per vertex of the main skinned mesh, glTF vertex order; otherwise, and for
// null, a vertex takes the region of its dominant joint), timings_ms {stage: ms}, warnings [...], counts {...} and any
// other top-level scalar.
'use strict';
(() => {
  const $ = (id) => document.getElementById(id);
  const hook = (window.atlasViewer = { ready: false, error: null });

  // ---------- small column-major 4x4 / quaternion (x, y, z, w) math ----------
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

  // ---------- glTF binary ----------
  function decodeBase64(text) {
    const raw = atob(text.trim());
    const bytes = new Uint8Array(raw.length);
    for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
    return bytes;
  }

  function parseGlb(bytes) {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    if (bytes.length < 20 || view.getUint32(0, true) !== 0x46546c67) throw new Error('the embedded model is not a glTF binary');
    let json = null;
    let bin = null;
    for (let offset = 12; offset + 8 <= bytes.length; ) {
      const length = view.getUint32(offset, true);
      const type = view.getUint32(offset + 4, true);
      const chunk = bytes.subarray(offset + 8, offset + 8 + length);
      if (type === 0x4e4f534a) json = JSON.parse(new TextDecoder().decode(chunk));
      else if (type === 0x004e4942) bin = chunk;
      offset += 8 + length;
    }
    if (!json) throw new Error('the glTF binary has no JSON chunk');
    const buffers = (json.buffers || []).map((buffer, i) => {
      if (buffer.uri === undefined && i === 0 && bin) return bin;
      if (typeof buffer.uri === 'string' && buffer.uri.startsWith('data:')) return decodeBase64(buffer.uri.slice(buffer.uri.indexOf(',') + 1));
      throw new Error(`buffer ${i} is not embedded (external files are not read)`);
    });
    return { json, buffers };
  }

  const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };
  const COMPONENT_TYPES = {
    5120: ['getInt8', 1, 127], 5121: ['getUint8', 1, 255], 5122: ['getInt16', 2, 32767],
    5123: ['getUint16', 2, 65535], 5125: ['getUint32', 4, 0], 5126: ['getFloat32', 4, 0],
  };

  // Reads accessor `index` into a flat Float32Array (normalised integers mapped to [0, 1] or
  // [-1, 1]) or, with `integers`, a Uint32Array. Handles byteStride and sparse accessors.
  function readAccessor(gltf, index, integers = false) {
    const accessor = gltf.json.accessors[index];
    const width = COMPONENTS[accessor.type];
    const [getter, size, maxInt] = COMPONENT_TYPES[accessor.componentType] || [];
    if (!width || !getter) throw new Error(`accessor ${index} has an unsupported type`);
    // Normalised integers: c / max, clamped at -1 for signed types (glTF 2.0 §3.11).
    const convert = accessor.normalized && maxInt && !integers ? (c) => Math.max(c / maxInt, -1) : (c) => c;
    const out = integers ? new Uint32Array(accessor.count * width) : new Float32Array(accessor.count * width);
    const readInto = (viewIndex, byteOffset, count, componentGetter, componentSize, stride, write) => {
      const bufferView = gltf.json.bufferViews[viewIndex];
      const bytes = gltf.buffers[bufferView.buffer];
      const view = new DataView(bytes.buffer, bytes.byteOffset + (bufferView.byteOffset || 0) + byteOffset);
      for (let i = 0; i < count; i++) write(i, (c) => view[componentGetter](i * stride + c * componentSize, true));
    };
    if (accessor.bufferView !== undefined) {
      const stride = gltf.json.bufferViews[accessor.bufferView].byteStride || width * size;
      readInto(accessor.bufferView, accessor.byteOffset || 0, accessor.count, getter, size, stride, (i, get) => {
        for (let c = 0; c < width; c++) out[i * width + c] = convert(get(c));
      });
    }
    if (accessor.sparse) {
      const { count, indices, values } = accessor.sparse;
      const [indexGetter, indexSize] = COMPONENT_TYPES[indices.componentType];
      const targets = [];
      readInto(indices.bufferView, indices.byteOffset || 0, count, indexGetter, indexSize, indexSize, (i, get) => targets.push(get(0)));
      readInto(values.bufferView, values.byteOffset || 0, count, getter, size, width * size, (i, get) => {
        for (let c = 0; c < width; c++) out[targets[i] * width + c] = convert(get(c));
      });
    }
    return out;
  }

  // ---------- scene graph and pose ----------
  function buildScene(gltf) {
    const nodes = (gltf.json.nodes || []).map((node, i) => ({
      name: node.name || `node ${i}`,
      children: node.children || [],
      matrix: node.matrix ? new Float32Array(node.matrix) : null,
      rest: { t: node.translation || [0, 0, 0], r: node.rotation || [0, 0, 0, 1], s: node.scale || [1, 1, 1] },
      parent: -1,
      user: [0, 0, 0],
      world: mat4.identity(),
    }));
    nodes.forEach((node, i) => node.children.forEach((c) => (nodes[c].parent = i)));
    const scenes = gltf.json.scenes || [];
    const scene = scenes[gltf.json.scene || 0];
    const roots = scene ? scene.nodes || [] : nodes.map((n, i) => i).filter((i) => nodes[i].parent < 0);
    const order = [];
    const visit = (i) => {
      order.push(i);
      nodes[i].children.forEach(visit);
    };
    roots.forEach(visit);
    nodes.forEach((node) => (node.pose = { t: node.rest.t, r: node.rest.r, s: node.rest.s }));
    return { nodes, order };
  }

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

  // ---------- animations (LINEAR, STEP, CUBICSPLINE) ----------
  function readAnimations(gltf) {
    return (gltf.json.animations || []).map((animation, a) => {
      const channels = [];
      for (const channel of animation.channels || []) {
        const { node, path } = channel.target || {};
        const sampler = (animation.samplers || [])[channel.sampler];
        if (node === undefined || !['translation', 'rotation', 'scale'].includes(path) || !sampler) continue;
        const times = readAccessor(gltf, sampler.input);
        if (!times.length) continue;
        channels.push({
          node, path, times, values: readAccessor(gltf, sampler.output),
          width: path === 'rotation' ? 4 : 3, interpolation: sampler.interpolation || 'LINEAR',
        });
      }
      const duration = channels.reduce((d, c) => Math.max(d, c.times[c.times.length - 1] || 0), 0);
      return { name: animation.name || `animation ${a}`, channels, duration };
    });
  }

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

  function applyAnimation(scene, animation, time) {
    scene.nodes.forEach((node) => (node.pose = { t: node.rest.t, r: node.rest.r, s: node.rest.s }));
    if (!animation) return;
    for (const channel of animation.channels) {
      const node = scene.nodes[channel.node];
      if (node) node.pose[channel.path[0]] = sampleChannel(channel, time);
    }
  }

  // ---------- meshes and skins ----------
  function readSkins(gltf) {
    return (gltf.json.skins || []).map((skin) => {
      const count = skin.joints.length;
      const inverseBind = skin.inverseBindMatrices !== undefined ? readAccessor(gltf, skin.inverseBindMatrices) : null;
      return {
        joints: skin.joints,
        inverseBind: (j) => (inverseBind ? inverseBind.subarray(j * 16, j * 16 + 16) : mat4.identity()),
        palette: new Float32Array(count * 7 * 4),
      };
    });
  }

  function smoothNormals(positions, indices) {
    const normals = new Float32Array(positions.length);
    for (let f = 0; f < indices.length; f += 3) {
      const p = [0, 1, 2].map((k) => Array.from(positions.subarray(indices[f + k] * 3, indices[f + k] * 3 + 3)));
      const n = vec3.cross(vec3.sub(p[1], p[0]), vec3.sub(p[2], p[0]));
      for (let k = 0; k < 3; k++) for (let c = 0; c < 3; c++) normals[indices[f + k] * 3 + c] += n[c];
    }
    for (let v = 0; v < normals.length; v += 3) normals.set(vec3.normalize(Array.from(normals.subarray(v, v + 3))), v);
    return normals;
  }

  // Normalised influences: renderers divide by the sum (some files store sums below 1).
  function normaliseWeights(weights0, weights1) {
    const count = weights0.length / 4;
    for (let v = 0; v < count; v++) {
      let sum = 0;
      for (let k = 0; k < 4; k++) sum += weights0[v * 4 + k] + (weights1 ? weights1[v * 4 + k] : 0);
      if (sum <= 0) continue;
      for (let k = 0; k < 4; k++) {
        weights0[v * 4 + k] /= sum;
        if (weights1) weights1[v * 4 + k] /= sum;
      }
    }
  }

  function readPrimitives(gltf, scene, skins) {
    const items = [];
    for (const nodeIndex of scene.order) {
      const node = gltf.json.nodes[nodeIndex];
      if (node.mesh === undefined) continue;
      // An unskinned mesh follows its node: a one-joint skin with the node as the joint.
      const skin = node.skin !== undefined ? skins[node.skin] : { joints: [nodeIndex], inverseBind: () => mat4.identity(), palette: new Float32Array(28), rigid: true };
      for (const primitive of gltf.json.meshes[node.mesh].primitives) {
        const attributes = primitive.attributes;
        if ((primitive.mode !== undefined && primitive.mode !== 4) || attributes.POSITION === undefined) continue;
        const positions = readAccessor(gltf, attributes.POSITION);
        const vertexCount = positions.length / 3;
        const indices = primitive.indices !== undefined ? readAccessor(gltf, primitive.indices, true) : Uint32Array.from({ length: vertexCount }, (_, i) => i);
        const item = {
          skin, positions, indices, vertexCount,
          normals: attributes.NORMAL !== undefined ? readAccessor(gltf, attributes.NORMAL) : smoothNormals(positions, indices),
        };
        if (!skin.rigid && attributes.JOINTS_0 !== undefined && attributes.WEIGHTS_0 !== undefined) {
          item.joints0 = readAccessor(gltf, attributes.JOINTS_0, true);
          item.weights0 = readAccessor(gltf, attributes.WEIGHTS_0);
          if (attributes.JOINTS_1 !== undefined && attributes.WEIGHTS_1 !== undefined) {
            item.joints1 = readAccessor(gltf, attributes.JOINTS_1, true);
            item.weights1 = readAccessor(gltf, attributes.WEIGHTS_1);
          }
          for (const [set, joints, weights] of [[0, item.joints0, item.weights0], [1, item.joints1, item.weights1]]) {
            if (!joints) continue;
            if (joints.length !== vertexCount * 4 || weights.length !== vertexCount * 4) throw new Error(`mesh ${node.mesh}: JOINTS_${set}/WEIGHTS_${set} do not match POSITION`);
            const bad = joints.find((j) => j >= skin.joints.length);
            if (bad !== undefined) throw new Error(`mesh ${node.mesh} uses joint ${bad} but its skin has ${skin.joints.length} joints`);
          }
          normaliseWeights(item.weights0, item.weights1);
        }
        items.push(item);
      }
    }
    return items;
  }

  // Skin joint with the largest weight at each vertex (0 for rigid meshes).
  function dominantJoints(item) {
    const dominant = new Uint32Array(item.vertexCount);
    if (!item.weights0) return dominant;
    for (let v = 0; v < item.vertexCount; v++) {
      let best = -1;
      for (const [joints, weights] of [[item.joints0, item.weights0], [item.joints1, item.weights1]]) {
        if (!weights) continue;
        for (let k = 0; k < 4; k++) {
          if (weights[v * 4 + k] > best) {
            best = weights[v * 4 + k];
            dominant[v] = joints[v * 4 + k];
          }
        }
      }
    }
    return dominant;
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

  // ---------- report ----------
  function readReport() {
    const element = $('report-json');
    const text = element ? element.textContent.trim() : '';
    return text ? JSON.parse(text) : null;
  }

  const regionHue = (k) => (k * 0.618034) % 1;
  function hslToRgb(h, s, l) {
    const f = (n) => {
      const k = (n + h * 12) % 12;
      return l - s * Math.min(l, 1 - l) * Math.max(-1, Math.min(k - 3, 9 - k, 1));
    };
    return [f(0), f(8), f(4)];
  }

  // Region of each skin joint: the report's regions (by joint name) when present, inherited
  // from the nearest ancestor in a region; without a report every joint is its own region.
  function regionOfJoints(scene, skin, report) {
    const regions = (report && report.decomposition && report.decomposition.regions) || [];
    const jointByName = new Map(skin.joints.map((n, j) => [scene.nodes[n].name, j]));
    const jointOfNode = new Map(skin.joints.map((n, j) => [n, j]));
    const region = new Int32Array(skin.joints.length).fill(-1);
    regions.forEach((r, k) => {
      const members = Array.isArray(r.joints) ? r.joints : r.joint !== undefined ? [r.joint] : [];
      for (const m of members) {
        const j = typeof m === 'number' ? m : jointByName.get(m);
        if (j !== undefined && j < region.length && region[j] < 0) region[j] = k;
      }
    });
    if (!regions.length) return region.map((_, j) => j);
    return region.map((r, j) => {
      for (let n = skin.joints[j]; r < 0 && n >= 0; n = scene.nodes[n].parent) {
        const ancestor = jointOfNode.get(n);
        if (ancestor !== undefined && region[ancestor] >= 0) r = region[ancestor];
      }
      return r < 0 ? regions.length + j : r;
    });
  }

  // Boundaries as closed polylines in bind space: `cuts` from decomposition.joints[].curve,
  // `planes` a circle of the boundary's diameter in its plane (point, normal) for a joint
  // with a plane but no curve (a soft boundary).
  function boundaryCurves(report) {
    const joints = (report && report.decomposition && report.decomposition.joints) || [];
    const isVec3 = (v) => Array.isArray(v) && v.length === 3 && v.every(Number.isFinite);
    const cuts = [];
    const planes = [];
    for (const joint of joints) {
      if (Array.isArray(joint.curve) && joint.curve.length > 1 && joint.curve.every(isVec3)) {
        cuts.push(joint.curve);
      } else if (isVec3(joint.point) && isVec3(joint.normal) && Number.isFinite(joint.diameter)) {
        const n = vec3.normalize(joint.normal);
        const u = vec3.normalize(vec3.cross(n, Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0]));
        const w = vec3.cross(n, u);
        const radius = joint.diameter / 2;
        planes.push(Array.from({ length: 48 }, (_, k) => {
          const a = (2 * Math.PI * k) / 48;
          return [0, 1, 2].map((c) => joint.point[c] + radius * (Math.cos(a) * u[c] + Math.sin(a) * w[c]));
        }));
      }
    }
    return { cuts, planes };
  }

  // Line segments of the curves; each point takes the influences of the nearest mesh vertex
  // (bind space) so the curves follow the skinned surface.
  function curveGeometry(curves, item) {
    const segments = curves.reduce((s, c) => s + c.length, 0);
    const positions = new Float32Array(segments * 6);
    const joints0 = new Uint32Array(segments * 8);
    const weights0 = new Float32Array(segments * 8);
    let s = 0;
    const emit = (p) => {
      let best = 0;
      let bestDistance = Infinity;
      for (let v = 0; v < item.vertexCount; v++) {
        const dx = item.positions[v * 3] - p[0];
        const dy = item.positions[v * 3 + 1] - p[1];
        const dz = item.positions[v * 3 + 2] - p[2];
        const d = dx * dx + dy * dy + dz * dz;
        if (d < bestDistance) {
          bestDistance = d;
          best = v;
        }
      }
      positions.set(p, s * 3);
      if (item.weights0) {
        joints0.set(item.joints0.subarray(best * 4, best * 4 + 4), s * 4);
        weights0.set(item.weights0.subarray(best * 4, best * 4 + 4), s * 4);
      } else {
        weights0[s * 4] = 1;
      }
      s++;
    };
    for (const curve of curves) {
      curve.forEach((p, k) => {
        emit(p);
        emit(curve[(k + 1) % curve.length]);
      });
    }
    return { positions, joints0, weights0, count: s };
  }

  function formatValue(value) {
    if (typeof value === 'number') return Number.isInteger(value) ? String(value) : value.toPrecision(4);
    if (Array.isArray(value)) return value.map(formatValue).join(', ');
    if (value && typeof value === 'object') return JSON.stringify(value);
    return value === undefined || value === null ? '' : String(value);
  }

  function element(tag, text, className) {
    const e = document.createElement(tag);
    if (text !== undefined) e.textContent = text;
    if (className) e.className = className;
    return e;
  }

  // A table of objects: `preferred` columns first, then any other key whose values are
  // scalars or lists of names (vectors and curves are left out).
  function objectTable(rows, preferred, onRowClick) {
    const shown = (v) => v === null || typeof v !== 'object' || (Array.isArray(v) && v.every((x) => typeof x === 'string'));
    const columns = [];
    for (const row of rows) {
      for (const [key, value] of Object.entries(row || {})) {
        if (!columns.includes(key) && shown(value)) columns.push(key);
      }
    }
    columns.sort((a, b) => {
      const rank = (k) => {
        const i = preferred.findIndex((p) => k === p || k.startsWith(p));
        return i < 0 ? preferred.length : i;
      };
      return rank(a) - rank(b);
    });
    const wrapper = element('div', undefined, 'scroll');
    const table = wrapper.appendChild(element('table'));
    const head = table.appendChild(element('tr'));
    columns.forEach((c) => head.appendChild(element('th', c)));
    for (const row of rows) {
      const tr = table.appendChild(element('tr', undefined, row && row.status ? `status-${String(row.status).toLowerCase()}` : ''));
      for (const c of columns) {
        // Long texts are cut to one line; the whole text shows on hover.
        const text = formatValue(row && row[c]);
        tr.appendChild(element('td', text)).title = text;
      }
      if (onRowClick) tr.addEventListener('click', () => onRowClick(row));
    }
    return wrapper;
  }

  function renderReport(report, selectJointByName) {
    const panel = $('report');
    if (!report) {
      panel.appendChild(element('p', 'No skinning report was given: the view shows the weights stored in the file.', 'note'));
      return;
    }
    const section = (title) => {
      panel.appendChild(element('h3', title));
      return panel;
    };
    const decomposition = report.decomposition || {};
    if (Array.isArray(decomposition.joints) && decomposition.joints.length) {
      section('Joints').appendChild(objectTable(decomposition.joints, ['name', 'status', 'perimeter', 'diameter', 'overlap', 'reason'], (row) => selectJointByName(row && row.name)));
    }
    if (Array.isArray(decomposition.regions) && decomposition.regions.length) {
      section('Regions').appendChild(objectTable(decomposition.regions, ['joint', 'joints', 'faces', 'vertices']));
    }
    const timings = report.timings_ms;
    if (timings && typeof timings === 'object') {
      const rows = Array.isArray(timings) ? timings : Object.entries(timings).map(([stage, ms]) => ({ stage, ms }));
      section('Stage timings (ms)').appendChild(objectTable(rows, ['stage', 'ms']));
    }
    const facts = Object.entries(report).filter(([, v]) => v === null || typeof v !== 'object');
    if (report.counts && typeof report.counts === 'object') facts.push(...Object.entries(report.counts));
    if (facts.length) section('Counts').appendChild(objectTable(facts.map(([key, value]) => ({ key, value })), ['key', 'value']));
    const warnings = Array.isArray(report.warnings) ? report.warnings : [];
    const list = section(`Warnings (${warnings.length})`).appendChild(element('ul'));
    warnings.forEach((w) => list.appendChild(element('li', typeof w === 'string' ? w : JSON.stringify(w))));
  }

  // ---------- WebGL ----------
  const ATTRIBUTES = ['a_position', 'a_normal', 'a_color', 'a_joints0', 'a_weights0', 'a_joints1', 'a_weights1'];

  // `feedback`: vertex outputs to capture with transform feedback (the test hook's probe).
  function compileProgram(gl, vertexId, fragmentId, feedback = null) {
    const source = (id) => $(id).textContent;
    const shader = (type, text) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`shader ${vertexId}/${fragmentId}: ${gl.getShaderInfoLog(s)}`);
      return s;
    };
    const program = gl.createProgram();
    gl.attachShader(program, shader(gl.VERTEX_SHADER, `#version 300 es\n${source('glsl-skinning')}\n${source(vertexId)}`));
    gl.attachShader(program, shader(gl.FRAGMENT_SHADER, `#version 300 es\n${source(fragmentId)}`));
    ATTRIBUTES.forEach((name, location) => gl.bindAttribLocation(program, location, name));
    if (feedback) gl.transformFeedbackVaryings(program, feedback, gl.INTERLEAVED_ATTRIBS);
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(`link: ${gl.getProgramInfoLog(program)}`);
    const uniforms = {};
    for (let i = 0; i < gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS); i++) {
      const name = gl.getActiveUniform(program, i).name;
      uniforms[name] = gl.getUniformLocation(program, name);
    }
    return { program, uniforms };
  }

  // A vertex array from named arrays; integer arrays (joints) use integer attributes.
  function createVertexArray(gl, arrays, indices) {
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const buffers = {};
    for (const [name, [data, width]] of Object.entries(arrays)) {
      if (!data) continue;
      const location = ATTRIBUTES.indexOf(name);
      const buffer = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.DYNAMIC_DRAW);
      gl.enableVertexAttribArray(location);
      if (data instanceof Uint32Array) gl.vertexAttribIPointer(location, width, gl.UNSIGNED_INT, 0, 0);
      else gl.vertexAttribPointer(location, width, gl.FLOAT, false, 0, 0);
      buffers[name] = buffer;
    }
    if (indices) {
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    }
    gl.bindVertexArray(null);
    return { vao, buffers };
  }

  function createPaletteTexture(gl, skin) {
    const texture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 7, skin.joints.length, 0, gl.RGBA, gl.FLOAT, skin.palette);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    return texture;
  }

  // ---------- the viewer ----------
  function start() {
    const report = readReport();
    const gltf = parseGlb(decodeBase64($('model-glb').textContent));
    const scene = buildScene(gltf);
    const skins = readSkins(gltf);
    const items = readPrimitives(gltf, scene, skins);
    if (!items.length) throw new Error('the model has no triangle mesh');
    const animations = readAnimations(gltf);
    const main = items.reduce((a, b) => (b.weights0 && (!a.weights0 || b.vertexCount > a.vertexCount) ? b : a));
    const mainSkin = main.skin;
    const jointNames = mainSkin.joints.map((n) => scene.nodes[n].name);

    const canvas = $('view');
    const gl = canvas.getContext('webgl2', { antialias: true });
    if (!gl) throw new Error('this browser has no WebGL2');
    const meshProgram = compileProgram(gl, 'glsl-mesh-vert', 'glsl-mesh-frag');
    const lineProgram = compileProgram(gl, 'glsl-line-vert', 'glsl-line-frag');

    const regionOf = regionOfJoints(scene, mainSkin, report);
    const vertexRegions = report && report.decomposition && report.decomposition.vertex_regions;
    const explicitRegions = Array.isArray(vertexRegions) && vertexRegions.length === main.vertexCount ? vertexRegions : null;
    const dominantCount = new Uint32Array(mainSkin.joints.length);
    for (const item of items) {
      const dominant = dominantJoints(item);
      const colors = new Float32Array(item.vertexCount * 3);
      for (let v = 0; v < item.vertexCount; v++) {
        const explicit = item === main && explicitRegions ? explicitRegions[v] : null;
        const region = Number.isInteger(explicit) ? explicit : item.skin === mainSkin ? regionOf[dominant[v]] : 0;
        if (item.skin === mainSkin) dominantCount[dominant[v]]++;
        colors.set(hslToRgb(regionHue(region), 0.55, 0.6), v * 3);
      }
      item.gpu = createVertexArray(gl, {
        a_position: [item.positions, 3], a_normal: [item.normals, 3], a_color: [colors, 3],
        a_joints0: [item.joints0, 4], a_weights0: [item.weights0, 4], a_joints1: [item.joints1, 4], a_weights1: [item.weights1, 4],
      }, item.indices);
    }
    const textures = new Map();
    for (const item of items) if (!textures.has(item.skin)) textures.set(item.skin, createPaletteTexture(gl, item.skin));

    const boundaries = boundaryCurves(report);
    const curves = curveGeometry([...boundaries.cuts, ...boundaries.planes], main);
    const cutVertices = 2 * boundaries.cuts.reduce((n, c) => n + c.length, 0);
    const curveGpu = createVertexArray(gl, { a_position: [curves.positions, 3], a_joints0: [curves.joints0, 4], a_weights0: [curves.weights0, 4] });
    // Skin joint of each joint's parent node (-1 for a root) and the bones (joint, parent).
    const parentJoint = mainSkin.joints.map((n) => mainSkin.joints.indexOf(scene.nodes[n].parent));
    const bones = parentJoint.map((p, j) => [j, p]).filter(([, p]) => p >= 0);
    const childJoints = parentJoint.map(() => []);
    bones.forEach(([j, p]) => childJoints[p].push(j));
    const skeletonPoints = new Float32Array(mainSkin.joints.length * 3);
    const skeletonLines = new Float32Array(bones.length * 6);
    const skeletonGpu = createVertexArray(gl, { a_position: [skeletonLines, 3] });
    const pointGpu = createVertexArray(gl, { a_position: [skeletonPoints, 3] });

    // Camera framing the rest pose (CPU linear blend skinning of every mesh once).
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
    const camera = {
      target: lo.map((l, c) => (l + hi[c]) / 2),
      radius: Math.max(1e-6, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2),
      yaw: 0.5, pitch: 0.15, zoom: 1,
    };
    // Unit vector from the camera's target towards the eye.
    const viewDirection = () => [Math.cos(camera.pitch) * Math.sin(camera.yaw), Math.sin(camera.pitch), Math.cos(camera.pitch) * Math.cos(camera.yaw)];
    const state = { joint: 0, heat: false, dqs: false, skeleton: true, curves: true, animation: -1, time: 0, playing: false };
    let viewProjection = mat4.identity();

    function render() {
      const dpr = window.devicePixelRatio || 1;
      const width = Math.max(1, Math.round(canvas.clientWidth * dpr));
      const height = Math.max(1, Math.round(canvas.clientHeight * dpr));
      if (canvas.width !== width || canvas.height !== height) {
        canvas.width = width;
        canvas.height = height;
      }
      applyAnimation(scene, animations[state.animation], state.time);
      updateWorld(scene);
      gl.viewport(0, 0, width, height);
      gl.clearColor(0.13, 0.14, 0.16, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.enable(gl.DEPTH_TEST);

      const distance = (camera.radius / Math.tan(Math.PI / 8)) * camera.zoom;
      const direction = viewDirection();
      const eye = camera.target.map((t, c) => t + distance * direction[c]);
      const near = Math.max(distance - 4 * camera.radius, distance * 0.01);
      viewProjection = mat4.multiply(mat4.perspective(Math.PI / 4, width / height, near, distance + 4 * camera.radius), mat4.lookAt(eye, camera.target, [0, 1, 0]));

      for (const [skin, texture] of textures) {
        updatePalette(scene, skin);
        gl.bindTexture(gl.TEXTURE_2D, texture);
        gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 7, skin.joints.length, gl.RGBA, gl.FLOAT, skin.palette);
      }
      const setCommon = (p, skinned) => {
        gl.useProgram(p.program);
        gl.uniformMatrix4fv(p.uniforms.u_viewProjection, false, viewProjection);
        gl.uniform1i(p.uniforms.u_palette, 0);
        gl.uniform1i(p.uniforms.u_dqs, state.dqs ? 1 : 0);
        gl.uniform1i(p.uniforms.u_skinned, skinned ? 1 : 0);
      };
      // Constant influences for vertex arrays without JOINTS/WEIGHTS: the mesh's own node.
      const setConstantInfluences = () => {
        gl.vertexAttribI4ui(3, 0, 0, 0, 0);
        gl.vertexAttrib4f(4, 1, 0, 0, 0);
        gl.vertexAttribI4ui(5, 0, 0, 0, 0);
        gl.vertexAttrib4f(6, 0, 0, 0, 0);
      };
      setConstantInfluences();
      gl.activeTexture(gl.TEXTURE0);
      setCommon(meshProgram, true);
      gl.uniform3fv(meshProgram.uniforms.u_eyeDirection, direction);
      for (const item of items) {
        gl.bindTexture(gl.TEXTURE_2D, textures.get(item.skin));
        gl.uniform1i(meshProgram.uniforms.u_heatJoint, state.heat && item.skin === mainSkin ? state.joint : -1);
        gl.bindVertexArray(item.gpu.vao);
        gl.drawElements(gl.TRIANGLES, item.indices.length, gl.UNSIGNED_INT, 0);
      }

      setCommon(lineProgram, true);
      gl.bindTexture(gl.TEXTURE_2D, textures.get(mainSkin));
      if (state.curves && curves.count) {
        gl.bindVertexArray(curveGpu.vao);
        gl.uniform4f(lineProgram.uniforms.u_color, 1, 1, 1, 1);
        gl.drawArrays(gl.LINES, 0, cutVertices);
        gl.uniform4f(lineProgram.uniforms.u_color, 1, 0.6, 0.2, 1);
        gl.drawArrays(gl.LINES, cutVertices, curves.count - cutVertices);
      }
      if (state.skeleton) {
        mainSkin.joints.forEach((n, j) => skeletonPoints.set(scene.nodes[n].world.subarray(12, 15), j * 3));
        bones.forEach(([j, p], b) => {
          skeletonLines.set(skeletonPoints.subarray(j * 3, j * 3 + 3), b * 6);
          skeletonLines.set(skeletonPoints.subarray(p * 3, p * 3 + 3), b * 6 + 3);
        });
        gl.uniform1i(lineProgram.uniforms.u_skinned, 0);
        gl.disable(gl.DEPTH_TEST);
        gl.uniform4f(lineProgram.uniforms.u_color, 0.95, 0.95, 0.3, 1);
        gl.bindVertexArray(skeletonGpu.vao);
        gl.bindBuffer(gl.ARRAY_BUFFER, skeletonGpu.buffers.a_position);
        gl.bufferSubData(gl.ARRAY_BUFFER, 0, skeletonLines);
        gl.drawArrays(gl.LINES, 0, bones.length * 2);
        gl.bindVertexArray(pointGpu.vao);
        gl.bindBuffer(gl.ARRAY_BUFFER, pointGpu.buffers.a_position);
        gl.bufferSubData(gl.ARRAY_BUFFER, 0, skeletonPoints);
        gl.uniform1f(lineProgram.uniforms.u_pointSize, 5 * dpr);
        gl.drawArrays(gl.POINTS, 0, mainSkin.joints.length);
        gl.uniform1f(lineProgram.uniforms.u_pointSize, 10 * dpr);
        gl.uniform4f(lineProgram.uniforms.u_color, 1, 0.35, 0.2, 1);
        gl.drawArrays(gl.POINTS, state.joint, 1);
      }
      gl.bindVertexArray(null);
    }

    let frameRequested = false;
    let lastFrame = 0;
    function frame(now) {
      frameRequested = false;
      const animation = animations[state.animation];
      if (state.playing && animation) {
        state.time = animation.duration > 0 ? (state.time + (lastFrame ? (now - lastFrame) / 1000 : 0)) % animation.duration : 0;
        lastFrame = now;
        $('time').value = String(animation.duration > 0 ? state.time / animation.duration : 0);
        requestRender();
      }
      render();
    }
    function requestRender() {
      if (!frameRequested) {
        frameRequested = true;
        requestAnimationFrame(frame);
      }
    }

    // ---- controls ----
    const jointSelect = $('joint');
    jointNames.forEach((name, j) => jointSelect.appendChild(element('option', name)).setAttribute('value', String(j)));
    const axes = ['x', 'y', 'z'];
    function selectJoint(j) {
      state.joint = j;
      jointSelect.value = String(j);
      const user = scene.nodes[mainSkin.joints[j]].user;
      axes.forEach((a, k) => {
        $(`rot-${a}`).value = String(user[k]);
        $(`rot-${a}-value`).textContent = `${Math.round(user[k])}°`;
      });
      requestRender();
    }
    jointSelect.addEventListener('change', () => selectJoint(Number(jointSelect.value)));
    axes.forEach((a, k) => $(`rot-${a}`).addEventListener('input', (event) => {
      const degrees = Number(event.target.value);
      scene.nodes[mainSkin.joints[state.joint]].user[k] = degrees;
      $(`rot-${a}-value`).textContent = `${degrees}°`;
      requestRender();
    }));
    $('reset-pose').addEventListener('click', () => {
      scene.nodes.forEach((node) => (node.user = [0, 0, 0]));
      selectJoint(state.joint);
    });
    for (const [id, key, value] of [['colour-regions', 'heat', false], ['colour-weights', 'heat', true], ['method-lbs', 'dqs', false], ['method-dqs', 'dqs', true]]) {
      $(id).addEventListener('change', () => {
        state[key] = value;
        requestRender();
      });
    }
    for (const key of ['skeleton', 'curves']) {
      $(`show-${key}`).addEventListener('change', (event) => {
        state[key] = event.target.checked;
        requestRender();
      });
    }
    const animSelect = $('animation');
    animations.forEach((a, i) => animSelect.appendChild(element('option', `${a.name} (${a.duration.toFixed(2)} s)`)).setAttribute('value', String(i)));
    animSelect.addEventListener('change', () => {
      state.animation = Number(animSelect.value);
      state.time = 0;
      $('time').value = '0';
      requestRender();
    });
    $('play').disabled = !animations.length;
    $('play').addEventListener('click', () => {
      if (state.animation < 0 && animations.length) {
        state.animation = 0;
        animSelect.value = '0';
      }
      state.playing = !state.playing && state.animation >= 0;
      lastFrame = 0;
      $('play').textContent = state.playing ? 'Pause' : 'Play';
      requestRender();
    });
    $('time').addEventListener('input', (event) => {
      const animation = animations[state.animation];
      state.time = animation ? Number(event.target.value) * animation.duration : 0;
      requestRender();
    });

    // ---- camera: drag to orbit, shift/right drag to pan, wheel to zoom, click to pick;
    // ---- drag a joint (skeleton shown) to pose it ----
    const tip = $('tip');
    // Window coordinates of the world point p seen by the last frame's camera (null behind
    // the eye).
    const projectPoint = (p) => {
      const rect = canvas.getBoundingClientRect();
      const clip = [0, 1, 3].map((r) => viewProjection[r] * p[0] + viewProjection[4 + r] * p[1] + viewProjection[8 + r] * p[2] + viewProjection[12 + r]);
      if (clip[2] <= 0) return null;
      return { x: rect.left + ((clip[0] / clip[2] + 1) / 2) * rect.width, y: rect.top + ((1 - clip[1] / clip[2]) / 2) * rect.height };
    };
    // Window coordinates of joint j in the last computed pose.
    const projectJoint = (j) => projectPoint(scene.nodes[mainSkin.joints[j]].world.subarray(12, 15));
    const jointAt = (x, y) => {
      let best = -1;
      let bestDistance = 12;
      mainSkin.joints.forEach((n, j) => {
        const screen = projectJoint(j);
        const d = screen ? Math.hypot(screen.x - x, screen.y - y) : Infinity;
        if (d < bestDistance) {
          bestDistance = d;
          best = j;
        }
      });
      return best;
    };
    // Drag to pose, a screen-plane rotation: the dragged joint turns about the view direction
    // d through its posed position by the angle φ swept, around its projection J, from a
    // reference point R to the pointer P (window y points down, hence the sign):
    //   φ = -atan2((R - J) × (P - J), (R - J) · (P - J)).
    // R is the projection of the mean of the joint's children, so that the child side points
    // at the pointer; for a leaf, or children projecting within POSE_DEAD_ZONE pixels of J,
    // R is the previous pointer position, so that the joint turns with the pointer's sweep.
    // A pointer within POSE_DEAD_ZONE pixels of J gives no direction and is ignored. The world
    // rotation q_d(φ) is composed onto the slider rotation in the frame F, the rotation of
    // (parent world · base):  q_user ← (F⁻¹ q_d(φ) F) q_user = q_{F⁻¹ d}(φ) q_user.
    const POSE_DEAD_ZONE = 8;
    function turnJointTowards(drag, pointer) {
      updateWorld(scene);
      const node = scene.nodes[mainSkin.joints[drag.joint]];
      const centre = projectJoint(drag.joint);
      const away = (q) => q && Math.hypot(q.x - centre.x, q.y - centre.y) >= POSE_DEAD_ZONE;
      if (!centre || !away(pointer)) return;
      const children = childJoints[drag.joint].map((c) => scene.nodes[mainSkin.joints[c]].world);
      const child = children.length ? projectPoint([12, 13, 14].map((i) => children.reduce((s, m) => s + m[i], 0) / children.length)) : null;
      const reference = away(child) ? child : drag.previous;
      drag.previous = pointer;
      if (!reference) return;
      const r = [reference.x - centre.x, reference.y - centre.y];
      const p = [pointer.x - centre.x, pointer.y - centre.y];
      const angle = -Math.atan2(r[0] * p[1] - r[1] * p[0], r[0] * p[0] + r[1] * p[1]);
      const parentWorld = node.parent >= 0 ? scene.nodes[node.parent].world : mat4.identity();
      const frame = mat4.multiply(parentWorld, baseTransform(node));
      const axis = quat.rotate(quat.conjugate(quat.fromMatrix(frame, mat4.columnLengths(frame))), viewDirection());
      node.user = quat.toEulerDegrees(quat.multiply(quat.axisAngle(axis, angle), quat.fromEulerDegrees(node.user)));
      selectJoint(drag.joint);
    }

    // `joint`: the joint being posed, -1 when the drag moves the camera.
    let drag = null;
    canvas.addEventListener('contextmenu', (event) => event.preventDefault());
    canvas.addEventListener('pointerdown', (event) => {
      const pan = event.shiftKey || event.button === 2;
      const joint = !pan && event.button === 0 && state.skeleton ? jointAt(event.clientX, event.clientY) : -1;
      drag = { x: event.clientX, y: event.clientY, moved: false, pan, joint, previous: null };
      if (joint >= 0) selectJoint(joint);
      canvas.setPointerCapture(event.pointerId);
    });
    canvas.addEventListener('pointermove', (event) => {
      if (drag) {
        const dx = event.clientX - drag.x;
        const dy = event.clientY - drag.y;
        drag.moved = drag.moved || Math.abs(dx) + Math.abs(dy) > 3;
        drag.x = event.clientX;
        drag.y = event.clientY;
        if (drag.joint >= 0) {
          turnJointTowards(drag, { x: event.clientX, y: event.clientY });
        } else if (drag.pan) {
          const scale = (2 * camera.radius * camera.zoom) / canvas.clientHeight;
          const right = [Math.cos(camera.yaw), 0, -Math.sin(camera.yaw)];
          camera.target = camera.target.map((t, c) => t - dx * scale * right[c] + (c === 1 ? dy * scale : 0));
        } else {
          camera.yaw -= dx * 0.01;
          camera.pitch = Math.max(-1.5, Math.min(1.5, camera.pitch + dy * 0.01));
        }
        requestRender();
        return;
      }
      const j = jointAt(event.clientX, event.clientY);
      tip.hidden = j < 0;
      canvas.style.cursor = j >= 0 && state.skeleton ? 'crosshair' : '';
      if (j >= 0) {
        tip.textContent = jointNames[j];
        tip.style.left = `${event.clientX + 12}px`;
        tip.style.top = `${event.clientY + 12}px`;
      }
    });
    canvas.addEventListener('pointerup', (event) => {
      if (drag && !drag.moved) {
        const j = jointAt(event.clientX, event.clientY);
        if (j >= 0) selectJoint(j);
      }
      drag = null;
    });
    canvas.addEventListener('wheel', (event) => {
      event.preventDefault();
      camera.zoom = Math.max(0.05, Math.min(20, camera.zoom * Math.exp(event.deltaY * 0.001)));
      requestRender();
    }, { passive: false });
    window.addEventListener('resize', requestRender);

    $('model-facts').textContent = `${items.reduce((s, i) => s + i.vertexCount, 0)} vertices, ${items.reduce((s, i) => s + i.indices.length / 3, 0)} triangles, ${jointNames.length} joints, ${animations.length} animation(s)`;
    renderReport(report, (name) => {
      const j = jointNames.indexOf(name);
      if (j >= 0) selectJoint(j);
    });
    // Start on the skeleton's root (the first joint whose parent is not a joint).
    selectJoint(Math.max(0, mainSkin.joints.findIndex((n) => !mainSkin.joints.includes(scene.nodes[n].parent))));

    // Test hook: joints with the number of vertices they dominate and their parent joint (-1
    // for a root), a grey-level thumbnail (160 x 120 samples) of a freshly rendered frame, the
    // WebGL error flag, the camera, and the user rotation of joint j (the slider angles in
    // degrees and the quaternion (x, y, z, w) they make).
    hook.joints = () => jointNames.map((name, index) => ({ name, index, vertices: dominantCount[index], parent: parentJoint[index] }));
    hook.camera = () => ({ ...camera, target: [...camera.target] });
    hook.jointRotation = (j) => {
      const degrees = [...scene.nodes[mainSkin.joints[j]].user];
      return { degrees, quaternion: quat.fromEulerDegrees(degrees) };
    };
    hook.glError = () => gl.getError();
    hook.projectJoint = projectJoint;
    hook.curveSegments = curves.count / 2;
    // GPU-skinned positions of the main mesh in the current pose (transform feedback of
    // the mesh shader), with the inputs needed to recompute them: every `stride`-th vertex.
    let feedbackProgram = null;
    const skinOnGpu = (dqs) => {
      feedbackProgram = feedbackProgram || compileProgram(gl, 'glsl-mesh-vert', 'glsl-mesh-frag', ['v_position']);
      const { program, uniforms } = feedbackProgram;
      gl.useProgram(program);
      gl.uniformMatrix4fv(uniforms.u_viewProjection, false, mat4.identity());
      gl.uniform1i(uniforms.u_palette, 0);
      gl.uniform1i(uniforms.u_dqs, dqs ? 1 : 0);
      gl.uniform1i(uniforms.u_skinned, 1);
      gl.uniform1i(uniforms.u_heatJoint, -1);
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, textures.get(mainSkin));
      const buffer = gl.createBuffer();
      gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, buffer);
      gl.bufferData(gl.TRANSFORM_FEEDBACK_BUFFER, main.vertexCount * 12, gl.STREAM_READ);
      const feedback = gl.createTransformFeedback();
      gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, feedback);
      gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, buffer);
      gl.enable(gl.RASTERIZER_DISCARD);
      gl.bindVertexArray(main.gpu.vao);
      gl.beginTransformFeedback(gl.POINTS);
      gl.drawArrays(gl.POINTS, 0, main.vertexCount);
      gl.endTransformFeedback();
      gl.disable(gl.RASTERIZER_DISCARD);
      gl.bindVertexArray(null);
      gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, null);
      const out = new Float32Array(main.vertexCount * 3);
      gl.getBufferSubData(gl.TRANSFORM_FEEDBACK_BUFFER, 0, out);
      gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, null);
      gl.deleteTransformFeedback(feedback);
      gl.deleteBuffer(buffer);
      return out;
    };
    hook.skinningProbe = (maxVertices = 2000) => {
      if (!main.weights0 || main.joints1) return null;
      render();
      const lbs = skinOnGpu(false);
      const dqs = skinOnGpu(true);
      const stride = Math.ceil(main.vertexCount / maxVertices);
      const pick = (array, width) => {
        const out = [];
        for (let v = 0; v < main.vertexCount; v += stride) out.push(...array.subarray(v * width, v * width + width));
        return out;
      };
      const palette = mainSkin.joints.flatMap((_, j) => Array.from(mainSkin.palette.subarray(j * 28, j * 28 + 16)));
      return { stride, rest: pick(main.positions, 3), joints: pick(main.joints0, 4), weights: pick(main.weights0, 4), palette, lbs: pick(lbs, 3), dqs: pick(dqs, 3) };
    };
    hook.animations = () => animations.map((a) => ({ name: a.name, duration: a.duration }));
    // The animated values of animation `a` at `time` (the next frame re-applies the state).
    hook.poseAt = (a, time) => {
      applyAnimation(scene, animations[a], time);
      return animations[a].channels.map((c) => ({ node: c.node, path: c.path, value: Array.from(scene.nodes[c.node].pose[c.path[0]]) }));
    };
    hook.thumbnail = () => {
      render();
      const pixels = new Uint8Array(canvas.width * canvas.height * 4);
      gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
      const out = [];
      for (let ty = 0; ty < 120; ty++) {
        for (let tx = 0; tx < 160; tx++) {
          const i = (Math.floor(((ty + 0.5) * canvas.height) / 120) * canvas.width + Math.floor(((tx + 0.5) * canvas.width) / 160)) * 4;
          out.push(Math.round((pixels[i] + pixels[i + 1] + pixels[i + 2]) / 3));
        }
      }
      return out;
    };
    hook.state = state;
    // A first frame before `ready`, so that projectJoint sees the camera.
    render();
    hook.ready = true;
  }

  try {
    start();
  } catch (error) {
    hook.error = String(error && error.message ? error.message : error);
    $('status').textContent = `Cannot show the model: ${hook.error}`;
    $('status').hidden = false;
    console.error(error);
  }
})();
