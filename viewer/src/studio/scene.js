// The scene the studio draws into: renderer, cameras (perspective or orthographic) and orbit
// controls, lights, the groups each tool fills (surfaces, curves, handles, ink), the render loop,
// the standard views, and the pointer's geometry (rays, screen points, a pixel's size in
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
export const inkGroup = new THREE.Group();
scene.add(surfaceGroup, curveGroup, handleGroup, inkGroup);

// A render is asked for with `dirty()` and done in the next animation frame: input handlers run
// before it in the same frame, so ink drawn in a pointer event shows in that frame.
const loop = { needsRender: false, lastFrameAt: null, afterRender: [] };
export function dirty(then) {
  if (then) loop.afterRender.push(then);
  loop.needsRender = true;
}
/** Whether a render was asked for and not yet done. */
export const renderPending = () => loop.needsRender;
function frame(now) {
  if (state.dragging && loop.lastFrameAt !== null) metrics.frames.push(now - loop.lastFrameAt);
  loop.lastFrameAt = state.dragging ? now : null;
  if (loop.needsRender) {
    loop.needsRender = false;
    key.position.copy(camera.position).add(new THREE.Vector3(300, 200, 800));
    key.target.position.copy(controls.target);
    renderer.render(scene, camera);
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
  const rect = canvas.getBoundingClientRect();
  const v = new THREE.Vector3(...p).project(camera);
  return [rect.left + ((v.x + 1) / 2) * rect.width, rect.top + ((1 - v.y) / 2) * rect.height];
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
