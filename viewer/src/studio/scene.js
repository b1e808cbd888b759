// The scene the studio draws into: renderer, cameras (perspective or orthographic) and orbit
// controls, lights, the groups each tool fills (surfaces, curves, handles), the render loop and
// the 2D overlay drawn over it (ink, the snap ring), the standard views, and the pointer's geometry (rays, screen points, a pixel's size in
// millimetres). The grid and the other drafting aids are drafting.js's.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { $ } from './ui.js';
import { metrics, state } from './store.js';

export const canvas = $('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
renderer.setClearColor(0x30343a);
export const scene = new THREE.Scene();
// Two cameras, one in use: perspective (the default) or orthographic (drafting: parallel lines
// stay parallel, a view along an axis shows true lengths). `camera` is a live binding: every
// module that imports it sees the one in use.
const perspective = new THREE.PerspectiveCamera(35, 1, 1, 100000);
const orthographic = new THREE.OrthographicCamera(-1, 1, 1, -1, 1, 100000);
export let camera = perspective;
camera.up.set(0, 0, 1); // CAD convention: z up
camera.position.set(600, -900, 700);
scene.add(perspective, orthographic);
scene.add(new THREE.HemisphereLight(0xdfe8f5, 0x3a3530, 1.1));
const key = new THREE.DirectionalLight(0xffffff, 2.4);
scene.add(key, key.target);
export const controls = new OrbitControls(camera, canvas);
controls.enableDamping = false;

export const surfaceGroup = new THREE.Group();
export const curveGroup = new THREE.Group();
export const handleGroup = new THREE.Group();
scene.add(surfaceGroup, curveGroup, handleGroup);

// A render is asked for with `dirty()` and done in the next animation frame: input handlers run
// before it in the same frame, so ink drawn in a pointer event shows in that frame.
const loop = { needsRender: false, needsOverlay: false, lastFrameAt: null, afterRender: [] };
export function dirty(then) {
  if (then) loop.afterRender.push(then);
  loop.needsRender = true;
}
/** Whether a render (of the scene or of the overlay) was asked for and not yet done. */
export const renderPending = () => loop.needsRender || loop.needsOverlay;

// The overlay: a 2D canvas over the view for what changes under the pointer (a stroke's ink, the
// snap ring), drawn in 3D points projected with the camera of the frame, without rendering the
// scene again. Each pointer move of a stroke was a render of the whole scene: with a styled
// surface in view, 55 ms a frame in headless Chromium's software renderer, which the stroke's
// release and its reply then waited behind (issue #40).
const overlay = $('overlay');
const painters = [];
/** Adds `paint(ctx, at)` to the overlay's drawing: ctx a 2D context in CSS pixels, `at` a 3D point's [x, y] on it. */
export function addOverlayPainter(paint) {
  painters.push(paint);
}
/** Asks for the overlay alone to be drawn again in the next frame. */
export function overlayDirty() {
  loop.needsOverlay = true;
}
function drawOverlay() {
  const box = canvas.getBoundingClientRect();
  const scale = Math.min(window.devicePixelRatio || 1, 2);
  const w = Math.max(1, Math.round(box.width * scale));
  const h = Math.max(1, Math.round(box.height * scale));
  if (overlay.width !== w || overlay.height !== h) {
    overlay.width = w;
    overlay.height = h;
  }
  const ctx = overlay.getContext('2d');
  ctx.setTransform(scale, 0, 0, scale, 0, 0);
  ctx.clearRect(0, 0, box.width, box.height);
  const project = screenProjector();
  const at = (p) => {
    const [x, y] = project(p);
    return [x - box.left, y - box.top];
  };
  for (const paint of painters) paint(ctx, at);
}

function frame(now) {
  if (state.dragging && loop.lastFrameAt !== null) metrics.frames.push(now - loop.lastFrameAt);
  loop.lastFrameAt = state.dragging ? now : null;
  if (loop.needsRender) {
    loop.needsRender = false;
    loop.needsOverlay = true; // the camera may have moved: the overlay follows it
    key.position.copy(camera.position).add(new THREE.Vector3(300, 200, 800));
    key.target.position.copy(controls.target);
    renderer.render(scene, camera);
  }
  if (loop.needsOverlay) {
    loop.needsOverlay = false;
    drawOverlay();
  }
  if (loop.afterRender.length) {
    const done = performance.now();
    loop.afterRender.splice(0).forEach((f) => f(done));
  }
  requestAnimationFrame(frame);
}

function resize() {
  const stage = $('stage');
  const w = Math.max(1, stage.clientWidth);
  const h = Math.max(1, stage.clientHeight);
  renderer.setSize(w, h, false);
  // the aspect the canvas is shown at (its box may be fractional where the stage's is rounded):
  // a millimetre across is then as many pixels as a millimetre down (true lengths in ortho)
  const box = canvas.getBoundingClientRect();
  const aspect = box.width > 0 && box.height > 0 ? box.width / box.height : w / h;
  perspective.aspect = aspect;
  perspective.updateProjectionMatrix();
  const half = (orthographic.top - orthographic.bottom) / 2;
  orthographic.left = -half * aspect;
  orthographic.right = half * aspect;
  orthographic.updateProjectionMatrix();
  dirty();
}

/** Whether the view is orthographic. */
export const isOrthographic = () => camera === orthographic;

/**
 * Switches between the perspective and the orthographic camera, keeping the view: the same eye,
 * target and up, and the orthographic frustum as tall as the perspective's view is at the target.
 */
export function setOrthographic(on) {
  if (on === isOrthographic()) return;
  const from = camera;
  const to = on ? orthographic : perspective;
  to.position.copy(from.position);
  to.up.copy(from.up);
  to.near = from.near;
  to.far = from.far;
  const distance = from.position.distanceTo(controls.target);
  if (on) {
    const half = distance * Math.tan(THREE.MathUtils.degToRad(perspective.fov) / 2) / perspective.zoom;
    orthographic.top = half;
    orthographic.bottom = -half;
    orthographic.left = -half * perspective.aspect;
    orthographic.right = half * perspective.aspect;
    orthographic.zoom = 1;
  } else {
    // the eye moved so that the target looks as large as the orthographic view showed it
    const half = (orthographic.top - orthographic.bottom) / 2 / orthographic.zoom;
    const away = half / Math.tan(THREE.MathUtils.degToRad(perspective.fov) / 2);
    const dir = from.position.clone().sub(controls.target).normalize();
    to.position.copy(controls.target).addScaledVector(dir, away);
  }
  to.updateProjectionMatrix();
  to.lookAt(controls.target);
  camera = to;
  controls.object = to;
  controls.update();
  document.body.dataset.projection = on ? 'orthographic' : 'perspective';
  dirty();
}

/** The render loop, the stage's size and the view buttons. */
export function wireScene() {
  requestAnimationFrame(frame);
  controls.addEventListener('change', () => dirty());
  new ResizeObserver(resize).observe($('stage'));
  document.querySelectorAll('[data-view]').forEach((b) => b.addEventListener('click', () => setView(b.dataset.view)));
}

/** Removes a group's children, disposing of their geometry (not a drag preview's: its owner does). */
export function disposeGroup(group) {
  for (const child of [...group.children]) {
    child.traverse((o) => o.geometry && !o.geometry.userData.preview && !o.geometry.userData.kept && o.geometry.dispose());
    group.remove(child);
  }
}

// ------------------------------------------------------------------------------ camera
export function sceneBox() {
  const box = new THREE.Box3();
  surfaceGroup.traverse((o) => o.isMesh && box.union(new THREE.Box3().setFromObject(o)));
  curveGroup.traverse((o) => o.isLine && box.union(new THREE.Box3().setFromObject(o)));
  if (box.isEmpty()) box.set(new THREE.Vector3(-500, -500, -100), new THREE.Vector3(500, 500, 100));
  return box;
}
const VIEWS = { top: [0, 0, 1], bottom: [0, 0, -1], front: [0, -1, 0], back: [0, 1, 0], side: [1, 0, 0], left: [-1, 0, 0], iso: [1, -1.4, 1.1] };
export function setView(view) {
  const box = sceneBox();
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1);
  const dir = view === 'fit' ? camera.position.clone().sub(controls.target).normalize() : new THREE.Vector3(...VIEWS[view]).normalize();
  const fov = THREE.MathUtils.degToRad(perspective.fov);
  const fit = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * perspective.aspect));
  const distance = (1.1 * radius) / Math.sin(fit / 2);
  controls.target.copy(center);
  camera.position.copy(center).addScaledVector(dir, distance);
  if (isOrthographic()) {
    // the frustum holds the scene's sphere whichever way the stage is longer
    const aspect = perspective.aspect;
    const half = (1.1 * radius) / Math.min(1, aspect);
    orthographic.top = half;
    orthographic.bottom = -half;
    orthographic.left = -half * aspect;
    orthographic.right = half * aspect;
    orthographic.zoom = 1;
  }
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

// ------------------------------------------------------------------------------ pointer geometry
export function pointerRay(clientX, clientY) {
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
  const raycaster = new THREE.Raycaster();
  raycaster.setFromCamera(ndc, camera);
  return raycaster;
}
export function toScreen(p) {
  return screenProjector()(p);
}
/**
 * toScreen for many points under the camera as it is now: the canvas's box and the camera's
 * matrices read once, no object made per point (snapping and oversketch tests project every
 * point of every curve: with a Vector3 and a layout read per point, 12 ms at 40 strokes).
 */
export function screenProjector() {
  const rect = canvas.getBoundingClientRect();
  const m = new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse).elements;
  return (p) => {
    const [x, y, z] = p;
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    const sx = (m[0] * x + m[4] * y + m[8] * z + m[12]) / w;
    const sy = (m[1] * x + m[5] * y + m[9] * z + m[13]) / w;
    return [rect.left + ((sx + 1) / 2) * rect.width, rect.top + ((1 - sy) / 2) * rect.height];
  };
}
/** The size of a screen pixel, in mm, at the depth of point p. */
export function millimetresPerPixel(p) {
  const depth = new THREE.Vector3(...p).applyMatrix4(camera.matrixWorldInverse).z;
  const height = canvas.getBoundingClientRect().height || 1;
  if (isOrthographic()) return (camera.top - camera.bottom) / camera.zoom / height;
  return (2 * Math.abs(depth) * Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2)) / height;
}
export function onPlane(raycaster, plane) {
  const p = new THREE.Plane().setFromNormalAndCoplanarPoint(new THREE.Vector3(...plane.normal).normalize(), new THREE.Vector3(...plane.origin));
  return raycaster.ray.intersectPlane(p, new THREE.Vector3());
}
export function onSurface(raycaster) {
  const hits = raycaster.intersectObjects(surfaceGroup.children.filter((o) => o.isMesh), false);
  return hits.length ? hits[0] : null;
}
