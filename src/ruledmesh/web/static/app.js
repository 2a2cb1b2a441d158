// ruledmesh designer page: draws what the server builds and sends edits back.
// The state (the design) lives on the server; this page keeps only view state.
import * as THREE from './vendor/three-bundle.min.js';

const { OrbitControls, TransformControls } = THREE;
const $ = (id) => document.getElementById(id);

// ------------------------------------------------------------------ messages
// Binary message: uint32 JSON length, JSON (padded to 4), then arrays (see session.py).
const DTYPES = { float32: Float32Array, uint32: Uint32Array, uint8: Uint8Array,
                 int32: Int32Array, float64: Float64Array };

function decode(buffer) {
  const n = new DataView(buffer).getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, n)));
  const base = 4 + n;
  const arrays = {};
  for (const a of header.arrays || []) {
    const count = a.shape.reduce((x, y) => x * y, 1);
    arrays[a.name] = new DTYPES[a.dtype](buffer, base + a.offset, count);
  }
  return { header, arrays };
}

// The per-run secret from the page's address (http://127.0.0.1:PORT/?token=...): every API
// call sends it, so other pages and programs on this machine cannot drive the designer.
const TOKEN = new URLSearchParams(location.search).get('token') || '';

async function request(method, name, body) {
  const init = { method, headers: { Authorization: `Bearer ${TOKEN}` } };
  if (body !== undefined) {
    init.headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch('/api/' + name, init);
  } catch (err) {
    throw new Error('the designer server does not answer (was it stopped?)');
  }
  const ctype = response.headers.get('Content-Type') || '';
  if (!response.ok && ctype.startsWith('application/json')) {
    const data = await response.json();
    const err = new Error(data.error || response.statusText);
    err.status = response.status;
    err.data = data;
    throw err;
  }
  if (!response.ok) throw new Error(`${response.status} ${response.statusText}`);
  return response;
}

async function api(method, name, body) {
  const response = await request(method, name, body);
  if ((response.headers.get('Content-Type') || '').startsWith('application/json')) {
    return response.json();
  }
  const msg = decode(await response.arrayBuffer());
  const timing = /dur=([0-9.]+)/.exec(response.headers.get('Server-Timing') || '');
  msg.serverMs = timing ? parseFloat(timing[1]) : null;
  return msg;
}

// Save and export never replace a file the designer did not open or write itself unless the
// user agrees: the server answers 409 with {exists: true}, we ask, and send overwrite: true.
async function writeFile(name, body) {
  try {
    return await api('POST', name, body);
  } catch (err) {
    if (err.status === 409 && err.data?.exists && window.confirm(`${err.message}.\n\nReplace it?`)) {
      return api('POST', name, { ...body, overwrite: true });
    }
    throw err;
  }
}

// ------------------------------------------------------------------ status
function showError(message) {
  const box = $('error');
  box.textContent = message;
  box.hidden = !message;
}
function status(text) { $('status').textContent = text; }

// ------------------------------------------------------------------ scene
const canvas = $('canvas');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xfafafa);
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1e6);
camera.up.set(0, 0, 1);
camera.position.set(10, -20, 12);
const orbit = new OrbitControls(camera, canvas);
orbit.addEventListener('change', () => requestRender());
scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
scene.add(sun);
scene.add(camera);
sun.position.set(0.4, 0.3, 1);
camera.add(sun);

const gizmo = new TransformControls(camera, canvas);
gizmo.setSize(0.7);
gizmo.addEventListener('dragging-changed', (e) => { orbit.enabled = !e.value; });
gizmo.addEventListener('change', () => requestRender());
scene.add(gizmo.getHelper());

const layers = {
  faces: new THREE.Group(), edges: new THREE.Group(), generators: new THREE.Group(),
  curves: new THREE.Group(), handles: new THREE.Group(),
};
for (const g of Object.values(layers)) scene.add(g);

let renderPending = false;
function render() {
  renderPending = false;
  renderer.render(scene, camera);
}
function requestRender() {
  if (!renderPending) { renderPending = true; requestAnimationFrame(render); }
}
function resize() {
  const view = $('view');
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  render();
}
window.addEventListener('resize', resize);

function clearGroup(group) {
  for (const child of [...group.children]) {
    group.remove(child);
    child.traverse((o) => {
      if (o.geometry) o.geometry.dispose();
      if (o.material) o.material.dispose();
    });
  }
}

// ------------------------------------------------------------------ colours
const KIND_COLOURS = ['#4f86c6', '#7cb35a', '#e0a030', '#d05050', '#9060c0', '#909090'];
const RAMP = [[0.23, 0.30, 0.75], [0.35, 0.70, 0.90], [0.55, 0.80, 0.45], [0.95, 0.80, 0.25],
              [0.85, 0.25, 0.20]];
const SCALES = {  // log10 range of each relative measure
  planarity: [-16, -6, 'planarity (relative, log scale)'],
  closeness: [-6, -1, 'closeness: centroid distance / diagonal (log scale)'],
};
function ramp(t) {
  t = Math.min(Math.max(t, 0), 1) * (RAMP.length - 1);
  const i = Math.min(Math.floor(t), RAMP.length - 2), f = t - i;
  return RAMP[i].map((c, k) => c + (RAMP[i + 1][k] - c) * f);
}
function faceColours(mode) {
  const nf = current.arrays.kind.length;
  const out = new Float32Array(nf * 3);
  if (mode === 'kind' || (mode === 'closeness' && !closeness)) {
    const rgb = KIND_COLOURS.map((c) => new THREE.Color(c));
    const kind = current.arrays.kind;
    const grey = mode === 'closeness';
    for (let f = 0; f < nf; f++) {
      const c = grey ? rgb[5] : rgb[kind[f]] || rgb[5];
      out[3 * f] = c.r; out[3 * f + 1] = c.g; out[3 * f + 2] = c.b;
    }
    return out;
  }
  const values = mode === 'closeness' ? closeness : current.arrays.planarity;
  const [lo, hi] = SCALES[mode];
  for (let f = 0; f < nf; f++) {
    const v = Math.log10(Math.max(values[f], 1e-30));
    const c = ramp((v - lo) / (hi - lo));
    out[3 * f] = c[0]; out[3 * f + 1] = c[1]; out[3 * f + 2] = c[2];
  }
  return out;
}
function drawLegend(mode) {
  const legend = $('legend');
  if (mode === 'kind') {
    legend.innerHTML = (current?.header.choices.face_kinds || []).map(
      (k, i) => `<span class="swatch" style="background:${KIND_COLOURS[i]}"></span>${k}`).join('');
    return;
  }
  const [lo, hi, label] = SCALES[mode];
  const stops = RAMP.map((c, i) => `rgb(${c.map((x) => Math.round(255 * x)).join(',')}) ${
    100 * i / (RAMP.length - 1)}%`).join(',');
  const note = mode === 'closeness' && !closeness ? ' (computing...)' : '';
  legend.innerHTML = `${label}${note}<div class="ramp" style="background:linear-gradient(90deg,${
    stops})"></div>1e${lo} &le; &hellip; &le; 1e${hi}`;
}

// ------------------------------------------------------------------ drawing
let current = null;       // last decoded state message {header, arrays}
let closeness = null;     // per-face closeness of the current version (slow figures)
let size = 1;             // bounding-box diagonal

function drawFaces() {
  clearGroup(layers.faces);
  const { vertices: V, triangles: T, triangle_face: TF } = current.arrays;
  const nt = TF.length;
  const pos = new Float32Array(nt * 9);
  const col = new Float32Array(nt * 9);
  const fc = faceColours($('colour').value);
  for (let t = 0; t < nt; t++) {
    const f = TF[t];
    for (let k = 0; k < 3; k++) {
      const v = T[3 * t + k], o = 9 * t + 3 * k;
      pos[o] = V[3 * v]; pos[o + 1] = V[3 * v + 1]; pos[o + 2] = V[3 * v + 2];
      col[o] = fc[3 * f]; col[o + 1] = fc[3 * f + 1]; col[o + 2] = fc[3 * f + 2];
    }
  }
  const geom = new THREE.BufferGeometry();
  geom.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  geom.setAttribute('color', new THREE.BufferAttribute(col, 3));
  geom.computeVertexNormals();
  const mat = new THREE.MeshLambertMaterial({
    vertexColors: true, side: THREE.DoubleSide, polygonOffset: true,
    polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
  layers.faces.add(new THREE.Mesh(geom, mat));
  drawLegend($('colour').value);
}

function lines(positions, index, colour, opacity = 1) {
  const geom = new THREE.BufferGeometry();
  geom.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  if (index) geom.setIndex(new THREE.BufferAttribute(index, 1));
  const mat = new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1, opacity });
  return new THREE.LineSegments(geom, mat);
}

function drawScene() {
  const { header, arrays } = current;
  const [lo, hi] = header.bbox;
  size = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  drawFaces();
  clearGroup(layers.edges);
  layers.edges.add(lines(arrays.vertices, arrays.edges, 0x303030, 0.55));
  clearGroup(layers.generators);
  layers.generators.add(lines(arrays.generators, null, 0x1f5fbf, 0.8));
  clearGroup(layers.curves);
  let start = 0;
  for (const c of header.curves) {
    const geom = new THREE.BufferGeometry();
    geom.setAttribute('position', new THREE.BufferAttribute(
      arrays.curve_points.slice(3 * start, 3 * (start + c.count)), 3));
    start += c.count;
    layers.curves.add(new THREE.Line(geom, new THREE.LineBasicMaterial({ color: 0xd0308a })));
  }
  drawHandles();
  render();
}

function drawHandles() {
  const attached = gizmo.object?.userData.handle?.label;
  gizmo.detach();
  clearGroup(layers.handles);
  const r = 0.012 * size;
  const sphere = new THREE.SphereGeometry(1, 16, 12);
  for (const h of current.header.handles) {
    const normal = h.kind === 'normal';
    const mat = new THREE.MeshBasicMaterial({ color: normal ? 0x10a060 : 0xff6a00 });
    const m = new THREE.Mesh(sphere.clone(), mat);
    m.scale.setScalar(normal ? 1.4 * r : r);
    m.position.set(...h.position);
    m.userData.handle = h;
    layers.handles.add(m);
    if (normal) {
      const seg = new Float32Array([...h.anchor, ...h.position]);
      const line = lines(seg, null, 0x10a060);
      line.userData.isLeash = true;
      m.userData.leash = line;
      layers.handles.add(line);
    }
    if (attached && h.label === attached && !dragging) gizmo.attach(m);
  }
  sphere.dispose();
}

function fitView() {
  const [lo, hi] = current.header.bbox;
  const c = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  orbit.target.copy(c);
  const dir = new THREE.Vector3(0.55, -1, 0.6).normalize();
  camera.position.copy(c).addScaledVector(dir, 1.5 * size);
  camera.near = size / 1000; camera.far = size * 100;
  camera.updateProjectionMatrix();
  orbit.update();
  render();
}

// ------------------------------------------------------------------ figures
const fmt = (v, digits = 3) => (typeof v === 'number'
  ? (Math.abs(v) !== 0 && (Math.abs(v) < 1e-3 || Math.abs(v) >= 1e6) ? v.toExponential(2)
    : String(+v.toPrecision(digits + 1))) : String(v));

function setFig(name, text, pending = false) {
  const cell = document.querySelector(`[data-fig="${name}"]`);
  cell.textContent = text;
  cell.classList.toggle('pending', pending);
}

function showFigures(fig) {
  setFig('faces', fig.faces);
  setFig('kinds', fig.kinds_text || '-');
  setFig('planarity', fmt(fig.planarity_max));
  setFig('non_convex', fig.non_convex);
  for (const k of ['coverage', 'closeness', 'panels']) setFig(k, '...', true);
  $('warnings').innerHTML = '';
  for (const w of fig.warnings) {
    const li = document.createElement('li');
    li.textContent = w;
    $('warnings').append(li);
  }
}

let figureTimer = null;
function scheduleSlowFigures() {
  clearTimeout(figureTimer);
  // Wait until the edits settle: the slow figures are recomputed from scratch each time.
  figureTimer = setTimeout(fetchSlowFigures, 350);
}
async function fetchSlowFigures() {
  const version = current.header.version;
  let msg;
  try {
    msg = await api('GET', `figures?version=${version}`);
  } catch (err) {
    showError(err.message);
    return;
  }
  if (msg.header.stale || version !== current.header.version) return;
  const fig = msg.header.figures;
  setFig('coverage', fig.coverage !== undefined ? fmt(fig.coverage, 5) : 'n/a');
  setFig('closeness', fig.closeness ? fmt(fig.closeness.centroids_max) : 'n/a');
  setFig('panels', fig.panels !== undefined ? fig.panels : 'n/a');
  if (msg.header.error) {
    for (const k of ['coverage', 'closeness', 'panels']) setFig(k, 'error');
    status('figures: ' + msg.header.error);
  }
  closeness = msg.arrays.closeness ? new Float32Array(msg.arrays.closeness) : null;
  window.designer.figuresVersion = version;
  if ($('colour').value === 'closeness') { drawFaces(); render(); }
}

// ------------------------------------------------------------------ controls
const NUMERIC_OR_WORD = { primary: 'middle', extend: 'auto' };
const INT_RANGES = { count: [3, 200], rows: [1, 200], option: [0, 1], degree: [1, 5],
                     midpoints: [0, 8], divisions: [1, 64] };
const gestures = {};        // path key -> gesture counter (one undo step per slider gesture)
let activeInput = null;     // the input being changed: not overwritten by server echoes

function keyOf(path) { return JSON.stringify(path); }

function numberRange(name, v, isInt) {
  if (isInt) {
    const [lo, hi] = INT_RANGES[name] || [0, 20];
    return [Math.min(lo, v), Math.max(hi, v, isInt && INT_RANGES[name] ? 0 : 2 * v), 1];
  }
  let lo = v > 0 ? 0 : v < 0 ? 2 * v : -1, hi = v > 0 ? 2 * v : v < 0 ? 0 : 1;
  if (hi - lo < 1e-9) { lo -= 1; hi += 1; }
  return [lo, hi, (hi - lo) / 400];
}

function control(parent, path, name, value) {
  const row = document.createElement('div');
  row.className = 'ctl';
  row.dataset.path = path.join('.');
  const label = document.createElement('span');
  label.className = 'name';
  label.textContent = name;
  label.title = path.join('.');
  row.append(label);
  const k = keyOf(path);
  const send = (v, coalesce) => queueEdit([[path, v]], coalesce);

  if (typeof value === 'boolean') {
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = value;
    box.addEventListener('change', () => send(box.checked));
    row.append(box);
  } else if (typeof value === 'number' || name in NUMERIC_OR_WORD) {
    const isInt = Number.isInteger(value) && !(name === 'extend');
    let numeric = typeof value === 'number' ? value : 0;
    let [lo, hi, step] = numberRange(name, numeric, isInt);
    if (name === 'primary') { lo = 0; hi = Math.max((current.header.design.rulings?.count || 3) - 1, 1); step = 1;
      if (typeof value !== 'number') numeric = Math.floor(hi / 2); }
    if (name === 'extend') { lo = 0; hi = Math.max(2, 2 * numeric); step = 0.01; }
    const slider = document.createElement('input');
    slider.type = 'range';
    Object.assign(slider, { min: lo, max: hi, step });
    slider.value = numeric;
    slider.dataset.path = path.join('.');
    const field = document.createElement('input');
    field.type = 'text';
    field.className = 'val';
    field.value = String(value);
    field.dataset.path = path.join('.');
    slider.addEventListener('input', () => {
      activeInput = slider;
      const v = isInt || step === 1 ? parseInt(slider.value, 10) : parseFloat(slider.value);
      field.value = String(v);
      send(v, `slider:${k}:${gestures[k] || 0}`);
    });
    slider.addEventListener('change', () => { gestures[k] = (gestures[k] || 0) + 1; activeInput = null; });
    field.addEventListener('change', () => {
      const text = field.value.trim();
      const num = Number(text);
      const v = text !== '' && !Number.isNaN(num) ? num
        : (name in NUMERIC_OR_WORD ? text : text);
      send(v);
    });
    row.append(slider, field);
  } else if (typeof value === 'string') {
    const choices = choiceList(path, name);
    if (choices) {
      const sel = document.createElement('select');
      for (const c of choices) sel.add(new Option(c, c, false, c === value));
      if (!choices.includes(value)) sel.add(new Option(value, value, true, true));
      sel.dataset.path = path.join('.');
      sel.addEventListener('change', () => changeChoice(path, name, sel.value));
      row.append(sel);
    } else {
      const input = document.createElement('input');
      input.type = 'text';
      input.className = 'wide';
      input.value = value;
      input.dataset.path = path.join('.');
      input.addEventListener('change', () => send(input.value));
      row.append(input);
    }
  } else {
    return;
  }
  parent.append(row);
}

function choiceList(path, name) {
  const ch = current.header.choices;
  if (name === 'distribution') return ch.distributions;
  if (name === 'method' && path[0] === 'mesh') return ch.methods;
  if (name === 'type' && path[0] === 'curves') return ch.curve_types;
  return null;
}

const meshTables = {};  // method -> the last [mesh] table used with it
function changeChoice(path, name, value) {
  const design = current.header.design;
  if (name === 'method') {
    meshTables[design.mesh?.method || 'pq'] = design.mesh;
    const table = meshTables[value] || { method: value };
    queueEdit([[['mesh'], table]]);
    return;
  }
  if (name === 'distribution') {
    const changes = [[path, value], [['rulings', 'director_plane'], null], [['rulings', 'directrix'], null]];
    const old = design.rulings || {};
    if (value === 'director-plane') changes.push([['rulings', 'director_plane'], old.director_plane || [1, 0, 0]]);
    if (value === 'linear-directrix') changes.push([['rulings', 'directrix'], old.directrix || defaultDirectrix()]);
    queueEdit(changes);
    return;
  }
  queueEdit([[path, value]]);
}

// A line d for the linear-directrix distribution: parallel to the mean generator, off the
// surface along its normal, so the planes through d sweep across both director curves.
function defaultDirectrix() {
  const g = current.arrays.generators;
  const m = g.length / 6;
  const i = Math.floor(m / 2);
  const a = new THREE.Vector3(g[6 * i], g[6 * i + 1], g[6 * i + 2]);
  const b = new THREE.Vector3(g[6 * i + 3], g[6 * i + 4], g[6 * i + 5]);
  const first = new THREE.Vector3(g[0], g[1], g[2]);
  const last = new THREE.Vector3(g[6 * (m - 1)], g[6 * (m - 1) + 1], g[6 * (m - 1) + 2]);
  const along = last.sub(first).normalize();
  const dir = b.clone().sub(a);
  const normal = along.clone().cross(dir).normalize();
  const mid = a.clone().add(b).multiplyScalar(0.5).addScaledVector(normal, 0.5 * size);
  const round = (v) => v.toArray().map((x) => +x.toFixed(4));
  return [round(mid.clone().addScaledVector(dir, -0.5)), round(mid.clone().addScaledVector(dir, 0.5))];
}

function designShape(design) {
  // Controls are rebuilt only when the set of fields changes, not on every value change.
  const walk = (v) => (Array.isArray(v) ? `[${v.length}]` : v && typeof v === 'object'
    ? `{${Object.keys(v).map((k) => k + ':' + walk(v[k])).join(',')}}` : typeof v);
  return walk(design);
}

let shownShape = null;
function buildControls() {
  const design = current.header.design;
  const shape = designShape(design) + '|' + (design.surface?.kind || '');
  if (shape === shownShape) { syncControls(); return; }
  shownShape = shape;
  const box = $('controls');
  box.innerHTML = '';
  const section = (title, table, path) => {
    if (!table || typeof table !== 'object' || Array.isArray(table)) return;
    const head = document.createElement('div');
    head.className = 'group';
    head.textContent = title;
    box.append(head);
    for (const [k, v] of Object.entries(table)) {
      if (path.length === 1 && path[0] === 'surface' && k === 'kind') continue;
      control(box, [...path, k], k, v);
    }
  };
  section('[surface]', design.surface, ['surface']);
  section('[rulings]', design.rulings, ['rulings']);
  if (design.rulings?.conoid) section('[rulings.conoid]', design.rulings.conoid, ['rulings', 'conoid']);
  section('[mesh]', design.mesh, ['mesh']);
  for (const [name, spec] of Object.entries(design.curves || {})) section(`[curves.${name}]`, spec, ['curves', name]);
  // the primary slider's range follows the generator count
  const count = design.rulings?.count;
  const prim = box.querySelector('input[type=range][data-path="mesh.primary"]');
  if (prim && count) prim.max = count - 1;
}

function valueAt(path) {
  let v = current.header.design;
  for (const p of path) v = v?.[p];
  return v;
}

let forceSync = false;
function syncControls() {
  // While later edits wait to be sent, this answer is already out of date: showing its values
  // would move a slider back under the user's hand (and the next key press would start there).
  if (jobs.length && !forceSync) return;
  const force = forceSync;
  forceSync = false;
  for (const el of $('controls').querySelectorAll('[data-path]')) {
    if (!force && (el === activeInput || el === document.activeElement && el.type === 'text')) continue;
    const v = valueAt(el.dataset.path.split('.'));
    if (v === undefined) continue;
    if (el.type === 'checkbox') el.checked = v;
    else if (el.type === 'range') { if (typeof v === 'number') el.value = v; }
    else if (el.tagName === 'SELECT' || el.type === 'text') el.value = String(v);
  }
}

function buildKindChooser() {
  const sel = $('kind');
  const kinds = current.header.choices.kinds;
  const want = ['(ruled: director curves)', ...kinds].join('|');
  if (sel.dataset.options !== want) {
    sel.innerHTML = '';
    sel.add(new Option('ruled: director curves', ''));
    for (const k of kinds) sel.add(new Option(k, k));
    sel.dataset.options = want;
  }
  sel.value = current.header.design.surface?.kind || '';
}

let lastRuled = null;
$('kind').addEventListener('change', async () => {
  const kind = $('kind').value;
  const design = current.header.design;
  if (!design.surface) lastRuled = design;
  if (!kind) {
    await send('design', lastRuled ? { design: lastRuled } : { default: true });
    return;
  }
  const candidate = { name: kind, surface: { kind }, mesh: {} };
  const ok = await send('design', { design: candidate });
  if (!ok) {
    // The kind needs fields: offer a template in the TOML pane to fill in.
    $('toml').value = `name = "${kind}"\n\n[surface]\nkind = "${kind}"\n# add the fields the ` +
      `message above asks for, then Apply\n\n[mesh]\n`;
    tomlDirty = true;
    $('toml-pane').open = true;
    buildKindChooser();
  }
});

// ------------------------------------------------------------------ edits
let inFlight = false;
const jobs = [];      // edits waiting to be sent: {changes: Map key -> [path, value], coalesce}
let sentAt = 0;
const timings = [];
const breakdown = [];  // {total, server, page} ms per edit

// Edits go one at a time; while one is on its way, later moves of the same gesture merge
// (only the newest position matters), so a fast drag never builds a backlog.
function queueEdit(changes, coalesce = null) {
  let job = jobs[jobs.length - 1];
  if (!job || coalesce === null || job.coalesce !== coalesce) {
    job = { changes: new Map(), coalesce };
    jobs.push(job);
  }
  for (const [path, value] of changes) job.changes.set(keyOf(path), [path, value]);
  if (!inFlight) flush();
}

async function flush() {
  inFlight = true;
  while (jobs.length) {
    const job = jobs.shift();
    await send('edit', { changes: [...job.changes.values()], coalesce: job.coalesce });
  }
  inFlight = false;
}

// POST an action that answers with the state; returns false (and shows why) on error.
async function send(name, body) {
  sentAt = performance.now();
  try {
    const msg = await api('POST', name, body || {});
    const received = performance.now();
    showError('');
    applyState(msg);
    const ms = performance.now() - sentAt;
    timings.push(ms);
    breakdown.push({ total: ms, server: msg.serverMs, page: performance.now() - received });
    if (timings.length > 50) { timings.shift(); breakdown.shift(); }
    status(`updated in ${ms.toFixed(0)} ms (server ${msg.serverMs?.toFixed(0)} ms)`);
    return true;
  } catch (err) {
    // Superseded: another tab's newer edit won; show the design as it is now, not an error.
    if (err.data?.superseded) status('edit superseded by a newer one'); else showError(err.message);
    activeInput = null;
    forceSync = true;  // even the field just typed in shows the server's value again
    await refresh();  // show the design as the server has it (the edit was refused)
    return false;
  }
}

async function refresh() {
  try {
    applyState(await api('GET', 'state'));
  } catch (err) {
    showError(err.message);
  }
}

let tomlDirty = false;
let firstState = true;
function applyState(msg) {
  const changed = !current || current.header.version !== msg.header.version;
  current = msg;
  if (changed) closeness = null;
  const h = msg.header;
  $('file').textContent = h.path || '(unsaved design)';
  $('undo').disabled = !h.can_undo;
  $('redo').disabled = !h.can_redo;
  $('folder').textContent = h.folder;
  if (!$('save-path').value || document.activeElement !== $('save-path')) {
    $('save-path').value = h.save_name;  // the design file, or a free name in the folder
  }
  const fmtSel = $('export-format');
  if (fmtSel.options.length !== h.choices.formats.length) {
    fmtSel.innerHTML = '';
    for (const f of h.choices.formats) fmtSel.add(new Option(f, f, false, f === '.obj'));
    updateDownload();
  }
  if (!tomlDirty) $('toml').value = h.toml;
  showFigures(h.figures);
  buildKindChooser();
  buildControls();
  drawScene();
  if (firstState) { fitView(); firstState = false; }
  document.body.dataset.version = h.version;
  window.designer.version = h.version;
  window.designer.renders += 1;
  if (changed) scheduleSlowFigures();
}

function updateDownload() {
  $('download').dataset.format = $('export-format').value;
}

// Downloads go through fetch (a plain link cannot send the token) and a temporary blob URL.
async function download(event) {
  event.preventDefault();
  const fmt = $('export-format').value;
  try {
    const response = await request('GET', `download?format=${encodeURIComponent(fmt)}`);
    const name = /filename="([^"]+)"/.exec(response.headers.get('Content-Disposition') || '');
    const url = URL.createObjectURL(await response.blob());
    const a = document.createElement('a');
    a.href = url;
    a.download = name ? name[1] : `design${fmt}`;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 10_000);
    showError('');
  } catch (err) { showError(err.message); }
}

// ------------------------------------------------------------------ handle dragging
const raycaster = new THREE.Raycaster();
const pointer = new THREE.Vector2();
let dragging = null;   // {mesh, plane, offset, id}
let dragCount = 0;

function pick(event) {
  if (!$('view').contains(event.target) || !layers.handles.visible) return null;
  const rect = canvas.getBoundingClientRect();
  pointer.set(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  const hits = raycaster.intersectObjects(layers.handles.children.filter((o) => o.userData.handle));
  return hits.length ? hits[0] : null;
}

function handleValue(h, pos) {
  const r = (x) => +x.toFixed(6);
  if (h.kind === 'normal') {
    const n = pos.clone().sub(new THREE.Vector3(...h.anchor));
    if (n.length() < 1e-9 * size) return null;
    n.normalize();
    return n.toArray().map(r);
  }
  return pos.toArray().map(r);
}

function moveHandle(m, pos) {
  m.position.copy(pos);
  const h = m.userData.handle;
  if (m.userData.leash) {
    const a = m.userData.leash.geometry.attributes.position;
    a.setXYZ(1, pos.x, pos.y, pos.z);
    a.needsUpdate = true;
  }
  const v = handleValue(h, pos);
  if (v) queueEdit([[h.path, v]], `drag:${h.label}:${dragCount}`);
}

canvas.addEventListener('pointerdown', (event) => {
  if (event.button !== 0 || gizmo.dragging || gizmo.axis) return;
  const hit = pick(event);
  if (!hit) return;
  const m = hit.object;
  const normal = camera.getWorldDirection(new THREE.Vector3());
  const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, m.position);
  dragging = { mesh: m, plane, offset: m.position.clone().sub(hit.point), moved: false };
  dragCount += 1;
  orbit.enabled = false;
  canvas.setPointerCapture(event.pointerId);
  event.preventDefault();
});

canvas.addEventListener('pointermove', (event) => {
  if (!dragging) {
    const hit = pick(event);
    const label = $('pick-label');
    if (hit) {
      label.textContent = hit.object.userData.handle.label;
      label.style.left = `${event.offsetX + 12}px`;
      label.style.top = `${event.offsetY + 12}px`;
    }
    label.hidden = !hit;
    canvas.style.cursor = hit ? 'grab' : '';
    return;
  }
  const rect = canvas.getBoundingClientRect();
  pointer.set(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  const p = new THREE.Vector3();
  if (!raycaster.ray.intersectPlane(dragging.plane, p)) return;
  dragging.moved = true;
  moveHandle(dragging.mesh, p.add(dragging.offset));
  render();
});

function endDrag(event) {
  if (!dragging) return;
  const { mesh, moved } = dragging;
  dragging = null;
  orbit.enabled = true;
  if (canvas.hasPointerCapture(event.pointerId)) canvas.releasePointerCapture(event.pointerId);
  if (!moved) { gizmo.attach(mesh); render(); }   // a click: axis arrows for precise moves
}
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);

gizmo.addEventListener('mouseDown', () => { dragCount += 1; });
gizmo.addEventListener('objectChange', () => {
  if (gizmo.object && gizmo.dragging) moveHandle(gizmo.object, gizmo.object.position.clone());
});

// ------------------------------------------------------------------ buttons
$('undo').addEventListener('click', () => send('undo'));
$('redo').addEventListener('click', () => send('redo'));
$('fit').addEventListener('click', () => fitView());
$('colour').addEventListener('change', () => { drawFaces(); render(); });
$('export-format').addEventListener('change', updateDownload);
for (const box of document.querySelectorAll('[data-layer]')) {
  box.addEventListener('change', () => {
    layers[box.dataset.layer].visible = box.checked;
    if (box.dataset.layer === 'handles' && !box.checked) gizmo.detach();
    render();
  });
}
$('download').addEventListener('click', download);
$('save').addEventListener('click', async () => {
  try {
    const r = await writeFile('save', { path: $('save-path').value.trim() });
    showError('');
    status(`saved ${r.path}`);
    await refresh();
  } catch (err) { showError(err.message); }
});
$('export').addEventListener('click', async () => {
  try {
    const r = await writeFile('export', { format: $('export-format').value });
    showError('');
    status(`wrote ${r.path}`);
    window.designer.lastExport = r.path;
  } catch (err) { showError(err.message); }
});
$('toml').addEventListener('input', () => { tomlDirty = true; });
$('apply-toml').addEventListener('click', async () => {
  if (await send('design', { toml: $('toml').value })) {
    tomlDirty = false;
    $('toml').value = current.header.toml;
  }
});
window.addEventListener('keydown', (event) => {
  const tag = document.activeElement?.tagName;
  if (tag === 'TEXTAREA' || (tag === 'INPUT' && document.activeElement.type === 'text')) return;
  if (!(event.ctrlKey || event.metaKey)) {
    if (event.key === 'Escape') { gizmo.detach(); render(); }
    return;
  }
  const key = event.key.toLowerCase();
  if (key === 'z' && !event.shiftKey) { event.preventDefault(); send('undo'); }
  else if ((key === 'z' && event.shiftKey) || key === 'y') { event.preventDefault(); send('redo'); }
});

// ------------------------------------------------------------------ test and debugging hooks
window.designer = {
  version: null, renders: 0, figuresVersion: null, lastExport: null, timings, breakdown,
  busy: () => inFlight || jobs.length > 0,
  handles: () => layers.handles.children.filter((o) => o.userData.handle).map((o) => {
    const p = o.position.clone().project(camera);
    const rect = canvas.getBoundingClientRect();
    return { label: o.userData.handle.label, path: o.userData.handle.path,
             x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height };
  }),
};

resize();
if (!TOKEN) showError('this address has no token: open the one that ruledmesh design printed ' +
                      '(it ends in ?token=...)');
else refresh();
