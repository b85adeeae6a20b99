// The orbit camera: framing the model, its view-projection matrix, window coordinates of a
// world point, and the pointer's orbit and pan.

// A camera looking at the centre `target` of the box lo–hi from the angles `yaw` and `pitch`
// (radians), far enough for the half diagonal `radius` to fill a 45° view, times `zoom`.
function frameCamera({ lo, hi }) {
  return {
    target: lo.map((l, c) => (l + hi[c]) / 2),
    radius: Math.max(1e-6, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2),
    yaw: 0.5, pitch: 0.15, zoom: 1,
  };
}

// Unit vector from the camera's target towards the eye.
const viewDirection = (camera) => [Math.cos(camera.pitch) * Math.sin(camera.yaw), Math.sin(camera.pitch), Math.cos(camera.pitch) * Math.cos(camera.yaw)];

// Perspective (45° vertical field of view, `aspect` width / height) times the camera's view.
function viewProjectionOf(camera, aspect) {
  const distance = (camera.radius / Math.tan(Math.PI / 8)) * camera.zoom;
  const direction = viewDirection(camera);
  const eye = camera.target.map((t, c) => t + distance * direction[c]);
  const near = Math.max(distance - 4 * camera.radius, distance * 0.01);
  return mat4.multiply(mat4.perspective(Math.PI / 4, aspect, near, distance + 4 * camera.radius), mat4.lookAt(eye, camera.target, [0, 1, 0]));
}

// Window coordinates of the world point p seen by the last frame's camera (null behind the
// eye).
function projectPoint(viewer, p) {
  const rect = viewer.canvas.getBoundingClientRect();
  const m = viewer.viewProjection;
  const clip = [0, 1, 3].map((r) => m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
  if (clip[2] <= 0) return null;
  return { x: rect.left + ((clip[0] / clip[2] + 1) / 2) * rect.width, y: rect.top + ((1 - clip[1] / clip[2]) / 2) * rect.height };
}

// A pointer move of (dx, dy) pixels: the target moves with the pointer in the view plane
// (`viewHeight` pixels high).
function panCamera(camera, dx, dy, viewHeight) {
  const scale = (2 * camera.radius * camera.zoom) / viewHeight;
  const right = [Math.cos(camera.yaw), 0, -Math.sin(camera.yaw)];
  camera.target = camera.target.map((t, c) => t - dx * scale * right[c] + (c === 1 ? dy * scale : 0));
}

// A pointer move of (dx, dy) pixels turns the camera around its target, pitch within ±1.5.
function orbitCamera(camera, dx, dy) {
  camera.yaw -= dx * 0.01;
  camera.pitch = Math.max(-1.5, Math.min(1.5, camera.pitch + dy * 0.01));
}
