// Where a stroke goes (docs/studio.md § A plane at a picked surface point, § Strokes in 3D, step
// 2): the sketch plane chosen in the toolbar, the plane placed at a picked surface point, the
// mirror plane, the sheet a planar stroke sweeps along its normal (a stroke in 3D between two
// views), snapping of a stroke's ends, and the stroke an oversketch redraws.
import * as THREE from 'three';
import { curvePolyline } from './nurbs.js';
import { $, showMessage } from './ui.js';
import { doc } from './store.js';
import { scene, camera, controls, curveGroup, dirty, sceneBox, screenProjector, millimetresPerPixel } from './scene.js';
import { PICK_PX } from './select.js';
import { gridNode } from './drafting.js';

const PLANE_NORMALS = { xy: [0, 0, 1], xz: [0, 1, 0], yz: [1, 0, 0] };
const PLANE_X = { xy: [1, 0, 0], xz: [1, 0, 0], yz: [0, 1, 0] };
// "plane at a picked surface point": the first press on a surface places the plane there (its
// normal the surface's), the strokes after it are drawn on it; a press off the surfaces keeps it.
const picked = { plane: null };
const pickedOutline = new THREE.LineLoop(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0x8fd0ff, depthTest: false }));
pickedOutline.renderOrder = 3;
pickedOutline.visible = false;
scene.add(pickedOutline);
/** The plane placed at a picked surface point, {origin, normal}, or null. */
export const pickedPlane = () => picked.plane;
export function placePickedPlane(hit) {
  const normal = hit.face.normal.clone().transformDirection(hit.object.matrixWorld).normalize();
  picked.plane = { origin: hit.point.toArray().map((x) => Number(x.toPrecision(12))), normal: normal.toArray().map((x) => Number(x.toPrecision(12))) };
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
export function sketchPlane() {
  const on = $('sketch-on').value;
  if (on === 'picked') return picked.plane;
  const offset = Number($('sketch-offset').value) || 0;
  if (on === 'view') {
    const normal = camera.position.clone().sub(controls.target).normalize();
    return { origin: controls.target.toArray(), normal: normal.toArray() };
  }
  if (!PLANE_NORMALS[on]) return null;
  const n = PLANE_NORMALS[on];
  return { origin: n.map((c) => c * offset), normal: n, x_axis: PLANE_X[on] };
}

/**
 * The plane new strokes are mirrored in, {origin, normal}, or null: x, y or z = the "at" value, or
 * the plane placed at a picked surface point.
 */
export function mirrorPlane() {
  const axis = $('mirror').value;
  if (!axis) return null;
  if (axis === 'picked') {
    if (!picked.plane) showMessage('no plane is placed yet: sketch "on a plane at a picked surface point" and click a surface first', true);
    return picked.plane;
  }
  const normal = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] }[axis];
  const at = Number($('mirror-at').value) || 0;
  return { origin: normal.map((c) => c * at), normal };
}

/**
 * Strokes in 3D between two views: a stroke drawn on a plane in one view is the shadow of the 3D
 * curve along that plane's normal; drawn again from another view, each pointer ray meets the
 * sheet swept by the first curve along the normal, and the meeting point is the 3D point. In the
 * plane's coordinates the ray is a line: its crossing with the curve's polyline gives the curve
 * point, and the ray's point above it the depth. Of several crossings the one nearest the
 * previous ink point is taken (the first: nearest the eye).
 */
export function extrusionOf(name) {
  const stroke = (doc.recipe.strokes || {})[name];
  const curve = doc.curves.get(name);
  if (!stroke || !stroke.plane || !curve) return null;
  const n = new THREE.Vector3(...(stroke.plane.normal || new THREE.Vector3(...stroke.plane.x_axis).cross(new THREE.Vector3(...stroke.plane.y_axis)).toArray())).normalize();
  const polyline = curvePolyline(curve, 400);
  return { name, normal: n, polyline };
}
export function onExtrusion(ray, sheet, previous) {
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
/** A polyline's length on the screen, in pixels (`toScreen`: a projector already made, or one made here). */
export function screenLength(points, toScreen = screenProjector()) {
  let length = 0;
  for (let i = 1; i < points.length; i++) {
    const a = toScreen(points[i - 1]);
    const b = toScreen(points[i]);
    length += Math.hypot(b[0] - a[0], b[1] - a[1]);
  }
  return length;
}
/** The stroke's end point snapped: to a curve end, else a curve, else a node of the grid drawn; or null. */
export function snapEnd(p) {
  const toScreen = screenProjector();
  const s = toScreen(p);
  let best = null;
  for (const e of curveEnds()) {
    const q = toScreen(e.p);
    const d = Math.hypot(q[0] - s[0], q[1] - s[1]);
    if (d < SNAP_PX && (!best || d < best.d)) best = { d, p: e.p, to: `${e.name}.${e.at}` };
  }
  if (best) return best;
  const x = [0, 0, 0];
  for (const [name] of doc.curves) {
    const pos = curveGroup.getObjectByName(name)?.geometry.getAttribute('position').array;
    if (!pos) continue;
    for (let k = 0; k < pos.length / 3; k++) {
      x[0] = pos[3 * k];
      x[1] = pos[3 * k + 1];
      x[2] = pos[3 * k + 2];
      const q = toScreen(x);
      const d = Math.hypot(q[0] - s[0], q[1] - s[1]);
      if (d < PICK_PX && (!best || d < best.d)) best = { d, p: x.slice(), to: name };
    }
  }
  if (best) return best;
  // the grid drawn on the sketch plane, at the spacing shown (an invisible 10 mm grid moved a
  // stroke end by 5 mm, issue #40); in the plane's own axes, the offset along its normal kept
  const g = gridNode(p);
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
export function oversketchTarget(points) {
  const strokes = doc.recipe.strokes || {};
  const toScreen = screenProjector();
  const a = points[0];
  const b = points[points.length - 1];
  const ink = screenLength(points, toScreen);
  const ends = [a, b].map((x) => ({ x, s: toScreen(x), reach: SNAP_PX * millimetresPerPixel(x) }));
  for (const [name, stroke] of Object.entries(strokes)) {
    const q = stroke.points;
    if (!Array.isArray(q) || q.length < 4) continue;
    // the nearest point on the screen of those near in space (tested first: it needs no projection)
    const near = ({ x, s, reach }) => {
      let best = { d: Infinity, i: -1 };
      q.forEach((p, i) => {
        if (!(Math.hypot(p[0] - x[0], p[1] - x[1], p[2] - x[2]) < reach)) return;
        const t = toScreen(p);
        const d = Math.hypot(t[0] - s[0], t[1] - s[1]);
        if (d < best.d) best = { d, i };
      });
      return best;
    };
    const ia = near(ends[0]);
    const ib = near(ends[1]);
    const endsFree = (i) => i > 1 && i < q.length - 2;
    if (!(ia.d < SNAP_PX && ib.d < SNAP_PX && Math.abs(ia.i - ib.i) > 2 && endsFree(ia.i) && endsFree(ib.i))) continue;
    // Both the ink and the part it redraws longer on the screen than twice the reach: else the
    // ends' nearness says nothing (zoomed out, strokes 35 mm apart were 11 px apart and 13 px
    // long, and each new one was taken for an oversketch of its neighbour, issue #40).
    const part = q.slice(Math.min(ia.i, ib.i), Math.max(ia.i, ib.i) + 1);
    if (ink >= 2 * SNAP_PX && screenLength(part, toScreen) >= 2 * SNAP_PX) return { name, from: ia.i, to: ib.i };
  }
  return null;
}
