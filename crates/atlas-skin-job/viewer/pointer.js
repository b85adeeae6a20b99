// The pointer on the canvas: drag to orbit, shift/right drag to pan, wheel to zoom; hover a
// joint for its name, click it to select it, drag it (skeleton shown) to pose it.

// Window coordinates of skin joint j in the last computed pose.
const projectJoint = (viewer, j) => projectPoint(viewer, viewer.scene.nodes[viewer.mainSkin.joints[j]].world.subarray(12, 15));

// The skin joint drawn nearest the window point (x, y) within 12 pixels, or -1.
function jointAt(viewer, x, y) {
  let best = -1;
  let bestDistance = 12;
  viewer.mainSkin.joints.forEach((n, j) => {
    const screen = projectJoint(viewer, j);
    const d = screen ? Math.hypot(screen.x - x, screen.y - y) : Infinity;
    if (d < bestDistance) {
      bestDistance = d;
      best = j;
    }
  });
  return best;
}

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
function turnJointTowards(viewer, drag, pointer) {
  const { scene, mainSkin } = viewer;
  updateWorld(scene);
  const node = scene.nodes[mainSkin.joints[drag.joint]];
  const centre = projectJoint(viewer, drag.joint);
  const away = (q) => q && Math.hypot(q.x - centre.x, q.y - centre.y) >= POSE_DEAD_ZONE;
  if (!centre || !away(pointer)) return;
  const children = viewer.tree.childJoints[drag.joint].map((c) => scene.nodes[mainSkin.joints[c]].world);
  const child = children.length ? projectPoint(viewer, [12, 13, 14].map((i) => children.reduce((s, m) => s + m[i], 0) / children.length)) : null;
  const reference = away(child) ? child : drag.previous;
  drag.previous = pointer;
  if (!reference) return;
  const r = [reference.x - centre.x, reference.y - centre.y];
  const p = [pointer.x - centre.x, pointer.y - centre.y];
  const angle = -Math.atan2(r[0] * p[1] - r[1] * p[0], r[0] * p[0] + r[1] * p[1]);
  const parentWorld = node.parent >= 0 ? scene.nodes[node.parent].world : mat4.identity();
  const userFrame = mat4.multiply(parentWorld, baseTransform(node));
  const axis = quat.rotate(quat.conjugate(quat.fromMatrix(userFrame, mat4.columnLengths(userFrame))), viewDirection(viewer.camera));
  node.user = quat.toEulerDegrees(quat.multiply(quat.axisAngle(axis, angle), quat.fromEulerDegrees(node.user)));
  selectJoint(viewer, drag.joint);
}

// A move of the pointer while pressed: poses the dragged joint, or pans or orbits the camera.
function dragTo(viewer, drag, event) {
  const dx = event.clientX - drag.x;
  const dy = event.clientY - drag.y;
  drag.moved = drag.moved || Math.abs(dx) + Math.abs(dy) > 3;
  drag.x = event.clientX;
  drag.y = event.clientY;
  if (drag.joint >= 0) turnJointTowards(viewer, drag, { x: event.clientX, y: event.clientY });
  else if (drag.pan) panCamera(viewer.camera, dx, dy, viewer.canvas.clientHeight);
  else orbitCamera(viewer.camera, dx, dy);
  requestRender(viewer);
}

// The name of the joint under the free pointer, beside it; a crosshair when it can be dragged.
function showJointTip(viewer, event) {
  const tip = $('tip');
  const j = jointAt(viewer, event.clientX, event.clientY);
  tip.hidden = j < 0;
  viewer.canvas.style.cursor = j >= 0 && viewer.state.skeleton ? 'crosshair' : '';
  if (j >= 0) {
    tip.textContent = viewer.jointNames[j];
    tip.style.left = `${event.clientX + 12}px`;
    tip.style.top = `${event.clientY + 12}px`;
  }
}

// The canvas's pointer and wheel handlers.
function bindPointer(viewer) {
  const { canvas, camera, state } = viewer;
  // The pointer's last position, whether it moved over 3 pixels, whether it pans, the joint
  // being posed (-1 when the drag moves the camera) and its previous position while posing.
  let drag = null;
  canvas.addEventListener('contextmenu', (event) => event.preventDefault());
  canvas.addEventListener('pointerdown', (event) => {
    const pan = event.shiftKey || event.button === 2;
    const joint = !pan && event.button === 0 && state.skeleton ? jointAt(viewer, event.clientX, event.clientY) : -1;
    drag = { x: event.clientX, y: event.clientY, moved: false, pan, joint, previous: null };
    if (joint >= 0) selectJoint(viewer, joint);
    canvas.setPointerCapture(event.pointerId);
  });
  canvas.addEventListener('pointermove', (event) => (drag ? dragTo(viewer, drag, event) : showJointTip(viewer, event)));
  canvas.addEventListener('pointerup', (event) => {
    if (drag && !drag.moved) {
      const j = jointAt(viewer, event.clientX, event.clientY);
      if (j >= 0) selectJoint(viewer, j);
    }
    drag = null;
  });
  canvas.addEventListener('wheel', (event) => {
    event.preventDefault();
    camera.zoom = Math.max(0.05, Math.min(20, camera.zoom * Math.exp(event.deltaY * 0.001)));
    requestRender(viewer);
  }, { passive: false });
}
