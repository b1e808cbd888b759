// The Select tool (docs/studio.md, step 3): a click picks the curve nearest the pointer on the
// screen, else the surface or model under it; Shift-click adds to (or removes from) the selection,
// whose order is the order the builds take their curves in.
import { $, showMessage } from './ui.js';
import { doc, state, selected } from './store.js';
import { curveGroup, toScreen, pointerRay, onSurface } from './scene.js';
import { rebuildSurfaces, rebuildCurves } from './display.js';
import { rebuildHandles } from './handles.js';
import { showPanels } from './panels.js';

export const PICK_PX = 8;
export function pick(clientX, clientY) {
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
export function select(item, add) {
  if (!item) state.selection = add ? state.selection : [];
  else if (add) {
    const i = state.selection.findIndex((s) => s.kind === item.kind && s.name === item.name);
    if (i >= 0) state.selection.splice(i, 1);
    else state.selection.push({ kind: item.kind, name: item.name });
  } else state.selection = [{ kind: item.kind, name: item.name }];
  const { selection } = state;
  $('selection').textContent = selection.length ? selection.map((s, i) => `${i + 1}. ${s.kind} ${s.name}`).join('\n') : 'nothing selected';
  rebuildCurves();
  rebuildSurfaces();
  rebuildHandles();
  showPanels();
}

/** The surface an operation applies to: the selected one, or the only one shown. */
export function targetSurface() {
  const chosen = selected('surface');
  if (chosen.length === 1) return chosen[0];
  if (!chosen.length && doc.surfaces.size === 1) return [...doc.surfaces.keys()][0];
  showMessage('select one surface first (click it with the Select tool)', true);
  return null;
}
