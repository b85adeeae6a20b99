// The skinning report: the regions that colour the mesh, the boundary curves drawn on it
// and the side panel's tables.

function readReport() {
  const element = $('report-json');
  const text = element ? element.textContent.trim() : '';
  return text ? JSON.parse(text) : null;
}

const regionHue = (k) => (k * 0.618034) % 1;
function hslToRgb(h, s, l) {
  const f = (n) => {
    const k = (n + h * 12) % 12;
    return l - s * Math.min(l, 1 - l) * Math.max(-1, Math.min(k - 3, 9 - k, 1));
  };
  return [f(0), f(8), f(4)];
}

// Region of each skin joint: the report's regions (by joint name) when present, inherited
// from the nearest ancestor in a region; without a report every joint is its own region.
function regionOfJoints(scene, skin, report) {
  const regions = (report && report.decomposition && report.decomposition.regions) || [];
  const jointByName = new Map(skin.joints.map((n, j) => [scene.nodes[n].name, j]));
  const jointOfNode = new Map(skin.joints.map((n, j) => [n, j]));
  const region = new Int32Array(skin.joints.length).fill(-1);
  regions.forEach((r, k) => {
    const members = Array.isArray(r.joints) ? r.joints : r.joint !== undefined ? [r.joint] : [];
    for (const m of members) {
      const j = typeof m === 'number' ? m : jointByName.get(m);
      if (j !== undefined && j < region.length && region[j] < 0) region[j] = k;
    }
  });
  if (!regions.length) return region.map((_, j) => j);
  return region.map((r, j) => {
    for (let n = skin.joints[j]; r < 0 && n >= 0; n = scene.nodes[n].parent) {
      const ancestor = jointOfNode.get(n);
      if (ancestor !== undefined && region[ancestor] >= 0) r = region[ancestor];
    }
    return r < 0 ? regions.length + j : r;
  });
}

// Where each mesh's vertices start in one of the report's per-vertex arrays of `length`
// entries (decomposition.vertex_regions, pieces.vertex_treatments): by the report's
// vertex_ranges (the node and primitive of every range of stored vertices) when given, else
// 0 for the main mesh when the array has its vertex count; -1 for a mesh it does not cover.
function reportOffsets(model, length) {
  const ranges = model.report && Array.isArray(model.report.vertex_ranges) ? model.report.vertex_ranges : null;
  return model.items.map((item) => {
    if (!ranges) return item === model.main && length === item.vertexCount ? 0 : -1;
    const range = ranges.find((r) => r.node === item.node && r.primitive === item.primitive);
    return range && range.count === item.vertexCount && range.first + range.count <= length ? range.first : -1;
  });
}

// Vertex colours of each mesh, the hue of the vertex's region: the report's vertex_regions
// where they cover the mesh (reportOffsets), else the region of its dominant joint (region 0
// in meshes of other skins); and the number of vertices each main-skin joint dominates.
function regionColours(model) {
  const { report, items, mainSkin } = model;
  const regionOf = regionOfJoints(model.scene, mainSkin, report);
  const vertexRegions = report && report.decomposition && report.decomposition.vertex_regions;
  const explicitRegions = Array.isArray(vertexRegions) ? vertexRegions : [];
  const offsets = reportOffsets(model, explicitRegions.length);
  const dominantCount = new Uint32Array(mainSkin.joints.length);
  const colours = items.map((item, i) => {
    const dominant = dominantJoints(item);
    const rgb = new Float32Array(item.vertexCount * 3);
    for (let v = 0; v < item.vertexCount; v++) {
      const explicit = offsets[i] >= 0 ? explicitRegions[offsets[i] + v] : null;
      const region = Number.isInteger(explicit) ? explicit : item.skin === mainSkin ? regionOf[dominant[v]] : 0;
      if (item.skin === mainSkin) dominantCount[dominant[v]]++;
      rgb.set(hslToRgb(regionHue(region), 0.55, 0.6), v * 3);
    }
    return rgb;
  });
  return { colours, dominantCount };
}

// Fixed colour of each piece treatment the report names (pieces.treatments); a name this
// viewer does not know is grey.
const TREATMENT_COLOURS = {
  body: [0.6, 0.66, 0.75],
  attached: [0.2, 0.72, 0.66],
  rigid: [0.95, 0.68, 0.18],
  joints: [0.62, 0.42, 0.88],
  fallback: [0.92, 0.22, 0.22],
};
const treatmentColour = (name) => TREATMENT_COLOURS[name] || [0.45, 0.45, 0.45];

// The report's treatment of the stored vertices: the treatment names, each vertex's index
// into them (pieces.treatments, pieces.vertex_treatments) and where each mesh's vertices
// start in them (reportOffsets); null without them or when they cover no mesh.
function vertexTreatments(model) {
  const pieces = model.report && model.report.pieces;
  const names = pieces && pieces.treatments;
  const indices = pieces && pieces.vertex_treatments;
  if (!Array.isArray(names) || !Array.isArray(indices)) return null;
  const offsets = reportOffsets(model, indices.length);
  if (offsets.every((offset) => offset < 0)) return null;
  return { names: names.map(String), indices, offsets };
}

// Vertex colours of each mesh in the pieces view: its vertex's treatment colour where the
// report covers the mesh, grey elsewhere; and how many vertices each treatment has.
function pieceColours(model, treatments) {
  const counts = new Map();
  const colours = model.items.map((item, i) => {
    const offset = treatments.offsets[i];
    const rgb = new Float32Array(item.vertexCount * 3);
    for (let v = 0; v < item.vertexCount; v++) {
      const name = offset >= 0 ? treatments.names[treatments.indices[offset + v]] : undefined;
      if (name !== undefined) counts.set(name, (counts.get(name) || 0) + 1);
      rgb.set(treatmentColour(name), v * 3);
    }
    return rgb;
  });
  return { colours, counts };
}

// The pieces view's legend: a swatch, the name and the vertex count of every treatment
// present, in the report's order.
function renderPieceLegend(names, counts) {
  const legend = $('pieces-legend');
  for (const name of names.filter((n) => counts.has(n))) {
    const entry = legend.appendChild(element('span', undefined, 'treatment'));
    const swatch = entry.appendChild(element('span', undefined, 'swatch area'));
    swatch.style.background = `rgb(${treatmentColour(name).map((c) => Math.round(c * 255)).join(',')})`;
    entry.appendChild(document.createTextNode(`${name} ${counts.get(name)}`));
  }
}

// Boundaries as closed polylines in bind space: `cuts` from decomposition.joints[].curve,
// `planes` a circle of the boundary's diameter in its plane (point, normal) for a joint
// with a plane but no curve (a soft boundary).
function boundaryCurves(report) {
  const joints = (report && report.decomposition && report.decomposition.joints) || [];
  const isVec3 = (v) => Array.isArray(v) && v.length === 3 && v.every(Number.isFinite);
  const cuts = [];
  const planes = [];
  for (const joint of joints) {
    if (Array.isArray(joint.curve) && joint.curve.length > 1 && joint.curve.every(isVec3)) {
      cuts.push(joint.curve);
    } else if (isVec3(joint.point) && isVec3(joint.normal) && Number.isFinite(joint.diameter)) {
      const n = vec3.normalize(joint.normal);
      const u = vec3.normalize(vec3.cross(n, Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0]));
      const w = vec3.cross(n, u);
      const radius = joint.diameter / 2;
      planes.push(Array.from({ length: 48 }, (_, k) => {
        const a = (2 * Math.PI * k) / 48;
        return [0, 1, 2].map((c) => joint.point[c] + radius * (Math.cos(a) * u[c] + Math.sin(a) * w[c]));
      }));
    }
  }
  return { cuts, planes };
}

// The meshes whose influences the boundary curves take: the main mesh and every other mesh
// skinned over the same joints in the same order (a character split into several skinned
// meshes), so that a curve around a part outside the main mesh follows that part.
function curveMeshes(model) {
  const joints = model.mainSkin.joints;
  const sameJoints = (skin) => skin === model.mainSkin || (!skin.rigid && skin.joints.length === joints.length && skin.joints.every((n, j) => n === joints[j]));
  return model.items.filter((item) => item === model.main || (item.weights0 && sameJoints(item.skin)));
}

// Line segments of the curves; each point takes the influences of the nearest vertex of
// `items` (bind space) so the curves follow the skinned surface.
function curveGeometry(curves, items) {
  const segments = curves.reduce((s, c) => s + c.length, 0);
  const positions = new Float32Array(segments * 6);
  const joints0 = new Uint32Array(segments * 8);
  const weights0 = new Float32Array(segments * 8);
  let s = 0;
  const emit = (p) => {
    let item = items[0];
    let best = 0;
    let bestDistance = Infinity;
    for (const candidate of items) {
      for (let v = 0; v < candidate.vertexCount; v++) {
        const dx = candidate.positions[v * 3] - p[0];
        const dy = candidate.positions[v * 3 + 1] - p[1];
        const dz = candidate.positions[v * 3 + 2] - p[2];
        const d = dx * dx + dy * dy + dz * dz;
        if (d < bestDistance) {
          bestDistance = d;
          best = v;
          item = candidate;
        }
      }
    }
    positions.set(p, s * 3);
    if (item.weights0) {
      joints0.set(item.joints0.subarray(best * 4, best * 4 + 4), s * 4);
      weights0.set(item.weights0.subarray(best * 4, best * 4 + 4), s * 4);
    } else {
      weights0[s * 4] = 1;
    }
    s++;
  };
  for (const curve of curves) {
    curve.forEach((p, k) => {
      emit(p);
      emit(curve[(k + 1) % curve.length]);
    });
  }
  return { positions, joints0, weights0, count: s };
}

function formatValue(value) {
  if (typeof value === 'number') return Number.isInteger(value) ? String(value) : value.toPrecision(4);
  if (Array.isArray(value)) return value.map(formatValue).join(', ');
  if (value && typeof value === 'object') return JSON.stringify(value);
  return value === undefined || value === null ? '' : String(value);
}

function element(tag, text, className) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (className) e.className = className;
  return e;
}

// A table of objects: `preferred` columns first, then any other key whose values are
// scalars or lists of names (vectors and curves are left out).
function objectTable(rows, preferred, onRowClick) {
  const shown = (v) => v === null || typeof v !== 'object' || (Array.isArray(v) && v.every((x) => typeof x === 'string'));
  const columns = [];
  for (const row of rows) {
    for (const [key, value] of Object.entries(row || {})) {
      if (!columns.includes(key) && shown(value)) columns.push(key);
    }
  }
  columns.sort((a, b) => {
    const rank = (k) => {
      const i = preferred.findIndex((p) => k === p || k.startsWith(p));
      return i < 0 ? preferred.length : i;
    };
    return rank(a) - rank(b);
  });
  const wrapper = element('div', undefined, 'scroll');
  const table = wrapper.appendChild(element('table'));
  const head = table.appendChild(element('tr'));
  columns.forEach((c) => head.appendChild(element('th', c)));
  for (const row of rows) {
    const tr = table.appendChild(element('tr', undefined, row && row.status ? `status-${String(row.status).toLowerCase()}` : ''));
    for (const c of columns) {
      // Long texts are cut to one line; the whole text shows on hover.
      const text = formatValue(row && row[c]);
      tr.appendChild(element('td', text)).title = text;
    }
    if (onRowClick) tr.addEventListener('click', () => onRowClick(row));
  }
  return wrapper;
}

function renderReport(report, selectJointByName) {
  const panel = $('report');
  if (!report) {
    panel.appendChild(element('p', 'No skinning report was given: the view shows the weights stored in the file.', 'note'));
    return;
  }
  const section = (title) => {
    panel.appendChild(element('h3', title));
    return panel;
  };
  const decomposition = report.decomposition || {};
  if (Array.isArray(decomposition.joints) && decomposition.joints.length) {
    section('Joints').appendChild(objectTable(decomposition.joints, ['name', 'status', 'perimeter', 'diameter', 'overlap', 'reason'], (row) => selectJointByName(row && row.name)));
  }
  if (Array.isArray(decomposition.regions) && decomposition.regions.length) {
    section('Regions').appendChild(objectTable(decomposition.regions, ['joint', 'joints', 'faces', 'vertices']));
  }
  const timings = report.timings_ms;
  if (timings && typeof timings === 'object') {
    const rows = Array.isArray(timings) ? timings : Object.entries(timings).map(([stage, ms]) => ({ stage, ms }));
    section('Stage timings (ms)').appendChild(objectTable(rows, ['stage', 'ms']));
  }
  const facts = Object.entries(report).filter(([, v]) => v === null || typeof v !== 'object');
  if (report.counts && typeof report.counts === 'object') facts.push(...Object.entries(report.counts));
  if (facts.length) section('Counts').appendChild(objectTable(facts.map(([key, value]) => ({ key, value })), ['key', 'value']));
  const warnings = Array.isArray(report.warnings) ? report.warnings : [];
  const list = section(`Warnings (${warnings.length})`).appendChild(element('ul'));
  warnings.forEach((w) => list.appendChild(element('li', typeof w === 'string' ? w : JSON.stringify(w))));
}
