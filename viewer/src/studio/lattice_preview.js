// The lattice drag preview: while a lattice point is dragged, each surface that the lattice alone
// deforms is drawn from the FFD of its parent's samples (ffd_preview.js: the exact result's points
// at those parameters) in the frame of the pointer move; the kernel's exact nets follow, and
// replace the picture once the drag is let go and its last update is answered.
import { surfaceGrid } from './nurbs.js';
import { withMove } from './recipe_edits.js';
import { stepLatticePoints } from './lattice_math.js';
import { prepareFfd, applyFfd } from './ffd_preview.js';
import { doc, metrics, busy } from './store.js';
import { surfaceGroup, dirty } from './scene.js';
import { surfaceResolution, gridGeometry } from './meshes.js';
import { rebuildSurfaces } from './display.js';
import { showLatticeFigures } from './lattice.js';

/** Surface name -> {prepared, geometry, step, points}: the pictures drawn while a drag lasts. */
export const previews = new Map();
const preview = { ending: false }; // let go: the picture stays until the last update is answered

export function startPreview(h) {
  previews.clear();
  preview.ending = false;
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
export function showPreview(h, to, inputAt) {
  if (!previews.size) return;
  let live = [Infinity, -Infinity];
  for (const p of previews.values()) {
    const moved = { ...p.step, moves: withMove(p.step.moves || [], h.index, to) };
    const position = p.geometry.getAttribute('position');
    const normal = p.geometry.getAttribute('normal');
    const points = stepLatticePoints(moved);
    const ratio = applyFfd(p.prepared, points, position.array, normal.array);
    p.points = points;
    live = [Math.min(live[0], ratio[0]), Math.max(live[1], ratio[1])];
    position.needsUpdate = true;
    normal.needsUpdate = true;
    p.geometry.computeBoundingSphere();
  }
  if (!surfaceGroup.children.some((o) => o.geometry && o.geometry.userData.preview)) rebuildSurfaces();
  showLatticeFigures(live);
  dirty((drawnAt) => metrics.preview.push({ at: drawnAt, ms: drawnAt - inputAt }));
}
export function endPreview() {
  if (!previews.size) return;
  preview.ending = true;
  if (!busy()) finishPreview();
}
export function finishPreview() {
  preview.ending = false;
  const geometries = [...previews.values()].map((p) => p.geometry);
  previews.clear();
  rebuildSurfaces();
  geometries.forEach((g) => g.dispose());
}
/** Whether the drag was let go and its picture waits for the kernel's last answer. */
export const previewEnding = () => preview.ending;
