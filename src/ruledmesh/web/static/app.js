// ruledmesh designer page: draws what the server builds and sends edits back.
// The state (the design) lives on the server; this page keeps only view state.
import * as THREE from './vendor/three-bundle.min.js';
import { faceColours, fmt, legend, panelFigures } from './colours.js';

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
  // The faces this page has: an answer with the same ones leaves them out (see applyState).
  if (current?.header.topology) init.headers['X-Ruledmesh-Topology'] = current.header.topology;
  // With the live socket open, a change is answered {version} and its state comes on the
  // socket (to this tab and every other), so it is never sent twice.
  if (body !== undefined && liveOpen()) init.headers['X-Ruledmesh-Answer'] = 'version';
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
  const timing = /dur=([0-9.]+)/.exec(response.headers.get('Server-Timing') || '');
  if ((response.headers.get('Content-Type') || '').startsWith('application/json')) {
    const data = await response.json();
    data.serverMs = timing ? parseFloat(timing[1]) : null;
    return data;
  }
  const raw = await response.arrayBuffer();
  const msg = decode(raw);
  msg.raw = raw;
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
// A note about what the state of `version` did (a panel closed): added to the status line,
// and kept in that version's timing line, whichever of the two comes first.
let updateNote = null;   // {version, text}
function noteUpdate(version, text) {
  updateNote = { version, text };
  const line = $('status').textContent;
  status(line ? `${line}; ${text}` : text);
}

// ------------------------------------------------------------------ scene
const canvas = $('canvas');
// Multisampling is cheap on a graphics card but costs a software renderer (SwiftShader, as
// in headless or GPU-less browsers) most of each frame: there it is off.
function softwareGL() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
    const name = info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : '';
    gl?.getExtension('WEBGL_lose_context')?.loseContext();
    return /swiftshader|llvmpipe|software/i.test(name);
  } catch (err) { return false; }
}
const SOFTWARE_GL = softwareGL();
const renderer = new THREE.WebGLRenderer({ canvas, antialias: !SOFTWARE_GL, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xfafafa);
// Two cameras, one shared orbit target: the orthographic one for the view presets
// (top, front, right) and measured drawings, the perspective one for looking around.
const perspective = new THREE.PerspectiveCamera(40, 1, 0.01, 1e6);
const orthographic = new THREE.OrthographicCamera(-1, 1, 1, -1, -1e6, 1e6);
for (const cam of [perspective, orthographic]) { cam.up.set(0, 0, 1); scene.add(cam); }
let camera = perspective;
camera.position.set(10, -20, 12);
const orbit = new OrbitControls(camera, canvas);
orbit.addEventListener('change', () => { syncOrtho(); requestRender(); });
scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
sun.position.set(0.4, 0.3, 1);
perspective.add(sun);
const orthoSun = sun.clone();
orthographic.add(orthoSun);

const gizmo = new TransformControls(camera, canvas);
gizmo.setSize(0.7);
gizmo.addEventListener('dragging-changed', (e) => { orbit.enabled = !e.value; });
gizmo.addEventListener('change', () => requestRender());
scene.add(gizmo.getHelper());
// The arrows move a point along one axis; the free-move square in their middle would cover
// the sphere and steal its drags (and moving all selected points with it), so it goes.
for (const part of ['picker', 'gizmo']) {
  const group = gizmo._gizmo?.[part]?.translate;
  for (const o of [...(group?.children || [])]) if (o.name === 'XYZ') group.remove(o);
}

const layers = {
  faces: new THREE.Group(), edges: new THREE.Group(), generators: new THREE.Group(),
  curves: new THREE.Group(), construction: new THREE.Group(), handles: new THREE.Group(),
  grid: new THREE.Group(), labels: new THREE.Group(), highlight: new THREE.Group(),
};
for (const g of Object.values(layers)) scene.add(g);
layers.labels.visible = false;

// The orthographic frustum follows the distance to the target, so zooming (which moves the
// perspective camera) and switching cameras keep the same scale on screen.
function syncOrtho() {
  if (camera !== orthographic) return;
  const dist = camera.position.distanceTo(orbit.target);
  const h = dist * Math.tan(THREE.MathUtils.degToRad(perspective.fov / 2)) / camera.zoom;
  const aspect = perspective.aspect;
  Object.assign(camera, { left: -h * aspect, right: h * aspect, top: h, bottom: -h });
  camera.updateProjectionMatrix();
}

function useCamera(next) {
  if (next === camera) return;
  next.position.copy(camera.position);
  next.quaternion.copy(camera.quaternion);
  next.zoom = 1;
  camera = next;
  orbit.object = camera;
  gizmo.camera = camera;
  orbit.update();
  syncOrtho();
  camera.updateProjectionMatrix();
  $('ortho').checked = camera === orthographic;
  requestRender();
}

let renderPending = false;
function render() {
  renderPending = false;
  fadeEdges();
  renderer.render(scene, camera);
  freeRetired();
  if (layers.labels.visible) drawLabels();
  window.designer.frames += 1;
}
function requestRender() {
  if (!renderPending) { renderPending = true; requestAnimationFrame(render); }
}
function resize() {
  const view = $('view');
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  perspective.aspect = w / Math.max(h, 1);
  perspective.updateProjectionMatrix();
  syncOrtho();
  render();
}
window.addEventListener('resize', resize);

// Geometries and materials of removed objects, freed after the next render: three deletes a
// shader program when the last material using it is freed, so freeing the old handles' and
// construction's materials before their replacements are drawn would compile the same
// programs again on every update (tens of milliseconds each in a software renderer).
const retired = [];
function clearGroup(group) {
  for (const child of [...group.children]) {
    group.remove(child);
    child.traverse((o) => {
      if (o.geometry) retired.push(o.geometry);
      if (o.material) retired.push(o.material);
    });
  }
}
function freeRetired() {
  for (const r of retired.splice(0)) r.dispose();
}

// ------------------------------------------------------------------ colours
// The colourings, legend and panel figures are in colours.js; they read this state.
let closeness = null;     // per-face closeness of the current version (slow figures)
let classes = null;       // per-face congruence class of the current version (slow figures)
let areas = null;         // per-face area, computed here from the faces
const colourState = () => ({ header: current.header, arrays: current.arrays, areas, closeness, classes });

// The legend of the colouring and the panel figures under it; returns the legend's figures.
function drawLegend(mode) {
  const state = colourState();
  const { html, stats } = legend(state, mode);
  $('legend').innerHTML = html;
  const panel = panelFigures(state);
  $('panel-figures').innerHTML = panel.html;
  window.designer.panelFigures = panel.stats;
  return stats;
}

// ------------------------------------------------------------------ drawing
let current = null;       // last decoded state message {header, arrays}
let size = 1;             // bounding-box diagonal

// Per-face area and the interior angles of each face, in space (the read-out and the
// "panel area" colouring use them).
function faceGeometry() {
  const { vertices: V, face_offsets: off, face_indices: idx } = current.arrays;
  const nf = off.length - 1;
  areas = new Float64Array(nf);
  for (let f = 0; f < nf; f++) {
    let x = 0, y = 0, z = 0;
    const a = 3 * idx[off[f]];
    for (let k = off[f] + 1; k < off[f + 1] - 1; k++) {
      const b = 3 * idx[k], c = 3 * idx[k + 1];
      const ux = V[b] - V[a], uy = V[b + 1] - V[a + 1], uz = V[b + 2] - V[a + 2];
      const vx = V[c] - V[a], vy = V[c + 1] - V[a + 1], vz = V[c + 2] - V[a + 2];
      x += uy * vz - uz * vy; y += uz * vx - ux * vz; z += ux * vy - uy * vx;
    }
    areas[f] = 0.5 * Math.hypot(x, y, z);
  }
}

function faceInfo(f) {
  const { vertices: V, face_offsets: off, face_indices: idx, planarity, kind } = current.arrays;
  const pts = [];
  for (let k = off[f]; k < off[f + 1]; k++) {
    pts.push(new THREE.Vector3(V[3 * idx[k]], V[3 * idx[k] + 1], V[3 * idx[k] + 2]));
  }
  const n = pts.length;
  const angles = pts.map((p, i) => {
    const a = pts[(i + n - 1) % n].clone().sub(p), b = pts[(i + 1) % n].clone().sub(p);
    return THREE.MathUtils.radToDeg(a.angleTo(b));
  });
  const edges = pts.map((p, i) => p.distanceTo(pts[(i + 1) % n]));
  return { face: f, label: `P${f}`, kind: current.header.choices.face_kinds[kind[f]],
           planarity: planarity[f], area: areas[f], corners: n, angles, edges,
           cls: classes ? classes[f] : null };
}

// The geometry's buffer `name` to write `length` numbers into: the one drawn until now when
// it is large enough (and not far too large), else a new one with a quarter of headroom (a
// whole number of items), so the next updates of a drag or a slider (whose counts change a
// little) are written in place. `reused` says which; `written` then uploads the used part.
function bufferFor(geom, name, length, Type, itemSize) {
  const attr = name === 'index' ? geom.index : geom.getAttribute(name);
  if (attr && attr.array.length >= length && attr.array.length <= 2 * length + 64
      && attr.array.constructor === Type) {
    return { array: attr.array, reused: true };
  }
  const fresh = new THREE.BufferAttribute(new Type(itemSize * (Math.ceil(1.25 * length / itemSize) + 16)),
                                          itemSize);
  if (name === 'index') geom.setIndex(fresh); else geom.setAttribute(name, fresh);
  return { array: fresh.array, reused: false };
}
function written(geom, name, length) {
  const attr = name === 'index' ? geom.index : geom.getAttribute(name);
  attr.clearUpdateRanges();
  attr.addUpdateRange(0, length);
  attr.needsUpdate = true;
}
// `data` copied into the geometry's buffer `name` (see bufferFor); returns true if reused.
function fitBuffer(geom, name, data, itemSize) {
  const buf = bufferFor(geom, name, data.length, data.constructor, itemSize);
  buf.array.set(data);
  written(geom, name, data.length);
  return buf.reused;
}
// The bounding sphere from the state's bounding box (every vertex is inside it): no pass over
// the buffers, whose unused tail holds what an earlier, larger mesh left there.
function boxSphere(geom) {
  const [lo, hi] = current.header.bbox;
  const box = new THREE.Box3(new THREE.Vector3(...lo), new THREE.Vector3(...hi));
  geom.boundingSphere = box.getBoundingSphere(geom.boundingSphere || new THREE.Sphere());
}
const setAttribute = fitBuffer;

// The faces' material: three's Lambert shading (the scene's hemisphere light and the suns
// that follow the cameras, the same formulas) evaluated per vertex instead of per pixel. The
// faces are flat (every corner of a face has the face's normal), so the colour is the same
// as Lambert's per-pixel one, but a software renderer (SwiftShader) shades each of the
// million pixels with a copy instead of a lighting loop: a third of its frame time.
const FACE_VERTEX = `
#include <common>
#include <lights_pars_begin>
varying vec3 vFront;
varying vec3 vBack;
vec3 lambert(vec3 n, vec3 albedo) {
  vec3 irradiance = getAmbientLightIrradiance(ambientLightColor);
  #if NUM_HEMI_LIGHTS > 0
  for (int i = 0; i < NUM_HEMI_LIGHTS; i++) irradiance += getHemisphereLightIrradiance(hemisphereLights[i], n);
  #endif
  #if NUM_DIR_LIGHTS > 0
  for (int i = 0; i < NUM_DIR_LIGHTS; i++) {
    irradiance += saturate(dot(n, directionalLights[i].direction)) * directionalLights[i].color;
  }
  #endif
  return irradiance * BRDF_Lambert(albedo);
}
void main() {
  vec3 n = normalize(normalMatrix * normal);
  vFront = lambert(n, color);
  vBack = lambert(-n, color);
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;
const FACE_FRAGMENT = `
varying vec3 vFront;
varying vec3 vBack;
void main() {
  gl_FragColor = vec4(gl_FrontFacing ? vFront : vBack, 1.0);
  #include <tonemapping_fragment>
  #include <colorspace_fragment>
}`;
function faceMaterial() {
  return new THREE.ShaderMaterial({
    uniforms: THREE.UniformsUtils.clone(THREE.UniformsLib.lights), lights: true,
    vertexShader: FACE_VERTEX, fragmentShader: FACE_FRAGMENT, vertexColors: true,
    side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
}

// The faces drawn as one indexed mesh with a vertex per face corner (so each face has its
// own colour and flat normal), written into the buffers drawn until now where they fit (the
// draw range hides what is left of the old picture). The triangles, in corner numbers, are
// the same while the faces are: then only positions, normals and colours are written.
function drawFaces(sameFaces = false) {
  const { vertices: V, face_offsets: off, face_indices: idx } = current.arrays;
  const nf = off.length - 1, nc = idx.length;
  const fc = faceColours(colourState(), $('colour').value);
  let mesh = layers.faces.children[0];
  if (!mesh) {
    mesh = new THREE.Mesh(new THREE.BufferGeometry(), faceMaterial());
    layers.faces.add(mesh);
  }
  const geom = mesh.geometry;
  // Written straight into the buffers drawn until now (no arrays made and copied per update).
  const posBuf = bufferFor(geom, 'position', 3 * nc, Float32Array, 3);
  const pos = posBuf.array;
  const nor = bufferFor(geom, 'normal', 3 * nc, Float32Array, 3).array;
  const col = bufferFor(geom, 'color', 3 * nc, Float32Array, 3).array;
  for (let c = 0; c < nc; c++) {
    const v = 3 * idx[c];
    pos[3 * c] = V[v]; pos[3 * c + 1] = V[v + 1]; pos[3 * c + 2] = V[v + 2];
  }
  for (let f = 0; f < nf; f++) {
    // Newell's normal of the face (planar faces: its plane's normal), for every corner.
    let x = 0, y = 0, z = 0;
    const s = off[f], e = off[f + 1];
    for (let c = s; c < e; c++) {
      const p = 3 * c, q = 3 * (c + 1 < e ? c + 1 : s);
      x += (pos[p + 1] - pos[q + 1]) * (pos[p + 2] + pos[q + 2]);
      y += (pos[p + 2] - pos[q + 2]) * (pos[p] + pos[q]);
      z += (pos[p] - pos[q]) * (pos[p + 1] + pos[q + 1]);
    }
    const l = Math.hypot(x, y, z) || 1;
    x /= l; y /= l; z /= l;
    const r = fc[3 * f], g = fc[3 * f + 1], b = fc[3 * f + 2];
    for (let c = 3 * s; c < 3 * e; c += 3) {
      nor[c] = x; nor[c + 1] = y; nor[c + 2] = z;
      col[c] = r; col[c + 1] = g; col[c + 2] = b;
    }
  }
  for (const name of ['position', 'normal', 'color']) written(geom, name, 3 * nc);
  const nt = current.arrays.triangle_face.length;
  if (!sameFaces || !geom.index || geom.userData.faces !== current.arrays.face_offsets) {
    // Fan triangles of each face in corner numbers, in the server's order (so a picked
    // triangle's face is triangle_face[triangle]).
    const tri = bufferFor(geom, 'index', 3 * nt, Uint32Array, 1).array;
    let t = 0;
    for (let f = 0; f < nf; f++) {
      for (let c = off[f] + 1; c < off[f + 1] - 1; c++, t += 3) {
        tri[t] = off[f]; tri[t + 1] = c; tri[t + 2] = c + 1;
      }
    }
    written(geom, 'index', 3 * nt);
    geom.userData.faces = current.arrays.face_offsets;
  }
  geom.setDrawRange(0, 3 * nt);
  boxSphere(geom);
  window.designer.reused = posBuf.reused;
  window.designer.legend = drawLegend($('colour').value);
}

function recolour() {
  if (!layers.faces.children[0]) return;
  drawFaces();
  render();
}

function lines(positions, index, colour, opacity = 1, dashed = false) {
  const geom = new THREE.BufferGeometry();
  geom.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  if (index) geom.setIndex(new THREE.BufferAttribute(index, 1));
  const mat = dashed
    ? new THREE.LineDashedMaterial({ color: colour, transparent: opacity < 1, opacity,
                                      dashSize: 0.012 * size, gapSize: 0.008 * size })
    : new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1, opacity });
  const seg = new THREE.LineSegments(geom, mat);
  if (dashed) seg.computeLineDistances();
  return seg;
}

// Face edges (the quads as quads), in the buffers drawn until now where they fit.
function drawEdges(sameFaces = false) {
  const { vertices: V, edges: E } = current.arrays;
  let seg = layers.edges.children[0];
  if (!seg) {
    seg = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color: 0x202020, transparent: true, opacity: 0.8 }));
    layers.edges.add(seg);
  }
  fitBuffer(seg.geometry, 'position', V, 3);
  if (!sameFaces || !seg.geometry.index) fitBuffer(seg.geometry, 'index', E, 1);  // the same edges
  seg.geometry.setDrawRange(0, E.length);
  boxSphere(seg.geometry);
  // The faces' median width (area / longest edge, of up to 2,000 faces): the spacing of the
  // edges across the faces, also for long thin ones; fadeEdges dims dense meshes by it.
  const { face_offsets: off, face_indices: idx } = current.arrays;
  const nf = off.length - 1, stride = Math.max(1, Math.floor(nf / 2000)), widths = [];
  for (let f = 0; f < nf; f += stride) {
    let longest = 0;
    for (let k = off[f]; k < off[f + 1]; k++) {
      const a = 3 * idx[k], b = 3 * idx[k + 1 < off[f + 1] ? k + 1 : off[f]];
      longest = Math.max(longest, Math.hypot(V[a] - V[b], V[a + 1] - V[b + 1], V[a + 2] - V[b + 2]));
    }
    if (longest > 0) widths.push(areas[f] / longest);
  }
  widths.sort((x, y) => x - y);
  seg.userData.edgeLength = widths.length ? widths[widths.length >> 1] : 0;
}

// Where edges come closer on screen than about 6 pixels they fade, so a dense mesh reads
// as a surface with a fine net rather than a black moiré; zooming in brings them back.
function fadeEdges() {
  const seg = layers.edges.children[0];
  if (!seg || !seg.userData.edgeLength) return;
  const h = canvas.clientHeight || 1;
  const pxPerUnit = camera === orthographic
    ? h * camera.zoom / (camera.top - camera.bottom)
    : h / (2 * camera.position.distanceTo(orbit.target) * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)));
  const px = seg.userData.edgeLength * pxPerUnit;
  seg.material.opacity = Math.min(0.8, Math.max(0.08, 0.8 * px / 6));
  window.designer.edgeOpacity = seg.material.opacity;
}

// The generators are the rulings the mesh was built on: a separate, dashed layer, shown by
// default only while they are few enough not to cover the quads.
const GENERATORS_SHOWN_UP_TO = 40;
let generatorsTouched = false;
function drawGenerators(reuse) {
  const G = current.arrays.generators;
  const old = layers.generators.children[0];
  if (!G.length) { clearGroup(layers.generators); return; }  // a catalogue surface: none
  if (reuse && old && old.geometry.getAttribute('position').array.length === G.length) {
    setAttribute(old.geometry, 'position', G, 3);
    old.computeLineDistances();
  } else {
    clearGroup(layers.generators);
    layers.generators.add(lines(G, null, 0x1f5fbf, 0.55, true));
  }
  if (!generatorsTouched) {
    const show = G.length / 6 <= GENERATORS_SHOWN_UP_TO;
    layers.generators.visible = show;
    document.querySelector('[data-layer=generators]').checked = show;
  }
}

function polyline(points, colour, opacity = 1) {
  const geom = new THREE.BufferGeometry();
  geom.setAttribute('position', new THREE.BufferAttribute(new Float32Array(points.flat()), 3));
  return new THREE.Line(geom, new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1,
                                                           opacity }));
}

function drawCurves() {
  const { header, arrays } = current;
  clearGroup(layers.curves);
  let start = 0;
  for (const c of header.curves) {
    const geom = new THREE.BufferGeometry();
    geom.setAttribute('position', new THREE.BufferAttribute(
      arrays.curve_points.slice(3 * start, 3 * (start + c.count)), 3));
    start += c.count;
    layers.curves.add(new THREE.Line(geom, new THREE.LineBasicMaterial({ color: 0xd0308a })));
  }
}

// The construction: control polygons, the directrix line, the director plane, the primary
// generator with its division, the torsal generators.
function drawConstruction() {
  clearGroup(layers.construction);
  const { header, arrays } = current;
  const design = header.design;
  const add = (o, name) => { o.userData.construction = name; layers.construction.add(o); };
  for (const [name, spec] of Object.entries(design.curves || {})) {
    if (Array.isArray(spec.points) && spec.points.length > 1 && spec.type !== 'polyline') {
      add(polyline(spec.points, 0xff8c3a, 0.7), `control polygon ${name}`);
    }
  }
  const r = design.rulings || {};
  const directrix = r.directrix || r.conoid?.directrix;
  if (Array.isArray(directrix) && directrix.length === 2) {
    const a = new THREE.Vector3(...directrix[0]), b = new THREE.Vector3(...directrix[1]);
    const d = b.clone().sub(a).normalize().multiplyScalar(0.6 * size);
    add(polyline([a.clone().sub(d).toArray(), b.clone().add(d).toArray()], 0x008a8a), 'directrix');
  }
  const normal = header.handles.find((h) => h.kind === 'normal');
  if (normal) {
    const n = new THREE.Vector3(...normal.position).sub(new THREE.Vector3(...normal.anchor)).normalize();
    const plane = new THREE.Mesh(new THREE.PlaneGeometry(0.6 * size, 0.6 * size),
      new THREE.MeshBasicMaterial({ color: 0x10a060, transparent: true, opacity: 0.12,
                                    side: THREE.DoubleSide, depthWrite: false }));
    plane.position.set(...normal.anchor);
    plane.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), n);
    add(plane, 'director plane');
  }
  const G = arrays.generators;
  const m = G.length / 6;
  const gen = (i) => [[G[6 * i], G[6 * i + 1], G[6 * i + 2]], [G[6 * i + 3], G[6 * i + 4], G[6 * i + 5]]];
  const cons = header.construction || {};
  if (m && cons.primary !== undefined && cons.primary < m) {
    const [a, b] = gen(cons.primary);
    add(polyline([a, b], 0xc01010), 'primary generator');
    const rows = Math.min(cons.rows || 20, 2000);
    const ticks = new Float32Array(3 * (rows + 1));
    for (let k = 0; k <= rows; k++) {
      for (let j = 0; j < 3; j++) ticks[3 * k + j] = a[j] + (b[j] - a[j]) * k / rows;
    }
    const geom = new THREE.BufferGeometry();
    geom.setAttribute('position', new THREE.BufferAttribute(ticks, 3));
    add(new THREE.Points(geom, new THREE.PointsMaterial({ color: 0xc01010, size: 5,
                                                          sizeAttenuation: false })),
        'division of the primary generator');
  }
  for (const i of arrays.torsal || []) {
    if (i >= m) continue;
    const seg = lines(new Float32Array(gen(i).flat()), null, 0xe00000, 1, true);
    add(seg, `torsal generator ${i}`);
  }
}

function drawGrid() {
  clearGroup(layers.grid);
  const [lo, hi] = current.header.bbox;
  const span = Math.max(hi[0] - lo[0], hi[1] - lo[1], 1e-9);
  const step = 10 ** Math.floor(Math.log10(span / 5));
  const half = Math.ceil(span / step) * step;
  const n = Math.round(2 * half / step);
  const grid = new THREE.GridHelper(2 * half, n, 0xb0b0b0, 0xdddddd);
  grid.rotation.x = Math.PI / 2;  // three's grid lies in XZ; the designer is Z-up
  grid.position.set(Math.round((lo[0] + hi[0]) / 2 / step) * step,
                    Math.round((lo[1] + hi[1]) / 2 / step) * step, lo[2]);
  grid.userData.step = step;
  layers.grid.add(grid);
  const axes = new THREE.AxesHelper(0.25 * size);
  axes.position.set(0, 0, 0);
  layers.grid.add(axes);
  $('grid-step').textContent = `grid ${fmt(step)}`;
}

function drawScene() {
  const { header, arrays } = current;
  const [lo, hi] = header.bbox;
  // Three digits: the handles' radius, the dashes and the construction's extent do not
  // follow the last digits of the box, which move with every row count (the layers stay).
  size = Number((Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1).toPrecision(3));
  // Buffers of the same size are written in place (no new GPU buffers, no garbage): a
  // moved point or a continuous slider mostly keeps the face and edge counts.
  // How long each part of drawing takes (window.designer.drawTimes, for the speed figures).
  const times = {};
  let t = performance.now();
  const lap = (name) => { const now = performance.now(); times[name] = now - t; t = now; };
  faceGeometry(); lap('areas');
  drawFaces(header.same_topology); lap('faces');
  drawEdges(header.same_topology); drawGenerators(true); lap('lines');
  // The layers of the construction are made again only when what they show changed (a
  // slider of the rows or a moved point leaves most of them as they are).
  const G = arrays.generators, p = header.construction?.primary;
  const gen = p !== undefined && 6 * p + 6 <= G.length ? Array.from(G.subarray(6 * p, 6 * p + 6)) : null;
  redrawIf('curves', [header.curves, header.design.curves], drawCurves);
  redrawIf('construction', [header.design.curves, header.design.rulings, header.construction, gen,
    Array.from(arrays.torsal || []), header.handles.filter((h) => h.kind === 'normal'), size,
    Array.from(arrays.torsal || []).map((i) => Array.from(G.subarray(6 * i, 6 * i + 6)))], drawConstruction);
  redrawIf('grid', [header.bbox], drawGrid);
  redrawIf('handles', [header.handles, size, [...selection], primaryLabel], drawHandles);
  if (highlighted) drawHighlight();
  lap('construction');
  render(); lap('render');
  window.designer.drawTimes = times;
}

const drawnKeys = {};  // layer -> what it was last drawn from (JSON)
function redrawIf(layer, inputs, draw) {
  const key = JSON.stringify(inputs);
  if (drawnKeys[layer] === key) { window.designer.kept[layer] = (window.designer.kept[layer] || 0) + 1; return; }
  drawnKeys[layer] = key;
  draw();
}

// ------------------------------------------------------------------ handles and selection
const selection = new Set();   // labels of the selected handles
let primaryLabel = null;       // the handle the axis arrows and typed coordinates act on

function handleMeshes() { return layers.handles.children.filter((o) => o.userData.handle); }

function drawHandles() {
  const attached = gizmo.object?.userData.handle?.label;
  gizmo.detach();
  clearGroup(layers.handles);
  const r = 0.012 * size;
  const sphere = new THREE.SphereGeometry(1, 16, 12);
  const cube = new THREE.BoxGeometry(1.6, 1.6, 1.6);
  const labels = new Set(current.header.handles.map((h) => h.label));
  for (const l of [...selection]) if (!labels.has(l)) selection.delete(l);
  if (primaryLabel && !labels.has(primaryLabel)) primaryLabel = null;
  for (const h of current.header.handles) {
    const normal = h.kind === 'normal', sized = h.kind === 'size';
    const picked = selection.has(h.label);
    // Drawn over the faces: a handle inside a tube or behind a sheet can still be taken.
    const mat = new THREE.MeshBasicMaterial({
      color: picked ? 0x1d4ed8 : normal ? 0x10a060 : sized ? 0x8a2be2 : 0xff6a00,
      depthTest: false, transparent: true, opacity: 0.95 });
    const m = new THREE.Mesh(sized ? cube.clone() : sphere.clone(), mat);
    m.renderOrder = 10;
    m.scale.setScalar((normal ? 1.4 : 1) * (picked ? 1.35 : 1) * r);
    m.position.set(...h.position);
    m.userData.handle = h;
    layers.handles.add(m);
    if (normal || sized) {
      const seg = new Float32Array([...h.anchor, ...h.position]);
      const line = lines(seg, null, sized ? 0x8a2be2 : 0x10a060);
      line.userData.isLeash = true;
      m.userData.leash = line;
      layers.handles.add(line);
    }
    if (attached && h.label === attached && !dragging) gizmo.attach(m);
  }
  sphere.dispose();
  cube.dispose();
  showSelection();
}

function select(label, add) {
  if (!add) selection.clear();
  if (label === null) { primaryLabel = null; gizmo.detach(); }
  else if (add && selection.has(label)) {
    selection.delete(label);
    if (primaryLabel === label) primaryLabel = [...selection][0] || null;
  } else { selection.add(label); primaryLabel = label; }
  drawHandles();
  render();
}

function handleByLabel(label) { return current.header.handles.find((h) => h.label === label); }

// The point list a handle belongs to (a curve's points or a [surface] list) and its index.
function listOf(h) {
  const path = h.path;
  if (!path.length || typeof path[path.length - 1] !== 'number') return null;
  const listPath = path.slice(0, -1);
  if (listPath[0] === 'rulings') return null;  // a directrix has exactly two points
  return { listPath, index: path[path.length - 1], points: valueAt(listPath) };
}

function showSelection() {
  const box = $('selection');
  const h = primaryLabel && handleByLabel(primaryLabel);
  $('sel-name').textContent = !selection.size ? 'nothing selected (click a sphere; Shift+click adds)'
    : selection.size === 1 ? primaryLabel : `${selection.size} points (${primaryLabel} typed)`;
  for (const [i, axis] of ['x', 'y', 'z'].entries()) {
    const input = $(`sel-${axis}`);
    input.disabled = !h || h.kind !== 'point';
    if (document.activeElement !== input) input.value = h ? +h.position[i].toFixed(6) : '';
  }
  const list = h && h.kind === 'point' ? listOf(h) : null;
  for (const id of ['pt-insert', 'pt-delete', 'pt-append']) $(id).disabled = !list;
  box.dataset.count = selection.size;
}

// Typing one coordinate of the typed point moves every selected point by the same amount.
function typeCoordinate(axis) {
  const h = primaryLabel && handleByLabel(primaryLabel);
  const input = $(`sel-${'xyz'[axis]}`);
  const text = input.value.trim();
  const v = text === '' ? NaN : Number(text);   // Number('') is 0: a cleared field is no value
  if (!h) { showSelection(); return; }
  if (!Number.isFinite(v)) {
    showError(`${h.label} ${'xyz'[axis]}: expected a finite number, got ${text ? JSON.stringify(text) : 'nothing'}`);
    input.value = +h.position[axis].toFixed(6);
    return;
  }
  const delta = v - h.position[axis];
  const changes = [];
  for (const label of selection) {
    const o = handleByLabel(label);
    if (!o || o.kind !== 'point') continue;
    const p = [...o.position];
    p[axis] = +(p[axis] + delta).toFixed(9);
    changes.push([o.path, p]);
  }
  if (changes.length) queueEdit(changes);
}

// Insert a point after the typed one (half way to the next, or continuing the last span),
// delete it, or add one after the end: the whole list is sent, one edit, one undo step.
function editPoints(action) {
  const h = primaryLabel && handleByLabel(primaryLabel);
  const list = h && listOf(h);
  if (!list) return;
  const pts = list.points.map((p) => [...p]);
  const i = list.index;
  const mid = (a, b) => a.map((x, k) => +((x + b[k]) / 2).toFixed(6));
  const beyond = (a, b) => b.map((x, k) => +(2 * x - a[k]).toFixed(6));
  let chosen = i;
  if (action === 'delete') {
    pts.splice(i, 1);
    chosen = Math.min(i, pts.length - 1);
  } else if (action === 'insert') {
    const p = i + 1 < pts.length ? mid(pts[i], pts[i + 1]) : beyond(pts[i - 1] || pts[i], pts[i]);
    pts.splice(i + 1, 0, p);
    chosen = i + 1;
  } else {
    const n = pts.length;
    pts.push(beyond(pts[n - 2] || pts[n - 1], pts[n - 1]));
    chosen = n;
  }
  // The new selection once the server has the edit: a refused delete keeps the point chosen.
  const label = `${h.label.replace(/\[\d+\]$/, '')}[${chosen}]`;
  queueEdit([[list.listPath, pts]], null, (ok) => {
    if (ok && handleByLabel(label)) { select(label, false); showSelection(); }
  });
}

// Snapping while dragging: to the grid (its step) and to the other points (within 10 px).
function snapped(pos, h) {
  if ($('snap-points').checked) {
    let best = null, bestD = 10;
    const rect = canvas.getBoundingClientRect();
    const screen = (v) => { const p = v.clone().project(camera);
      return [(p.x + 1) / 2 * rect.width, (1 - p.y) / 2 * rect.height]; };
    const [sx, sy] = screen(pos);
    for (const o of current.header.handles) {
      if (o.label === h.label || selection.has(o.label) || o.kind !== 'point') continue;
      const [x, y] = screen(new THREE.Vector3(...o.position));
      const d = Math.hypot(x - sx, y - sy);
      if (d < bestD) { bestD = d; best = o; }
    }
    if (best) return new THREE.Vector3(...best.position);
  }
  if ($('snap-grid').checked) {
    const step = layers.grid.children[0]?.userData.step || 1;
    return new THREE.Vector3(...pos.toArray().map((x) => Math.round(x / step) * step));
  }
  return pos;
}

function fitView() {
  const [lo, hi] = current.header.bbox;
  const c = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  const dir = camera.position.clone().sub(orbit.target);
  if (dir.lengthSq() < 1e-20) dir.set(0.55, -1, 0.6);
  orbit.target.copy(c);
  camera.position.copy(c).addScaledVector(dir.normalize(), 1.5 * size);
  camera.zoom = 1;
  perspective.near = size / 1000; perspective.far = size * 100;
  perspective.updateProjectionMatrix();
  orbit.update();
  syncOrtho();
  render();
}

// View presets: top (looking down -Z), front (looking along +Y), right (along -X), and the
// perspective three-quarter view. Presets other than perspective use the orthographic camera.
const VIEWS = { top: [0, 0, 1], front: [0, -1, 0], right: [1, 0, 0], perspective: [0.55, -1, 0.6] };
function setView(name) {
  useCamera(name === 'perspective' ? perspective : orthographic);
  const dir = new THREE.Vector3(...VIEWS[name]);
  // OrbitControls keeps +Z up: straight down is its pole, so look down a hair off it
  // (then +Y is up on screen, as on a plan).
  if (name === 'top') dir.set(0, -1e-3, 1);
  camera.position.copy(orbit.target).addScaledVector(dir.normalize(), 1.5 * size);
  camera.lookAt(orbit.target);
  orbit.update();
  window.designer.view = name;
  fitView();
}

function screenshot() {
  render();
  const a = document.createElement('a');
  a.href = canvas.toDataURL('image/png');
  a.download = `${(current.header.save_name || 'design').replace(/\.toml$/, '').replace(/\//g, '_')}.png`;
  document.body.append(a);
  a.click();
  a.remove();
}

// ------------------------------------------------------------------ face read-out and panels
const faceRay = new THREE.Raycaster();
function faceAt(event) {
  const mesh = layers.faces.children[0];
  if (!mesh || !layers.faces.visible) return null;
  const rect = canvas.getBoundingClientRect();
  const p = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  faceRay.setFromCamera(p, camera);
  const hit = faceRay.intersectObject(mesh, false)[0];
  return hit ? current.arrays.triangle_face[hit.faceIndex] : null;
}

function readoutHtml(info) {
  const ang = info.angles;
  return `<b>${info.label}</b> ${info.kind}, ${info.corners} corners<br>planarity ${
    fmt(info.planarity)}<br>area ${fmt(info.area)}<br>angles ${ang.map((a) => a.toFixed(1)).join(
    '°, ')}°<br>edges ${info.edges.map((e) => fmt(e)).join(', ')}${info.cls !== null
    ? `<br>class ${info.cls}` : ''}`;
}

// The face under the pointer outlined (so the read-out says which face it is, also in a
// dense mesh): one line loop whose buffer is rewritten, nothing made per pointer move.
const HOVER_CORNERS = 64;
// (Transparent, so it is drawn in the pass of the face edges, after them: they lie on it.)
const hoverOutline = new THREE.LineLoop(new THREE.BufferGeometry(),
  new THREE.LineBasicMaterial({ color: 0xffd400, depthTest: false, transparent: true }));
hoverOutline.geometry.setAttribute('position',
  new THREE.BufferAttribute(new Float32Array(3 * HOVER_CORNERS), 3));
Object.assign(hoverOutline, { frustumCulled: false, renderOrder: 9, visible: false });
scene.add(hoverOutline);
function outlineFace(f) {
  if (f === null) {
    if (hoverOutline.visible) { hoverOutline.visible = false; requestRender(); }
    return;
  }
  const { vertices: V, face_offsets: off, face_indices: idx } = current.arrays;
  const n = Math.min(off[f + 1] - off[f], HOVER_CORNERS);
  const attr = hoverOutline.geometry.getAttribute('position');
  for (let k = 0; k < n; k++) {
    for (let i = 0; i < 3; i++) attr.array[3 * k + i] = V[3 * idx[off[f] + k] + i];
  }
  attr.needsUpdate = true;
  hoverOutline.geometry.setDrawRange(0, n);
  hoverOutline.visible = true;
  requestRender();
}

// The face's corners on screen, as a box in the view's pixels: {left, top, right, bottom}.
// A corner behind a perspective camera projects mirrored, so then the box is the whole view.
const corner = new THREE.Vector3(), eye = new THREE.Vector3();
function faceBox(f) {
  const { vertices: V, face_offsets: off, face_indices: idx } = current.arrays;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  const box = { left: Infinity, top: Infinity, right: -Infinity, bottom: -Infinity };
  for (let k = off[f]; k < off[f + 1]; k++) {
    const v = 3 * idx[k];
    corner.set(V[v], V[v + 1], V[v + 2]);
    if (camera.isPerspectiveCamera && eye.copy(corner).applyMatrix4(camera.matrixWorldInverse).z >= 0) {
      return { left: 0, top: 0, right: w, bottom: h };
    }
    corner.project(camera);
    const x = (corner.x + 1) / 2 * w, y = (1 - corner.y) / 2 * h;
    box.left = Math.min(box.left, x); box.right = Math.max(box.right, x);
    box.top = Math.min(box.top, y); box.bottom = Math.max(box.bottom, y);
  }
  return box;
}

// The read-out goes beside the face's box on screen, never over it (it would hide the face
// it describes): right of it, else left, below or above, the first side with room in the
// view (left of the panel drawer when that is open), level with the pointer and kept
// inside the view. Only a face whose box leaves no room on any side (zoomed in close) gets
// the read-out in the view's corner farthest from the pointer, over the face.
const READOUT_GAP = 12;     // pixels between the face's box and the read-out
const READOUT_MARGIN = 4;   // pixels kept free at the view's edges
function placeReadout(box, f, pointer) {
  const r = faceBox(f);
  const drawer = $('drawer');
  const w = (drawer.hidden ? canvas.clientWidth : drawer.offsetLeft) - READOUT_MARGIN;
  const h = canvas.clientHeight - READOUT_MARGIN, m = READOUT_MARGIN;
  // Measured at the view's corner: placed near its right edge, the box would be narrower
  // (its width shrinks to the room left of the edge) and grow again where it goes.
  box.style.left = '0px';
  box.style.top = '0px';
  const bw = box.offsetWidth, bh = box.offsetHeight;
  const clamp = (v, lo, hi) => Math.max(lo, Math.min(v, hi));
  const x = clamp(pointer.x + 14, m, w - bw), y = clamp(pointer.y + 14, m, h - bh);
  const sides = [
    ['right', r.right + READOUT_GAP, y, r.right + READOUT_GAP + bw <= w],
    ['left', r.left - READOUT_GAP - bw, y, r.left - READOUT_GAP - bw >= m],
    ['below', x, r.bottom + READOUT_GAP, r.bottom + READOUT_GAP + bh <= h],
    ['above', x, r.top - READOUT_GAP - bh, r.top - READOUT_GAP - bh >= m],
  ];
  let [side, left, top] = sides.find((s) => s[3])
    || ['corner', pointer.x < (m + w) / 2 ? w - bw : m, pointer.y < (m + h) / 2 ? h - bh : m];
  left = Math.max(m, left); top = Math.max(m, top);
  box.style.left = `${left}px`;
  box.style.top = `${top}px`;
  window.designer.readoutSide = side;
}

let hoverPointer = { x: 0, y: 0 };   // where the pointer was over the view (its pixels)
function showReadout(event, f) {
  const box = $('readout');
  outlineFace(f);
  if (f === null) { box.hidden = true; window.designer.hover = null; return; }
  const info = faceInfo(f);
  box.innerHTML = readoutHtml(info);
  box.hidden = false;   // shown before it is placed: its size is known only then
  hoverPointer = { x: event.offsetX, y: event.offsetY };
  placeReadout(box, f, hoverPointer);
  window.designer.hover = info;
}

// The face of the open panel (clicked, or named in the panel figures): its outline and a
// dot at its centre drawn over everything, since a small face of a dense mesh is hard to
// find. Kept while the faces are the same; a new topology numbers them anew.
let highlighted = null;   // {face, topology}
const HIGHLIGHT = 0xb0208a;
function drawHighlight() {
  clearGroup(layers.highlight);
  if (!highlighted || !current || highlighted.topology !== current.header.topology) {
    highlighted = null;
    return;
  }
  const { vertices: V, face_offsets: off, face_indices: idx } = current.arrays;
  const f = highlighted.face, n = off[f + 1] - off[f];
  const corners = new Float32Array(3 * n), centre = new Float32Array(3);
  for (let k = 0; k < n; k++) {
    for (let i = 0; i < 3; i++) {
      corners[3 * k + i] = V[3 * idx[off[f] + k] + i];
      centre[i] += corners[3 * k + i] / n;
    }
  }
  const outline = new THREE.BufferGeometry().setAttribute('position', new THREE.BufferAttribute(corners, 3));
  const dot = new THREE.BufferGeometry().setAttribute('position', new THREE.BufferAttribute(centre, 3));
  for (const o of [
    // transparent: drawn after the face edges, which lie on the outline
    new THREE.LineLoop(outline, new THREE.LineBasicMaterial({ color: HIGHLIGHT, depthTest: false,
                                                              transparent: true })),
    new THREE.Points(dot, new THREE.PointsMaterial({ color: HIGHLIGHT, size: 9, sizeAttenuation: false,
                                                     depthTest: false, transparent: true }))]) {
    o.renderOrder = 10;
    layers.highlight.add(o);
  }
}
function highlightFace(f) {
  highlighted = f === null ? null : { face: f, topology: current.header.topology };
  drawHighlight();
  requestRender();
}

// After a new state: the hovered face's read-out and outline with its new figures while
// the faces are the same, else gone until the pointer moves.
function followHover(sameFaces) {
  const info = window.designer.hover;
  if (!info) return;
  if (!sameFaces) { showReadout(null, null); return; }
  const now = faceInfo(info.face);
  $('readout').innerHTML = readoutHtml(now);
  placeReadout($('readout'), info.face, hoverPointer);   // the face may have moved or grown
  window.designer.hover = now;
  outlineFace(info.face);
}

// A face number names a face of one set of faces (a topology): the request says which, the
// server answers {stale} when its faces are others by then, and an answer is shown only
// while the page still draws those faces and no newer request (or a close) came after it.
// An answer from an older build of the same faces is the right face: shown, and read again.
let panelAsk = 0;   // the newest panel request; closing the drawer counts as one
async function openPanel(f) {
  const ask = ++panelAsk;
  const topology = current.header.topology;
  highlightFace(f);
  let data;
  try {
    data = await api('GET', `panel?face=${f}&topology=${encodeURIComponent(topology)}`);
  } catch (err) {
    if (ask === panelAsk) showError(err.message);
    return;
  }
  if (ask !== panelAsk) return;
  if (data.stale || data.topology !== topology || current.header.topology !== topology) {
    window.designer.panelsDropped += 1;
    if (highlighted?.face === f) highlightFace(null);
    noteUpdate(current.header.version, `panel P${f} not opened: the faces changed`);
    return;
  }
  const drawer = $('drawer');
  drawer.hidden = false;
  $('drawer-title').textContent = `panel ${data.row.label}`;
  const pts = data.outline;
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const w = x1 - x0 || 1, h = y1 - y0 || 1, pad = 0.08 * Math.max(w, h);
  const poly = pts.map((p) => `${p[0]},${-p[1]}`).join(' ');
  const edgeLabels = pts.map((p, i) => {
    const q = pts[(i + 1) % pts.length];
    const len = Math.hypot(q[0] - p[0], q[1] - p[1]);
    return `<text x="${(p[0] + q[0]) / 2}" y="${-(p[1] + q[1]) / 2}" font-size="${
      0.05 * Math.max(w, h)}" text-anchor="middle">${fmt(len)}</text>`;
  }).join('');
  $('drawer-shape').innerHTML = `<svg viewBox="${x0 - pad} ${-y1 - pad} ${w + 2 * pad} ${h + 2 * pad}"
    width="280" height="${Math.min(280, 280 * (h + 2 * pad) / (w + 2 * pad))}">
    <polygon points="${poly}" fill="#dde8f6" stroke="#1d4ed8" stroke-width="${0.006 * Math.max(w, h)}"/>
    ${edgeLabels}</svg>`;
  $('drawer-row').innerHTML = Object.entries(data.row).map(([k, v]) => `<tr><th>${k}</th><td>${
    typeof v === 'number' ? fmt(v) : v}</td></tr>`).join('');
  window.designer.panel = data;
  if (data.version < current.header.version) followPanel(true);  // built before the newest
}

function closePanel() {
  panelAsk += 1;   // an answer still on its way does not open the drawer again
  $('drawer').hidden = true;
  window.designer.panel = null;
  highlightFace(null);
}

// The open panel follows the design: read again once edits pause while the faces are the
// same (its edges and angles move with the points), closed when they change (the face
// numbers then name other faces).
let panelTimer = null;
function followPanel(sameFaces) {
  clearTimeout(panelTimer);
  const open = window.designer.panel;
  if ($('drawer').hidden || !open) return;
  if (!sameFaces) {
    closePanel();
    noteUpdate(current.header.version, `panel ${open.row.label} closed: the faces changed`);
    return;
  }
  panelTimer = setTimeout(() => { if (window.designer.panel) openPanel(open.face); }, 350);
}

// Labels of the faces, on demand: the fabrication names (P0, P1, ... as on the cutting
// sheets and in panels.csv), drawn for the faces whose centres are on screen (at most 400).
const MAX_LABELS = 400;
function drawLabels() {
  const box = $('labels');
  if (!layers.labels.visible || !current) { box.innerHTML = ''; box.hidden = true; return; }
  box.hidden = false;
  const { vertices: V, face_offsets: off, face_indices: idx } = current.arrays;
  const rect = canvas.getBoundingClientRect();
  const out = [];
  const v = new THREE.Vector3();
  for (let f = 0; f < off.length - 1 && out.length <= MAX_LABELS; f++) {
    v.set(0, 0, 0);
    for (let k = off[f]; k < off[f + 1]; k++) {
      v.x += V[3 * idx[k]]; v.y += V[3 * idx[k] + 1]; v.z += V[3 * idx[k] + 2];
    }
    v.divideScalar(off[f + 1] - off[f]).project(camera);
    if (Math.abs(v.x) > 1 || Math.abs(v.y) > 1 || v.z > 1) continue;
    out.push(`<span style="left:${(v.x + 1) / 2 * rect.width}px;top:${
      (1 - v.y) / 2 * rect.height}px">P${f}</span>`);
  }
  box.innerHTML = out.length > MAX_LABELS
    ? `<em class="note">${off.length - 1} faces: zoom in to label them</em>` : out.join('');
  window.designer.labels = out.length > MAX_LABELS ? -1 : out.length;
}

// ------------------------------------------------------------------ figures
function setFig(name, text, pending = false) {
  const cell = document.querySelector(`[data-fig="${name}"]`);
  cell.textContent = text;
  cell.classList.toggle('pending', pending);
}

function showFigures(fig, quick = false) {
  setFig('faces', fig.faces);
  setFig('kinds', fig.kinds_text || '-');
  setFig('planarity', fmt(fig.planarity_max));
  setFig('non_convex', fig.non_convex);
  // Coverage, closeness and the panel count are computed on request (a button, or a
  // colouring that needs them): during edits they would compete with the builds.
  if (window.designer.figuresVersion !== current?.header.version) {
    for (const k of ['coverage', 'closeness', 'panels']) setFig(k, '-', true);
    $('report').textContent = 'not computed for this version';
  }
  $('warnings').innerHTML = '';
  // A quick mesh's warnings (its share of triangles, its strips without rows) are not the
  // design's: the full mesh that replaces it has its own. Said above them, not hidden.
  $('warnings').classList.toggle('quick', quick && fig.warnings.length > 0);
  $('warnings').dataset.caption = quick ? 'warnings of the quick mesh (the full mesh has its own):' : '';
  for (const w of fig.warnings) {
    const li = document.createElement('li');
    li.textContent = w;
    $('warnings').append(li);
  }
}

let figureTimer = null;
const needsSlowFigures = () => ['closeness', 'class'].includes($('colour').value);
function scheduleSlowFigures() {
  clearTimeout(figureTimer);
  if (!needsSlowFigures()) return;
  // Wait until the edits settle: the slow figures are recomputed from scratch each time.
  figureTimer = setTimeout(fetchSlowFigures, 350);
}
async function fetchSlowFigures() {
  const version = current.header.version;
  for (const k of ['coverage', 'closeness', 'panels']) setFig(k, '...', true);
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
  // The full report, as `ruledmesh analyze --json` prints it.
  $('report').textContent = fig.report ? JSON.stringify(fig.report, null, 1) : 'n/a';
  window.designer.report = fig.report || null;
  if (msg.header.error) {
    for (const k of ['coverage', 'closeness', 'panels']) setFig(k, 'error');
    status('figures: ' + msg.header.error);
  }
  closeness = msg.arrays.closeness ? new Float32Array(msg.arrays.closeness) : null;
  classes = msg.arrays.class ? new Uint32Array(msg.arrays.class) : null;
  window.designer.figuresVersion = version;
  if (['closeness', 'class'].includes($('colour').value)) recolour();
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

// A slider with a number field (and a button widening its range) for a numeric field.
function numberControl(row, path, name, value, send) {
  const k = keyOf(path);
  const isInt = Number.isInteger(value) && !(name === 'extend')
    && !(current.header.decimal_fields || []).includes(path.join('.'));
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
    field.dataset.synced = field.value;
    send(v, `slider:${k}:${gestures[k] || 0}`);
  });
  slider.addEventListener('change', () => { gestures[k] = (gestures[k] || 0) + 1; activeInput = null; });
  field.dataset.synced = field.value;
  field.addEventListener('change', () => {
    field.dataset.synced = field.value;
    const text = field.value.trim();
    const num = Number(text);
    // Only finite numbers travel as numbers: Infinity and 1e400 would become JSON null, which
    // deletes the field. As text, the server refuses them with a line naming the field.
    const v = text !== '' && Number.isFinite(num) ? num : text;
    // A typed value past the slider's ends widens it.
    if (typeof v === 'number') {
      if (v > +slider.max) slider.max = v;
      if (v < +slider.min) slider.min = v;
    }
    send(v);
  });
  // The range can be widened: twice as far either side of the value (integers: up).
  const widen = document.createElement('button');
  widen.className = 'widen';
  widen.textContent = '↔';
  widen.title = 'widen the slider range';
  widen.dataset.widen = path.join('.');
  widen.addEventListener('click', () => {
    const v = +slider.value, lo = +slider.min, hi = +slider.max;
    if (isInt) { slider.max = Math.max(2 * hi, hi + 10); if (lo < 0) slider.min = 2 * lo; }
    else {
      const span = Math.max(hi - lo, 1e-9);
      slider.min = lo >= 0 && v - span >= 0 ? v - span : lo >= 0 ? 0 : v - span;
      slider.max = v + span;
      slider.step = (slider.max - slider.min) / 400;
    }
  });
  row.append(slider, field, widen);
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
  const send = (v, coalesce) => queueEdit([[path, v]], coalesce);

  if ((name === 'respace' || name === 'thin') && path[0] === 'mesh') {
    // "auto" or a boolean: one list of the three, the booleans sent as booleans.
    const sel = document.createElement('select');
    for (const c of ['auto', 'true', 'false']) sel.add(new Option(c, c, false, c === String(value)));
    sel.dataset.path = path.join('.');
    sel.addEventListener('change', () => send(sel.value === 'auto' ? 'auto' : sel.value === 'true'));
    row.append(sel);
  } else if (typeof value === 'boolean') {
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = value;
    box.addEventListener('change', () => send(box.checked));
    row.append(box);
  } else if (typeof value === 'number' || name in NUMERIC_OR_WORD) {
    numberControl(row, path, name, value, send);
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
  if (name === 'rows_from' && path[0] === 'mesh') return ['auto', 'primary', 'c1', 'c2', 'both', 'none'];
  if (name === 'division' && path[0] === 'mesh') return ['auto', 'even', 'graded', 'bounded'];
  if (path[0] === 'surface' && path.length === 2) {
    return ch.kind_choices?.[current.header.design.surface?.kind]?.[name] || null;
  }
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
  const shape = designShape(design) + '|' + (design.surface?.kind || '') + '|'
    + (design.mesh?.method || 'pq') + '|' + JSON.stringify(design.rulings?.between || null);
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
  if (Array.isArray(design.rulings?.between)) betweenControl(box, design);
  section('[mesh]', design.mesh, ['mesh']);
  // Every numeric (and boolean) field of the method, also those left at their defaults; for
  // a catalogue kind its [surface] and [mesh] fields with literal defaults (the server's).
  for (const table of ['surface', 'mesh']) {
    for (const [k, v] of Object.entries(defaultsOf(design, table))) {
      if (design[table] && k in design[table]) continue;
      control(box, [table, k], k, v);
      box.lastElementChild?.classList.add('default');
    }
  }
  for (const [name, spec] of Object.entries(design.curves || {})) section(`[curves.${name}]`, spec, ['curves', name]);
  // the primary slider's range follows the generator count
  const count = design.rulings?.count;
  const prim = box.querySelector('input[type=range][data-path="mesh.primary"]');
  if (prim && count) prim.max = count - 1;
}

// The fields of ``table`` ('surface' or 'mesh') that ``design`` shows at their defaults: a
// catalogue kind's (the server's), else the mesh method's; {} where there are none.
function defaultsOf(design, table) {
  if (design.surface) return current.header.choices.kind_fields?.[design.surface.kind]?.[table] || {};
  return table === 'mesh' ? METHOD_FIELDS[design.mesh?.method || 'pq'] || {} : {};
}

// The default shown for a field the design leaves out, or undefined.
function defaultAt(path) {
  return path.length === 2 ? defaultsOf(current.header.design, path[0])[path[1]] : undefined;
}

// The fields of each mesh method with their defaults (as the builders read them), so every
// one has a control even while the design leaves it out.
const METHOD_FIELDS = {
  pq: { rows: 20, primary: 'middle', option: 0, extend: 'auto', trim: true, max_extend: 20.0,
        planarity_tolerance: 1e-12, refine: true, respace: 'auto', rows_from: 'auto', division: 'auto',
        thin: 'auto' },
  hybrid: { midpoints: 1, divisions: 8, flip: false, orient: true },
};

// The two director curves the surface is ruled between: menus of the design's curves.
function betweenControl(box, design) {
  const row = document.createElement('div');
  row.className = 'ctl';
  const label = document.createElement('span');
  label.className = 'name';
  label.textContent = 'between';
  row.append(label);
  const names = Object.keys(design.curves || {});
  design.rulings.between.forEach((cur, i) => {
    const sel = document.createElement('select');
    for (const n of names) sel.add(new Option(n, n, false, n === cur));
    sel.dataset.between = i;
    sel.addEventListener('change', () => {
      const pair = [...design.rulings.between];
      pair[i] = sel.value;
      queueEdit([[['rulings', 'between'], pair]]);
    });
    row.append(sel);
  });
  box.append(row);
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
    // A focused text field keeps what the user is typing (not yet sent): it differs from the
    // value last shown or sent; once sent, the server's answers (and other tabs') show again.
    if (!force && (el === activeInput || (el === document.activeElement && el.type === 'text'
                                          && el.value !== el.dataset.synced))) continue;
    const path = el.dataset.path.split('.');
    let v = valueAt(path);
    if (v === undefined) v = defaultAt(path);
    if (v === undefined) continue;
    if (el.type === 'checkbox') el.checked = v;
    else if (el.type === 'range') { if (typeof v === 'number') el.value = v; }
    else if (el.tagName === 'SELECT' || el.type === 'text') { el.value = String(v); el.dataset.synced = el.value; }
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
    if (await sendNow('design', lastRuled ? { design: lastRuled } : { default: true }) && tomlTemplate) {
      showDesignToml();
    }
    return;
  }
  const candidate = { name: kind, surface: { kind }, mesh: {} };
  const ok = await sendNow('design', { design: candidate });
  if (ok && tomlTemplate) showDesignToml();
  if (!ok) {
    // The kind needs fields: offer a template in the TOML pane to fill in.
    $('toml').value = `name = "${kind}"\n\n[surface]\nkind = "${kind}"\n# add the fields the ` +
      `message above asks for, then Apply\n\n[mesh]\n`;
    tomlDirty = true;
    tomlTemplate = true;
    $('toml-pane').open = true;
    buildKindChooser();
  }
});

// ------------------------------------------------------------------ edits
let inFlight = false;
const jobs = [];      // edits waiting to be sent: {changes: Map key -> [path, value], coalesce, t}
let sentAt = 0;
const timings = [];
const breakdown = [];  // {total, server, page} ms per edit (see settleMarks)
const frameTimes = []; // ms from the input event to the next frame after its state was drawn
const frameLog = [];   // {ms, version, changes}: what each of frameTimes measured
const marks = [];      // input events waiting for the frame that shows them: {t, version, ...}
let shown = { version: -1, at: 0, received: 0 };  // the last state drawn and its frame

// Edits go one at a time. While one is on its way, later values of the same fields replace
// the waiting ones (the newest wins: a slider moved on, a point dragged further), so fast
// input never builds a backlog of designs nobody will see.
function queueEdit(changes, coalesce = null, after = null) {
  const keys = changes.map(([path]) => keyOf(path));
  let job = jobs[jobs.length - 1];
  const sameFields = job && job.changes.size === keys.length && keys.every((k) => job.changes.has(k));
  if (!job || !(sameFields || (coalesce !== null && job.coalesce === coalesce))) {
    job = { changes: new Map(), coalesce, t: 0, after: [] };
    jobs.push(job);
  }
  if (after) job.after.push(after);  // told whether the server accepted the edit
  if (coalesce !== null) job.coalesce = coalesce;
  for (const [path, value] of changes) job.changes.set(keyOf(path), [path, value]);
  job.t = performance.now();  // the input whose value the frame will show
  if (!inFlight) flush();
}

async function flush() {
  inFlight = true;
  while (jobs.length) {
    const job = jobs.shift();
    const ok = await send('edit', { changes: [...job.changes.values()], coalesce: job.coalesce }, job.t);
    for (const f of job.after) f(ok);
  }
  inFlight = false;
  catchUp();
}

// Slider to frame: from the input event to the animation frame after the state it asked
// for was written into the buffers (performance marks, also in the browser's timeline).
function settleMarks() {
  for (let i = marks.length - 1; i >= 0; i--) {
    const m = marks[i];
    if (m.version === null || m.version > shown.version) continue;
    marks.splice(i, 1);
    const ms = shown.at - m.t;
    performance.measure('ruledmesh slider-to-frame', { start: m.t, end: shown.at });
    frameTimes.push(ms);
    frameLog.push({ ms, version: shown.version, changes: m.changes });
    // server: the edit's build and commit; answered, arrived: when the answer to the edit
    // and the state's frame reached the page; page: from then to the frame.
    breakdown.push({ total: ms, server: m.serverMs, answered: m.answered - m.t,
                     arrived: shown.received - m.t, page: shown.at - shown.received });
    for (const list of [frameTimes, frameLog, breakdown]) if (list.length > 200) list.shift();
  }
}

function frameDrawn(version, received) {
  requestAnimationFrame(() => {
    if (version < shown.version) return;
    shown = { version, at: performance.now(), received };
    performance.mark('ruledmesh frame');
    settleMarks();
  });
}

// POST an action that changes the state; returns false (and shows why) on error. With the
// live socket the answer is {version} and the state arrives on the socket (applyState).
async function send(name, body, inputAt = null) {
  sentAt = performance.now();
  const started = inputAt ?? sentAt;
  try {
    const msg = await api('POST', name, body || {});
    const received = performance.now();
    showError('');
    const mark = { t: started, version: null, changes: body?.changes || name, serverMs: msg.serverMs,
                   answered: received };
    marks.push(mark);
    if (msg.header) {         // the state itself (no live socket)
      applyState(msg);
      frameDrawn(msg.header.version, received);
      mark.version = msg.header.version;
    } else {
      mark.version = msg.version;
      settleMarks();          // the socket may have brought it already
    }
    const ms = received - sentAt;
    timings.push(ms);
    if (timings.length > 50) timings.shift();
    const note = updateNote?.version === mark.version ? `; ${updateNote.text}` : '';
    status(`updated in ${ms.toFixed(0)} ms (server ${msg.serverMs?.toFixed(0)} ms)${note}`);
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

// Actions sent outside the edit queue (Apply, the kind menu): the page is busy while they
// build, and an error left from an earlier action goes at once.
let direct = 0;
async function sendNow(name, body) {
  direct += 1;
  showError('');
  status('building...');
  try {
    return await send(name, body);
  } finally {
    direct -= 1;
  }
}

// The whole state, faces included (when an answer without them found other faces here).
async function refreshFull() {
  const saved = current;
  current = null;  // no topology header: the server sends everything
  try {
    applyState(await api('GET', 'state'));
  } catch (err) {
    current = saved;
    showError(err.message);
  }
}

async function refresh() {
  try {
    applyState(await api('GET', 'state'));
  } catch (err) {
    showError(err.message);
  }
}

// ------------------------------------------------------------------ live updates
// The server pushes every new state on a WebSocket as a binary frame (the message of
// /api/state; without the faces while they stay the same), to every open tab: an edit,
// undo or redo in any tab shows in all of them, and this tab's own edits come this way too.
let live = null;
let liveVersion = null;
const liveOpen = () => live !== null && live.readyState === WebSocket.OPEN && window.designer.live;
function connectLive(delay = 500) {
  const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/api/live?token=${
    encodeURIComponent(TOKEN)}`;
  live = new WebSocket(url);
  live.binaryType = 'arraybuffer';
  live.addEventListener('open', () => { window.designer.live = true; delay = 500; });
  live.addEventListener('message', (event) => {
    if (typeof event.data === 'string') {
      // What the full build of the quick mesh shown is at ("mesh 7, 60 generators").
      const note = JSON.parse(event.data);
      if (note.refining && current && note.version === current.header.version
          && current.header.refining) {
        current.header.refine_note = note.refining;
        showRefining(current.header);
        window.designer.refineNotes += 1;
        window.designer.refineNote = note.refining;
      }
      return;
    }
    const received = performance.now();
    const msg = decode(event.data);
    msg.raw = event.data;
    liveVersion = msg.header.version;
    window.designer.liveFrames += 1;
    if (current && msg.header.version < current.header.version) return;
    applyState(msg);
    frameDrawn(msg.header.version, received);
  });
  live.addEventListener('close', () => {
    window.designer.live = false;
    setTimeout(() => connectLive(Math.min(2 * delay, 10_000)), delay);
  });
}
function catchUp() {
  // Without the socket's frames (it reconnects), a newer version is fetched.
  if (inFlight || jobs.length || liveVersion === null || !current || liveOpen()) return;
  if (liveVersion !== current.header.version) refresh();
}

// The session's history: what each step did; a click goes back or forward to it.
function showHistory(history) {
  const list = $('history');
  const items = [
    ...history.undo.map((t, i) => ({ t, steps: history.undo.length - i, cls: 'past' })),
    { t: history.current, steps: 0, cls: 'now' },
    ...history.redo.map((t, i) => ({ t, steps: -(i + 1), cls: 'future' })),
  ];
  list.innerHTML = '';
  for (const it of items) {
    const li = document.createElement('li');
    li.textContent = it.t;
    li.className = it.cls;
    li.title = it.steps > 0 ? `undo ${it.steps} step(s)` : it.steps < 0 ? `redo ${-it.steps} step(s)` : 'now';
    if (it.steps) li.addEventListener('click', () => goTo(it.steps));
    list.append(li);
  }
  list.scrollTop = list.scrollHeight;  // the newest steps in sight (the panel does not scroll)
}
async function goTo(steps) {
  for (let k = 0; k < Math.abs(steps); k++) {
    if (!(await send(steps > 0 ? 'undo' : 'redo'))) break;
  }
}

let tomlDirty = false;
let tomlBase = null;       // the design's TOML when the text in the pane began to differ from it
let tomlTemplate = false;  // the text is a kind's template the page put there (not the user's)
// Typed text is kept while the design changes (another tab, an edit here), but said to be
// behind it: Apply would replace the newer design with it.
function showTomlStale() {
  $('toml-stale').hidden = !(tomlDirty && !tomlTemplate && tomlBase !== null
                             && current && current.header.toml !== tomlBase);
}
let firstState = true;
const FACE_ARRAYS = ['triangles', 'triangle_face', 'kind', 'edges', 'face_offsets', 'face_indices'];
function applyState(msg) {
  const applyStart = performance.now();
  // An answer overtaken by a newer state (another tab, a live refresh) is not drawn.
  if (current && msg.header.version < current.header.version) return;
  if (msg.header.same_topology) {
    // Same faces as drawn: only the vertices (and figures) came; keep our face arrays.
    if (!current || current.header.topology !== msg.header.topology) { refreshFull(); return; }
    for (const name of FACE_ARRAYS) msg.arrays[name] = current.arrays[name];
    window.designer.sameTopology += 1;
  }
  const changed = !current || current.header.version !== msg.header.version;
  const sameFaces = current !== null && current.header.topology === msg.header.topology;
  current = msg;
  if (changed) followPanel(sameFaces);
  if (changed) { closeness = null; classes = null; }
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
  if (tomlDirty && $('toml').value === h.toml) tomlDirty = false;  // typed back to the design
  if (!tomlDirty) $('toml').value = h.toml;
  showTomlStale();
  showRefining(h);
  showFigures(h.figures, !!h.refining || !!h.refine_error);
  if (h.history) showHistory(h.history);
  buildKindChooser();
  buildControls();
  drawScene();
  if (changed) followHover(sameFaces);
  if (firstState) { fitView(); firstState = false; }
  document.body.dataset.version = h.version;
  window.designer.version = h.version;
  window.designer.renders += 1;
  window.designer.applyMs = performance.now() - applyStart;
  if (changed) scheduleSlowFigures();
}

// A design that refines its generators shows its quick mesh ([mesh] refine = false) while
// the server builds the full one, which then arrives as a new state.
function showRefining(h) {
  const box = $('refining');
  box.hidden = !h.refining && !h.refine_error;
  box.classList.toggle('failed', !!h.refine_error);
  box.textContent = h.refine_error ? `quick mesh shown, the full build failed: ${h.refine_error}`
    : h.refining ? `quick mesh shown (refine = false); refining the generators\u2026${
      h.refine_note ? ` (${h.refine_note})` : ''}` : '';
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
let dragging = null;   // {mesh, plane, offset, moved, starts}
let dragCount = 0;
let pressed = null;    // a press on a face (a click opens its panel)

function setPointer(event) {
  const rect = canvas.getBoundingClientRect();
  pointer.set(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
}

function pick(event) {
  if (!$('view').contains(event.target) || !layers.handles.visible) return null;
  setPointer(event);
  const hits = raycaster.intersectObjects(handleMeshes());
  return hits.length ? hits[0] : null;
}

function handleValue(h, pos) {
  const r = (x) => +x.toFixed(6);
  if (h.kind === 'size') {   // the length along the handle's axis, kept positive
    const along = pos.clone().sub(new THREE.Vector3(...h.anchor)).dot(new THREE.Vector3(...h.axis));
    return along > 0 ? r(along / h.scale) : null;
  }
  if (h.kind === 'normal') {
    const n = pos.clone().sub(new THREE.Vector3(...h.anchor));
    if (n.length() < 1e-9 * size) return null;
    n.normalize();
    return n.toArray().map(r);
  }
  return pos.toArray().map(r);
}

// Moving one handle moves every selected point by the same amount (from where each was when
// the drag began, so answers arriving during the drag do not shift them): one edit per move,
// all the moves of one drag one undo step.
function selectionStarts() {
  const starts = new Map();
  for (const label of selection) {
    const h = handleByLabel(label);
    if (h && h.kind === 'point') starts.set(label, new THREE.Vector3(...h.position));
  }
  return starts;
}

function moveHandle(m, pos, starts) {
  const h = m.userData.handle;
  if (h.kind === 'point') pos = snapped(pos, h);
  if (h.kind === 'size') {   // slides along its axis
    const a = new THREE.Vector3(...h.anchor), u = new THREE.Vector3(...h.axis);
    pos = a.clone().addScaledVector(u, pos.clone().sub(a).dot(u));
  }
  m.position.copy(pos);
  if (m.userData.leash) {
    const a = m.userData.leash.geometry.attributes.position;
    a.setXYZ(1, pos.x, pos.y, pos.z);
    a.needsUpdate = true;
  }
  const v = handleValue(h, pos);
  if (!v) return;
  const changes = [[h.path, v]];
  if (starts && starts.size > 1 && starts.has(h.label)) {
    const delta = pos.clone().sub(starts.get(h.label));
    for (const [label, p0] of starts) {
      const oh = handleByLabel(label);
      if (label === h.label || !oh) continue;
      const p = p0.clone().add(delta);
      const om = handleMeshes().find((o) => o.userData.handle.label === label);
      if (om) om.position.copy(p);
      changes.push([oh.path, handleValue(oh, p)]);
    }
  }
  queueEdit(changes, `drag:${h.label}:${dragCount}`);
}

// Listened to on the view in the capture phase, before the axis arrows' own listener on the
// canvas: a press on a sphere drags the sphere (and the selected points) even where the
// arrows' pick zones overlap it; the arrows are off until the pointer comes up.
$('view').addEventListener('pointerdown', (event) => {
  if (event.target !== canvas || event.button !== 0 || gizmo.dragging) return;
  if (drawing) { addDrawnPoint(event); event.preventDefault(); return; }
  const hit = pick(event);
  if (!hit) {
    if (!gizmo.axis) pressed = { x: event.clientX, y: event.clientY };
    return;
  }
  gizmo.enabled = false;
  const m = hit.object;
  const normal = camera.getWorldDirection(new THREE.Vector3());
  const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, m.position);
  dragging = { mesh: m, plane, offset: m.position.clone().sub(hit.point), moved: false,
               shift: event.shiftKey };
  dragCount += 1;
  orbit.enabled = false;
  canvas.setPointerCapture(event.pointerId);
  event.preventDefault();
}, { capture: true });

let hoverPending = null;
canvas.addEventListener('pointermove', (event) => {
  if (!dragging) {
    if (gizmo.dragging) return;
    const hit = pick(event);
    const label = $('pick-label');
    if (hit) {
      label.textContent = hit.object.userData.handle.label;
      label.style.left = `${event.offsetX + 12}px`;
      label.style.top = `${event.offsetY + 12}px`;
    }
    label.hidden = !hit;
    canvas.style.cursor = hit ? 'grab' : drawing ? 'crosshair' : '';
    // The face read-out: at most one ray cast per frame.
    if (!hit && !hoverPending && current) {
      hoverPending = requestAnimationFrame(() => {
        hoverPending = null;
        showReadout(event, faceAt(event));
      });
    } else if (hit) showReadout(event, null);
    return;
  }
  setPointer(event);
  const p = new THREE.Vector3();
  if (!raycaster.ray.intersectPlane(dragging.plane, p)) return;
  if (!dragging.moved && !selection.has(dragging.mesh.userData.handle.label)) {
    select(dragging.mesh.userData.handle.label, dragging.shift);
    dragging.mesh = handleMeshes().find((o) => o.userData.handle.label === primaryLabel) || dragging.mesh;
  }
  if (!dragging.moved) dragging.starts = selectionStarts();
  dragging.moved = true;
  moveHandle(dragging.mesh, p.add(dragging.offset), dragging.starts);
  render();
});

function endDrag(event) {
  if (pressed && !dragging) {
    const click = Math.hypot(event.clientX - pressed.x, event.clientY - pressed.y) < 4;
    pressed = null;
    if (click && event.type === 'pointerup') {
      const f = faceAt(event);
      if (f !== null) openPanel(f);
      else if (!event.shiftKey) select(null, false);
    }
    return;
  }
  if (!dragging) return;
  const { mesh, moved, shift } = dragging;
  dragging = null;
  orbit.enabled = true;
  gizmo.enabled = true;
  if (canvas.hasPointerCapture(event.pointerId)) canvas.releasePointerCapture(event.pointerId);
  if (!moved) {   // a click: select (Shift adds), axis arrows for precise moves
    select(mesh.userData.handle.label, shift);
    const m = handleMeshes().find((o) => o.userData.handle.label === primaryLabel);
    if (m) gizmo.attach(m);
    render();
  }
}
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);
canvas.addEventListener('pointerleave', (event) => showReadout(event, null));

// The axis arrows move the sphere themselves; the other selected points follow.
let gizmoStarts = null;
gizmo.addEventListener('mouseDown', () => { dragCount += 1; gizmoStarts = selectionStarts(); });
gizmo.addEventListener('objectChange', () => {
  if (gizmo.object && gizmo.dragging) moveHandle(gizmo.object, gizmo.object.position.clone(), gizmoStarts);
});

// ------------------------------------------------------------------ drawing a new curve
// "New curve": clicks on the construction plane (through the design's centre, facing the
// chosen axis) place points; Enter or "Finish" adds the curve as a B-spline (a polyline
// with two points), Esc cancels.
let drawing = null;   // {points: [[x,y,z]], line}

function constructionPlane() {
  const axis = $('cplane').value;
  const [lo, hi] = current.header.bbox;
  const c = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  const n = { xy: [0, 0, 1], xz: [0, 1, 0], yz: [1, 0, 0] }[axis];
  return new THREE.Plane().setFromNormalAndCoplanarPoint(new THREE.Vector3(...n), c);
}

function startDrawing() {
  if (drawing) { finishDrawing(); return; }
  drawing = { points: [], line: null };
  $('new-curve').textContent = 'Finish curve';
  $('new-curve').blur();  // Enter finishes the curve, it does not press the button again
  status('click points on the construction plane; Enter finishes, Esc cancels');
}

function addDrawnPoint(event) {
  setPointer(event);
  const p = new THREE.Vector3();
  if (!raycaster.ray.intersectPlane(constructionPlane(), p)) return;
  const q = $('snap-grid').checked ? snapped(p, { label: '' }) : p;
  drawing.points.push(q.toArray().map((x) => +x.toFixed(6)));
  if (drawing.line) layers.construction.remove(drawing.line);
  drawing.line = polyline(drawing.points.length > 1 ? drawing.points
    : [drawing.points[0], drawing.points[0]], 0x1d4ed8);
  layers.construction.add(drawing.line);
  window.designer.drawn = drawing.points.length;
  render();
}

function stopDrawing() {
  if (drawing?.line) layers.construction.remove(drawing.line);
  drawing = null;
  $('new-curve').textContent = 'New curve';
  render();
}

function finishDrawing() {
  const pts = drawing?.points || [];
  stopDrawing();
  if (pts.length < 2) { status('a curve needs at least two points'); return; }
  const curves = current.header.design.curves || {};
  let k = Object.keys(curves).length + 1;
  while (`c${k}` in curves) k += 1;
  const spec = pts.length > 2 ? { type: 'bspline', degree: Math.min(3, pts.length - 1), points: pts }
    : { type: 'polyline', points: pts };
  queueEdit([[['curves', `c${k}`], spec]]);
  status(`added curve c${k}: choose it in "between" to rule the surface on it`);
}

// ------------------------------------------------------------------ buttons
$('undo').addEventListener('click', () => send('undo'));
$('redo').addEventListener('click', () => send('redo'));
$('fit').addEventListener('click', () => fitView());
$('colour').addEventListener('change', () => {
  recolour();
  if (needsSlowFigures() && window.designer.figuresVersion !== current?.header.version) fetchSlowFigures();
});
$('slow-figures').addEventListener('click', () => { if (current) fetchSlowFigures(); });
for (const b of document.querySelectorAll('[data-view]')) {
  b.addEventListener('click', () => setView(b.dataset.view));
}
$('ortho').addEventListener('change', () => useCamera($('ortho').checked ? orthographic : perspective));
$('screenshot').addEventListener('click', screenshot);
$('drawer-close').addEventListener('click', closePanel);
$('panel-figures').addEventListener('click', (event) => {
  const link = event.target.closest('a.face');
  if (!link) return;
  event.preventDefault();
  openPanel(Number(link.dataset.face));
});
for (const [i, axis] of ['x', 'y', 'z'].entries()) {
  $(`sel-${axis}`).addEventListener('change', () => typeCoordinate(i));
}
$('pt-insert').addEventListener('click', () => editPoints('insert'));
$('pt-delete').addEventListener('click', () => editPoints('delete'));
$('pt-append').addEventListener('click', () => editPoints('append'));
$('new-curve').addEventListener('click', startDrawing);
$('export-format').addEventListener('change', updateDownload);
for (const box of document.querySelectorAll('[data-layer]')) {
  box.addEventListener('change', () => {
    layers[box.dataset.layer].visible = box.checked;
    if (box.dataset.layer === 'handles' && !box.checked) gizmo.detach();
    if (box.dataset.layer === 'generators') generatorsTouched = true;
    if (box.dataset.layer === 'labels') drawLabels();
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
$('toml').addEventListener('input', () => {
  if (!tomlDirty || tomlTemplate) tomlBase = current.header.toml;
  tomlDirty = true;
  tomlTemplate = false;
  showTomlStale();
});
function showDesignToml() {
  tomlDirty = false;
  tomlTemplate = false;
  $('toml').value = current.header.toml;
  showTomlStale();
}
$('toml-revert').addEventListener('click', showDesignToml);
$('apply-toml').addEventListener('click', async () => {
  if (await sendNow('design', { toml: $('toml').value })) showDesignToml();
});
window.addEventListener('keydown', (event) => {
  const tag = document.activeElement?.tagName;
  if (tag === 'TEXTAREA' || (tag === 'INPUT' && document.activeElement.type === 'text')) return;
  if (!(event.ctrlKey || event.metaKey)) {
    if (event.key === 'Escape') {
      if (drawing) stopDrawing(); else { gizmo.detach(); select(null, false); }
      render();
    } else if (event.key === 'Enter' && drawing) {
      event.preventDefault();  // not also a click of the focused "Finish curve" button
      finishDrawing();
    }
    else if ((event.key === 'Delete' || event.key === 'Backspace') && tag !== 'INPUT'
             && primaryLabel) editPoints('delete');
    return;
  }
  const key = event.key.toLowerCase();
  if (key === 'z' && !event.shiftKey) { event.preventDefault(); send('undo'); }
  else if ((key === 'z' && event.shiftKey) || key === 'y') { event.preventDefault(); send('redo'); }
});

// ------------------------------------------------------------------ test and debugging hooks
window.designer = {
  version: null, renders: 0, frames: 0, figuresVersion: null, lastExport: null, timings,
  breakdown, frameTimes, frameLog, liveFrames: 0, refineNotes: 0, kept: {}, sameTopology: 0, legend: null, panelFigures: null, hover: null, readoutSide: null, panel: null, panelsDropped: 0, reused: false, view: null,
  busy: () => inFlight || jobs.length > 0 || direct > 0,
  softwareGL: SOFTWARE_GL,
  // The page's own part of an update, without the server: decode the last state message
  // again, draw it, and wait for the frame; resolves to the milliseconds it took.
  replay: () => new Promise((resolve) => {
    const t0 = performance.now();
    const msg = decode(current.raw);
    msg.raw = current.raw;
    for (const name of FACE_ARRAYS) msg.arrays[name] ||= current.arrays[name];
    msg.header.same_topology = false;
    current = null;
    for (const k of Object.keys(drawnKeys)) delete drawnKeys[k];  // everything drawn again
    applyState(msg);
    requestAnimationFrame(() => resolve(performance.now() - t0));
  }),
  selection: () => [...selection],
  // The shader programs in use (their ids: a program compiled again gets a new one).
  programs: () => renderer.info.programs.map((p) => p.id),
  // Milliseconds of one render of the scene as it is (nothing new to upload), the minimum of
  // n; reading a pixel back waits until the renderer has drawn every pixel of it.
  renderMs: (n = 5) => {
    let best = Infinity;
    for (let k = 0; k < n; k++) {
      const t = performance.now();
      renderer.render(scene, camera);
      const gl = renderer.getContext();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
      best = Math.min(best, performance.now() - t);
    }
    return best;
  },
  design: () => current?.header.design,
  // What the GPU buffers hold now: faces and triangles drawn, and the vertices written into
  // the face edges' position buffer (their count and sum), to check a frame against a build.
  drawn: () => {
    const faces = layers.faces.children[0]?.geometry, edges = layers.edges.children[0]?.geometry;
    const n = current.arrays.vertices.length;
    const buf = edges.getAttribute('position').array;
    let sum = 0;
    for (let i = 0; i < n; i++) sum += buf[i];
    return { faces: current.arrays.face_offsets.length - 1, triangles: faces.drawRange.count / 3,
             vertices: n / 3, vertexSum: sum };
  },
  camera: () => ({ ortho: camera === orthographic, direction:
    camera.getWorldDirection(new THREE.Vector3()).toArray() }),
  layer: (name) => layers[name].visible,
  edgeCount: () => (layers.edges.children[0]?.geometry.drawRange.count || 0) / 2,
  generatorsDashed: () => !!layers.generators.children[0]?.material.isLineDashedMaterial,
  construction: () => layers.construction.children.map((o) => o.userData.construction).filter(Boolean),
  grid: () => layers.grid.children[0]?.userData.step,
  faceInfo: (f) => faceInfo(f),
  faceAt: (x, y) => faceAt({ clientX: x, clientY: y }),   // the face under page point (x, y)
  highlighted: () => highlighted?.face ?? null,
  hoverOutline: () => {
    const n = hoverOutline.geometry.drawRange.count;
    const a = hoverOutline.geometry.getAttribute('position').array;
    return { visible: hoverOutline.visible, corners: Array.from({ length: Math.min(n, HOVER_CORNERS) },
      (_, k) => Array.from(a.subarray(3 * k, 3 * k + 3))) };
  },
  faceScreen: (f) => {
    const { vertices: V, face_offsets: off, face_indices: idx } = current.arrays;
    const v = new THREE.Vector3();
    for (let k = off[f]; k < off[f + 1]; k++) {
      v.x += V[3 * idx[k]]; v.y += V[3 * idx[k] + 1]; v.z += V[3 * idx[k] + 2];
    }
    v.divideScalar(off[f + 1] - off[f]).project(camera);
    const rect = canvas.getBoundingClientRect();
    return { x: rect.left + (v.x + 1) / 2 * rect.width, y: rect.top + (1 - v.y) / 2 * rect.height };
  },
  screen: (p) => {
    const v = new THREE.Vector3(...p).project(camera);
    const rect = canvas.getBoundingClientRect();
    return { x: rect.left + (v.x + 1) / 2 * rect.width, y: rect.top + (1 - v.y) / 2 * rect.height };
  },
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
else { refresh(); connectLive(); }
