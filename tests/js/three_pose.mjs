// Skins a glb with three.js's own skinning (SkinnedMesh.getVertexPosition →
// applyBoneTransform) after posing it, for comparison with `atlas-skin pose`.
//
// Usage:
//   node tests/js/three_pose.mjs FILE.glb --pose POSE.json
//   node tests/js/three_pose.mjs FILE.glb --anim INDEX --time SECONDS
// POSE.json maps joint names (the node's name, or "node<index>" for an unnamed node) to a
// quaternion [x, y, z, w] applied after the node's rest rotation (q_rest · q), as
// `atlas-skin pose --pose` does. Prints {"positions": [x0, y0, z0, x1, ...]}: every skinned
// mesh's vertices in document order, where three.js draws them: getVertexPosition gives
// mesh-local coordinates (bindMatrixInverse = the mesh's inverse world matrix, "attached"
// bind mode), and the mesh's world matrix takes them to Σ w · jointWorld · inverseBind · v,
// the glTF specification's skinned position. Exit code 1 on any error.
//
// Images cannot be decoded in node: materials are replaced by defaults before parsing
// (geometry and skinning do not depend on them).

import { readFile } from "node:fs/promises";
import { pathToFileURL } from "node:url";
import { AnimationMixer, Vector3 } from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";

const GLB_MAGIC = 0x46546c67;
const CHUNK_JSON = 0x4e4f534a;
const CHUNK_BIN = 0x004e4942;

/** The glb at `file` with textures, images, samplers and material contents removed. */
async function untexturedGlb(file) {
  const bytes = await readFile(file);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (view.getUint32(0, true) !== GLB_MAGIC) throw new Error(`${file} is not a glb`);
  const jsonLength = view.getUint32(12, true);
  if (view.getUint32(16, true) !== CHUNK_JSON) throw new Error(`${file}: first chunk is not JSON`);
  const json = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  let bin = new Uint8Array(0);
  const binStart = 20 + jsonLength;
  if (binStart + 8 <= bytes.length && view.getUint32(binStart + 4, true) === CHUNK_BIN) {
    bin = bytes.subarray(binStart + 8, binStart + 8 + view.getUint32(binStart, true));
  }
  delete json.images;
  delete json.textures;
  delete json.samplers;
  if (json.materials) json.materials = json.materials.map(() => ({}));
  let jsonBytes = new TextEncoder().encode(JSON.stringify(json));
  const jsonPadded = new Uint8Array(Math.ceil(jsonBytes.length / 4) * 4).fill(0x20);
  jsonPadded.set(jsonBytes);
  const binPadded = new Uint8Array(Math.ceil(bin.length / 4) * 4);
  binPadded.set(bin);
  const total = 12 + 8 + jsonPadded.length + (bin.length ? 8 + binPadded.length : 0);
  const out = new Uint8Array(total);
  const outView = new DataView(out.buffer);
  outView.setUint32(0, GLB_MAGIC, true);
  outView.setUint32(4, 2, true);
  outView.setUint32(8, total, true);
  outView.setUint32(12, jsonPadded.length, true);
  outView.setUint32(16, CHUNK_JSON, true);
  out.set(jsonPadded, 20);
  if (bin.length) {
    const at = 20 + jsonPadded.length;
    outView.setUint32(at, binPadded.length, true);
    outView.setUint32(at + 4, CHUNK_BIN, true);
    out.set(binPadded, at + 8);
  }
  return { json, buffer: out.buffer };
}

/**
 * Loads a glb with three's GLTFLoader. Returns {gltf, json, nodes}: the loader's result,
 * the document JSON, and the three.js object of every glTF node index.
 */
export async function loadGlb(file) {
  const { json, buffer } = await untexturedGlb(file);
  const gltf = await new Promise((resolve, reject) =>
    new GLTFLoader().parse(buffer, "", resolve, reject),
  );
  const nodes = new Array((json.nodes || []).length).fill(null);
  gltf.scene.traverse((object) => {
    const mapping = gltf.parser.associations.get(object);
    if (mapping && mapping.nodes !== undefined && nodes[mapping.nodes] === null) {
      nodes[mapping.nodes] = object;
    }
  });
  return { gltf, json, nodes };
}

/** The name atlas-skin gives glTF node `index`. */
export function nodeName(json, index) {
  return json.nodes[index].name ?? `node${index}`;
}

function argument(args, flag) {
  const at = args.indexOf(flag);
  if (at < 0 || at + 1 >= args.length) return undefined;
  return args[at + 1];
}

async function main() {
  const args = process.argv.slice(2);
  if (args.length < 3) {
    console.error("usage: three_pose.mjs FILE.glb (--pose POSE.json | --anim INDEX --time T)");
    process.exit(2);
  }
  const { gltf, json, nodes } = await loadGlb(args[0]);
  const posePath = argument(args, "--pose");
  const anim = argument(args, "--anim");
  if (posePath !== undefined) {
    const pose = JSON.parse(await readFile(posePath, "utf8"));
    for (const [name, q] of Object.entries(pose)) {
      const index = json.nodes.findIndex((_, i) => nodeName(json, i) === name);
      if (index < 0 || !nodes[index]) throw new Error(`no node named ${name}`);
      const rotation = nodes[index].quaternion.clone().set(q[0], q[1], q[2], q[3]).normalize();
      nodes[index].quaternion.multiply(rotation);
    }
  } else if (anim !== undefined) {
    const clip = gltf.animations[Number(anim)];
    if (!clip) throw new Error(`no animation ${anim}`);
    const mixer = new AnimationMixer(gltf.scene);
    mixer.clipAction(clip).play();
    mixer.setTime(Number(argument(args, "--time") ?? 0));
  } else {
    throw new Error("give --pose or --anim");
  }
  gltf.scene.updateMatrixWorld(true);
  const positions = [];
  const v = new Vector3();
  gltf.scene.traverse((object) => {
    if (!object.isSkinnedMesh) return;
    const count = object.geometry.attributes.position.count;
    for (let i = 0; i < count; i++) {
      object.getVertexPosition(i, v).applyMatrix4(object.matrixWorld);
      positions.push(v.x, v.y, v.z);
    }
  });
  console.log(JSON.stringify({ positions }));
}

if (import.meta.url === pathToFileURL(process.argv[1]).href) {
  main().catch((error) => {
    console.error(String(error && error.stack ? error.stack : error));
    process.exit(1);
  });
}
