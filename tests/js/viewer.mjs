// Browser test of an atlas-skin HTML report in Debian's headless Chromium.
//
//   node tests/js/viewer.mjs REPORT.html SCREENSHOT_PREFIX
//
// Opens the report from file://, records console errors, page errors and every network
// request other than the file itself and data: URLs, then checks through the viewer's test
// hook (window.atlasViewer) that the canvas is not blank, that moving a joint slider, the
// weight heat map and the animation time change the pixels, that the LBS/DQS switch switches
// (checks.dqs_changed_fraction: how much of the picture it changed), that a hovered joint
// shows its name and a clicked one is selected, and that dragging a joint poses it
// (checks.drag_*, see dragJoint); when the report gives every vertex's piece treatment, that
// the pieces view changes the colours, shows a legend (checks.pieces_legend: "name count"
// per treatment) and switches back. checks.skinning_probe holds GPU-skinned positions (LBS
// and DQS) of the posed model with the weights and palette that made them. Saves
// screenshots SCREENSHOT_PREFIX-{regions,weights,pieces (when offered),pose-lbs,pose-dqs}.png
// and prints one JSON object: { failures: [...], checks: {...}, screenshots: [...] };
// checks.half_time_poses holds, per animation, the animated node values at half its
// duration.
import { launchChromium } from './chromium.mjs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [reportPath, screenshotPrefix] = process.argv.slice(2);
if (!reportPath || !screenshotPrefix) {
  console.error('usage: node viewer.mjs REPORT.html SCREENSHOT_PREFIX');
  process.exit(2);
}
const fileUrl = pathToFileURL(resolve(reportPath)).href;
const failures = [];
const checks = {};
const screenshots = [];

// Fraction of thumbnail samples that differ by more than 8 grey levels.
const changed = (a, b) => a.filter((v, i) => Math.abs(v - b[i]) > 8).length / a.length;

// Grey-level thumbnail of a freshly rendered frame (see the viewer's test hook).
const thumbnail = (page) => page.evaluate(() => window.atlasViewer.thumbnail());
// Angle in degrees between the rotations of two unit quaternions.
const rotationAngle = (a, b) => (2 * Math.acos(Math.min(1, Math.abs(a.reduce((s, x, i) => s + x * b[i], 0)))) * 180) / Math.PI;
// Angle in degrees between two window-space vectors.
const screenAngle = (a, b) => (Math.abs(Math.atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y)) * 180) / Math.PI;
const meanPoint = (points) => ({ x: points.reduce((s, p) => s + p.x, 0) / points.length, y: points.reduce((s, p) => s + p.y, 0) / points.length });
// The joint sliders' values (degrees).
const sliders = (page) => Promise.all(['x', 'y', 'z'].map((a) => page.locator(`#rot-${a}`).inputValue().then(Number)));

// Drag to pose: picks the non-root joint with children whose bone (joint to the mean of its
// children) is longest on screen, presses on it and moves the pointer 80 px across the bone.
// Records that the camera stayed, the joint's rotation, the picture and its sliders changed,
// the bone points at the pointer and "Reset pose" undoes the drag. `screen`: every joint's
// window position in the rest pose (null behind the eye).
// Models without a joint that has a parent and children (checks.drag_joint null) are left out.
async function dragJoint(page, screen) {
  const joints = await page.evaluate(() => window.atlasViewer.joints());
  const view = await page.evaluate(() => document.getElementById('view').getBoundingClientRect().toJSON());
  const inView = (p) => p.x > view.left + 2 && p.x < view.right - 2 && p.y > view.top + 2 && p.y < view.bottom - 2;
  const childMean = (j) => {
    const children = joints.filter((k) => k.parent === j && screen[k.index]).map((k) => screen[k.index]);
    return children.length ? meanPoint(children) : null;
  };
  const withChildren = joints.filter((j) => j.parent >= 0 && joints.some((k) => k.parent === j.index));
  checks.drag_joint = null;
  if (!withChildren.length) return;
  let best = null;
  for (const { index } of withChildren) {
    const at = screen[index];
    const mean = childMean(index);
    if (!at || !mean || !inView(at) || screen.some((q, k) => k !== index && q && Math.hypot(q.x - at.x, q.y - at.y) < 4)) continue;
    const bone = { x: mean.x - at.x, y: mean.y - at.y };
    const length = Math.hypot(bone.x, bone.y);
    const targets = [1, -1].map((side) => ({ x: at.x - (side * 80 * bone.y) / length, y: at.y + (side * 80 * bone.x) / length }));
    const target = targets.find(inView);
    if (length >= 20 && target && (!best || length > best.length)) best = { index, at, length, target };
  }
  if (!best) {
    failures.push('no joint with children stands apart on screen to drag');
    return;
  }
  const { index, at, target } = best;
  checks.drag_joint = joints[index].name;
  await page.selectOption('#joint', String(index));
  const camera = await page.evaluate(() => window.atlasViewer.camera());
  const rotation = await page.evaluate((j) => window.atlasViewer.jointRotation(j), index);
  const before = await thumbnail(page);
  checks.drag_sliders_before = await sliders(page);
  await page.mouse.move(at.x, at.y);
  await page.mouse.down();
  await page.mouse.move(target.x, target.y, { steps: 10 });
  await page.mouse.up();
  const after = await thumbnail(page);
  checks.drag_camera_unchanged = JSON.stringify(camera) === JSON.stringify(await page.evaluate(() => window.atlasViewer.camera()));
  const turned = await page.evaluate((j) => window.atlasViewer.jointRotation(j), index);
  checks.drag_rotation_degrees = rotationAngle(rotation.quaternion, turned.quaternion);
  checks.drag_changed_fraction = changed(before, after);
  checks.drag_sliders_after = await sliders(page);
  checks.drag_sliders_changed = checks.drag_sliders_after.some((v, k) => v !== checks.drag_sliders_before[k])
    && checks.drag_sliders_after.every((v, k) => Math.abs(v - turned.degrees[k]) <= 0.5)
    && (await page.locator('#joint').inputValue()) === String(index);
  const [centre, ...children] = await page.evaluate(({ j, children }) => [j, ...children].map((k) => window.atlasViewer.projectJoint(k)), { j: index, children: joints.filter((k) => k.parent === index).map((k) => k.index) });
  const mean = meanPoint(children);
  checks.drag_aim_error_degrees = screenAngle({ x: mean.x - centre.x, y: mean.y - centre.y }, { x: target.x - centre.x, y: target.y - centre.y });
  await page.click('#reset-pose');
  checks.drag_reset_degrees = rotationAngle(rotation.quaternion, (await page.evaluate((j) => window.atlasViewer.jointRotation(j), index)).quaternion);
  if (!checks.drag_camera_unchanged) failures.push(`dragging joint ${checks.drag_joint} moved the camera`);
  if (!(checks.drag_rotation_degrees > 20)) failures.push(`dragging joint ${checks.drag_joint} turned it by ${checks.drag_rotation_degrees}°`);
  if (checks.drag_changed_fraction < 0.002) failures.push(`dragging joint ${checks.drag_joint} did not change the picture`);
  if (!checks.drag_sliders_changed) failures.push(`dragging joint ${checks.drag_joint} did not show its angles on the sliders`);
  if (!(checks.drag_aim_error_degrees < 10)) failures.push(`after dragging joint ${checks.drag_joint} its bone misses the pointer by ${checks.drag_aim_error_degrees}°`);
  if (!(checks.drag_reset_degrees < 1e-6)) failures.push(`"Reset pose" left joint ${checks.drag_joint} turned by ${checks.drag_reset_degrees}°`);
}

const { context, close } = await launchChromium();
try {
  context.on('request', (request) => {
    const url = request.url();
    if (url !== fileUrl && !url.startsWith('data:')) failures.push(`network request: ${url}`);
  });
  const page = context.pages()[0] || (await context.newPage());
  // SwiftShader on a loaded 2-core machine can be slow: generous limits, never a hang.
  page.setDefaultTimeout(120000);
  page.on('console', (message) => {
    if (message.type() === 'error') failures.push(`console error: ${message.text()}`);
  });
  page.on('pageerror', (error) => failures.push(`page error: ${error.message}`));

  await page.goto(fileUrl);
  await page.waitForFunction(() => window.atlasViewer && (window.atlasViewer.ready || window.atlasViewer.error), null, { timeout: 120000 });
  const error = await page.evaluate(() => window.atlasViewer.error);
  if (error) throw new Error(`viewer error: ${error}`);
  const shoot = async (name) => {
    const path = `${screenshotPrefix}-${name}.png`;
    await page.screenshot({ path });
    screenshots.push(path);
  };

  // Not blank: enough samples away from the background and some spread of grey levels.
  const rest = await thumbnail(page);
  const background = rest[0];
  const mean = rest.reduce((s, v) => s + v, 0) / rest.length;
  checks.foreground_fraction = rest.filter((v) => Math.abs(v - background) > 8).length / rest.length;
  checks.grey_variance = rest.reduce((s, v) => s + (v - mean) ** 2, 0) / rest.length;
  if (checks.foreground_fraction < 0.02 || checks.grey_variance < 10) failures.push('the canvas is blank');
  await shoot('regions');

  // Hover a joint that stands apart from the others: its name shows; a click selects it.
  const screen = await page.evaluate(() => window.atlasViewer.joints().map((j) => window.atlasViewer.projectJoint(j.index)));
  const apart = screen.findIndex((p, j) => p && screen.every((q, k) => k === j || !q || Math.hypot(p.x - q.x, p.y - q.y) > 14));
  if (apart < 0) {
    failures.push('no joint stands apart on screen to hover');
  } else {
    const names = await page.evaluate(() => window.atlasViewer.joints().map((j) => j.name));
    await page.mouse.move(screen[apart].x, screen[apart].y);
    checks.hover_name = await page.locator('#tip').textContent();
    if (!(await page.locator('#tip').isVisible()) || checks.hover_name !== names[apart]) failures.push(`hovering joint ${names[apart]} showed "${checks.hover_name}"`);
    await page.mouse.click(screen[apart].x, screen[apart].y);
    if ((await page.locator('#joint').inputValue()) !== String(apart)) failures.push('clicking a joint did not select it');
  }
  await dragJoint(page, screen);
  checks.curve_segments = await page.evaluate(() => window.atlasViewer.curveSegments);
  checks.report_tables = await page.locator('#report table').count();
  checks.report_rows = await page.locator('#report tr').count();

  // The weights of the joint that dominates the most vertices, then bend that joint.
  const joints = await page.evaluate(() => window.atlasViewer.joints());
  const joint = joints.reduce((a, b) => (b.vertices > a.vertices ? b : a));
  checks.posed_joint = joint.name;
  await page.selectOption('#joint', String(joint.index));
  await page.check('#colour-weights');
  checks.heat_map_changed_fraction = changed(rest, await thumbnail(page));
  if (checks.heat_map_changed_fraction < 0.005) failures.push('the weight heat map did not change the picture');
  await shoot('weights');
  await page.check('#colour-regions');

  // The pieces view, offered when the report gives every vertex's treatment: other colours
  // and a legend of the treatments present; back on the regions, the picture is as before.
  checks.pieces_offered = await page.locator('#colour-pieces').isVisible();
  if (checks.pieces_offered) {
    const regions = await thumbnail(page);
    await page.check('#colour-pieces');
    checks.pieces_changed_fraction = changed(regions, await thumbnail(page));
    checks.pieces_legend = await page.locator('#pieces-legend .treatment').allTextContents();
    const legendShown = await page.locator('#pieces-legend').isVisible();
    await shoot('pieces');
    await page.check('#colour-regions');
    checks.pieces_back_changed_fraction = changed(regions, await thumbnail(page));
    if (checks.pieces_changed_fraction < 0.005) failures.push('the pieces view did not change the picture');
    if (!checks.pieces_legend.length || !legendShown) failures.push('the pieces view shows no legend');
    if (await page.locator('#pieces-legend').isVisible()) failures.push('the legend of the pieces stays in the regions view');
    if (checks.pieces_back_changed_fraction > 0) failures.push('back from the pieces view, the regions did not come back');
  }

  await page.locator('#rot-x').fill('90');
  await page.locator('#rot-z').fill('45');
  const posed = await thumbnail(page);
  checks.slider_changed_fraction = changed(rest, posed);
  checks.skinning_probe = await page.evaluate(() => window.atlasViewer.skinningProbe());
  if (checks.slider_changed_fraction < 0.005) failures.push('moving a joint slider did not change the picture');
  await shoot('pose-lbs');

  await page.check('#method-dqs');
  const dqs = await thumbnail(page);
  checks.dqs_enabled = await page.evaluate(() => window.atlasViewer.state.dqs);
  checks.dqs_changed_fraction = changed(posed, dqs);
  if (!checks.dqs_enabled) failures.push('the DQS switch did not switch');
  if (dqs.filter((v) => Math.abs(v - background) > 8).length / dqs.length < 0.02) failures.push('the canvas is blank under DQS');
  await shoot('pose-dqs');

  await page.click('#reset-pose');
  checks.animations = await page.locator('#animation option').count() - 1;
  if (checks.animations > 0) {
    await page.selectOption('#animation', '0');
    const start = await thumbnail(page);
    await page.locator('#time').fill('0.5');
    checks.animation_changed_fraction = changed(start, await thumbnail(page));
    if (checks.animation_changed_fraction < 0.002) failures.push('the animation time slider did not change the picture');
  }
  checks.half_time_poses = await page.evaluate(() => window.atlasViewer.animations().map((a, i) => window.atlasViewer.poseAt(i, a.duration / 2)));
  checks.gl_error = await page.evaluate(() => window.atlasViewer.glError());
  if (checks.gl_error !== 0) failures.push(`WebGL error ${checks.gl_error}`);
} catch (error) {
  failures.push(String(error && error.stack ? error.stack : error));
} finally {
  await close();
}
console.log(JSON.stringify({ failures, checks, screenshots }, null, 1));
