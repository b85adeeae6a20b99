// Loads skinned glTF binaries with three.js's GLTFLoader (GLTFLoader.parse in node) and
// checks that the skin is bound: a SkinnedMesh with a Skeleton whose bone count equals the
// glTF skin's joint count, every bone a three.js Bone.
//
// Usage: node tests/js/three_load.mjs FILE.glb [FILE.glb ...]
// Prints one JSON line per file:
//   {"file", "ok", "skinned_meshes", "bones", "skin_joints", "vertices", "error"?}
// Exit code 1 when any file fails to load or has no bound skin, 2 on bad usage.
//
// Images cannot be decoded in node: the glb is loaded through three_pose.mjs's loader, which
// drops textures and material contents first (skinning does not depend on them).

import { loadGlb } from "./three_pose.mjs";

async function check(file) {
  const { gltf, json } = await loadGlb(file);
  const skins = json.skins || [];
  const skinned = [];
  gltf.scene.traverse((object) => {
    if (object.isSkinnedMesh) skinned.push(object);
  });
  const result = {
    file,
    skinned_meshes: skinned.length,
    bones: skinned.length ? skinned[0].skeleton.bones.length : 0,
    skin_joints: skins.length ? skins[0].joints.length : 0,
    vertices: skinned.reduce((n, m) => n + m.geometry.attributes.position.count, 0),
  };
  const bound = skinned.every(
    (mesh) =>
      mesh.skeleton &&
      mesh.skeleton.bones.length > 0 &&
      mesh.skeleton.bones.every((bone) => bone && bone.isBone) &&
      skins.some((skin) => skin.joints.length === mesh.skeleton.bones.length),
  );
  result.ok = skinned.length > 0 && bound && result.bones === result.skin_joints;
  return result;
}

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error("usage: node tests/js/three_load.mjs FILE.glb [FILE.glb ...]");
    process.exit(2);
  }
  let failed = false;
  for (const file of files) {
    let result;
    try {
      result = await check(file);
    } catch (error) {
      result = { file, ok: false, error: String(error && error.message ? error.message : error) };
    }
    failed ||= !result.ok;
    console.log(JSON.stringify(result));
  }
  process.exit(failed ? 1 : 0);
}

main();
