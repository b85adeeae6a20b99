// Drawing a frame on demand: the meshes skinned on the GPU (region or piece colours or one
// joint's weights), the boundary curves, the skeleton on top; the animation advancing while it plays.

// Draws the current state: the animation's pose at state.time with the user's rotations.
function render(viewer) {
  const { canvas, gl, state } = viewer;
  const dpr = window.devicePixelRatio || 1;
  const width = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const height = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== width || canvas.height !== height) {
    canvas.width = width;
    canvas.height = height;
  }
  applyAnimation(viewer.scene, viewer.animations[state.animation], state.time);
  updateWorld(viewer.scene);
  gl.viewport(0, 0, width, height);
  gl.clearColor(0.13, 0.14, 0.16, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  viewer.viewProjection = viewProjectionOf(viewer.camera, width / height);
  for (const [skin, texture] of viewer.textures) {
    updatePalette(viewer.scene, skin);
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 7, skin.joints.length, gl.RGBA, gl.FLOAT, skin.palette);
  }
  drawMeshes(viewer);
  useProgram(gl, viewer.programs.line, viewer.viewProjection, state.dqs, true);
  gl.bindTexture(gl.TEXTURE_2D, viewer.textures.get(viewer.mainSkin));
  if (state.curves && viewer.curves.count) drawCurves(viewer);
  if (state.skeleton) drawSkeleton(viewer, dpr);
  gl.bindVertexArray(null);
}

// Every mesh with its skin's palette, coloured by region or by piece treatment; in the
// heat-map view the main skin's meshes show the selected joint's weights.
function drawMeshes(viewer) {
  const { gl, state } = viewer;
  showColours(viewer, state.pieces ? 'pieces' : 'regions');
  const program = viewer.programs.mesh;
  // Constant influences for vertex arrays without JOINTS/WEIGHTS: the mesh's own node.
  gl.vertexAttribI4ui(3, 0, 0, 0, 0);
  gl.vertexAttrib4f(4, 1, 0, 0, 0);
  gl.vertexAttribI4ui(5, 0, 0, 0, 0);
  gl.vertexAttrib4f(6, 0, 0, 0, 0);
  gl.activeTexture(gl.TEXTURE0);
  useProgram(gl, program, viewer.viewProjection, state.dqs, true);
  gl.uniform3fv(program.uniforms.u_eyeDirection, viewDirection(viewer.camera));
  for (const item of viewer.items) {
    gl.bindTexture(gl.TEXTURE_2D, viewer.textures.get(item.skin));
    gl.uniform1i(program.uniforms.u_heatJoint, state.heat && item.skin === viewer.mainSkin ? state.joint : -1);
    gl.bindVertexArray(item.gpu.vao);
    gl.drawElements(gl.TRIANGLES, item.indices.length, gl.UNSIGNED_INT, 0);
  }
}

// The boundary curves (line program bound): cuts in white, soft boundaries in orange.
function drawCurves(viewer) {
  const { gl, curves } = viewer;
  const color = viewer.programs.line.uniforms.u_color;
  gl.bindVertexArray(curves.gpu.vao);
  gl.uniform4f(color, 1, 1, 1, 1);
  gl.drawArrays(gl.LINES, 0, curves.cutVertices);
  gl.uniform4f(color, 1, 0.6, 0.2, 1);
  gl.drawArrays(gl.LINES, curves.cutVertices, curves.count - curves.cutVertices);
}

// The main skin's bones and joints in the current pose over everything (line program bound),
// the selected joint larger and red.
function drawSkeleton(viewer, dpr) {
  const { gl, skeleton } = viewer;
  const { points, lines, linesGpu, pointsGpu } = skeleton;
  const uniforms = viewer.programs.line.uniforms;
  viewer.mainSkin.joints.forEach((n, j) => points.set(viewer.scene.nodes[n].world.subarray(12, 15), j * 3));
  viewer.tree.bones.forEach(([j, p], b) => {
    lines.set(points.subarray(j * 3, j * 3 + 3), b * 6);
    lines.set(points.subarray(p * 3, p * 3 + 3), b * 6 + 3);
  });
  gl.uniform1i(uniforms.u_skinned, 0);
  gl.disable(gl.DEPTH_TEST);
  gl.uniform4f(uniforms.u_color, 0.95, 0.95, 0.3, 1);
  gl.bindVertexArray(linesGpu.vao);
  gl.bindBuffer(gl.ARRAY_BUFFER, linesGpu.buffers.a_position);
  gl.bufferSubData(gl.ARRAY_BUFFER, 0, lines);
  gl.drawArrays(gl.LINES, 0, viewer.tree.bones.length * 2);
  gl.bindVertexArray(pointsGpu.vao);
  gl.bindBuffer(gl.ARRAY_BUFFER, pointsGpu.buffers.a_position);
  gl.bufferSubData(gl.ARRAY_BUFFER, 0, points);
  gl.uniform1f(uniforms.u_pointSize, 5 * dpr);
  gl.drawArrays(gl.POINTS, 0, viewer.mainSkin.joints.length);
  gl.uniform1f(uniforms.u_pointSize, 10 * dpr);
  gl.uniform4f(uniforms.u_color, 1, 0.35, 0.2, 1);
  gl.drawArrays(gl.POINTS, viewer.state.joint, 1);
}

// Asks for one frame (at most one pending).
function requestRender(viewer) {
  if (!viewer.playback.requested) {
    viewer.playback.requested = true;
    requestAnimationFrame((now) => frame(viewer, now));
  }
}

// A frame at time `now` (ms): while playing, the animation time advances by the time since
// the last frame (looping), the time slider follows and the next frame is requested.
function frame(viewer, now) {
  const { state, playback } = viewer;
  playback.requested = false;
  const animation = viewer.animations[state.animation];
  if (state.playing && animation) {
    state.time = animation.duration > 0 ? (state.time + (playback.lastFrame ? (now - playback.lastFrame) / 1000 : 0)) % animation.duration : 0;
    playback.lastFrame = now;
    $('time').value = String(animation.duration > 0 ? state.time / animation.duration : 0);
    requestRender(viewer);
  }
  render(viewer);
}
