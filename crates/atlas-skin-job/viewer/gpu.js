// WebGL2 resources: shader programs, vertex arrays, palette textures, the model's upload
// and skinning on the GPU read back by transform feedback.

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

// Binds program `p` with the uniforms every program has: the view-projection matrix, the
// palette on texture unit 0, DQS or LBS, and whether vertices are skinned.
function useProgram(gl, p, viewProjection, dqs, skinned) {
  gl.useProgram(p.program);
  gl.uniformMatrix4fv(p.uniforms.u_viewProjection, false, viewProjection);
  gl.uniform1i(p.uniforms.u_palette, 0);
  gl.uniform1i(p.uniforms.u_dqs, dqs ? 1 : 0);
  gl.uniform1i(p.uniforms.u_skinned, skinned ? 1 : 0);
}

// A vertex array per mesh (`item.gpu`, with its region colours) and a palette texture per
// skin.
function uploadMeshes(gl, items, colours) {
  items.forEach((item, i) => {
    item.gpu = createVertexArray(gl, {
      a_position: [item.positions, 3], a_normal: [item.normals, 3], a_color: [colours[i], 3],
      a_joints0: [item.joints0, 4], a_weights0: [item.weights0, 4], a_joints1: [item.joints1, 4], a_weights1: [item.weights1, 4],
    }, item.indices);
  });
  const textures = new Map();
  for (const item of items) if (!textures.has(item.skin)) textures.set(item.skin, createPaletteTexture(gl, item.skin));
  return textures;
}

// Puts colour set `name` of `viewer.colours` (`regions` or `pieces`, one array per mesh)
// into the meshes' colour buffers, unless it is there already.
function showColours(viewer, name) {
  const { gl, items } = viewer;
  if (viewer.shownColours === name) return;
  items.forEach((item, i) => {
    gl.bindBuffer(gl.ARRAY_BUFFER, item.gpu.buffers.a_color);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, viewer.colours[name][i]);
  });
  viewer.shownColours = name;
}

// The report's boundaries as line segments skinned like the nearest of `meshes`
// (curveMeshes): `cutVertices` vertices of cuts, then the soft boundaries' circles; `count`
// vertices in all.
function uploadCurves(gl, report, meshes) {
  const boundaries = boundaryCurves(report);
  const curves = curveGeometry([...boundaries.cuts, ...boundaries.planes], meshes);
  return {
    count: curves.count,
    cutVertices: 2 * boundaries.cuts.reduce((n, c) => n + c.length, 0),
    gpu: createVertexArray(gl, { a_position: [curves.positions, 3], a_joints0: [curves.joints0, 4], a_weights0: [curves.weights0, 4] }),
  };
}

// The skeleton's joint points and bone lines, refilled with the pose at each frame.
function uploadSkeleton(gl, jointCount, boneCount) {
  const points = new Float32Array(jointCount * 3);
  const lines = new Float32Array(boneCount * 6);
  const linesGpu = createVertexArray(gl, { a_position: [lines, 3] });
  return { points, lines, linesGpu, pointsGpu: createVertexArray(gl, { a_position: [points, 3] }) };
}

// The main mesh's vertex positions in the current pose as the mesh shader computes them (LBS
// or DQS), captured by transform feedback.
function skinOnGpu(viewer, dqs) {
  const { gl, main } = viewer;
  const programs = viewer.programs;
  programs.feedback = programs.feedback || compileProgram(gl, 'glsl-mesh-vert', 'glsl-mesh-frag', ['v_position']);
  useProgram(gl, programs.feedback, mat4.identity(), dqs, true);
  gl.uniform1i(programs.feedback.uniforms.u_heatJoint, -1);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, viewer.textures.get(viewer.mainSkin));
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
}
