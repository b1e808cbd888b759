// Clayform's browser viewer: every surface of a run (run/view/manifest.json, relative to the page),
// shaded, zebra, Gaussian/mean curvature and deviation maps, with control nets, curves, a
// before/after toggle per deformation step and the report's figures. See docs/viewer.md.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import './style.css';
import { checkManifest, fetchJson, MeshStore, netGeometry, polylineGeometry } from './data.js';
import { shadedMaterial, zebraMaterial, scalarMaterial, setZebraAxis } from './materials.js';
import { colourRange, cssGradient, DIVERGING, SEQUENTIAL, formatNumber } from './colormap.js';
import { surfacePanel } from './panels.js';

const MODES = ['shaded', 'zebra', 'gaussian', 'mean', 'deviation'];
const SCALAR = {
  gaussian: { label: 'Gaussian curvature K', unit: '1/mm²', diverging: true },
  mean: { label: 'mean curvature H', unit: '1/mm', diverging: true },
  deviation: { label: 'deviation from the pointwise deformation', unit: 'mm', diverging: false },
};
const CURVE_COLOURS = [0xff7a00, 0x00a8e8, 0xd63af9, 0x2bb24c];

const body = document.body;
const params = new URLSearchParams(location.search);
const messageBox = document.getElementById('message');

function showMessage(text, isError) {
  messageBox.hidden = !text;
  messageBox.textContent = text || '';
  messageBox.classList.toggle('error', !!isError);
}

// ?ui=0: the picture alone (no toolbar, no panels), for `clayform snapshot --bare`.
if (params.get('ui') === '0') body.classList.add('bare');

let mode = params.get('mode') || 'shaded';
if (!MODES.includes(mode)) {
  showMessage(`unknown mode "${mode}": showing shaded (modes: ${MODES.join(', ')})`);
  mode = 'shaded';
}
body.dataset.mode = mode;

// ---------------------------------------------------------------------------------------- scene
const canvas = document.getElementById('view');
let renderer;
try {
  // preserveDrawingBuffer: screenshots (clayform snapshot, the e2e test) read the canvas any time
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
} catch (e) {
  fail(new Error(`WebGL is not available in this browser (${e.message})`));
  throw e;
}
renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
renderer.setClearColor(0x30343a);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, 1, 1, 1000);
camera.up.set(0, 0, 1); // CAD convention: z up
scene.add(camera);
scene.add(new THREE.HemisphereLight(0xdfe8f5, 0x3a3530, 1.1));
const key = new THREE.DirectionalLight(0xffffff, 2.4);
const rim = new THREE.DirectionalLight(0xbfd4ff, 0.8);
scene.add(key, key.target, rim, rim.target);
const controls = new OrbitControls(camera, canvas);
controls.enableDamping = false;

const materials = {
  shaded: shadedMaterial(),
  zebra: zebraMaterial(),
  gaussian: scalarMaterial('gaussian', true),
  mean: scalarMaterial('mean', true),
  deviation: scalarMaterial('deviation', false),
};
const netMaterial = new THREE.LineBasicMaterial({ color: 0xffd166, transparent: true, opacity: 0.55 });
const netDotMaterial = new THREE.PointsMaterial({ color: 0xffd166, size: 4, sizeAttenuation: false });
// Nets drawn with their control points as dots up to this size; the net overlay starts switched
// off when the nets shown hold more points than DENSE_NETS (an exact composition's net can be far
// denser than the surface's sampling and would hide it).
const NET_DOTS_MAX = 400;
const DENSE_NETS = 2000;

let framePending = false;
let afterFrame = [];
function requestRender(then) {
  if (then) afterFrame.push(then);
  if (framePending) return;
  framePending = true;
  // A microtask, not requestAnimationFrame: headless Chromium's --screenshot with a virtual time
  // budget (clayform snapshot) may take its picture before any animation frame runs.
  queueMicrotask(() => {
    framePending = false;
    // key light over the viewer's right shoulder, rim light from behind: highlights follow the eye
    const eye = camera.position.clone();
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    const dist = eye.distanceTo(controls.target);
    key.position.copy(eye).addScaledVector(right, 0.6 * dist).addScaledVector(up, 0.8 * dist);
    key.target.position.copy(controls.target);
    rim.position.copy(controls.target).addScaledVector(eye.clone().sub(controls.target), -1).addScaledVector(up, dist);
    rim.target.position.copy(controls.target);
    renderer.render(scene, camera);
    const callbacks = afterFrame;
    afterFrame = [];
    callbacks.forEach((f) => f());
  });
}
controls.addEventListener('change', () => requestRender());

function resize() {
  const stage = document.getElementById('stage');
  const w = Math.max(1, stage.clientWidth);
  const h = Math.max(1, stage.clientHeight);
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  requestRender();
}
new ResizeObserver(resize).observe(document.getElementById('stage'));

// ?eye=x,y,z: the direction from the model towards the eye (clayform snapshot --eye); ?hide=a,b:
// surfaces not shown at start (--hide).
const eyeParam = (() => {
  const v = (params.get('eye') || '').split(',').map(Number);
  return v.length === 3 && v.every(Number.isFinite) && v.some((x) => x !== 0) ? new THREE.Vector3(...v).normalize() : null;
})();
const hiddenAtStart = new Set((params.get('hide') || '').split(',').filter(Boolean));

function fitCamera(box) {
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(1e-6, 0.5 * box.getSize(new THREE.Vector3()).length());
  const fov = THREE.MathUtils.degToRad(camera.fov);
  const fit = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * camera.aspect));
  const distance = (1.08 * radius) / Math.sin(fit / 2);
  const dir = eyeParam || new THREE.Vector3(0.9, -1.5, 1.1).normalize();
  camera.position.copy(center).addScaledVector(dir, distance);
  camera.near = Math.max(distance / 1000, distance - 4 * radius);
  camera.far = distance + 4 * radius;
  camera.updateProjectionMatrix();
  controls.target.copy(center);
  controls.update();
  requestRender();
}

// ---------------------------------------------------------------------------------------- state
const manifestUrl = new URL('run/view/manifest.json', document.baseURI);
const store = new MeshStore(manifestUrl);
let manifest = null;
let sceneBox = null;
const surfaces = []; // {entry, state, group, mesh, net, curves, panel, data}

function meshOf(s) {
  return s.state.stage < 0 ? s.entry.mesh : s.entry.stages[s.state.stage][s.state.side];
}
function netOf(s) {
  if (s.state.stage < 0) return s.entry.net;
  return s.entry.stages[s.state.stage][`net_${s.state.side}`] || null;
}
function curvesOf(s) {
  const stages = s.entry.stages || [];
  return s.state.stage < 0 ? stages.flatMap((st) => st.curves || []) : stages[s.state.stage].curves || [];
}

function buildNet(net) {
  const group = new THREE.Group();
  if (net && net.points && net.points.length) {
    const { lines, dots } = netGeometry(net);
    group.add(new THREE.LineSegments(lines, netMaterial));
    if (net.points.length <= NET_DOTS_MAX) group.add(new THREE.Points(dots, netDotMaterial));
  }
  return group;
}
function buildCurves(curves) {
  const group = new THREE.Group();
  curves.forEach((c, i) => {
    if (!c.points || c.points.length < 2) return;
    const material = new THREE.LineBasicMaterial({ color: CURVE_COLOURS[i % CURVE_COLOURS.length], depthTest: false });
    const line = new THREE.Line(polylineGeometry(c.points), material);
    line.renderOrder = 10;
    group.add(line);
  });
  return group;
}
function disposeGroup(group) {
  group.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    if (o.material && o.material !== netMaterial && o.material !== netDotMaterial) o.material.dispose();
  });
}

let generation = 0; // of state changes: only the latest one's completion applies and sets data-ready

/** Loads what every surface's state shows and swaps it into the scene. */
async function applyStates() {
  const token = generation;
  const loaded = await Promise.all(surfaces.map((s) => store.load(meshOf(s))));
  if (token !== generation) return; // a later change superseded this one
  surfaces.forEach((s, i) => {
    s.data = loaded[i];
    s.mesh.geometry = loaded[i].geometry;
    s.group.remove(s.net, s.curves);
    disposeGroup(s.net);
    disposeGroup(s.curves);
    s.net = buildNet(netOf(s));
    s.curves = buildCurves(curvesOf(s));
    s.group.add(s.net, s.curves);
  });
  body.dataset.vertices = String(surfaces.reduce((n, s) => n + s.data.vertices, 0));
  const anyBefore = surfaces.some((s) => s.state.side === 'before');
  body.dataset.stage = anyBefore ? 'before' : 'after';
  const global = document.getElementById('toggle-before-after');
  global.setAttribute('aria-pressed', surfaces.every((s) => s.state.stage < 0) ? 'false' : 'true');
  applyVisibility();
  applyMode();
}

function applyVisibility() {
  const net = document.getElementById('show-net').checked;
  const curves = document.getElementById('show-curves').checked;
  surfaces.forEach((s) => {
    s.net.visible = net;
    s.curves.visible = curves;
  });
  requestRender();
}

function range(values) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const v of values) {
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  return [lo, hi];
}

function applyMode() {
  body.dataset.mode = mode;
  for (const m of MODES) document.getElementById(`mode-${m}`).setAttribute('aria-pressed', m === mode ? 'true' : 'false');
  document.getElementById('zebra-controls').classList.toggle('inactive', mode !== 'zebra');
  surfaces.forEach((s) => (s.mesh.material = materials[mode]));
  const legend = document.getElementById('legend');
  const scalar = SCALAR[mode];
  if (scalar) {
    // one range over the surfaces shown, so their colours compare
    const r = colourRange(surfaces.filter((s) => s.group.visible).map((s) => s.data[mode]), scalar.diverging);
    materials[mode].uniforms.lo.value = r.lo;
    materials[mode].uniforms.hi.value = r.hi;
    showLegend(legend, scalar, r);
  } else if (mode === 'zebra') {
    legend.hidden = false;
    legend.className = 'text';
    legend.dataset.lo = legend.dataset.hi = '';
    legend.textContent =
      'Reflection lines: continuous stripes = tangent-continuous (G1), stripes without kinks = curvature-continuous (G2); a break in a stripe = a crease.';
  } else {
    legend.hidden = true;
    legend.dataset.lo = legend.dataset.hi = '';
  }
  surfaces.forEach((s) => {
    let stat = null;
    if (scalar) {
      const [min, max] = range(s.data[mode]);
      const symbol = mode === 'gaussian' ? 'K' : mode === 'mean' ? 'H' : 'deviation';
      stat = { min, max, text: `${symbol}: ${formatNumber(min)} … ${formatNumber(max)} ${scalar.unit}` };
    }
    s.panel.update(s.state, stat);
  });
  requestRender();
}

function showLegend(legend, scalar, r) {
  legend.hidden = false;
  legend.className = 'scale';
  legend.dataset.lo = String(r.lo);
  legend.dataset.hi = String(r.hi);
  legend.dataset.unit = scalar.unit;
  legend.replaceChildren();
  const title = document.createElement('div');
  title.className = 'legend-title';
  title.textContent = `${scalar.label} (${scalar.unit})`;
  const bar = document.createElement('div');
  bar.className = 'legend-bar';
  bar.style.background = cssGradient(scalar.diverging ? DIVERGING : SEQUENTIAL);
  const ticks = document.createElement('div');
  ticks.className = 'legend-ticks';
  for (let i = 0; i <= 4; i++) {
    const t = document.createElement('span');
    const v = r.lo + ((r.hi - r.lo) * i) / 4;
    t.textContent = (i === 0 && scalar.diverging ? '≤ ' : i === 4 ? '≥ ' : '') + formatNumber(Math.abs(v) < 1e-12 * r.hi ? 0 : v);
    ticks.append(t);
  }
  const note = document.createElement('div');
  note.className = 'legend-note';
  if (r.zero) note.textContent = 'zero everywhere';
  else if (scalar.diverging) {
    const radius = mode === 'mean' ? 1 / r.hi : 1 / Math.sqrt(r.hi);
    note.textContent = `range: ±(2–98 % percentile) · ends ↔ radius ${formatNumber(radius)} mm · data ${formatNumber(r.min)} … ${formatNumber(r.max)}`;
  } else note.textContent = `max ${formatNumber(r.max)} mm`;
  legend.append(title, bar, ticks, note);
}

// ---------------------------------------------------------------------------------------- events
function setMode(m) {
  if (!MODES.includes(m) || m === mode) return;
  mode = m;
  if (surfaces.length) applyMode();
  else body.dataset.mode = mode;
}

async function withLoading(change) {
  const mine = ++generation;
  body.dataset.ready = '0';
  try {
    change();
    await applyStates();
    if (mine === generation) requestRender(() => mine === generation && (body.dataset.ready = '1'));
  } catch (e) {
    fail(e);
  }
}

function toggleStage(index, k) {
  const s = surfaces[index];
  withLoading(() => {
    s.state = s.state.stage === k && s.state.side === 'before' ? { stage: k, side: 'after' } : { stage: k, side: 'before' };
  });
}

/** From the final surfaces to every first stage's before; from anything else back to the final surfaces. */
function toggleAll() {
  const allFinal = surfaces.every((s) => s.state.stage < 0);
  withLoading(() => {
    surfaces.forEach((s) => {
      s.state = allFinal && s.entry.stages && s.entry.stages.length ? { stage: 0, side: 'before' } : { stage: -1, side: 'after' };
    });
  });
}

function showSurface(index, shown) {
  surfaces[index].group.visible = shown;
  applyMode();
}

function focusSurface(index) {
  const g = surfaces[index].mesh.geometry;
  if (g.boundingBox) fitCamera(g.boundingBox.clone());
}

for (const m of MODES) document.getElementById(`mode-${m}`).addEventListener('click', () => setMode(m));
document.getElementById('show-net').addEventListener('change', applyVisibility);
document.getElementById('show-curves').addEventListener('change', applyVisibility);
document.getElementById('toggle-before-after').addEventListener('click', toggleAll);
document.getElementById('fit-all').addEventListener('click', () => sceneBox && fitCamera(sceneBox));
document.getElementById('zebra-stripes').addEventListener('input', (e) => {
  materials.zebra.uniforms.stripes.value = Number(e.target.value);
  requestRender();
});
document.getElementById('zebra-axis').addEventListener('change', (e) => {
  setZebraAxis(materials.zebra, e.target.value);
  requestRender();
});
window.addEventListener('keydown', (e) => {
  if (e.target.closest && e.target.closest('input, select, textarea')) return;
  const i = '12345'.indexOf(e.key);
  if (i >= 0) setMode(MODES[i]);
  else if (e.key === 'b') toggleAll();
  else if (e.key === 'f' && sceneBox) fitCamera(sceneBox);
  else if (e.key === 'n' || e.key === 'c') {
    const box = document.getElementById(e.key === 'n' ? 'show-net' : 'show-curves');
    box.checked = !box.checked;
    applyVisibility();
  }
});

function fail(e) {
  body.dataset.ready = 'error';
  body.dataset.error = String(e && e.message ? e.message : e);
  showMessage(`Cannot show the run: ${body.dataset.error}`, true);
  console.error(e);
}

// ---------------------------------------------------------------------------------------- start
async function loadReport() {
  if (!manifest.report) return;
  const title = document.getElementById('run-title');
  try {
    const report = await fetchJson(new URL(manifest.report, manifestUrl));
    const status = report.ok === false ? 'failed' : report.warnings ? 'ok, with warnings' : 'ok';
    const seconds = typeof report.seconds === 'number' ? ` · ${formatNumber(report.seconds)} s` : '';
    title.textContent = `${manifest.recipe || report.recipe || 'run'} — ${status}${seconds}`;
    title.title = `clayform ${report.clayform || ''}`;
  } catch (e) {
    title.textContent = `${manifest.recipe || 'run'} (no report: ${e.message})`;
  }
}

async function start() {
  resize();
  manifest = checkManifest(await fetchJson(manifestUrl));
  document.title = `Clayform — ${manifest.recipe || 'run'}`;
  document.getElementById('run-title').textContent = manifest.recipe || 'run';
  const before = params.get('stage') === 'before';
  const panels = document.getElementById('panels');
  manifest.surfaces.forEach((entry, index) => {
    const state = before && entry.stages && entry.stages.length ? { stage: 0, side: 'before' } : { stage: -1, side: 'after' };
    const mesh = new THREE.Mesh(new THREE.BufferGeometry(), materials[mode]);
    const group = new THREE.Group();
    const net = new THREE.Group();
    const curves = new THREE.Group();
    group.add(mesh, net, curves);
    scene.add(group);
    const panel = surfacePanel(entry, index, { onToggle: toggleStage, onFocus: focusSurface, onVisible: showSurface });
    panels.append(panel.root);
    surfaces.push({ entry, state, group, mesh, net, curves, panel, data: null });
    if (hiddenAtStart.has(entry.name)) {
      group.visible = false;
      const box = panel.root.querySelector('.surface-visible');
      if (box) box.checked = false;
    }
  });
  body.dataset.surfaces = String(surfaces.length);
  const netPoints = surfaces.reduce((n, s) => n + ((netOf(s) && netOf(s).points) || []).length, 0);
  if (netPoints > DENSE_NETS) {
    document.getElementById('show-net').checked = false;
    document.getElementById('show-net').parentElement.title = `off at start: the nets hold ${netPoints} control points`;
  }
  if (!surfaces.length) showMessage('This run has no surfaces.');
  loadReport();
  await applyStates();
  const b = manifest.box;
  if (hiddenAtStart.size && surfaces.some((s) => s.group.visible)) {
    sceneBox = new THREE.Box3();  // fitted to what is shown
    surfaces.forEach((s) => s.group.visible && s.mesh.geometry.boundingBox && sceneBox.union(s.mesh.geometry.boundingBox));
  } else if (b && b.min && b.max) sceneBox = new THREE.Box3(new THREE.Vector3(...b.min), new THREE.Vector3(...b.max));
  else {
    sceneBox = new THREE.Box3();
    surfaces.forEach((s) => sceneBox.union(s.mesh.geometry.boundingBox));
  }
  if (sceneBox.isEmpty()) sceneBox.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
  fitCamera(sceneBox);
  requestRender(() => (body.dataset.ready = '1'));
}

start().catch(fail);
