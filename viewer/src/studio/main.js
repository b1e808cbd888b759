// Clayform Studio (docs/studio.md): strokes drawn in the browser, parent surfaces built from
// them, styled by a bound and a target curve and shaped by lattices, live. The kernel runs in
// `clayform studio` behind one WebSocket; every action is an edit of the recipe (with a named
// history there), and what the page shows is evaluated here from the nets the kernel sends.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import '../style.css';
import './studio.css';
import { shadedMaterial, zebraMaterial, scalarMaterial } from '../materials.js';
import { Link } from './link.js';
import { curvePolyline, surfaceGrid, domain, sampleParameters, meshOnNets } from './nurbs.js';
import * as names from './recipe_edits.js';
import { prepareFfd, applyFfd } from './ffd_preview.js';
import { latticeCounts, stepLatticePoints } from './lattice_math.js';

const body = document.body;
const $ = (id) => document.getElementById(id);

// ------------------------------------------------------------------------------ messages
const messageBox = $('message');
let messageTimer = null;
function showMessage(text, isError) {
  messageBox.hidden = !text;
  messageBox.textContent = text || '';
  messageBox.classList.toggle('error', !!isError);
  clearTimeout(messageTimer);
  if (text && !isError) messageTimer = setTimeout(() => showMessage(''), 4000);
}

// ------------------------------------------------------------------------------ scene
const canvas = $('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
renderer.setClearColor(0x30343a);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, 1, 1, 100000);
camera.up.set(0, 0, 1); // CAD convention: z up
camera.position.set(600, -900, 700);
scene.add(camera);
scene.add(new THREE.HemisphereLight(0xdfe8f5, 0x3a3530, 1.1));
const key = new THREE.DirectionalLight(0xffffff, 2.4);
scene.add(key, key.target);
const controls = new OrbitControls(camera, canvas);
controls.enableDamping = false;
const grid = new THREE.GridHelper(2000, 40, 0x4a505a, 0x3a3f47);
grid.rotation.x = Math.PI / 2; // the XY plane
// drawn first and without depth, so a surface lying in the plane covers it
grid.renderOrder = -1;
grid.material.depthWrite = false;
scene.add(grid);

const materials = {
  shaded: shadedMaterial(),
  zebra: zebraMaterial(),
  mean: scalarMaterial('mean', true),
  gaussian: scalarMaterial('gaussian', true),
  deviation: scalarMaterial('deviation', false),
};
const surfaceGroup = new THREE.Group();
const curveGroup = new THREE.Group();
const handleGroup = new THREE.Group();
const inkGroup = new THREE.Group();
scene.add(surfaceGroup, curveGroup, handleGroup, inkGroup);

// A render is asked for with `dirty()` and done in the next animation frame: input handlers run
// before it in the same frame, so ink drawn in a pointer event shows in that frame.
let needsRender = false;
const afterRender = [];
function dirty(then) {
  if (then) afterRender.push(then);
  needsRender = true;
}
const metrics = { drag: [], dragEnd: [], preview: [], stroke: [], frames: [], kernel: [], evaluate: [] };
let dragging = false;
let lastFrameAt = null;
function frame(now) {
  if (dragging && lastFrameAt !== null) metrics.frames.push(now - lastFrameAt);
  lastFrameAt = dragging ? now : null;
  if (needsRender) {
    needsRender = false;
    key.position.copy(camera.position).add(new THREE.Vector3(300, 200, 800));
    key.target.position.copy(controls.target);
    renderer.render(scene, camera);
    const done = performance.now();
    afterRender.splice(0).forEach((f) => f(done));
  }
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);
controls.addEventListener('change', () => dirty());

function resize() {
  const stage = $('stage');
  const w = Math.max(1, stage.clientWidth);
  const h = Math.max(1, stage.clientHeight);
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  dirty();
}
new ResizeObserver(resize).observe($('stage'));

// ------------------------------------------------------------------------------ document state
// What the last run gave: the recipe, its final surfaces' nets (and their parents before their
// first step), every named curve's net, the history.
const doc = { recipe: {}, surfaces: new Map(), befores: new Map(), curves: new Map(), models: new Map(), deviations: new Map(), history: { entries: [], position: 0 }, steps: [], reply: null };
let selection = []; // [{kind: 'curve' | 'surface' | 'lattice', name, index?}]
let mode = 'shaded';
let showBefore = false;

function surfaceResolution(net, direction) {
  const knots = direction === 0 ? net.knots_u : net.knots_v;
  const p = net.degrees[direction];
  const [a, b] = domain(knots, p);
  const spans = new Set(knots.filter((t) => t > a && t < b)).size + 1;
  return Math.max(33, Math.min(129, 8 * spans * Math.max(1, Math.ceil(p / 3)) + 1));
}

/**
 * The kernel's deviation map of a surface (a rows x cols grid evenly over its domain), at the
 * mesh's samples: bilinear in the samples' fractions of the domain.
 */
function fillDeviation(geometry, net, map, us, vs) {
  const out = geometry.getAttribute('deviation').array;
  const [u0, u1] = domain(net.knots_u, net.degrees[0]);
  const [v0, v1] = domain(net.knots_v, net.degrees[1]);
  const { rows, cols } = map.header;
  const at = (r, c) => map.values[r * cols + c];
  for (let r = 0; r < us.length; r++) {
    const x = ((us[r] - u0) / (u1 - u0)) * (rows - 1);
    const i = Math.min(rows - 2, Math.floor(x));
    const a = x - i;
    for (let c = 0; c < vs.length; c++) {
      const y = ((vs[c] - v0) / (v1 - v0)) * (cols - 1);
      const j = Math.min(cols - 2, Math.floor(y));
      const b = y - j;
      out[r * vs.length + c] = (1 - a) * ((1 - b) * at(i, j) + b * at(i, j + 1)) + a * ((1 - b) * at(i + 1, j) + b * at(i + 1, j + 1));
    }
  }
}

function meshOf(net, deviation) {
  const t0 = performance.now();
  const rows = surfaceResolution(net, 0);
  const cols = surfaceResolution(net, 1);
  const g = surfaceGrid(net, rows, cols);
  metrics.evaluate.push(performance.now() - t0);
  const geometry = gridGeometry(g);
  // each sample's (u, v), so a pick on the surface knows its parameters (direct manipulation)
  const us = sampleParameters(net.knots_u, net.degrees[0], rows);
  const vs = sampleParameters(net.knots_v, net.degrees[1], cols);
  const uv = new Float64Array(2 * rows * cols);
  for (let r = 0; r < rows; r++)
    for (let c = 0; c < cols; c++) {
      uv[2 * (r * cols + c)] = us[r];
      uv[2 * (r * cols + c) + 1] = vs[c];
    }
  geometry.userData.parameters = uv;
  if (deviation) fillDeviation(geometry, net, deviation, us, vs);
  return geometry;
}

/** The (u, v) of a raycast hit on a surface mesh: its triangle's corners' parameters, blended. */
function hitParameters(hit) {
  const uv = hit.object.geometry.userData.parameters;
  if (!uv || !hit.face) return null;
  const { a, b, c } = hit.face;
  const bary = new THREE.Triangle(
    new THREE.Vector3().fromBufferAttribute(hit.object.geometry.getAttribute('position'), a),
    new THREE.Vector3().fromBufferAttribute(hit.object.geometry.getAttribute('position'), b),
    new THREE.Vector3().fromBufferAttribute(hit.object.geometry.getAttribute('position'), c),
  ).getBarycoord(hit.point, new THREE.Vector3());
  return [0, 1].map((e) => bary.x * uv[2 * a + e] + bary.y * uv[2 * b + e] + bary.z * uv[2 * c + e]);
}

function gridGeometry(g) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(g.position, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(g.normal, 3));
  geometry.setAttribute('mean', new THREE.BufferAttribute(g.mean, 1));
  geometry.setAttribute('gaussian', new THREE.BufferAttribute(g.gaussian, 1));
  geometry.setAttribute('deviation', new THREE.BufferAttribute(new Float32Array(g.rows * g.cols), 1));
  const index = [];
  for (let r = 0; r + 1 < g.rows; r++)
    for (let c = 0; c + 1 < g.cols; c++) {
      const k = r * g.cols + c;
      index.push(k, k + g.cols, k + 1, k + 1, k + g.cols, k + g.cols + 1);
    }
  geometry.setIndex(index);
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  geometry.userData = { rows: g.rows, cols: g.cols };
  return geometry;
}

function netLines(net) {
  const [nu, nv] = net.counts;
  const pts = [];
  const at = (i, j) => net.points.slice(3 * (i * nv + j), 3 * (i * nv + j) + 3);
  for (let i = 0; i < nu; i++) for (let j = 0; j + 1 < nv; j++) pts.push(...at(i, j), ...at(i, j + 1));
  for (let j = 0; j < nv; j++) for (let i = 0; i + 1 < nu; i++) pts.push(...at(i, j), ...at(i + 1, j));
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xffd166, transparent: true, opacity: 0.45 }));
}

function disposeGroup(group) {
  for (const child of [...group.children]) {
    child.traverse((o) => o.geometry && !o.geometry.userData.preview && o.geometry.dispose());
    group.remove(child);
  }
}

function scalarRange(attr) {
  const values = [];
  surfaceGroup.traverse((o) => {
    if (o.isMesh && o.geometry.getAttribute(attr)) values.push(...o.geometry.getAttribute(attr).array);
  });
  const finite = values.filter(Number.isFinite).sort((a, b) => a - b);
  if (!finite.length) return [-1, 1];
  const q = (x) => finite[Math.floor(x * (finite.length - 1))];
  const r = Math.max(Math.abs(q(0.02)), Math.abs(q(0.98))) || Math.max(Math.abs(finite[0]), Math.abs(finite[finite.length - 1])) || 1;
  return [-r, r];
}

function applyMode() {
  const material = materials[mode];
  if (mode === 'mean' || mode === 'gaussian') {
    const [lo, hi] = scalarRange(mode);
    material.uniforms.lo.value = lo;
    material.uniforms.hi.value = hi;
    showLegend(`${mode === 'mean' ? 'mean curvature H (1/mm)' : 'Gaussian curvature K (1/mm²)'}: ${lo.toPrecision(3)} … ${hi.toPrecision(3)}`);
  } else if (mode === 'deviation') {
    // sequential, from 0 to the largest deviation of the surfaces shown (the kernel's own figure)
    const maps = [...doc.deviations.values()];
    const hi = Math.max(0, ...maps.map((d) => d.header.max));
    material.uniforms.lo.value = 0;
    material.uniforms.hi.value = hi || 1;
    showLegend(
      maps.length
        ? `deviation from the pointwise deformation (mm): 0 … ${hi.toPrecision(3)} (${maps.map((d) => `${d.header.name} ${d.header.max.toExponential(1)}`).join(', ')})${previews.size ? '; while a drag is drawn, the page shows the pointwise FFD itself' : ''}`
        : 'deviation from the pointwise deformation: no surface shown has a lattice, taper, twist or bend as its last step (a style moves control points: no pointwise map)',
    );
  } else showLegend('');
  surfaceGroup.traverse((o) => {
    if (o.isMesh) o.material = o.userData.selected && mode === 'shaded' ? selectedMaterial : material;
  });
  document.querySelectorAll('[data-mode]').forEach((b) => b.setAttribute('aria-pressed', String(b.dataset.mode === mode)));
  body.dataset.mode = mode;
  dirty();
}
const selectedMaterial = shadedMaterial();
selectedMaterial.color.set(0x9fc2ea);
function showLegend(text) {
  $('legend').hidden = !text;
  $('legend').textContent = text;
}

function rebuildSurfaces() {
  disposeGroup(surfaceGroup);
  const nets = showBefore ? new Map([...doc.surfaces].map(([n, net]) => [n, doc.befores.get(n) || net])) : doc.surfaces;
  for (const [name, net] of nets) {
    const preview = previews.get(name);
    const mesh = new THREE.Mesh(preview && !showBefore ? preview.geometry : meshOf(net, !showBefore && doc.deviations.get(name)), materials.shaded);
    mesh.name = name;
    mesh.userData = { kind: 'surface', name, selected: selection.some((s) => s.kind === 'surface' && s.name === name) };
    surfaceGroup.add(mesh);
    if ($('show-net').checked && net.points.length / 3 <= 20000) surfaceGroup.add(netLines(net));
  }
  for (const [name, m] of doc.models) {
    // a whole model's trimmed faces, meshed by the kernel (no curvature: zero in those modes)
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(m.positions), 3));
    geometry.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(m.normals), 3));
    geometry.setAttribute('mean', new THREE.BufferAttribute(new Float32Array(m.positions.length / 3), 1));
    geometry.setAttribute('gaussian', new THREE.BufferAttribute(new Float32Array(m.positions.length / 3), 1));
    geometry.setAttribute('deviation', new THREE.BufferAttribute(new Float32Array(m.positions.length / 3), 1));
    geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(m.triangles), 1));
    geometry.computeBoundingSphere();
    const mesh = new THREE.Mesh(geometry, materials.shaded);
    mesh.name = name;
    mesh.userData = { kind: 'model', name, selected: selection.some((s) => s.kind === 'model' && s.name === name) };
    surfaceGroup.add(mesh);
  }
  applyMode();
}

const CURVE_COLOUR = 0xff9b3d;
const SELECTED_COLOUR = 0x4fd1ff;
/** Strokes that are entities of a sketch: the sketch's solved curve ("SKETCH.NAME") is drawn instead. */
function inSketches() {
  const out = new Set();
  for (const [sketch, def] of Object.entries(doc.recipe.sketches || {}))
    for (const [name, e] of Object.entries(def.entities || {})) {
      if (e.curve) out.add(e.curve);
      // a construction chord between a curve's ends (horizontal, vertical) is not drawn
      if (Array.isArray(e.line) && e.line.every((p) => /\.(start|end)$/.test(p))) out.add(`${sketch}.${name}`);
    }
  return out;
}
function rebuildCurves() {
  disposeGroup(curveGroup);
  const hidden = inSketches();
  for (const [name, curve] of doc.curves) {
    if (hidden.has(name)) continue;
    const samples = Math.min(400, 24 * (curve.knots.length - 2 * curve.degree) + 40);
    const line = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: selection.some((s) => s.kind === 'curve' && s.name === name) ? SELECTED_COLOUR : CURVE_COLOUR, depthTest: false }));
    line.geometry.setAttribute('position', new THREE.BufferAttribute(curvePolyline(curve, samples), 3));
    line.renderOrder = 2;
    line.name = name;
    line.userData = { kind: 'curve', name };
    curveGroup.add(line);
  }
  dirty();
}

// ------------------------------------------------------------------------------ the kernel
// The session's token (docs/studio.md "Security"): from the address `clayform studio` printed;
// the server also keeps it in a cookie, so a reload without it still connects.
const pageToken = new URLSearchParams(location.search).get('token');
const socketUrl = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws${pageToken ? `?token=${encodeURIComponent(pageToken)}` : ''}`;
let link = null;
function onReply(reply, frames, meta) {
  if (reply.op === 'error') {
    showMessage(`${reply.category}: ${reply.message}`, true);
    body.dataset.error = reply.message;
    return;
  }
  body.dataset.error = '';
  if (reply.op === 'saved') {
    showMessage(`saved ${reply.file}`);
    return;
  }
  if (reply.op === 'exported') {
    showMessage(`exported ${reply.files.join(', ')} into ${reply.folder}${reply.valid ? ' (read back and checked)' : ''}`);
    return;
  }
  if (!('steps' in reply)) return;
  metrics.kernel.push(reply.seconds * 1000);
  doc.reply = reply;
  doc.steps = reply.steps;
  doc.history = reply.history;
  // Said once: the session continues an autosave (the studio restarted after a crash or
  // Ctrl-C), or the last autosave failed (the edit itself was applied).
  if (reply.history.restored && !doc.restoredShown) {
    doc.restoredShown = true;
    showMessage(`continued the autosave ${reply.history.restored.file}: ${reply.history.restored.entries} history entries (start clayform studio with --fresh to begin from the recipe file)`);
  }
  if (reply.history.autosave_problem) showMessage(`autosave failed: ${reply.history.autosave_problem}`, true);
  if (typeof reply.text === 'string') doc.recipe = JSON.parse(reply.text);
  if (reply.nets === false) {
    // a drag update the page draws itself: the kernel's figures and history only
    metrics.drag.push({ at: performance.now(), ms: performance.now() - meta.inputAt });
    showReport();
    showHistory();
    return;
  }
  const meshes = doc.models;
  doc.surfaces = new Map();
  doc.befores = new Map();
  doc.curves = new Map();
  doc.models = new Map();
  doc.deviations = new Map();
  for (const f of frames) {
    const h = f.header;
    if (h.kind === 'mesh') doc.models.set(h.name, f);
    else if (h.kind === 'deviation') doc.deviations.set(h.name, f);
    else if (h.kind === 'model_nets') {
      // only the faces' control points changed: the mesh the page holds, evaluated on them
      const mesh = meshes.get(h.name);
      const t0 = performance.now();
      if (mesh) doc.models.set(h.name, { ...mesh, ...meshOnNets(mesh, f.faces), faces: f.faces });
      else setTimeout(() => link.send({ op: 'run' })); // no mesh to move: ask for everything
      metrics.evaluate.push(performance.now() - t0);
    }
    else if (h.kind === 'curve') doc.curves.set(h.name, { degree: h.degree, knots: h.knots, rational: h.rational, points: f.points, weights: f.weights });
    else (h.before ? doc.befores : doc.surfaces).set(h.name, { degrees: h.degrees, counts: h.counts, knots_u: h.knots_u, knots_v: h.knots_v, rational: h.rational, points: f.points, weights: f.weights });
  }
  selection = selection.filter((s) => (s.kind === 'curve' ? doc.curves.has(s.name) : s.kind === 'surface' ? doc.surfaces.has(s.name) : s.kind === 'model' ? doc.models.has(s.name) : true));
  if (previewEnding && !link.busy) finishPreview();
  else rebuildSurfaces();
  rebuildCurves();
  clearInk(meta.command);
  rebuildHandles();
  showPanels();
  showReport();
  showHistory();
  const kind = meta.command.kind;
  dirty((drawnAt) => {
    if (kind === 'drag') metrics.drag.push({ at: drawnAt, ms: drawnAt - meta.inputAt });
    if (kind === 'drag-end') metrics.dragEnd.push({ at: drawnAt, ms: drawnAt - meta.inputAt });
    if (kind === 'stroke') metrics.stroke.push({ at: drawnAt, ms: drawnAt - meta.inputAt });
    body.dataset.rendered = String(Number(body.dataset.rendered || 0) + 1);
  });
}

/** An edit command: one change ({path, value} or {path, remove}) or several, one history entry. */
function commandOf(changes, label, kind, group) {
  const command = Array.isArray(changes) ? { op: 'edit', label, changes } : { op: 'edit', label, ...changes };
  if (group) command.group = group;
  Object.defineProperty(command, 'kind', { value: kind, enumerable: false });
  return command;
}
/** Sends an edit as one entry of the history. */
function edit(changes, label, kind = 'edit', inputAt = performance.now()) {
  return link.send(commandOf(changes, label, kind), inputAt);
}
/**
 * A drag update: `build()` gives {changes, label} from the document as it is when the update is
 * sent (at most one is in flight; a newer one replaces a waiting one).
 */
function dragEdit(build, inputAt) {
  return link.drag(() => {
    const b = build();
    if (!b) return null;
    const command = commandOf(b.changes, b.label, 'drag', b.group);
    if (b.nets === false) command.nets = false;
    return command;
  }, inputAt);
}
// The updates of one drag (a handle, a slider) share a group: the kernel keeps them as one
// history entry.
let dragCount = 0;
const newGroup = () => `drag ${++dragCount}`;
function simple(op) {
  const command = { op };
  Object.defineProperty(command, 'kind', { value: op, enumerable: false });
  return link.send(command);
}

// ------------------------------------------------------------------------------ camera
function sceneBox() {
  const box = new THREE.Box3();
  surfaceGroup.traverse((o) => o.isMesh && box.union(new THREE.Box3().setFromObject(o)));
  curveGroup.traverse((o) => o.isLine && box.union(new THREE.Box3().setFromObject(o)));
  if (box.isEmpty()) box.set(new THREE.Vector3(-500, -500, -100), new THREE.Vector3(500, 500, 100));
  return box;
}
const VIEWS = { top: [0, 0, 1], front: [0, -1, 0], side: [1, 0, 0], iso: [1, -1.4, 1.1] };
function setView(view) {
  const box = sceneBox();
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1);
  const dir = view === 'fit' ? camera.position.clone().sub(controls.target).normalize() : new THREE.Vector3(...VIEWS[view]).normalize();
  const fov = THREE.MathUtils.degToRad(camera.fov);
  const fit = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * camera.aspect));
  const distance = (1.1 * radius) / Math.sin(fit / 2);
  controls.target.copy(center);
  camera.position.copy(center).addScaledVector(dir, distance);
  // looking straight down z, the up vector must not be the view direction
  camera.up.set(0, 0, 1);
  if (Math.abs(dir.z) > 0.999) camera.up.set(0, 1, 0);
  camera.near = distance / 100;
  camera.far = distance * 100;
  camera.updateProjectionMatrix();
  camera.lookAt(center);
  controls.update();
  dirty();
}
document.querySelectorAll('[data-view]').forEach((b) => b.addEventListener('click', () => setView(b.dataset.view)));

// ------------------------------------------------------------------------------ pointer geometry
function pointerRay(clientX, clientY) {
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
  const raycaster = new THREE.Raycaster();
  raycaster.setFromCamera(ndc, camera);
  return raycaster;
}
function toScreen(p) {
  const rect = canvas.getBoundingClientRect();
  const v = new THREE.Vector3(...p).project(camera);
  return [rect.left + ((v.x + 1) / 2) * rect.width, rect.top + ((1 - v.y) / 2) * rect.height];
}
/** The size of a screen pixel, in mm, at the depth of point p. */
function millimetresPerPixel(p) {
  const depth = new THREE.Vector3(...p).applyMatrix4(camera.matrixWorldInverse).z;
  const height = canvas.getBoundingClientRect().height || 1;
  return (2 * Math.abs(depth) * Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2)) / height;
}
const PLANE_NORMALS = { xy: [0, 0, 1], xz: [0, 1, 0], yz: [1, 0, 0] };
const PLANE_X = { xy: [1, 0, 0], xz: [1, 0, 0], yz: [0, 1, 0] };
// "plane at a picked surface point": the first press on a surface places the plane there (its
// normal the surface's), the strokes after it are drawn on it; a press off the surfaces keeps it.
let pickedPlane = null;
const pickedOutline = new THREE.LineLoop(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0x8fd0ff, depthTest: false }));
pickedOutline.renderOrder = 3;
pickedOutline.visible = false;
scene.add(pickedOutline);
function placePickedPlane(hit) {
  const normal = hit.face.normal.clone().transformDirection(hit.object.matrixWorld).normalize();
  pickedPlane = { origin: hit.point.toArray().map((x) => Number(x.toPrecision(12))), normal: normal.toArray().map((x) => Number(x.toPrecision(12))) };
  // an outline square of a quarter of the scene's size, in the plane
  const size = sceneBox().getSize(new THREE.Vector3()).length() / 8;
  const e1 = new THREE.Vector3(1, 0, 0);
  if (Math.abs(e1.dot(normal)) > 0.9) e1.set(0, 1, 0);
  e1.sub(normal.clone().multiplyScalar(e1.dot(normal))).normalize();
  const e2 = normal.clone().cross(e1);
  const corners = [
    [-1, -1],
    [1, -1],
    [1, 1],
    [-1, 1],
  ].map(([a, b]) => hit.point.clone().addScaledVector(e1, a * size).addScaledVector(e2, b * size));
  pickedOutline.geometry.setFromPoints(corners);
  pickedOutline.visible = true;
  showMessage('plane placed at the picked point: draw on it (pick again with Shift-press on a surface)');
  dirty();
}

/** The sketch plane chosen in the toolbar: {origin, normal, x_axis} (recipe form). */
function sketchPlane() {
  const on = $('sketch-on').value;
  if (on === 'picked') return pickedPlane;
  const offset = Number($('sketch-offset').value) || 0;
  if (on === 'view') {
    const normal = camera.position.clone().sub(controls.target).normalize();
    return { origin: controls.target.toArray(), normal: normal.toArray() };
  }
  if (!PLANE_NORMALS[on]) return null;
  const n = PLANE_NORMALS[on];
  return { origin: n.map((c) => c * offset), normal: n, x_axis: PLANE_X[on] };
}
function onPlane(raycaster, plane) {
  const p = new THREE.Plane().setFromNormalAndCoplanarPoint(new THREE.Vector3(...plane.normal).normalize(), new THREE.Vector3(...plane.origin));
  return raycaster.ray.intersectPlane(p, new THREE.Vector3());
}
function onSurface(raycaster) {
  const hits = raycaster.intersectObjects(surfaceGroup.children.filter((o) => o.isMesh), false);
  return hits.length ? hits[0] : null;
}

// ------------------------------------------------------------------------------ picking
const PICK_PX = 8;
function pick(clientX, clientY) {
  let best = null;
  for (const name of doc.curves.keys()) {
    const line = curveGroup.getObjectByName(name);
    if (!line) continue;
    const pos = line.geometry.getAttribute('position').array;
    for (let k = 0; k + 1 < pos.length / 3; k++) {
      const a = toScreen([pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]]);
      const b = toScreen([pos[3 * k + 3], pos[3 * k + 4], pos[3 * k + 5]]);
      const d = segmentDistance([clientX, clientY], a, b);
      if (d < PICK_PX && (!best || d < best.d)) best = { d, kind: 'curve', name };
    }
  }
  if (best) return best;
  const hit = onSurface(pointerRay(clientX, clientY));
  return hit ? { kind: hit.object.userData.kind, name: hit.object.name, hit } : null;
}
function segmentDistance(p, a, b) {
  const dx = b[0] - a[0];
  const dy = b[1] - a[1];
  const l2 = dx * dx + dy * dy;
  const t = l2 > 0 ? Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2)) : 0;
  return Math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}
function select(item, add) {
  if (!item) selection = add ? selection : [];
  else if (add) {
    const i = selection.findIndex((s) => s.kind === item.kind && s.name === item.name);
    if (i >= 0) selection.splice(i, 1);
    else selection.push({ kind: item.kind, name: item.name });
  } else selection = [{ kind: item.kind, name: item.name }];
  $('selection').textContent = selection.length ? selection.map((s, i) => `${i + 1}. ${s.kind} ${s.name}`).join('\n') : 'nothing selected';
  rebuildCurves();
  rebuildSurfaces();
  rebuildHandles();
  showPanels();
}

// ------------------------------------------------------------------------------ sketching
let ink = null; // {points: [[x,y,z]], plane, line, pointerId, started}
const pendingInk = []; // ink shown until the kernel's fitted curve replaces it
function inkLine() {
  const line = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xffffff, depthTest: false }));
  line.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * 4096), 3));
  line.geometry.setDrawRange(0, 0);
  line.renderOrder = 3;
  inkGroup.add(line);
  return line;
}
function pushInk(p) {
  const last = ink.points[ink.points.length - 1];
  if (last && Math.hypot(p[0] - last[0], p[1] - last[1], p[2] - last[2]) < 1e-6) return; // no repeated point
  if (ink.points.length >= 4096) return;
  ink.points.push(p);
  const attr = ink.line.geometry.getAttribute('position');
  attr.array.set(p, 3 * (ink.points.length - 1));
  attr.needsUpdate = true;
  ink.line.geometry.setDrawRange(0, ink.points.length);
  dirty();
}
function inkPoint(event) {
  const raycaster = pointerRay(event.clientX, event.clientY);
  if (ink.over) {
    const last = ink.points[ink.points.length - 1];
    const p = onExtrusion(raycaster.ray, ink.over, last);
    return p ? p.toArray() : null;
  }
  if (ink.plane) {
    const p = onPlane(raycaster, ink.plane);
    return p ? p.toArray() : null;
  }
  const hit = onSurface(raycaster);
  return hit ? hit.point.toArray() : null;
}
function clearInk(command) {
  if (!command || !command.label || !command.label.startsWith('stroke')) return;
  const i = pendingInk.findIndex((p) => p.label === command.label);
  if (i < 0) return;
  inkGroup.remove(pendingInk[i].line);
  pendingInk[i].line.geometry.dispose();
  pendingInk.splice(i, 1);
  dirty();
}

/**
 * Strokes in 3D between two views: a stroke drawn on a plane in one view is the shadow of the 3D
 * curve along that plane's normal; drawn again from another view, each pointer ray meets the
 * sheet swept by the first curve along the normal, and the meeting point is the 3D point. In the
 * plane's coordinates the ray is a line: its crossing with the curve's polyline gives the curve
 * point, and the ray's point above it the depth. Of several crossings the one nearest the
 * previous ink point is taken (the first: nearest the eye).
 */
function extrusionOf(name) {
  const stroke = (doc.recipe.strokes || {})[name];
  const curve = doc.curves.get(name);
  if (!stroke || !stroke.plane || !curve) return null;
  const n = new THREE.Vector3(...(stroke.plane.normal || new THREE.Vector3(...stroke.plane.x_axis).cross(new THREE.Vector3(...stroke.plane.y_axis)).toArray())).normalize();
  const polyline = curvePolyline(curve, 400);
  return { name, normal: n, polyline };
}
function onExtrusion(ray, sheet, previous) {
  const n = sheet.normal;
  // plane coordinates: drop the component along n
  const e1 = new THREE.Vector3(1, 0, 0);
  if (Math.abs(e1.dot(n)) > 0.9) e1.set(0, 1, 0);
  e1.sub(n.clone().multiplyScalar(e1.dot(n))).normalize();
  const e2 = n.clone().cross(e1);
  const flat = (v) => [v.dot(e1), v.dot(e2)];
  const o = flat(ray.origin);
  const d = flat(ray.direction);
  const dd = Math.hypot(d[0], d[1]);
  if (dd < 1e-9) return null; // looking along the sheet's normal: no depth to read
  const hits = [];
  const P = sheet.polyline;
  for (let k = 0; k + 1 < P.length / 3; k++) {
    const a = flat(new THREE.Vector3(P[3 * k], P[3 * k + 1], P[3 * k + 2]));
    const b = flat(new THREE.Vector3(P[3 * k + 3], P[3 * k + 4], P[3 * k + 5]));
    // o + l d = a + m (b - a)
    const ex = b[0] - a[0];
    const ey = b[1] - a[1];
    const den = d[0] * -ey - d[1] * -ex;
    if (Math.abs(den) < 1e-12) continue;
    const rx = a[0] - o[0];
    const ry = a[1] - o[1];
    const l = (rx * -ey - ry * -ex) / den;
    const m = (d[0] * ry - d[1] * rx) / den;
    if (m < 0 || m > 1 || l <= 0) continue;
    // the ray's parameter l is along its flattened direction: the same l on the 3D ray
    hits.push(ray.origin.clone().addScaledVector(ray.direction, l));
  }
  if (!hits.length) return null;
  if (!previous) return hits.reduce((best, h) => (h.distanceTo(ray.origin) < best.distanceTo(ray.origin) ? h : best));
  const prev = new THREE.Vector3(...previous);
  return hits.reduce((best, h) => (h.distanceTo(prev) < best.distanceTo(prev) ? h : best));
}

/** Every curve's two ends (for snapping). */
function curveEnds() {
  const out = [];
  for (const [name, c] of doc.curves) {
    const n = c.weights.length;
    out.push({ name, at: 'start', p: [c.points[0], c.points[1], c.points[2]] });
    out.push({ name, at: 'end', p: [c.points[3 * n - 3], c.points[3 * n - 2], c.points[3 * n - 1]] });
  }
  return out;
}
const SNAP_PX = 12;
const GRID_MM = 10;
/** The stroke's end point snapped: to a curve end, else a curve, else a grid node; or null. */
function snapEnd(p) {
  const s = toScreen(p);
  let best = null;
  for (const e of curveEnds()) {
    const q = toScreen(e.p);
    const d = Math.hypot(q[0] - s[0], q[1] - s[1]);
    if (d < SNAP_PX && (!best || d < best.d)) best = { d, p: e.p, to: `${e.name}.${e.at}` };
  }
  if (best) return best;
  for (const [name] of doc.curves) {
    const pos = curveGroup.getObjectByName(name)?.geometry.getAttribute('position').array;
    if (!pos) continue;
    for (let k = 0; k < pos.length / 3; k++) {
      const q = toScreen([pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]]);
      const d = Math.hypot(q[0] - s[0], q[1] - s[1]);
      if (d < PICK_PX && (!best || d < best.d)) best = { d, p: [pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]], to: name };
    }
  }
  if (best) return best;
  const g = p.map((c) => Math.round(c / GRID_MM) * GRID_MM);
  const q = toScreen(g);
  if (Math.hypot(q[0] - s[0], q[1] - s[1]) < 6) return { p: g, to: 'grid' };
  return null;
}

/**
 * A stroke over an existing stroke from near one of its points to near another: redrawn there.
 * Near on the screen and in space (as near in millimetres as the snap distance in pixels is
 * there), so a stroke drawn on another plane that only looks the same from here (sections seen
 * end on) is a new stroke.
 */
function oversketchTarget(points) {
  const strokes = doc.recipe.strokes || {};
  const a = points[0];
  const b = points[points.length - 1];
  for (const [name, stroke] of Object.entries(strokes)) {
    const q = stroke.points;
    if (!Array.isArray(q) || q.length < 4) continue;
    const near = (x) => {
      const s = toScreen(x);
      const reach = SNAP_PX * millimetresPerPixel(x);
      let best = { d: Infinity, i: -1 };
      q.forEach((p, i) => {
        const t = toScreen(p);
        const d = Math.hypot(t[0] - s[0], t[1] - s[1]);
        if (d < best.d && Math.hypot(p[0] - x[0], p[1] - x[1], p[2] - x[2]) < reach) best = { d, i };
      });
      return best;
    };
    const ia = near(a);
    const ib = near(b);
    const endsFree = (i) => i > 1 && i < q.length - 2;
    if (ia.d < SNAP_PX && ib.d < SNAP_PX && Math.abs(ia.i - ib.i) > 2 && endsFree(ia.i) && endsFree(ib.i)) return { name, from: ia.i, to: ib.i };
  }
  return null;
}

let lastLive = null; // the last stroke drawn as a live style target: {style, name, updates}
function finishStroke(event) {
  const live = ink.live;
  const points = ink.points;
  const line = ink.line;
  const plane = ink.plane;
  const over = ink.over;
  ink = null;
  if (points.length < 3) {
    inkGroup.remove(line);
    dirty();
    return;
  }
  const tolerance = Number($('stroke-tolerance').value) || 0.5;
  const dropInk = () => {
    inkGroup.remove(line);
    const i = pendingInk.findIndex((p) => p.line === line);
    if (i >= 0) pendingInk.splice(i, 1);
    dirty();
  };
  if (live) {
    // the live target's last update: the whole stroke, in the drawing's history entry
    link.cancelDrag();
    lastLive = live;
    const stroke = { points, tolerance };
    if (plane) stroke.plane = plane;
    const { changes, label } = liveTarget(live, stroke);
    pendingInk.push({ label, line });
    return link.send(commandOf(changes, label, 'stroke', live.group), event.timeStamp).then(({ reply }) => reply.op === 'error' && dropInk());
  }
  const redrawn = event.altKey || over ? null : oversketchTarget(points);
  if (redrawn) {
    const def = doc.recipe.strokes[redrawn.name];
    const q = def.points;
    const forward = redrawn.from < redrawn.to;
    const lo = Math.min(redrawn.from, redrawn.to);
    const hi = Math.max(redrawn.from, redrawn.to);
    const drawn = forward ? points : [...points].reverse();
    const next = [...q.slice(0, lo), ...drawn, ...q.slice(hi + 1)];
    const label = `stroke ${redrawn.name} (oversketch)`;
    pendingInk.push({ label, line });
    // a redrawn stroke may gain or lose corners: the kernel's fit says into how many pieces it splits
    piecesOf(next, def.plane, def.tolerance || tolerance).then((pieces) => {
      const changes = [{ path: `strokes.${redrawn.name}.points`, value: next }];
      if (pieces && (def.pieces || pieces > 1)) changes.push({ path: `strokes.${redrawn.name}.pieces`, value: pieces, create: true });
      return edit(changes, label, 'stroke', event.timeStamp);
    });
    return;
  }
  if ($('snap').checked && !event.altKey && !over) {
    for (const end of [0, points.length - 1]) {
      const s = snapEnd(points[end]);
      if (s) names.moveEnd(points, end, s.p);
    }
  }
  if (over) {
    // the 3D stroke takes the planar one's place (its name, so what was built from it follows)
    const label = `stroke ${over.name} (3D)`;
    pendingInk.push({ label, line });
    edit({ path: `strokes.${over.name}`, value: { points, tolerance } }, label, 'stroke', event.timeStamp);
    return;
  }
  const name = names.free(doc.recipe, 's');
  const stroke = { points, tolerance };
  if (plane) stroke.plane = plane;
  const label = `stroke ${name}`;
  pendingInk.push({ label, line });
  // The kernel's fit first: a stroke that turns sharply is split at its corners into pieces
  // NAME.1 .. NAME.N (the recipe's "pieces"), one curve each.
  piecesOf(points, plane, tolerance).then((pieces) => {
    if (!pieces) return dropInk();
    if (pieces > 1) stroke.pieces = pieces;
    const changes = [{ path: `strokes.${name}`, value: stroke, create: true }];
    const mirror = mirrorPlane();
    if (mirror) {
      const curves = pieces > 1 ? Array.from({ length: pieces }, (_, k) => `${name}.${k + 1}`) : [name];
      curves.forEach((curve, k) => changes.push({ path: `curves.${name}_mirror${pieces > 1 ? `_${k + 1}` : ''}`, value: { mirror: { curve, plane: mirror } }, create: true }));
    }
    return edit(changes, label, 'stroke', event.timeStamp).then(({ reply }) => {
      if (reply.op === 'error') dropInk();
    });
  });
}

/**
 * The plane new strokes are mirrored in, {origin, normal}, or null: x, y or z = the "at" value, or
 * the plane placed at a picked surface point.
 */
function mirrorPlane() {
  const axis = $('mirror').value;
  if (!axis) return null;
  if (axis === 'picked') {
    if (!pickedPlane) showMessage('no plane is placed yet: sketch "on a plane at a picked surface point" and click a surface first', true);
    return pickedPlane;
  }
  const normal = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] }[axis];
  const at = Number($('mirror-at').value) || 0;
  return { origin: normal.map((c) => c * at), normal };
}

/** The changes that make `stroke` the style's target under the live stroke's name (one history entry). */
function liveTarget(live, stroke) {
  live.updates++;
  return {
    changes: [
      { path: `strokes.${live.name}`, value: stroke, create: true },
      { path: `deformations.${live.style}[0].target`, value: live.name },
    ],
    label: `restyle ${live.style}: target ${live.name} drawn`,
  };
}

/** How many curves the kernel fits to the stroke (split at its corners), or null when it cannot. */
function piecesOf(points, plane, tolerance) {
  const command = { op: 'fit', points, tolerance };
  if (plane) command.plane = plane;
  return link.send(command).then(({ reply }) => (reply.op === 'fit' ? reply.pieces : null));
}

// ------------------------------------------------------------------------------ handles (Edit)
// Handles are the selected curve's control points (a style's target, or any curve), and the
// control points of lattices on the selected surface.
let handles = []; // {kind: 'curve' | 'lattice', name, index, p: [x,y,z], ...}
const handleMaterial = new THREE.PointsMaterial({ color: 0x7cf0a0, size: 9, sizeAttenuation: false, depthTest: false });
const activeHandleMaterial = new THREE.PointsMaterial({ color: 0xffffff, size: 12, sizeAttenuation: false, depthTest: false });
let activeHandle = null;

function rebuildHandles() {
  disposeGroup(handleGroup);
  handles = [];
  if (body.dataset.tool !== 'edit') {
    dirty();
    return;
  }
  for (const s of selection) {
    if (s.kind === 'curve' && doc.curves.has(s.name)) {
      const c = doc.curves.get(s.name);
      for (let i = 0; i < c.weights.length; i++) handles.push({ kind: 'curve', name: s.name, index: i, p: [c.points[3 * i], c.points[3 * i + 1], c.points[3 * i + 2]] });
    }
  }
  for (const lattice of latticesShown()) {
    const pts = stepLatticePoints(lattice.step);
    const [l, m, n] = latticeCounts(lattice.step).map((c) => c - 1);
    const seg = [];
    const at = (i, j, k) => pts[(i * (m + 1) + j) * (n + 1) + k];
    for (let i = 0; i <= l; i++)
      for (let j = 0; j <= m; j++)
        for (let k = 0; k <= n; k++) {
          handles.push({ kind: 'lattice', name: lattice.deformation, index: [i, j, k], p: at(i, j, k) });
          if (i < l) seg.push(...at(i, j, k), ...at(i + 1, j, k));
          if (j < m) seg.push(...at(i, j, k), ...at(i, j + 1, k));
          if (k < n) seg.push(...at(i, j, k), ...at(i, j, k + 1));
        }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(seg, 3));
    const lines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0x7cf0a0, transparent: true, opacity: 0.6, depthTest: false }));
    lines.renderOrder = 4;
    handleGroup.add(lines);
  }
  if (handles.length) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(handles.flatMap((h) => h.p), 3));
    const points = new THREE.Points(g, handleMaterial);
    points.renderOrder = 5;
    handleGroup.add(points);
  }
  if (activeHandle) {
    const h = handles.find((x) => x.kind === activeHandle.kind && x.name === activeHandle.name && String(x.index) === String(activeHandle.index));
    if (h) {
      activeHandle = { ...h, start: activeHandle.start };
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(h.p, 3));
      const p = new THREE.Points(g, activeHandleMaterial);
      p.renderOrder = 6;
      handleGroup.add(p);
      showLatticePoint();
    }
  }
  dirty();
}

/** The lattice steps that deform the selected surface (or every shown one when none is selected). */
function latticesShown() {
  const out = [];
  const surfaces = doc.recipe.surfaces || {};
  const chosen = selection.filter((s) => s.kind === 'surface').map((s) => s.name);
  for (const [name, def] of Object.entries(surfaces)) {
    if (!def.deform || !doc.surfaces.has(name)) continue;
    if (chosen.length && !chosen.includes(name)) continue;
    const stack = (doc.recipe.deformations || {})[def.deform.deformation] || [];
    stack.forEach((step, i) => {
      if (step.kind === 'bezier_lattice' || step.kind === 'bspline_lattice') out.push({ deformation: def.deform.deformation, stepIndex: i, step });
    });
  }
  const models = selection.filter((s) => s.kind === 'model').map((s) => s.name);
  for (const [name, def] of Object.entries(doc.recipe.models || {})) {
    if (!def.deformation || (models.length && !models.includes(name)) || (chosen.length && !models.length)) continue;
    const stack = (doc.recipe.deformations || {})[def.deformation] || [];
    stack.forEach((step, i) => {
      if ((step.kind === 'bezier_lattice' || step.kind === 'bspline_lattice') && !out.some((o) => o.deformation === def.deformation)) out.push({ deformation: def.deformation, stepIndex: i, step });
    });
  }
  return out;
}

function pickHandle(clientX, clientY) {
  let best = null;
  for (const h of handles) {
    const q = toScreen(h.p);
    const d = Math.hypot(q[0] - clientX, q[1] - clientY);
    if (d < 10 && (!best || d < best.d)) best = { ...h, d };
  }
  return best;
}

/** Where a dragged point goes for the pointer's ray: on its lock's axis or plane, else in the view plane. */
function dragTarget(start, raycaster, lock) {
  const s = new THREE.Vector3(...start);
  const axis = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };
  if (axis[lock]) {
    // the point of the axis line closest to the ray
    const d = new THREE.Vector3(...axis[lock]);
    const r = raycaster.ray;
    const w0 = s.clone().sub(r.origin);
    const b = d.dot(r.direction);
    const denom = 1 - b * b;
    if (denom < 1e-9) return null;
    const t = (b * r.direction.dot(w0) - d.dot(w0)) / denom;
    return s.addScaledVector(d, t).toArray();
  }
  const planeNormal = { yz: [1, 0, 0], xz: [0, 1, 0], xy: [0, 0, 1] }[lock];
  const normal = planeNormal ? new THREE.Vector3(...planeNormal) : camera.position.clone().sub(controls.target).normalize();
  const p = raycaster.ray.intersectPlane(new THREE.Plane().setFromNormalAndCoplanarPoint(normal, s), new THREE.Vector3());
  return p ? p.toArray() : null;
}

let handleDrag = null; // {handle, start, grab}
function moveHandle(h, to, inputAt, final, group) {
  const build = () => {
    if (h.kind === 'lattice') {
      const moves = names.withMove(doc.recipe.deformations[h.name][0].moves || [], h.index, to);
      // while the page draws the drag (previews), the kernel checks and runs each update but
      // sends no nets; the update at the release brings them
      const changes = { path: `deformations.${h.name}[0].moves`, value: moves };
      return { changes, label: `move lattice ${h.name} [${h.index}]`, group, nets: !(previews.size && !final) };
    }
    // a curve's control point: a stroke becomes the B-spline it was fitted to, once
    if (!doc.curves.has(h.name)) return null;
    if (names.strokeOf(doc.recipe, h.name) && names.strokeOf(doc.recipe, h.name) !== h.name) {
      showMessage(`${h.name} is a piece of stroke ${names.strokeOf(doc.recipe, h.name)} (split at its corners): redraw it over itself to change it`, true);
      return null;
    }
    return { changes: names.curvePointChanges(doc.recipe, doc.curves.get(h.name), h.name, h.index, to), label: `move ${h.name} point ${h.index}`, group };
  };
  if (!final) return dragEdit(build, inputAt);
  const b = build();
  if (!b) return null;
  const command = commandOf(b.changes, b.label, final === 'drag-end' ? 'drag-end' : 'edit', b.group);
  return link.send(command, inputAt);
}

function showLatticePoint() {
  const h = activeHandle;
  if (!h || h.kind !== 'lattice') return;
  $('lattice-point').textContent = `${h.name} point [${h.index.join(', ')}]`;
  ['x', 'y', 'z'].forEach((a, i) => {
    if (document.activeElement !== $(`lattice-${a}`)) $(`lattice-${a}`).value = Number(h.p[i].toFixed(4));
  });
}
['x', 'y', 'z'].forEach((a) =>
  $(`lattice-${a}`).addEventListener('change', () => {
    if (!activeHandle || activeHandle.kind !== 'lattice') return;
    const to = ['x', 'y', 'z'].map((c, i) => (c === a ? Number($(`lattice-${a}`).value) : activeHandle.p[i]));
    if (to.every(Number.isFinite)) moveHandle(activeHandle, to, performance.now(), true);
  }),
);

// ------------------------------------------------------------------------------ lattice drag preview
// While a lattice point is dragged, each surface that the lattice alone deforms is drawn from the
// FFD of its parent's samples (ffd_preview.js: the exact result's points at those parameters)
// in the frame of the pointer move; the kernel's exact nets follow, and replace the picture
// once the drag is let go and its last update is answered.
const previews = new Map(); // surface name -> {prepared, geometry, step}
let previewEnding = false;
function startPreview(h) {
  previews.clear();
  previewEnding = false;
  const stack = (doc.recipe.deformations || {})[h.name];
  if (!stack || stack.length !== 1 || !['bezier_lattice', 'bspline_lattice'].includes(stack[0].kind)) return;
  for (const [name, def] of Object.entries(doc.recipe.surfaces || {})) {
    if (!def.deform || def.deform.deformation !== h.name || !doc.surfaces.has(name) || !doc.befores.has(name)) continue;
    const parent = doc.befores.get(name);
    const grid = surfaceGrid(parent, surfaceResolution(parent, 0), surfaceResolution(parent, 1));
    const geometry = gridGeometry(grid);
    geometry.userData.preview = true;
    previews.set(name, { prepared: prepareFfd(grid, stack[0]), geometry, step: stack[0] });
  }
}
function showPreview(h, to, inputAt) {
  if (!previews.size) return;
  let live = [Infinity, -Infinity];
  for (const preview of previews.values()) {
    const moved = { ...preview.step, moves: names.withMove(preview.step.moves || [], h.index, to) };
    const position = preview.geometry.getAttribute('position');
    const normal = preview.geometry.getAttribute('normal');
    const points = stepLatticePoints(moved);
    const ratio = applyFfd(preview.prepared, points, position.array, normal.array);
    preview.points = points;
    live = [Math.min(live[0], ratio[0]), Math.max(live[1], ratio[1])];
    position.needsUpdate = true;
    normal.needsUpdate = true;
    preview.geometry.computeBoundingSphere();
  }
  if (!surfaceGroup.children.some((o) => o.geometry && o.geometry.userData.preview)) rebuildSurfaces();
  showLatticeFigures(live);
  dirty((drawnAt) => metrics.preview.push({ at: drawnAt, ms: drawnAt - inputAt }));
}
function endPreview() {
  if (!previews.size) return;
  previewEnding = true;
  if (!link.busy) finishPreview();
}
function finishPreview() {
  previewEnding = false;
  const geometries = [...previews.values()].map((p) => p.geometry);
  previews.clear();
  rebuildSurfaces();
  geometries.forEach((g) => g.dispose());
}

// ------------------------------------------------------------------------------ direct manipulation
// Shift-press on a surface with the Edit tool: Hsu–Hughes–Kaufman direct manipulation. A cubic
// B-spline lattice of 3 x 3 x 1 cells around the surface is solved so that the surface point
// pressed goes where the pointer goes (the recipe's direct_manipulation step, refitted: a
// B-spline lattice's knot planes cross the surface off its iso-lines).
let surfaceDrag = null; // {surface, deformation, uv, start, group}
function startDirectManipulation(event) {
  const hit = onSurface(pointerRay(event.clientX, event.clientY));
  if (!hit || hit.object.userData.kind !== 'surface') return;
  const uv = hitParameters(hit);
  if (!uv) return;
  const surface = hit.object.name;
  const start = hit.point.toArray();
  const deformation = names.free(doc.recipe, 'pull');
  const result = names.free(doc.recipe, `${surface}_pulled`);
  const lattice = { kind: 'bspline_lattice', frame: names.boxFrame(doc.surfaces.get(surface).points), cells: [3, 3, 1], degrees: [3, 3, 1], knots: 'clamped' };
  // the step, its surface and the drag's updates: one history entry (one group)
  const group = newGroup();
  const changes = [
    { path: `deformations.${deformation}`, value: [{ kind: 'direct_manipulation', name: deformation, lattice, moves: [{ surface_point: uv, to: start }] }], create: true },
    { path: `surfaces.${result}`, value: { deform: { surface, deformation, composition: { mode: 'refit', tolerance: 1e-4 } } }, create: true },
  ];
  link.send(commandOf(changes, `drag ${surface} at (${uv.map((x) => x.toPrecision(4))})`, 'edit', group)).then(({ reply }) => {
    if (reply.op !== 'error') select({ kind: 'surface', name: result }, false);
  });
  surfaceDrag = { surface, deformation, uv, start, group };
  dragging = true;
  canvas.setPointerCapture(event.pointerId);
  controls.enabled = false;
  event.stopImmediatePropagation();
}

// ------------------------------------------------------------------------------ pointer input
let down = null; // {x, y, button}
canvas.addEventListener(
  'pointerdown',
  (event) => {
    down = { x: event.clientX, y: event.clientY, button: event.button };
    const tool = body.dataset.tool;
    if (event.button !== 0) return;
    if (tool === 'sketch') {
      const on = $('sketch-on').value;
      let over = null;
      if (on === 'over') {
        const chosen = selected('curve');
        over = chosen.length === 1 ? extrusionOf(chosen[0]) : null;
        if (!over) {
          showMessage('select one stroke drawn on a plane, then draw it again from another view to give it depth', true);
          return;
        }
      }
      if (on === 'picked' && (!pickedPlane || event.shiftKey)) {
        const hit = onSurface(pointerRay(event.clientX, event.clientY));
        if (hit && hit.face) placePickedPlane(hit);
        else showMessage('press on a surface to place the plane there', true);
        event.stopImmediatePropagation();
        return;
      }
      const plane = on === 'surface' || on === 'over' ? null : sketchPlane();
      ink = { points: [], plane, over, line: inkLine(), pointerId: event.pointerId };
      // Restyle while drawing: the stroke is the selected style's new target from its first
      // points on, each pointer move one drag update (newest wins), the release the last.
      const style = !over && $('style-live').checked ? activeStyle() : null;
      if (style) ink.live = { style, name: names.free(doc.recipe, 's'), group: newGroup(), updates: 0 };
      const p = inkPoint(event);
      if (p) pushInk(p);
      canvas.setPointerCapture(event.pointerId);
      controls.enabled = false;
      event.stopImmediatePropagation();
    } else if (tool === 'edit') {
      const h = pickHandle(event.clientX, event.clientY);
      if (!h) {
        if (event.shiftKey) startDirectManipulation(event);
        return;
      }
      activeHandle = { ...h };
      handleDrag = { handle: h, start: h.p.slice(), group: newGroup() };
      if (h.kind === 'lattice') startPreview(h);
      dragging = true;
      canvas.setPointerCapture(event.pointerId);
      controls.enabled = false;
      event.stopImmediatePropagation();
      rebuildHandles();
    }
  },
  { capture: true },
);
/** Where a point grabbed at `start` goes for this pointer event: the lock's target, scaled by the strength; null off the lock. */
function draggedTo(start, event) {
  const target = dragTarget(start, pointerRay(event.clientX, event.clientY), $('lattice-lock').value);
  if (!target) return null;
  const strength = Number($('lattice-strength').value) || 1;
  return start.map((c, i) => c + strength * (target[i] - c));
}
canvas.addEventListener('pointermove', (event) => {
  if (ink) {
    const events = event.getCoalescedEvents ? event.getCoalescedEvents() : [event];
    for (const e of events.length ? events : [event]) {
      const p = inkPoint(e);
      if (p) pushInk(p);
    }
    if (ink.live && ink.points.length >= 4) {
      const live = ink.live;
      const stroke = { points: ink.points.slice(), tolerance: Number($('stroke-tolerance').value) || 0.5 };
      if (ink.plane) stroke.plane = ink.plane;
      dragEdit(() => ({ ...liveTarget(live, stroke), group: live.group }), event.timeStamp);
    }
  } else if (surfaceDrag) {
    const to = draggedTo(surfaceDrag.start, event);
    if (!to) return;
    surfaceDrag.last = to;
    const d = surfaceDrag;
    dragEdit(() => (doc.recipe.deformations && doc.recipe.deformations[d.deformation] ? { changes: { path: `deformations.${d.deformation}[0].moves[0].to`, value: to }, label: `drag ${d.surface} at (${d.uv.map((x) => x.toPrecision(4))})`, group: d.group } : null), event.timeStamp);
  } else if (handleDrag) {
    const to = draggedTo(handleDrag.start, event);
    if (!to) return;
    handleDrag.last = to;
    if (handleDrag.handle.kind === 'lattice') showPreview(handleDrag.handle, to, event.timeStamp);
    moveHandle(handleDrag.handle, to, event.timeStamp, false, handleDrag.group);
  }
});
canvas.addEventListener('pointerup', (event) => {
  const click = down && Math.hypot(event.clientX - down.x, event.clientY - down.y) < 4 && down.button === 0;
  down = null;
  if (ink) {
    finishStroke(event);
    controls.enabled = true;
    return;
  }
  if (surfaceDrag) {
    surfaceDrag = null;
    dragging = false;
    controls.enabled = true;
    return;
  }
  if (handleDrag) {
    // the release: the last position, with the kernel's nets, in the drag's history entry
    const d = handleDrag;
    handleDrag = null;
    dragging = false;
    controls.enabled = true;
    if (d.last) {
      link.cancelDrag();
      moveHandle(d.handle, d.last, event.timeStamp, 'drag-end', d.group);
    }
    endPreview();
    return;
  }
  if (click) select(pick(event.clientX, event.clientY), event.shiftKey);
});

// ------------------------------------------------------------------------------ tools and builds
function setTool(tool) {
  body.dataset.tool = tool;
  document.querySelectorAll('[data-tool]').forEach((b) => b.setAttribute('aria-pressed', String(b.dataset.tool === tool)));
  controls.mouseButtons.LEFT = tool === 'sketch' ? null : THREE.MOUSE.ROTATE;
  $('drag-panel').hidden = tool !== 'edit';
  rebuildHandles();
}
document.querySelectorAll('button[data-tool]').forEach((b) => b.addEventListener('click', () => setTool(b.dataset.tool)));
setTool('orbit');

function selected(kind) {
  return selection.filter((s) => s.kind === kind).map((s) => s.name);
}
/** The surface an operation applies to: the selected one, or the only one shown. */
function targetSurface() {
  const chosen = selected('surface');
  if (chosen.length === 1) return chosen[0];
  if (!chosen.length && doc.surfaces.size === 1) return [...doc.surfaces.keys()][0];
  showMessage('select one surface first (click it with the Select tool)', true);
  return null;
}

$('build-fill').addEventListener('click', () => {
  const curves = selected('curve');
  if (curves.length < 2 || curves.length > 4) return showMessage('select 2 to 4 curves that meet end to end, then Fill', true);
  const name = names.free(doc.recipe, 'fill');
  const tolerance = Number($('stroke-tolerance').value) || 0.5;
  edit({ path: `surfaces.${name}`, value: { fill: { curves, join: 'snap', gap_tolerance: 2 * tolerance } }, create: true }, `fill ${name}`).then(() => select(null));
});
$('build-skin').addEventListener('click', () => {
  const curves = selected('curve');
  if (curves.length < 2) return showMessage('select 2 or more section curves in order, then Skin', true);
  const name = names.free(doc.recipe, 'skin');
  edit({ path: `surfaces.${name}`, value: { skin: { sections: curves } }, create: true }, `skin ${name}`).then(() => select(null));
});
$('build-revolve').addEventListener('click', () => {
  const curves = selected('curve');
  if (curves.length < 1 || curves.length > 2) return showMessage('select the profile curve (and a second curve whose chord is the axis, or choose a world axis), then Revolve', true);
  let axis = { point: [0, 0, 0], direction: { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] }[$('revolve-axis').value] };
  if (curves.length === 2) {
    // the axis: the second curve's chord, from its start to its end
    const c = doc.curves.get(curves[1]);
    const n = c.weights.length;
    const a = [c.points[0], c.points[1], c.points[2]];
    const b = [c.points[3 * n - 3], c.points[3 * n - 2], c.points[3 * n - 1]];
    const d = b.map((x, e) => x - a[e]);
    if (Math.hypot(...d) === 0) return showMessage(`the axis curve "${curves[1]}" is closed: its chord has no direction`, true);
    axis = { point: a, direction: d };
  }
  const name = names.free(doc.recipe, 'revolve');
  edit({ path: `surfaces.${name}`, value: { revolve: { profile: curves[0], axis } }, create: true }, `revolve ${name}`).then(() => select(null));
});
$('build-style').addEventListener('click', () => {
  const curves = selected('curve');
  if (curves.length !== 2) return showMessage('select the bound (a closed curve) and then the target curve, then Style', true);
  const surface = targetSurface();
  if (!surface) return;
  const deformation = names.free(doc.recipe, 'style');
  const result = names.free(doc.recipe, `${surface}_styled`);
  edit(
    [
      { path: `deformations.${deformation}`, value: [{ kind: 'style', name: deformation, bound: curves[0], target: curves[1], mode: 'exact' }], create: true },
      { path: `surfaces.${result}`, value: { deform: { surface, deformation } }, create: true },
    ],
    `style ${surface}`,
  ).then(({ reply }) => reply.op !== 'error' && select({ kind: 'surface', name: result }));
});
$('build-lattice').addEventListener('click', () => {
  const model = selected('model')[0] || (!selection.length && !doc.surfaces.size && doc.models.size === 1 ? [...doc.models.keys()][0] : null);
  if (model) {
    // a whole model: its recipe entry takes the stack (models.M.deformation)
    const deformation = names.free(doc.recipe, 'lattice');
    const step = { kind: 'bezier_lattice', name: deformation, frame: names.boxFrame(doc.models.get(model).positions), degrees: [3, 3, 1], moves: [] };
    edit(
      [
        { path: `deformations.${deformation}`, value: [step], create: true },
        { path: `models.${model}.deformation`, value: deformation, create: true },
      ],
      `lattice on ${model}`,
    ).then(({ reply }) => reply.op !== 'error' && setTool('edit'));
    return;
  }
  const surface = targetSurface();
  if (!surface) return;
  const deformation = names.free(doc.recipe, 'lattice');
  const result = names.free(doc.recipe, `${surface}_ffd`);
  const frame = names.boxFrame(doc.surfaces.get(surface).points);
  // a Bézier lattice composes exactly; a B-spline lattice's knot planes cross the surface off its
  // iso-lines, so its result is a certified refit
  const bspline = $('lattice-kind').value === 'bspline';
  const step = bspline ? { kind: 'bspline_lattice', name: deformation, frame, cells: [4, 4, 1], degrees: [3, 3, 1], knots: 'clamped', moves: [] } : { kind: 'bezier_lattice', name: deformation, frame, degrees: [3, 3, 1], moves: [] };
  const deform = bspline ? { surface, deformation, composition: { mode: 'refit', tolerance: 1e-4 } } : { surface, deformation };
  edit(
    [
      { path: `deformations.${deformation}`, value: [step], create: true },
      { path: `surfaces.${result}`, value: { deform }, create: true },
    ],
    `lattice on ${surface}`,
  ).then(({ reply }) => {
    if (reply.op === 'error') return;
    select({ kind: 'surface', name: result });
    setTool('edit');
  });
});
$('build-global').addEventListener('click', () => {
  const surface = targetSurface();
  if (!surface) return;
  const deformation = names.free(doc.recipe, 'global');
  const result = names.free(doc.recipe, `${surface}_global`);
  edit(
    [
      { path: `deformations.${deformation}`, value: names.globalSteps(doc.surfaces.get(surface).points, 0, 0, 0), create: true },
      { path: `surfaces.${result}`, value: { deform: { surface, deformation, composition: { mode: 'refit', tolerance: 1e-4 } } }, create: true },
    ],
    `taper/twist/bend on ${surface}`,
  ).then(({ reply }) => reply.op !== 'error' && select({ kind: 'surface', name: result }));
});
$('delete').addEventListener('click', deleteSelected);
function deleteSelected() {
  const curves = selected('curve');
  if (!curves.length) return showMessage('select a curve to delete', true);
  // a piece of a stroke split at its corners goes with its stroke
  const paths = new Set(curves.map((n) => (names.strokeOf(doc.recipe, n) ? `strokes.${names.strokeOf(doc.recipe, n)}` : `curves.${n}`)));
  const changes = [...paths].map((path) => ({ path, remove: true }));
  edit(changes, `delete ${curves.join(', ')}`).then(({ reply }) => reply.op !== 'error' && select(null));
}

// constraints on planar sketches: the selected strokes (or a sketch's curves) become entities of
// a sketch on their plane, and each button appends a constraint; the solver's degrees of freedom
// and redundant sets are shown, and a conflicting constraint is refused with the solver's report.
function constrain(type) {
  const curves = selected('curve');
  if (!curves.length || curves.length > 2) return showMessage('select one or two curves drawn on one plane, then a constraint', true);
  const target = names.sketchFor(doc.recipe, curves);
  if (target.reason) return showMessage(target.reason, true);
  const [a, b] = target.entities;
  const nets = curves.map((c) => doc.curves.get(c));
  let constraints = [];
  const changes = [...target.changes];
  if (type === 'fixed') constraints = target.entities.flatMap((e) => [`${e}.start`, `${e}.end`]).map((point) => ({ type: 'fixed', point }));
  else if (type === 'horizontal' || type === 'vertical') {
    // a curve's chord, a construction line from its start to its end (not drawn), along the
    // plane's x or y axis
    for (const e of target.entities) {
      const chord = `${e}_chord`;
      const entities = target.create ? changes[0].value.entities : (doc.recipe.sketches[target.sketch].entities || {});
      if (!entities[chord]) {
        if (target.create) entities[chord] = { line: [`${e}.start`, `${e}.end`] };
        else changes.push({ path: `sketches.${target.sketch}.entities.${chord}`, value: { line: [`${e}.start`, `${e}.end`] }, create: true });
      }
      constraints.push({ type, entity: chord });
    }
  }
  else if (curves.length === 1) {
    if (type !== 'distance') return showMessage('coincident, tangent and curvature join two curves: select two', true);
    constraints = [{ type: 'distance', points: [`${a}.start`, `${a}.end`], value: Number($('constrain-value').value) }];
  } else {
    const [[ea, eb]] = names.nearestEnds(nets[0], nets[1]);
    if (type === 'coincident') constraints = [{ type: 'coincident', points: [`${a}.${ea}`, `${b}.${eb}`] }];
    else if (type === 'distance') constraints = [{ type: 'distance', points: [`${a}.${ea}`, `${b}.${eb}`], value: Number($('constrain-value').value) }];
    else constraints = [{ type, ends: [{ entity: a, end: ea }, { entity: b, end: eb }] }];
  }
  const existing = target.create ? [] : (doc.recipe.sketches[target.sketch].constraints || []);
  if (target.create) changes[0].value.constraints = constraints;
  else changes.push({ path: `sketches.${target.sketch}.constraints`, value: [...existing, ...constraints] });
  edit(changes, `${type} ${target.entities.join(', ')}`).then(({ reply }) => {
    if (reply.op !== 'error') select(null);
  });
}
for (const type of ['coincident', 'tangent', 'curvature', 'fixed', 'distance', 'horizontal', 'vertical']) $(`constrain-${type}`).addEventListener('click', () => constrain(type));
function showSketchFigures() {
  const curves = selected('curve');
  const target = curves.length && curves.length <= 2 ? names.sketchFor(doc.recipe, curves) : { reason: 'none' };
  $('constrain-panel').hidden = !!target.reason;
  if (target.reason) return;
  $('constrain-sketch').textContent = target.create ? '(a new sketch)' : target.sketch;
  const step = doc.steps.find((st) => st.path === `sketches.${target.sketch}`);
  $('sketch-figures').textContent = step ? `degrees of freedom ${step.figures.degrees_of_freedom}, ${step.figures.constraints} constraints, redundant sets ${step.figures.redundant_sets}, residual ${Number(step.figures.max_residual).toExponential(1)}` : '';
}

// style, lattice and global panels
function activeStyle() {
  for (const s of selected('surface')) {
    const def = (doc.recipe.surfaces || {})[s];
    const stack = def && def.deform && (doc.recipe.deformations || {})[def.deform.deformation];
    if (stack && stack[0] && stack[0].kind === 'style') return def.deform.deformation;
  }
  return null;
}
function activeGlobal() {
  for (const s of selected('surface')) {
    const def = (doc.recipe.surfaces || {})[s];
    const stack = def && def.deform && (doc.recipe.deformations || {})[def.deform.deformation];
    if (stack && stack.length === 3 && stack[0].kind === 'taper') return { deformation: def.deform.deformation, parent: def.deform.surface };
  }
  return null;
}
function showPanels() {
  showSketchFigures();
  const style = activeStyle();
  $('style-panel').hidden = !style;
  if (style) {
    const step = doc.recipe.deformations[style][0];
    $('style-name').textContent = style;
    $('style-mode').value = step.mode || 'paper';
    setSlider('style-lambda', step.lambda ?? 1);
    setSlider('style-kpr', step.key_points_per_row ?? 1);
    $('style-relaxation').checked = step.relaxation ?? true;
    $('style-smoothing').checked = step.smoothing ?? true;
  }
  const lattices = latticesShown();
  $('lattice-panel').hidden = !lattices.length;
  if (lattices.length) {
    $('lattice-name').textContent = lattices.map((l) => l.deformation).join(', ');
    showLatticeFigures();
  }
  const global = activeGlobal();
  $('global-panel').hidden = !global;
  if (global) {
    $('global-name').textContent = global.deformation;
    const g = names.globalValues(doc.recipe.deformations[global.deformation]);
    setSlider('global-taper', g.taper);
    setSlider('global-twist', g.twist);
    setSlider('global-bend', g.bend);
  }
}
/** The lattice steps' fold-free and volume-ratio figures from the kernel's last answer (certified bounds of det J). */
function showLatticeFigures(live) {
  const steps = doc.steps.filter((st) => st.kind === 'bezier_lattice' && 'fold_free' in st.figures);
  const kernel = steps.map((st) => `${st.figures.fold_free ? 'fold-free' : 'MAY FOLD'}, volume ratio ${st.figures.volume_ratio_min.toPrecision(3)} … ${st.figures.volume_ratio_max.toPrecision(3)}`).join('; ');
  $('lattice-figures').textContent = `${kernel ? `kernel: ${kernel}` : ''}${live ? `${kernel ? '\n' : ''}live, at the surface: volume ratio ${live[0].toPrecision(3)} … ${live[1].toPrecision(3)}` : ''}`;
}
function setSlider(id, value) {
  if (document.activeElement === $(id)) return;
  $(id).value = value;
  $(id).parentElement.querySelector('output').textContent = String(value);
}
// A slider's moves until it is let go ("change") are one drag.
const sliderGroups = {};
function sliderGroup(id) {
  if (!sliderGroups[id]) {
    sliderGroups[id] = newGroup();
    $(id).addEventListener('change', () => delete sliderGroups[id], { once: true });
  }
  return sliderGroups[id];
}
function styleField(id, field, read) {
  $(id).addEventListener('input', (event) => {
    const style = activeStyle();
    if (!style) return;
    const value = read($(id));
    if ($(id).parentElement.querySelector('output')) $(id).parentElement.querySelector('output').textContent = String(value);
    const group = sliderGroup(id);
    dragEdit(() => ({ changes: { path: `deformations.${style}[0].${field}`, value, create: true }, label: `${style} ${field}`, group }), event.timeStamp);
  });
}
styleField('style-lambda', 'lambda', (e) => Number(e.value));
styleField('style-kpr', 'key_points_per_row', (e) => Number(e.value));
styleField('style-relaxation', 'relaxation', (e) => e.checked);
styleField('style-smoothing', 'smoothing', (e) => e.checked);
styleField('style-mode', 'mode', (e) => e.value);
for (const id of ['global-taper', 'global-twist', 'global-bend'])
  $(id).addEventListener('input', (event) => {
    const g = activeGlobal();
    if (!g) return;
    $(id).parentElement.querySelector('output').textContent = $(id).value;
    const values = ['taper', 'twist', 'bend'].map((k) => Number($(`global-${k}`).value));
    const group = sliderGroup(id);
    dragEdit(() => ({ changes: { path: `deformations.${g.deformation}`, value: names.withGlobal(doc.recipe.deformations[g.deformation], ...values) }, label: `${g.deformation} ${id.slice(7)}`, group }), event.timeStamp);
  });
$('lattice-strength').addEventListener('input', () => ($('lattice-strength').parentElement.querySelector('output').textContent = $('lattice-strength').value));

// display
document.querySelectorAll('button[data-mode]').forEach((b) =>
  b.addEventListener('click', () => {
    mode = b.dataset.mode;
    applyMode();
  }),
);
$('before-after').addEventListener('click', toggleBefore);
function toggleBefore() {
  showBefore = !showBefore;
  $('before-after').setAttribute('aria-pressed', String(showBefore));
  rebuildSurfaces();
}
$('show-net').addEventListener('change', rebuildSurfaces);

// history, save, export
$('undo').addEventListener('click', () => simple('undo'));
$('redo').addEventListener('click', () => simple('redo'));
$('save').addEventListener('click', save);
async function save() {
  const file = $('save-name').value.trim();
  if (!file) return showMessage('give a file name to save the recipe to', true);
  // the saved recipe exports what is shown, so `clayform run` writes it
  const finals = [...doc.surfaces.keys()];
  const exports = doc.recipe.exports || {};
  const covered = Object.values(exports).some((e) => finals.every((n) => (e.surfaces || []).includes(n)));
  if (finals.length && !covered) {
    const { reply } = await edit({ path: `exports.${names.free(doc.recipe, doc.recipe.name || 'studio')}`, value: { surfaces: finals }, create: true }, 'export what is shown');
    if (reply.op === 'error') return;
  }
  return link.send({ op: 'save', file });
}
$('export').addEventListener('click', () => link.send({ op: 'export', folder: `${doc.recipe.name || 'studio'}-export` }));

function showHistory() {
  const list = $('history');
  list.replaceChildren(
    ...doc.history.entries.map((label, i) => {
      const li = document.createElement('li');
      li.textContent = label;
      if (i === doc.history.position) li.className = 'current';
      else if (i > doc.history.position) li.className = 'undone';
      return li;
    }),
  );
  $('undo').disabled = doc.history.position <= 0;
  $('redo').disabled = doc.history.position >= doc.history.entries.length - 1;
}
function showReport() {
  const wanted = doc.steps.filter((s) => s.path.startsWith('surfaces.') || s.path.startsWith('strokes.'));
  const box = $('report');
  box.replaceChildren(
    ...wanted.slice(-8).map((s) => {
      const d = document.createElement('details');
      d.open = s.path.includes('.steps[') || s.warning;
      const summary = document.createElement('summary');
      summary.textContent = `${s.path} (${s.kind}) ${(1000 * s.seconds).toFixed(1)} ms${s.warning ? ' ⚠' : ''}`;
      const table = document.createElement('table');
      table.className = 'figures';
      for (const [k, v] of Object.entries(s.figures)) {
        const tr = table.insertRow();
        tr.insertCell().textContent = k;
        tr.insertCell().textContent = typeof v === 'number' ? (Number.isInteger(v) ? String(v) : v.toPrecision(4)) : String(v);
      }
      d.append(summary, table);
      return d;
    }),
  );
  const redraw = metrics.preview[metrics.preview.length - 1];
  const kernel = metrics.drag[metrics.drag.length - 1];
  $('status').textContent = `kernel ${doc.reply ? (1000 * doc.reply.seconds).toFixed(0) : '-'} ms${redraw ? `, drag to redraw ${redraw.ms.toFixed(0)} ms` : ''}${kernel ? `, drag to kernel answer ${kernel.ms.toFixed(0)} ms` : ''}`;
}

// keyboard
window.addEventListener('keydown', (e) => {
  if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
  const ctrl = e.ctrlKey || e.metaKey;
  if (ctrl && e.key.toLowerCase() === 'z') {
    e.preventDefault();
    simple(e.shiftKey ? 'redo' : 'undo');
  } else if (ctrl && e.key.toLowerCase() === 'y') {
    e.preventDefault();
    simple('redo');
  } else if (ctrl && e.key.toLowerCase() === 's') {
    e.preventDefault();
    save();
  } else if (ctrl) return;
  else if (e.key === 'o') setTool('orbit');
  else if (e.key === 's') setTool('sketch');
  else if (e.key === 'e') setTool('edit');
  else if (e.key === 'b') toggleBefore();
  else if (e.key === 'f') setView('fit');
  else if (['1', '2', '3', '4'].includes(e.key)) setView(['top', 'front', 'side', 'iso'][Number(e.key) - 1]);
  else if (e.key === 'Delete' || e.key === 'Backspace') deleteSelected();
  else if (e.key === 'Escape') select(null);
  else if (['x', 'y', 'z', 'X', 'Y', 'Z'].includes(e.key)) {
    const axis = e.key.toLowerCase();
    const plane = { x: 'yz', y: 'xz', z: 'xy' }[axis];
    $('lattice-lock').value = $('lattice-lock').value === (e.shiftKey ? plane : axis) ? '' : e.shiftKey ? plane : axis;
  }
});

// ------------------------------------------------------------------------------ the window hook
// For the end-to-end test and for scripting the page: the nets as the kernel sent them, the
// camera, the latencies and frame times recorded, and a promise for "everything answered".
window.clayStudio = {
  recipe: () => doc.recipe,
  history: () => doc.history,
  reply: () => doc.reply,
  surfaces: () => Object.fromEntries([...doc.surfaces].map(([n, s]) => [n, plainNet(s)])),
  befores: () => Object.fromEntries([...doc.befores].map(([n, s]) => [n, plainNet(s)])),
  lastLive: () => lastLive && { ...lastLive },
  /** The page's pictures of a lattice drag in progress: per surface, its grid, vertices and the lattice points drawn. */
  previews: () => Object.fromEntries([...previews].map(([n, p]) => [n, { rows: p.prepared.grid.rows, cols: p.prepared.grid.cols, positions: Array.from(p.geometry.getAttribute('position').array), lattice: p.points }])),
  deviations: () => Object.fromEntries([...doc.deviations].map(([n, d]) => [n, { ...d.header, values: Array.from(d.values) }])),
  models: () => Object.fromEntries([...doc.models].map(([n, m]) => [n, { vertices: m.header.vertices, triangles: m.header.triangles, positions: Array.from(m.positions), from: m.faces ? 'model_nets' : 'mesh' }])),
  curves: () => Object.fromEntries([...doc.curves].map(([n, c]) => [n, { degree: c.degree, knots: c.knots, points: Array.from(c.points), weights: Array.from(c.weights) }])),
  camera: () => {
    camera.updateMatrixWorld();
    const rect = canvas.getBoundingClientRect();
    return { projectionInverse: camera.projectionMatrixInverse.elements.slice(), matrixWorld: camera.matrixWorld.elements.slice(), rect: { left: rect.left, top: rect.top, width: rect.width, height: rect.height } };
  },
  toScreen,
  setView,
  select: (items) => {
    selection = [];
    items.forEach((it) => select(it, true));
  },
  handles: () => handles.map((h) => ({ kind: h.kind, name: h.name, index: h.index, p: h.p, screen: toScreen(h.p) })),
  metrics,
  resetMetrics: () => Object.keys(metrics).forEach((k) => (metrics[k].length = 0)),
  idle: () =>
    new Promise((resolve) => {
      const poll = () => (link.busy || needsRender || previews.size ? setTimeout(poll, 10) : requestAnimationFrame(() => resolve(true)));
      poll();
    }),
};
function plainNet(s) {
  return { degrees: s.degrees, counts: s.counts, knots_u: s.knots_u, knots_v: s.knots_v, points: Array.from(s.points), weights: Array.from(s.weights) };
}

// ------------------------------------------------------------------------------ start
async function start() {
  link = new Link(socketUrl, onReply, (event) => {
    // A newer page (a reload, another tab) takes the session over at once: this one is told
    // so, and a reload here takes it back; otherwise the server is gone.
    const takenOver = event && /another page/.test(event.reason || '');
    showMessage(takenOver ? 'another page took this studio session over; reload this page to take it back' : 'the connection to clayform studio closed; restart it and reload the page', true);
    body.dataset.ready = 'closed';
  });
  try {
    await link.opened;
  } catch (e) {
    showMessage(`${e.message}: is clayform studio running?`, true);
    body.dataset.ready = 'error';
    return;
  }
  const { reply } = await simple('run');
  if (reply.op === 'error') showMessage(reply.message, true);
  $('run-title').textContent = `Clayform Studio — ${doc.recipe.name || reply.recipe || 'untitled'}`;
  $('save-name').value = `${doc.recipe.name || 'studio'}.json`;
  // a recipe with geometry is seen from the side, an empty one from the top (to sketch on XY)
  setView(doc.surfaces.size || doc.curves.size || doc.models.size ? 'iso' : 'top');
  body.dataset.ready = '1';
}
start();
setInterval(() => (body.dataset.busy = link && link.busy ? '1' : '0'), 50);
