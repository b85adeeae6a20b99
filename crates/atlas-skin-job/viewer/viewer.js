// atlas-skin report viewer: a small WebGL2 viewer of one skinned glTF binary embedded in the
// page (base64), with the skinning report JSON beside it. No network access, no libraries.
// html.rs joins the scripts of this folder into one strict-mode function of the page, in the
// order math, gltf, pose, report, gpu, draw, camera, controls, pointer and this file, which
// starts the viewer.
//
// Report keys read (all optional): decomposition.joints[] {name, status, reason, perimeter,
// diameter, overlap*, point [x,y,z], normal [x,y,z], curve [[x,y,z], ...] (bind space)},
// decomposition.regions[] {joint, joints: [name...]}, decomposition.vertex_regions (region
// index or null per stored vertex; otherwise, and for null, a vertex takes the region of
// its dominant joint), pieces.treatments [name...] with pieces.vertex_treatments (an index
// into them per stored vertex: the "pieces" colour mode), vertex_ranges [{node, primitive,
// first, count}] (which stored vertices each primitive of the file holds; without it the
// per-vertex arrays are the main skinned mesh's, glTF vertex order), timings_ms
// {stage: ms}, warnings [...], counts {...} and any other top-level scalar.

const $ = (id) => document.getElementById(id);
const hook = (window.atlasViewer = { ready: false, error: null });

// The embedded model and report: the node tree, the triangle meshes (`items`) with their
// skins, the animations, and `main`, the largest skinned mesh, whose skin's joints the
// panel lists.
function loadModel() {
  const report = readReport();
  const gltf = parseGlb(decodeBase64($('model-glb').textContent));
  const scene = buildScene(gltf);
  const items = readPrimitives(gltf, scene, readSkins(gltf));
  if (!items.length) throw new Error('the model has no triangle mesh');
  const animations = readAnimations(gltf);
  const main = items.reduce((a, b) => (b.weights0 && (!a.weights0 || b.vertexCount > a.vertexCount) ? b : a));
  const jointNames = main.skin.joints.map((n) => scene.nodes[n].name);
  return { report, scene, items, animations, main, mainSkin: main.skin, jointNames };
}

// What the viewer's parts share: the model, the canvas's WebGL2 context with the programs
// and the uploaded model, the vertex colours by region and by piece treatment (null without
// the report's treatments) with the treatments' names and vertex counts, the joint tree,
// the camera framing the rest pose, the panel's `state`, the last frame's view-projection
// and the animation player's frame clock.
function createViewer(model) {
  const canvas = $('view');
  const gl = canvas.getContext('webgl2', { antialias: true });
  if (!gl) throw new Error('this browser has no WebGL2');
  const programs = {
    mesh: compileProgram(gl, 'glsl-mesh-vert', 'glsl-mesh-frag'),
    line: compileProgram(gl, 'glsl-line-vert', 'glsl-line-frag'),
    feedback: null,
  };
  const { colours, dominantCount } = regionColours(model);
  const treatments = vertexTreatments(model);
  const pieces = treatments ? pieceColours(model, treatments) : { colours: null, counts: new Map() };
  const textures = uploadMeshes(gl, model.items, colours);
  const curves = uploadCurves(gl, model.report, curveMeshes(model));
  const tree = jointTree(model.scene, model.mainSkin);
  const skeleton = uploadSkeleton(gl, model.mainSkin.joints.length, tree.bones.length);
  return {
    ...model, canvas, gl, programs, textures, curves, tree, skeleton, dominantCount,
    colours: { regions: colours, pieces: pieces.colours }, shownColours: 'regions',
    treatmentNames: treatments ? treatments.names : [], treatmentCounts: pieces.counts,
    camera: frameCamera(restPoseBounds(model.scene, model.items)),
    state: { joint: 0, heat: false, pieces: false, dqs: false, skeleton: true, curves: true, animation: -1, time: 0, playing: false },
    viewProjection: mat4.identity(),
    playback: { requested: false, lastFrame: 0 },
  };
}

function start() {
  const viewer = createViewer(loadModel());
  const { items, jointNames, mainSkin } = viewer;
  bindJointControls(viewer);
  bindViewOptions(viewer);
  bindAnimationControls(viewer);
  bindPointer(viewer);
  window.addEventListener('resize', () => requestRender(viewer));
  $('model-facts').textContent = `${items.reduce((s, i) => s + i.vertexCount, 0)} vertices, ${items.reduce((s, i) => s + i.indices.length / 3, 0)} triangles, ${jointNames.length} joints, ${viewer.animations.length} animation(s)`;
  renderReport(viewer.report, (name) => {
    const j = jointNames.indexOf(name);
    if (j >= 0) selectJoint(viewer, j);
  });
  // Start on the skeleton's root (the first joint whose parent is not a joint).
  selectJoint(viewer, Math.max(0, mainSkin.joints.findIndex((n) => !mainSkin.joints.includes(viewer.scene.nodes[n].parent))));
  installTestHook(viewer);
  // A first frame before `ready`, so that projectJoint sees the camera.
  render(viewer);
  hook.ready = true;
}

// Test hook: joints with the number of vertices they dominate and their parent joint (-1
// for a root), a grey-level thumbnail of a freshly rendered frame, the WebGL error flag, the
// camera, and the user rotation of joint j (the slider angles in degrees and the quaternion
// (x, y, z, w) they make).
function installTestHook(viewer) {
  const { scene, mainSkin, animations } = viewer;
  hook.joints = () => viewer.jointNames.map((name, index) => ({ name, index, vertices: viewer.dominantCount[index], parent: viewer.tree.parentJoint[index] }));
  hook.camera = () => ({ ...viewer.camera, target: [...viewer.camera.target] });
  hook.jointRotation = (j) => {
    const degrees = [...scene.nodes[mainSkin.joints[j]].user];
    return { degrees, quaternion: quat.fromEulerDegrees(degrees) };
  };
  hook.glError = () => viewer.gl.getError();
  hook.projectJoint = (j) => projectJoint(viewer, j);
  hook.curveSegments = viewer.curves.count / 2;
  hook.skinningProbe = (maxVertices = 2000) => skinningProbe(viewer, maxVertices);
  hook.animations = () => animations.map((a) => ({ name: a.name, duration: a.duration }));
  // The animated values of animation `a` at `time` (the next frame re-applies the state).
  hook.poseAt = (a, time) => {
    applyAnimation(scene, animations[a], time);
    return animations[a].channels.map((c) => ({ node: c.node, path: c.path, value: Array.from(scene.nodes[c.node].pose[c.path[0]]) }));
  };
  hook.thumbnail = () => thumbnail(viewer);
  hook.state = viewer.state;
}

// GPU-skinned positions (LBS and DQS) of the main mesh in the current pose, with the inputs
// needed to recompute them: every `stride`-th vertex. Null for meshes the probe does not
// cover (unskinned, or more than 4 influences).
function skinningProbe(viewer, maxVertices) {
  const { main, mainSkin } = viewer;
  if (!main.weights0 || main.joints1) return null;
  render(viewer);
  const lbs = skinOnGpu(viewer, false);
  const dqs = skinOnGpu(viewer, true);
  const stride = Math.ceil(main.vertexCount / maxVertices);
  const pick = (array, width) => {
    const out = [];
    for (let v = 0; v < main.vertexCount; v += stride) out.push(...array.subarray(v * width, v * width + width));
    return out;
  };
  const palette = mainSkin.joints.flatMap((_, j) => Array.from(mainSkin.palette.subarray(j * 28, j * 28 + 16)));
  return { stride, rest: pick(main.positions, 3), joints: pick(main.joints0, 4), weights: pick(main.weights0, 4), palette, lbs: pick(lbs, 3), dqs: pick(dqs, 3) };
}

// Grey levels (mean of R, G, B) of 160 x 120 samples of a freshly rendered frame.
function thumbnail(viewer) {
  const { canvas, gl } = viewer;
  render(viewer);
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
}

try {
  start();
} catch (error) {
  hook.error = String(error && error.message ? error.message : error);
  $('status').textContent = `Cannot show the model: ${hook.error}`;
  $('status').hidden = false;
  console.error(error);
}
