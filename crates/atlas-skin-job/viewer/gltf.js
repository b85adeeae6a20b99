// Reading the embedded glTF binary: its chunks and accessors, the node tree, animations,
// skins and triangle meshes with their joint influences.

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

// Channels (translation, rotation, scale; LINEAR, STEP or CUBICSPLINE) of each animation.
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
    gltf.json.meshes[node.mesh].primitives.forEach((primitive, primitiveIndex) => {
      const attributes = primitive.attributes;
      if ((primitive.mode !== undefined && primitive.mode !== 4) || attributes.POSITION === undefined) return;
      const positions = readAccessor(gltf, attributes.POSITION);
      const vertexCount = positions.length / 3;
      const indices = primitive.indices !== undefined ? readAccessor(gltf, primitive.indices, true) : Uint32Array.from({ length: vertexCount }, (_, i) => i);
      const item = {
        skin, positions, indices, vertexCount, node: nodeIndex, primitive: primitiveIndex,
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
    });
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
