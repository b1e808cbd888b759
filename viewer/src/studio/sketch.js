// The Sketch tool (docs/studio.md, step 2, § Corners, mirror and restyling while drawing): ink
// drawn under the pointer on the sketch plane, on a surface or over a planar stroke from another
// view, then written as a stroke: the kernel's fit first (a stroke that turns sharply is split at
// its corners into pieces), ends snapped, mirrored when asked; an oversketch redraws part of a
// stroke; with "restyle while drawing" the ink is the style's target as it is drawn. The ink stays
// until the kernel's fitted curve replaces it.
import * as names from './recipe_edits.js';
import { $, showMessage } from './ui.js';
import { doc, selected, edit, dragEdit, commandOf, send, cancelDrag, newGroup } from './store.js';
import { canvas, controls, addOverlayPainter, overlayDirty, pointerRay, onPlane, onSurface, toScreen } from './scene.js';
import { pickedPlane, placePickedPlane, sketchPlane, mirrorPlane, extrusionOf, onExtrusion, snapEnd, oversketchTarget, screenLength } from './sketch_geometry.js';
import { activeStyle, liveTarget } from './style.js';

// ink: the stroke being drawn {points: [[x,y,z]], plane, over, line, pointerId, live};
// pending: ink shown until the kernel's fitted curve replaces it, {label, line};
// lastLive: the last stroke drawn as a live style target {style, name, group, updates}.
// A line is the ink's points; every line is drawn on the view's overlay (scene.js), not in the
// scene: a pointer move draws the overlay alone.
const sketch = { ink: null, pending: [], lastLive: null };
const INK_COLOUR = '#ffffff';
addOverlayPainter((ctx, at) => {
  const lines = sketch.pending.map((p) => p.line);
  if (sketch.ink) lines.push(sketch.ink.line);
  ctx.strokeStyle = INK_COLOUR;
  ctx.lineWidth = 1.5;
  ctx.lineJoin = 'round';
  for (const line of lines) {
    if (line.length < 2) continue;
    ctx.beginPath();
    line.forEach((p, k) => (k ? ctx.lineTo(...at(p)) : ctx.moveTo(...at(p))));
    ctx.stroke();
  }
});

/** Whether a stroke is being drawn. */
export const inking = () => !!sketch.ink;
/** The last stroke drawn as a live style target (for the test hook). */
export const lastLive = () => sketch.lastLive;

function pushInk(p) {
  const ink = sketch.ink;
  const last = ink.points[ink.points.length - 1];
  if (last && Math.hypot(p[0] - last[0], p[1] - last[1], p[2] - last[2]) < 1e-6) return; // no repeated point
  if (ink.points.length >= 4096) return;
  ink.points.push(p);
  overlayDirty();
}
function inkPoint(event) {
  const ink = sketch.ink;
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
/** The ink of a stroke command the kernel answered, removed (its fitted curve is drawn now). */
export function clearInk(command) {
  if (!command || !command.label || !command.label.startsWith('stroke')) return;
  const pendingInk = sketch.pending;
  const i = pendingInk.findIndex((p) => p.label === command.label);
  if (i < 0) return;
  pendingInk.splice(i, 1);
  overlayDirty();
}

function finishStroke(event) {
  const { live, points, line, plane, over } = sketch.ink;
  const pendingInk = sketch.pending;
  sketch.ink = null;
  if (points.length < 3) {
    overlayDirty();
    return;
  }
  const tolerance = Number($('stroke-tolerance').value) || 0.5; // mm: a stroke's tolerance_mm
  const dropInk = () => {
    const i = pendingInk.findIndex((p) => p.line === line);
    if (i >= 0) pendingInk.splice(i, 1);
    overlayDirty();
  };
  if (live) {
    // the live target's last update: the whole stroke, in the drawing's history entry
    cancelDrag();
    sketch.lastLive = live;
    const stroke = { points, tolerance_mm: tolerance };
    if (plane) stroke.plane = plane;
    const { changes, label } = liveTarget(live, stroke);
    pendingInk.push({ label, line });
    return send(commandOf(changes, label, 'stroke', live.group), event.timeStamp).then(({ reply }) => reply.op === 'error' && dropInk());
  }
  const redrawn = event.altKey || over ? null : oversketchTarget(points);
  if (redrawn) {
    const def = doc.recipe.strokes[redrawn.name];
    const q = def.points;
    const forward = redrawn.from < redrawn.to;
    const lo = Math.min(redrawn.from, redrawn.to);
    const hi = Math.max(redrawn.from, redrawn.to);
    const drawn = (forward ? points : [...points].reverse()).map((p) => p.slice());
    // The joins blended (issue #40): the new ink's ends moved onto the old stroke where it leaves
    // and rejoins it, fading over a fifth of the new ink (names.moveEnd), so the points have no
    // step there for the fit to chase; how far the ends moved is said.
    const gaps = [];
    if (lo > 0) {
      gaps.push(Math.hypot(...drawn[0].map((c, e) => c - q[lo - 1][e])));
      names.moveEnd(drawn, 0, q[lo - 1]);
    }
    if (hi + 1 < q.length) {
      gaps.push(Math.hypot(...drawn[drawn.length - 1].map((c, e) => c - q[hi + 1][e])));
      names.moveEnd(drawn, drawn.length - 1, q[hi + 1]);
    }
    const next = [...q.slice(0, Math.max(0, lo - 1)), ...drawn, ...q.slice(hi + 2)];
    const label = `stroke ${redrawn.name} (oversketch)`;
    pendingInk.push({ label, line });
    // a redrawn stroke may gain or lose corners: the kernel's fit says into how many pieces it splits
    fitOf(next, def.plane, def.tolerance_mm || tolerance).then((fit) => {
      if (!fit) return dropInk();
      const changes = [{ path: `strokes.${redrawn.name}.points`, value: next }];
      if (def.pieces || fit.pieces > 1) changes.push({ path: `strokes.${redrawn.name}.pieces`, value: fit.pieces, create: true });
      if (!fit.converged) changes.push({ path: `strokes.${redrawn.name}.accept_out_of_tolerance`, value: true, create: true });
      return edit(changes, label, 'stroke', event.timeStamp).then(({ reply }) => {
        if (reply.op === 'error') return dropInk();
        const joins = gaps.length ? `; its joins blended (the ends moved ${gaps.map((g) => `${g.toPrecision(2)} mm`).join(' and ')})` : '';
        if (!fit.converged) showMessage(kept(redrawn.name, fit, def.tolerance_mm || tolerance) + joins, 'warning');
        else if (gaps.some((g) => g > (def.tolerance_mm || tolerance))) showMessage(`stroke ${redrawn.name} redrawn${joins}`);
      });
    });
    return;
  }
  if ($('snap').checked && !event.altKey && !over) {
    // A snap is a small correction: an end moves by at most a quarter of the ink's length on
    // the screen (zoomed out, a 13 px stroke had an end pulled 12 px onto its neighbour).
    const reach = 0.25 * screenLength(points);
    for (const end of [0, points.length - 1]) {
      const s = snapEnd(points[end]);
      const from = toScreen(points[end]);
      const to = s && toScreen(s.p);
      if (s && Math.hypot(to[0] - from[0], to[1] - from[1]) <= reach) names.moveEnd(points, end, s.p);
    }
  }
  if (over) {
    // the 3D stroke takes the planar one's place (its name, so what was built from it follows)
    const label = `stroke ${over.name} (3D)`;
    pendingInk.push({ label, line });
    edit({ path: `strokes.${over.name}`, value: { points, tolerance_mm: tolerance } }, label, 'stroke', event.timeStamp);
    return;
  }
  const name = names.free(doc.recipe, 's');
  const stroke = { points, tolerance_mm: tolerance };
  if (plane) stroke.plane = plane;
  const label = `stroke ${name}`;
  pendingInk.push({ label, line });
  // The kernel's fit first: a stroke that turns sharply is split at its corners into pieces
  // NAME.1 .. NAME.N (the recipe's "pieces"), one curve each.
  fitOf(points, plane, tolerance).then((fit) => {
    if (!fit) return dropInk();
    const pieces = fit.pieces;
    if (pieces > 1) stroke.pieces = pieces;
    // Never thrown away (issue #40): a fit that misses the tolerance is kept as the best curve
    // the kernel found, marked accepted, and the stylist is told how far it is from the ink.
    if (!fit.converged) stroke.accept_out_of_tolerance = true;
    const changes = [{ path: `strokes.${name}`, value: stroke, create: true }];
    const mirror = mirrorPlane();
    if (mirror) {
      const curves = pieces > 1 ? Array.from({ length: pieces }, (_, k) => `${name}.${k + 1}`) : [name];
      curves.forEach((curve, k) => changes.push({ path: `curves.${name}_mirror${pieces > 1 ? `_${k + 1}` : ''}`, value: { mirror: { curve, plane: mirror } }, create: true }));
    }
    return edit(changes, label, 'stroke', event.timeStamp).then(({ reply }) => {
      if (reply.op === 'error') return dropInk();
      if (!fit.converged) showMessage(kept(name, fit, tolerance), 'warning');
    });
  });
}

/** What the stylist is told of a stroke kept beyond its tolerance. */
function kept(name, fit, tolerance) {
  return `stroke ${name} kept: its best fit is ${fit.max_deviation_mm.toPrecision(3)} mm from the ink at most, beyond its tolerance of ${tolerance} mm. Keep it, or undo (Ctrl+Z) and draw it again (or raise tol)`;
}

/** The kernel's fit of the stroke: {pieces (split at its corners), converged, max_deviation_mm}, or null when it cannot. */
function fitOf(points, plane, tolerance) {
  const command = { op: 'fit', points, tolerance_mm: tolerance };
  if (plane) command.plane = plane;
  return send(command).then(({ reply }) => (reply.op === 'fit' ? reply : null));
}

// ------------------------------------------------------------------------------ pointer input
/** A press with the Sketch tool: ink starts (or, on a picked plane, the plane is placed). */
export function sketchDown(event) {
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
  if (on === 'picked' && (!pickedPlane() || event.shiftKey)) {
    const hit = onSurface(pointerRay(event.clientX, event.clientY));
    if (hit && hit.face) placePickedPlane(hit);
    else showMessage('press on a surface to place the plane there', true);
    event.stopImmediatePropagation();
    return;
  }
  const plane = on === 'surface' || on === 'over' ? null : sketchPlane();
  const points = [];
  sketch.ink = { points, plane, over, line: points, pointerId: event.pointerId };
  // Restyle while drawing: the stroke is the selected style's new target from its first
  // points on, each pointer move one drag update (newest wins), the release the last.
  const style = !over && $('style-live').checked ? activeStyle() : null;
  if (style) sketch.ink.live = { style, name: names.free(doc.recipe, 's'), group: newGroup(), updates: 0 };
  const p = inkPoint(event);
  if (p) pushInk(p);
  canvas.setPointerCapture(event.pointerId);
  controls.enabled = false;
  event.stopImmediatePropagation();
}
/** A pointer move while drawing: the ink (every coalesced event), and a live target's update. */
export function sketchMove(event) {
  const ink = sketch.ink;
  const events = event.getCoalescedEvents ? event.getCoalescedEvents() : [event];
  for (const e of events.length ? events : [event]) {
    const p = inkPoint(e);
    if (p) pushInk(p);
  }
  if (ink.live && ink.points.length >= 4) {
    const live = ink.live;
    const stroke = { points: ink.points.slice(), tolerance_mm: Number($('stroke-tolerance').value) || 0.5 };
    if (ink.plane) stroke.plane = ink.plane;
    dragEdit(() => ({ ...liveTarget(live, stroke), group: live.group }), event.timeStamp);
  }
}
/** The release: the stroke written. */
export function sketchUp(event) {
  finishStroke(event);
  controls.enabled = true;
}
