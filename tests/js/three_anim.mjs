// Samples a glb's animation with three.js's AnimationMixer, for comparison with
// atlas-skin's clip sampling (atlas_skin_runtime::Clip::sample).
//
// Usage: node tests/js/three_anim.mjs FILE.glb ANIMATION_INDEX TIME [TIME ...]
// Prints {"frames": [{"time": t, "nodes": [{"translation": [x, y, z],
// "rotation": [x, y, z, w], "scale": [x, y, z]}, ...]}, ...]}: every glTF node's local
// transform (in node index order) after mixer.setTime(t). Times should lie within the
// clip: the mixer loops (LoopRepeat) where atlas-skin clamps. Exit code 1 on any error.

import { AnimationMixer } from "three";
import { loadGlb } from "./three_pose.mjs";

async function main() {
  const [file, index, ...times] = process.argv.slice(2);
  if (file === undefined || index === undefined || times.length === 0) {
    console.error("usage: three_anim.mjs FILE.glb ANIMATION_INDEX TIME [TIME ...]");
    process.exit(2);
  }
  const { gltf, nodes } = await loadGlb(file);
  const clip = gltf.animations[Number(index)];
  if (!clip) throw new Error(`no animation ${index}`);
  const mixer = new AnimationMixer(gltf.scene);
  mixer.clipAction(clip).play();
  const frames = times.map(Number).map((time) => {
    mixer.setTime(time);
    return {
      time,
      nodes: nodes.map((node) => {
        if (!node) throw new Error("a glTF node has no three.js object");
        return {
          translation: node.position.toArray(),
          rotation: node.quaternion.toArray(),
          scale: node.scale.toArray(),
        };
      }),
    };
  });
  console.log(JSON.stringify({ frames }));
}

main().catch((error) => {
  console.error(String(error && error.stack ? error.stack : error));
  process.exit(1);
});
