// The README's picture of a weight transfer: two HTML reports of one character (a garment
// before transfer and after it) opened in Debian's headless Chromium, posed alike, side by
// side in one PNG.
//
//   node tests/js/transfer_picture.mjs BEFORE.html AFTER.html OUT.png POSE
//
// POSE, JSON: { "orbit": [dx, dy] (pixels dragged across the view to turn the camera),
// "zoom": wheel steps (negative: nearer), "animation": [index, time in seconds] (the pose:
// a frame of one of the file's animations), "labels": [before, after] }. Each report is
// shown with the skeleton, the boundaries and the help line hidden, coloured by region
// (each vertex by its dominant joint); fails when a report does not load or the pose
// leaves its picture unchanged.
import { launchChromium } from './chromium.mjs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [beforePath, afterPath, outPath, poseJson] = process.argv.slice(2);
if (!beforePath || !afterPath || !outPath || !poseJson) {
  console.error('usage: node transfer_picture.mjs BEFORE.html AFTER.html OUT.png POSE');
  process.exit(2);
}
const pose = JSON.parse(poseJson);
const changed = (a, b) => a.filter((v, i) => Math.abs(v - b[i]) > 8).length / a.length;

const { context, close } = await launchChromium();

// The posed view of one report, as a PNG of the canvas.
async function posedView(page, path) {
  await page.goto(pathToFileURL(resolve(path)).href);
  await page.waitForFunction(() => window.atlasViewer && (window.atlasViewer.ready || window.atlasViewer.error), null, { timeout: 120000 });
  const error = await page.evaluate(() => window.atlasViewer.error);
  if (error) throw new Error(`${path}: viewer error: ${error}`);
  await page.addStyleTag({ content: '#help { display: none !important; }' });
  await page.uncheck('#show-skeleton');
  await page.uncheck('#show-curves');
  const view = await page.evaluate(() => document.getElementById('view').getBoundingClientRect().toJSON());
  const [dx, dy] = pose.orbit || [0, 0];
  await page.mouse.move(view.left + 10, view.top + 10);
  await page.mouse.down();
  await page.mouse.move(view.left + 10 + dx, view.top + 10 + dy, { steps: 10 });
  await page.mouse.up();
  if (pose.zoom) {
    await page.mouse.move(view.left + view.width / 2, view.top + view.height / 2);
    await page.mouse.wheel(0, pose.zoom * 100);
  }
  const rest = await page.evaluate(() => window.atlasViewer.thumbnail());
  await page.selectOption('#animation', String(pose.animation[0]));
  await page.locator('#time').fill(String(pose.animation[1]));
  const posed = await page.evaluate(() => window.atlasViewer.thumbnail());
  if (changed(rest, posed) < 0.005) throw new Error(`${path}: the pose did not change the picture`);
  return (await page.locator('#view').screenshot()).toString('base64');
}

let failed = null;
try {
  const page = context.pages()[0] || (await context.newPage());
  page.setDefaultTimeout(120000);
  const shots = [];
  for (const path of [beforePath, afterPath]) shots.push(await posedView(page, path));
  const [beforeLabel, afterLabel] = pose.labels || ['before', 'after'];
  const panel = (png, label) => `<figure><img src="data:image/png;base64,${png}"><figcaption>${label}</figcaption></figure>`;
  await page.setViewportSize({ width: 900, height: 200 });
  await page.setContent(`<!doctype html><style>
    body { margin: 0; display: flex; background: #fff; font: 16px sans-serif; }
    figure { margin: 0; width: 450px; text-align: center; }
    img { width: 450px; height: auto; display: block; }
    figcaption { padding: 8px 0; }
  </style>${panel(shots[0], beforeLabel)}${panel(shots[1], afterLabel)}`);
  await page.screenshot({ path: outPath, fullPage: true });
} catch (error) {
  failed = error;
} finally {
  await close();
}
if (failed) {
  console.error(String(failed && failed.stack ? failed.stack : failed));
  process.exit(1);
}
console.log(`wrote ${outPath}`);
