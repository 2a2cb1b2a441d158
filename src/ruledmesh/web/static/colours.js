// Face colourings, their legend and the panel figures: functions of a state, no DOM.
// `state` is {header, arrays, areas, closeness, classes}: the decoded message (see
// session.py) and the per-face figures the page has (areas measured here, closeness and
// classes from the slow figures, null until they arrive).
import * as THREE from './vendor/three-bundle.min.js';

export const KIND_COLOURS = ['#4f86c6', '#7cb35a', '#e0a030', '#d05050', '#9060c0', '#909090'];
const RAMP = [[0.23, 0.30, 0.75], [0.35, 0.70, 0.90], [0.55, 0.80, 0.45], [0.95, 0.80, 0.25],
              [0.85, 0.25, 0.20]];
export const CLASS_PALETTE = ['#4e79a7', '#f28e2b', '#e15759', '#76b7b2', '#59a14f', '#edc948',
                              '#b07aa1', '#ff9da7', '#9c755f', '#bab0ac', '#1f77b4', '#aec7e8'];
// Triangles in the planarity colouring: flat whatever the design, so they say nothing there.
const FLAT_GREY = '#d4d4d4';
const GREY = KIND_COLOURS[5];
// The smallest-angle colouring: a log scale from a right angle down, splinters and thin
// panels apart, the splinter limit at 80 % of the ramp like the planarity tolerance (so
// splinters are orange to red).
const RIGHT_ANGLE = 90;
const MARK_AT = 0.8;

export const fmt = (v, digits = 3) => (typeof v === 'number'
  ? (Math.abs(v) !== 0 && (Math.abs(v) < 1e-3 || Math.abs(v) >= 1e6) ? v.toExponential(2)
    : String(+v.toPrecision(digits + 1))) : String(v));
const pct = (share) => `${(100 * share).toFixed(1)} %`;
const faceLink = (f) => `<a href="#" class="face" data-face="${f}">P${f}</a>`;

function ramp(t) {
  t = Math.min(Math.max(t, 0), 1) * (RAMP.length - 1);
  const i = Math.min(Math.floor(t), RAMP.length - 2), f = t - i;
  return RAMP[i].map((c, k) => c + (RAMP[i + 1][k] - c) * f);
}
const rampCss = () => RAMP.map((c, i) => `rgb(${c.map((x) => Math.round(255 * x)).join(',')}) ${
  100 * i / (RAMP.length - 1)}%`).join(',');

export function range(values) {
  let lo = Infinity, hi = -Infinity;
  for (let i = 0; i < values.length; i++) {
    const v = values[i];
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  return values.length ? [lo, hi] : [0, 1];
}

function median(values) {
  if (!values.length) return 0;
  const sorted = Float64Array.from(values).sort();
  return sorted[Math.floor(sorted.length / 2)];
}

// Whether each face has more than three corners (only those can be out of plane).
function polygonal(state) {
  const off = state.arrays.face_offsets;
  const out = new Uint8Array(off.length - 1);
  for (let f = 0; f < out.length; f++) out[f] = off[f + 1] - off[f] > 3 ? 1 : 0;
  return out;
}

// The scale of each ramp colouring: {lo, hi, log, label, mark, markName, tick} (lo is the
// ramp's blue end: for the angle it is the largest value).
function scaleOf(state, mode) {
  const fig = state.header.figures;
  const logTick = (x) => `1e${+x.toFixed(1)}`;
  if (mode === 'planarity') {
    // From exact (1e-16) to two decades past the tolerance: the tolerance sits at 80 %, so
    // faces within it are blue-green and the ones over it orange to red.
    const tol = fig.planarity_tolerance || 1e-12;
    return { lo: -16, hi: Math.log10(tol) + 2, log: true, mark: Math.log10(tol), markName: 'tolerance',
             tick: logTick,
             label: `planarity (relative, log scale) of the faces with 4+ corners; tolerance ${
               tol.toExponential(0)}` };
  }
  if (mode === 'closeness') {
    return { lo: -6, hi: -1, log: true, tick: logTick,
             label: 'closeness: centroid distance / diagonal (log)' };
  }
  if (mode === 'angle') {
    const lo = Math.log10(RIGHT_ANGLE), mark = Math.log10(fig.splinter_deg);
    return { lo, hi: lo + (mark - lo) / MARK_AT, log: true, mark, markName: 'splinter',
             tick: (x) => `${+(10 ** x).toPrecision(2)}°`,
             label: `smallest angle of each face (log scale); splinters below ${fig.splinter_deg}°` };
  }
  const [lo, hi] = range(state.areas);
  return { lo, hi: hi > lo ? hi : lo + 1, log: false, tick: (x) => fmt(x), label: 'panel area (design units²)' };
}

function valuesOf(state, mode) {
  if (mode === 'planarity') return state.arrays.planarity;
  if (mode === 'closeness') return state.closeness;
  if (mode === 'area') return state.areas;
  if (mode === 'angle') return state.arrays.min_angle;
  return null;
}

// (F * 3) linear RGB of each face in colouring `mode`.
export function faceColours(state, mode) {
  const nf = state.arrays.kind.length;
  const out = new Float32Array(nf * 3);
  const values = valuesOf(state, mode);
  if (mode === 'kind' || mode === 'class' || !values) {
    const byClass = mode === 'class' && state.classes;
    const grey = !byClass && mode !== 'kind';  // slow figures not there yet
    const palette = (byClass ? CLASS_PALETTE : KIND_COLOURS).map((c) => new THREE.Color(c));
    const { kind } = state.arrays;
    const g = new THREE.Color(GREY);
    for (let f = 0; f < nf; f++) {
      const c = grey ? g : byClass ? palette[state.classes[f] % palette.length] : palette[kind[f]] || g;
      out[3 * f] = c.r; out[3 * f + 1] = c.g; out[3 * f + 2] = c.b;
    }
    return out;
  }
  const { lo, hi, log } = scaleOf(state, mode);
  const flat = mode === 'planarity' ? polygonal(state) : null;
  const fg = new THREE.Color(FLAT_GREY);
  for (let f = 0; f < nf; f++) {
    if (flat && !flat[f]) { out[3 * f] = fg.r; out[3 * f + 1] = fg.g; out[3 * f + 2] = fg.b; continue; }
    const v = log ? Math.log10(Math.max(values[f], 1e-30)) : values[f];
    const c = ramp((v - lo) / (hi - lo));
    out[3 * f] = c[0]; out[3 * f + 1] = c[1]; out[3 * f + 2] = c[2];
  }
  return out;
}

function kindLegend(state) {
  const kinds = state.header.choices.face_kinds || [];
  const shares = state.header.figures.area_share?.by_kind || {};
  const counts = new Array(kinds.length).fill(0);
  for (const k of state.arrays.kind) counts[k] += 1;
  const html = kinds.map((k, i) => (counts[i] ? `<span class="swatch" style="background:${
    KIND_COLOURS[i]}"></span>${k} <b>${counts[i]}</b>${k in shares ? ` (${pct(shares[k])})` : ''}`
    : '')).join('');
  return { html, stats: { counts: Object.fromEntries(kinds.map((k, i) => [k, counts[i]])) } };
}

function classLegend(state) {
  const { classes } = state;
  const n = classes ? range(classes)[1] + 1 : null;
  const html = classes ? `congruence classes: <b>${n}</b> different panels for ${
    classes.length} faces (colours repeat every ${CLASS_PALETTE.length})`
    : 'congruence classes (computing...)';
  return { html, stats: { classes: n } };
}

// The legend of colouring `mode`: {html, stats}; the stats are the figures it shows (min,
// median, max; for planarity and the angle how many faces are past the mark).
export function legend(state, mode) {
  if (mode === 'kind') return kindLegend(state);
  if (mode === 'class') return classLegend(state);
  let values = valuesOf(state, mode);
  const sc = scaleOf(state, mode);
  const stats = {};
  let figures = '';
  if (values && mode === 'planarity') {
    const poly = polygonal(state);
    values = values.filter((v, f) => poly[f]);
  }
  if (values) {
    const [lo, hi] = range(values);
    Object.assign(stats, { min: lo, median: median(values), max: hi, faces: values.length });
    const unit = mode === 'angle' ? '°' : '';
    figures = `min <b>${fmt(lo)}${unit}</b> · median <b>${fmt(stats.median)}${unit}</b> · max <b>${
      fmt(hi)}${unit}</b>`;
    if (mode === 'planarity') {
      // As analyze tells them apart: exact to rounding, within the design's tolerance, over.
      const { planarity_tolerance: tol, planarity_exact: exact, planarity_counts: counts }
        = state.header.figures;
      // The server's counts (analyze's rule: far from the origin a face is exact within what
      // its stored coordinates' rounding explains).
      stats.exact = counts.exact;
      stats.over = counts.over;
      stats.within = values.length - stats.exact - stats.over;
      figures += `<br>exact <b data-legend="exact">${stats.exact}</b>${tol > exact
        ? ` · within the tolerance <b data-legend="within">${stats.within}</b>` : ''}` +
        ` · over the tolerance <b data-legend="over">${stats.over}</b> of ${values.length}` +
        ` (triangles, flat, in grey)`;
    } else if (mode === 'angle') {
      const below = state.header.figures.splinter_deg;
      stats.below = values.reduce((n, v) => n + (v < below), 0);
      figures += `<br>below ${below}°: <b data-legend="below">${stats.below}</b> of ${values.length}`;
    }
  }
  // The mark's name beside it, on the side away from the nearer end (not over its tick).
  const at = sc.mark !== undefined ? 100 * (sc.mark - sc.lo) / (sc.hi - sc.lo) : null;
  const mark = at !== null ? `<div class="mark" style="left:${at}%" title="${sc.markName}"></div>` : '';
  const html = `${sc.label}${values ? '' : ' (computing...)'}<div class="ramp" style="background:${
    `linear-gradient(90deg,${rampCss()})`}">${mark}</div><div class="ticks"><span>${
    sc.tick(sc.lo)}</span>${at !== null ? `<span class="tol" style="left:${at}%;transform:translateX(${
      at > 50 ? -100 : 0}%)">${sc.markName}</span>` : ''}<span>${sc.tick(sc.hi)}</span></div>${figures}`;
  return { html, stats };
}

// The panel figures under every colouring, those of `ruledmesh analyze`: the area share in
// quads, the smallest angle and the worst planarity, each with the face it is at (a link).
export function panelFigures(state) {
  const fig = state.header.figures;
  if (!fig.faces) return { html: '', stats: {} };
  const share = fig.area_share || {};
  const stats = { quads: share.quads, minAngle: fig.min_angle_deg, minAngleFace: fig.min_angle_face,
                  splinters: fig.splinters, planarity: fig.planarity_max, planarityFace: fig.planarity_face };
  const html = `<div>quads <b data-panel="quads">${pct(share.quads)}</b> of the area${
    share.polygons ? `, polygons ${pct(share.polygons)}` : ''}, triangles ${pct(share.triangles)}</div>`
    + `<div>smallest angle <b data-panel="angle">${fig.min_angle_deg.toFixed(2)}°</b> at ${
      faceLink(fig.min_angle_face)}; <b data-panel="splinters">${fig.splinters}</b> faces below ${
      fig.splinter_deg}°</div>`
    + `<div>worst planarity <b data-panel="planarity">${fmt(fig.planarity_max)}</b> at ${
      faceLink(fig.planarity_face)} (tolerance ${fig.planarity_tolerance.toExponential(0)})</div>`;
  return { html, stats };
}
