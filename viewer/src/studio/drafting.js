// Drafting aids (issue #40 item 4; docs/studio.md § Drafting aids): the grid drawn on the sketch
// plane at a spacing that follows the zoom, which is the spacing stroke ends snap to and is shown
// in the status line; the snap target shown under the pointer while sketching; the pointer's
// coordinates; the orthographic camera; an underlay image (a side-view photo, a package drawing)
// placed on a plane. The underlay stays in this browser (localStorage), never sent to the kernel.
import * as THREE from 'three';
import { $, showMessage } from './ui.js';
import { scene, canvas, controls, dirty, addOverlayPainter, overlayDirty, pointerRay, onPlane, onSurface, millimetresPerPixel, isOrthographic, setOrthographic } from './scene.js';

// ------------------------------------------------------------------------------ the plane's frame
/** Where the grid lies: set by wireDrafting (the sketch plane, which sketch_geometry.js owns). */
const source = { plane: () => null };

/** The plane's frame {o, n, ex, ey} (THREE vectors); the XY plane when there is no plane. */
function frameOf(plane) {
  const o = new THREE.Vector3(...(plane ? plane.origin : [0, 0, 0]));
  const n = new THREE.Vector3(...(plane ? plane.normal : [0, 0, 1])).normalize();
  const ex = plane && plane.x_axis ? new THREE.Vector3(...plane.x_axis) : new THREE.Vector3(1, 0, 0);
  if (!(plane && plane.x_axis) && Math.abs(ex.dot(n)) > 0.9) ex.set(0, 1, 0);
  ex.sub(n.clone().multiplyScalar(ex.dot(n))).normalize();
  const ey = n.clone().cross(ex);
  return { o, n, ex, ey };
}
const currentFrame = () => frameOf(source.plane());

// ------------------------------------------------------------------------------ the grid
const GRID_MIN_PX = 14; // the smallest cell drawn, in screen pixels
const GRID_CELLS = 40; // cells each way from the centre
const MAJOR_EVERY = 5;
const grid = { spacing: 10, centre: [0, 0], lines: null, major: null, frameKey: '' };
const minorMaterial = new THREE.LineBasicMaterial({ color: 0x3d434c, depthWrite: false });
const majorMaterial = new THREE.LineBasicMaterial({ color: 0x545c68, depthWrite: false });
const axisMaterial = new THREE.LineBasicMaterial({ color: 0x6b7686, depthWrite: false });
const gridGroup = new THREE.Group();
// drawn first and without depth writes, so a surface lying in the plane covers it
gridGroup.renderOrder = -1;
scene.add(gridGroup);

/** The spacing (mm) of 1, 2 or 5 x 10^k whose cell is at least GRID_MIN_PX on the screen at `p`. */
export function spacingAt(p) {
  const wanted = GRID_MIN_PX * millimetresPerPixel(p);
  const decade = 10 ** Math.floor(Math.log10(wanted));
  for (const m of [1, 2, 5, 10]) if (m * decade >= wanted * (1 - 1e-12)) return m * decade;
  return 10 * decade;
}

/** The grid's spacing (mm): the one drawn and snapped to. */
export const gridSpacing = () => grid.spacing;

/** The grid node nearest p in the plane's own coordinates (the normal coordinate kept), as [x, y, z]. */
export function gridNode(p) {
  const { o, n, ex, ey } = currentFrame();
  const d = new THREE.Vector3(...p).sub(o);
  const s = grid.spacing;
  const a = Math.round(d.dot(ex) / s) * s;
  const b = Math.round(d.dot(ey) / s) * s;
  const q = o.clone().addScaledVector(ex, a).addScaledVector(ey, b).addScaledVector(n, d.dot(n));
  return q.toArray();
}

function segmentsGeometry(list) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(list, 3));
  return g;
}

/** Redraws the grid on the plane around the view's target, at the spacing the zoom asks for. */
export function updateGrid() {
  const f = currentFrame();
  const target = controls.target.clone();
  const onIt = target.clone().sub(f.n.clone().multiplyScalar(target.clone().sub(f.o).dot(f.n)));
  const spacing = spacingAt(onIt.toArray());
  const major = spacing * MAJOR_EVERY;
  const d = onIt.clone().sub(f.o);
  const centre = [Math.round(d.dot(f.ex) / major) * major, Math.round(d.dot(f.ey) / major) * major];
  const key = [f.o, f.n, f.ex].map((v) => v.toArray().join(',')).join(';');
  if (spacing === grid.spacing && centre[0] === grid.centre[0] && centre[1] === grid.centre[1] && key === grid.frameKey && grid.lines) return;
  grid.spacing = spacing;
  grid.centre = centre;
  grid.frameKey = key;
  for (const child of [...gridGroup.children]) {
    child.geometry.dispose();
    gridGroup.remove(child);
  }
  const at = (a, b) => f.o.clone().addScaledVector(f.ex, a).addScaledVector(f.ey, b).toArray();
  const half = GRID_CELLS * spacing;
  const minor = [];
  const majors = [];
  const axes = [];
  for (let k = -GRID_CELLS; k <= GRID_CELLS; k++) {
    const a = centre[0] + k * spacing;
    const b = centre[1] + k * spacing;
    const onAxisA = Math.abs(a) < spacing / 2;
    const onAxisB = Math.abs(b) < spacing / 2;
    const isMajorA = Math.abs(a / major - Math.round(a / major)) < 1e-9;
    const isMajorB = Math.abs(b / major - Math.round(b / major)) < 1e-9;
    (onAxisA ? axes : isMajorA ? majors : minor).push(...at(a, centre[1] - half), ...at(a, centre[1] + half));
    (onAxisB ? axes : isMajorB ? majors : minor).push(...at(centre[0] - half, b), ...at(centre[0] + half, b));
  }
  for (const [list, material] of [
    [minor, minorMaterial],
    [majors, majorMaterial],
    [axes, axisMaterial],
  ]) {
    if (!list.length) continue;
    const lines = new THREE.LineSegments(segmentsGeometry(list), material);
    lines.renderOrder = -1;
    gridGroup.add(lines);
  }
  grid.lines = true;
  gridGroup.visible = $('show-grid').checked;
  $('grid-spacing').textContent = `grid ${formatMm(spacing)} mm`;
  dirty();
}

function formatMm(x) {
  return Number(x.toPrecision(6)).toString();
}

// ------------------------------------------------------------------------------ snap marker and cursor
// drawn on the view's overlay (scene.js): showing it as the pointer moves renders no scene
const snapShown = { p: null };
addOverlayPainter((ctx, at) => {
  if (!snapShown.p) return;
  const [x, y] = at(snapShown.p);
  ctx.strokeStyle = '#ffd166';
  ctx.lineWidth = 2;
  ctx.beginPath();
  ctx.arc(x, y, 4, 0, 2 * Math.PI);
  ctx.stroke();
});

/** Shows (or hides, with null) where a stroke end would snap: a ring 10 px wide. */
export function showSnap(target) {
  if (!target) {
    if (snapShown.p) overlayDirty();
    snapShown.p = null;
    $('snap-target').textContent = '';
    return;
  }
  snapShown.p = target.p;
  $('snap-target').textContent = `snap: ${target.to === 'grid' ? 'grid node' : target.to}`;
  overlayDirty();
}

/** The point under the pointer: on the sketch plane when there is one, else on a surface, else on XY. */
export function pointerPoint(clientX, clientY) {
  const ray = pointerRay(clientX, clientY);
  const plane = source.plane();
  if (plane) {
    const p = onPlane(ray, plane);
    if (p) return p.toArray();
  }
  const hit = onSurface(ray);
  if (hit) return hit.point.toArray();
  const p = onPlane(ray, { origin: [0, 0, 0], normal: [0, 0, 1] });
  return p ? p.toArray() : null;
}

/** The pointer's coordinates in the status line, to a tenth of the grid's spacing. */
export function showCursor(p) {
  if (!p) {
    $('cursor').textContent = '';
    return;
  }
  const digits = Math.max(0, Math.min(6, 1 - Math.floor(Math.log10(grid.spacing))));
  $('cursor').textContent = `x ${p[0].toFixed(digits)}  y ${p[1].toFixed(digits)}  z ${p[2].toFixed(digits)} mm`;
}

// ------------------------------------------------------------------------------ underlay image
const UNDERLAY_KEY = 'clayform.studio.underlay';
const underlay = { mesh: null, settings: null, image: null };

/**
 * Places an image on a plane: `settings` = {image (a data: URL), plane ('xy', 'xz', 'yz'),
 * centre [a, b] (mm, in the plane's own axes), width (mm), opacity (0..1)}. The height follows the
 * image's aspect. Kept in localStorage (when it fits), so a reload keeps it.
 */
export function placeUnderlay(settings) {
  return new Promise((resolve, reject) => {
    const image = new Image();
    image.onload = () => {
      removeUnderlay(false);
      const texture = new THREE.Texture(image);
      texture.colorSpace = THREE.SRGBColorSpace;
      texture.needsUpdate = true;
      const height = (settings.width * image.height) / image.width;
      const material = new THREE.MeshBasicMaterial({ map: texture, transparent: true, opacity: settings.opacity, depthWrite: false, side: THREE.DoubleSide });
      const mesh = new THREE.Mesh(new THREE.PlaneGeometry(settings.width, height), material);
      const f = frameOf(UNDERLAY_PLANES[settings.plane]);
      const basis = new THREE.Matrix4().makeBasis(f.ex, f.ey, f.n);
      mesh.quaternion.setFromRotationMatrix(basis);
      mesh.position.copy(f.o).addScaledVector(f.ex, settings.centre[0]).addScaledVector(f.ey, settings.centre[1]);
      mesh.renderOrder = -2;
      mesh.name = 'underlay';
      scene.add(mesh);
      underlay.mesh = mesh;
      underlay.settings = { ...settings, height };
      underlay.image = settings.image;
      // the form shows what is placed (a reload restores it from localStorage)
      $('underlay-plane').value = settings.plane;
      $('underlay-x').value = settings.centre[0];
      $('underlay-y').value = settings.centre[1];
      $('underlay-width').value = settings.width;
      $('underlay-opacity').value = settings.opacity;
      try {
        localStorage.setItem(UNDERLAY_KEY, JSON.stringify(settings));
      } catch {
        showMessage('the underlay is shown, but too large to keep for a reload (browser storage is full): place it again after a reload', 'warning');
      }
      dirty();
      resolve(underlay.settings);
    };
    image.onerror = () => reject(new Error('the underlay image could not be read: choose a PNG, JPEG or WebP file'));
    image.src = settings.image;
  });
}
const UNDERLAY_PLANES = { xy: { origin: [0, 0, 0], normal: [0, 0, 1], x_axis: [1, 0, 0] }, xz: { origin: [0, 0, 0], normal: [0, -1, 0], x_axis: [1, 0, 0] }, yz: { origin: [0, 0, 0], normal: [1, 0, 0], x_axis: [0, 1, 0] } };

/** Removes the underlay (and forgets it for reloads, unless `forget` is false). */
export function removeUnderlay(forget = true) {
  if (underlay.mesh) {
    scene.remove(underlay.mesh);
    underlay.mesh.geometry.dispose();
    underlay.mesh.material.map.dispose();
    underlay.mesh.material.dispose();
  }
  underlay.mesh = null;
  underlay.settings = null;
  if (forget) underlay.image = null;
  if (forget) localStorage.removeItem(UNDERLAY_KEY);
  dirty();
}

/** The underlay's settings with its height (mm), without the image, or null. */
export function underlaySettings() {
  if (!underlay.settings) return null;
  const { image, ...rest } = underlay.settings;
  return { ...rest, imageBytes: image.length };
}

function underlayFromForm(image) {
  const width = Number($('underlay-width').value);
  if (!(width > 0)) throw new Error(`the underlay's width ${$('underlay-width').value} mm must be a positive number`);
  return { image, plane: $('underlay-plane').value, centre: [Number($('underlay-x').value) || 0, Number($('underlay-y').value) || 0], width, opacity: Number($('underlay-opacity').value) };
}

// ------------------------------------------------------------------------------ wiring
/** Wires the drafting aids: `plane` gives the sketch plane (sketch_geometry.js's sketchPlane). */
export function wireDrafting({ plane, snap }) {
  source.plane = plane;
  controls.addEventListener('change', updateGrid);
  for (const id of ['sketch-on', 'sketch-offset']) $(id).addEventListener('input', updateGrid);
  $('show-grid').addEventListener('change', () => {
    gridGroup.visible = $('show-grid').checked;
    dirty();
  });
  $('projection').addEventListener('click', () => {
    setOrthographic(!isOrthographic());
    $('projection').textContent = isOrthographic() ? 'Ortho' : 'Persp';
    updateGrid();
  });
  canvas.addEventListener('pointermove', (e) => {
    const p = pointerPoint(e.clientX, e.clientY);
    showCursor(p);
    const sketching = document.body.dataset.tool === 'sketch' && $('snap').checked && !e.altKey;
    showSnap(sketching && p ? snap(p) : null);
  });
  canvas.addEventListener('pointerleave', () => {
    showCursor(null);
    showSnap(null);
  });
  $('underlay-file').addEventListener('change', () => {
    const file = $('underlay-file').files[0];
    if (!file) return;
    const reader = new FileReader();
    reader.onload = () =>
      Promise.resolve()
        .then(() => placeUnderlay(underlayFromForm(reader.result)))
        .then((s) => showMessage(`underlay placed on ${s.plane.toUpperCase()}: ${formatMm(s.width)} x ${formatMm(s.height)} mm`))
        .catch((err) => showMessage(err.message, 'error'));
    reader.readAsDataURL(file);
  });
  for (const id of ['underlay-plane', 'underlay-x', 'underlay-y', 'underlay-width', 'underlay-opacity'])
    $(id).addEventListener('change', () => {
      if (!underlay.image) return;
      try {
        placeUnderlay(underlayFromForm(underlay.image)).catch((err) => showMessage(err.message, 'error'));
      } catch (err) {
        showMessage(err.message, 'error');
      }
    });
  $('underlay-remove').addEventListener('click', () => removeUnderlay());
  const kept = JSON.parse(localStorage.getItem(UNDERLAY_KEY) || 'null');
  if (kept && kept.image) placeUnderlay(kept).catch(() => localStorage.removeItem(UNDERLAY_KEY));
  updateGrid();
}
