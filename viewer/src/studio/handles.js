// The Edit tool's handles (docs/studio.md, steps 7 and 8): the selected curve's control points (a
// style's target, or any curve) and the control points of the lattices on the selected surface,
// picked and dragged (on a locked axis or plane, or in the view plane, scaled by the strength), or
// typed. A lattice drag is drawn by the page (lattice_preview.js) while the kernel checks each
// update without sending nets; the release sends the last position with nets.
import * as THREE from 'three';
import * as names from './recipe_edits.js';
import { stepLatticePoints, latticeCounts } from './lattice_math.js';
import { $, body, showMessage } from './ui.js';
import { doc, state, commandOf, dragEdit, send, cancelDrag, newGroup } from './store.js';
import { canvas, camera, controls, handleGroup, disposeGroup, dirty, pointerRay, toScreen, millimetresPerPixel } from './scene.js';
import { previews, startPreview, showPreview, endPreview } from './lattice_preview.js';
import { latticesShown } from './lattice.js';

// handles: {kind: 'curve' | 'lattice', name, index, p: [x,y,z]}; active: the one last grabbed;
// drag: {handle, start, group, last} while one is held
const edit = { handles: [], active: null, drag: null };
const handleMaterial = new THREE.PointsMaterial({ color: 0x7cf0a0, size: 9, sizeAttenuation: false, depthTest: false });
const activeHandleMaterial = new THREE.PointsMaterial({ color: 0xffffff, size: 12, sizeAttenuation: false, depthTest: false });

/** The handles shown (for the test hook). */
export const handleList = () => edit.handles;

export function rebuildHandles() {
  disposeGroup(handleGroup);
  edit.handles = [];
  const handles = edit.handles;
  if (body.dataset.tool !== 'edit') {
    dirty();
    return;
  }
  for (const s of state.selection) {
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
  const active = edit.active;
  if (active) {
    const h = handles.find((x) => x.kind === active.kind && x.name === active.name && String(x.index) === String(active.index));
    if (h) {
      edit.active = { ...h, start: active.start };
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

function pickHandle(clientX, clientY) {
  let best = null;
  for (const h of edit.handles) {
    const q = toScreen(h.p);
    const d = Math.hypot(q[0] - clientX, q[1] - clientY);
    if (d < 10 && (!best || d < best.d)) best = { ...h, d };
  }
  return best;
}

/** Sine squared of 15 degrees: an axis closer than this to the line of sight is dragged by the pointer's height (dragTarget). */
const SIGHT_SIN2 = Math.sin(THREE.MathUtils.degToRad(15)) ** 2;

/**
 * Where a dragged point goes for the pointer at (x, y): on its lock's axis or plane, else in the
 * view plane. A locked axis or plane keeps the other coordinates exactly (they are copied, not
 * recomputed).
 */
function dragTarget(start, x, y, lock) {
  const raycaster = pointerRay(x, y);
  const s = new THREE.Vector3(...start);
  const axisIndex = { x: 0, y: 1, z: 2 }[lock];
  if (axisIndex !== undefined) {
    const d = new THREE.Vector3(...[0, 1, 2].map((e) => (e === axisIndex ? 1 : 0)));
    const r = raycaster.ray;
    const w0 = s.clone().sub(r.origin);
    const b = d.dot(r.direction);
    const out = start.slice();
    if (1 - b * b < SIGHT_SIN2) {
      // An axis near the line of sight (z in the Top view): the axis point closest to the ray
      // runs off to infinity as they turn parallel (a z-locked drag in the Top view threw a
      // lattice point to z = 857 mm, issue #40). Here the pointer's height on the screen moves
      // the point along the axis, a pixel's size at its depth per pixel, up towards the viewer.
      const towards = Math.sign(d.dot(camera.position.clone().sub(s))) || 1;
      out[axisIndex] = start[axisIndex] + towards * (toScreen(start)[1] - y) * millimetresPerPixel(start);
      return out;
    }
    // the point of the axis line closest to the ray
    out[axisIndex] = start[axisIndex] + (b * r.direction.dot(w0) - d.dot(w0)) / (1 - b * b);
    return out;
  }
  const kept = { yz: 0, xz: 1, xy: 2 }[lock];
  const viewNormal = camera.position.clone().sub(controls.target).normalize();
  let normal = viewNormal;
  if (kept !== undefined) {
    normal = new THREE.Vector3(...[0, 1, 2].map((e) => (e === kept ? 1 : 0)));
    // a plane seen edge-on (xy in the Front view): the view plane's point, then onto the plane
    if (Math.abs(normal.dot(raycaster.ray.direction)) < Math.sin(THREE.MathUtils.degToRad(5))) normal = viewNormal;
  }
  const p = raycaster.ray.intersectPlane(new THREE.Plane().setFromNormalAndCoplanarPoint(normal, s), new THREE.Vector3());
  if (!p) return null;
  const out = p.toArray();
  if (kept !== undefined) out[kept] = start[kept];
  return out;
}
/** Where a point grabbed at `start` goes for this pointer event: the lock's target, scaled by the strength; null off the lock. */
export function draggedTo(start, event) {
  const target = dragTarget(start, event.clientX, event.clientY, $('lattice-lock').value);
  if (!target) return null;
  const strength = Number($('lattice-strength').value) || 1;
  return start.map((c, i) => c + strength * (target[i] - c));
}

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
  return send(command, inputAt);
}

function showLatticePoint() {
  const h = edit.active;
  if (!h || h.kind !== 'lattice') return;
  $('lattice-point').textContent = `${h.name} point [${h.index.join(', ')}]`;
  ['x', 'y', 'z'].forEach((a, i) => {
    if (document.activeElement !== $(`lattice-${a}`)) $(`lattice-${a}`).value = Number(h.p[i].toFixed(4));
  });
}

// ------------------------------------------------------------------------------ pointer input
/** A press with the Edit tool: grabs the handle under the pointer; false when there is none. */
export function handleDown(event) {
  const h = pickHandle(event.clientX, event.clientY);
  if (!h) return false;
  edit.active = { ...h };
  edit.drag = { handle: h, start: h.p.slice(), group: newGroup() };
  if (h.kind === 'lattice') startPreview(h);
  state.dragging = true;
  canvas.setPointerCapture(event.pointerId);
  controls.enabled = false;
  event.stopImmediatePropagation();
  rebuildHandles();
  return true;
}
/** A pointer move while a handle is held; false when none is. */
export function handleMove(event) {
  const drag = edit.drag;
  if (!drag) return false;
  const to = draggedTo(drag.start, event);
  if (!to) return true;
  drag.last = to;
  if (drag.handle.kind === 'lattice') showPreview(drag.handle, to, event.timeStamp);
  moveHandle(drag.handle, to, event.timeStamp, false, drag.group);
  return true;
}
/** The release of a held handle: the last position, with the kernel's nets, in the drag's history entry; false when none is held. */
export function handleUp(event) {
  const d = edit.drag;
  if (!d) return false;
  edit.drag = null;
  state.dragging = false;
  controls.enabled = true;
  if (d.last) {
    cancelDrag();
    moveHandle(d.handle, d.last, event.timeStamp, 'drag-end', d.group);
  }
  endPreview();
  return true;
}

/** The lattice point's typed coordinates. */
export function wireHandles() {
  ['x', 'y', 'z'].forEach((a) =>
    $(`lattice-${a}`).addEventListener('change', () => {
      const active = edit.active;
      if (!active || active.kind !== 'lattice') return;
      const to = ['x', 'y', 'z'].map((c, i) => (c === a ? Number($(`lattice-${a}`).value) : active.p[i]));
      if (to.every(Number.isFinite)) moveHandle(active, to, performance.now(), true);
    }),
  );
}
