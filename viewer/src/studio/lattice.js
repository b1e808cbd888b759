// Lattices and the other space deformations (docs/studio.md, step 8): a Bézier or B-spline lattice
// placed around the selected surface or model, the lattice panel (the kernel's fold-free verdict
// and volume-ratio bounds, live det J while the page draws a drag), Shift-drag on a surface (direct
// manipulation), and the global taper, twist and bend with their sliders.
import * as names from './recipe_edits.js';
import { $, setSlider, sliderGroup } from './ui.js';
import { doc, state, selected, edit, dragEdit, commandOf, send, newGroup } from './store.js';
import { canvas, controls, pointerRay, onSurface } from './scene.js';
import { hitParameters } from './meshes.js';
import { draggedTo } from './handles.js';
import { select, targetSurface } from './select.js';
import { setTool } from './input.js';

/** The lattice steps that deform the selected surface (or every shown one when none is selected). */
export function latticesShown() {
  const out = [];
  const surfaces = doc.recipe.surfaces || {};
  const chosen = state.selection.filter((s) => s.kind === 'surface').map((s) => s.name);
  for (const [name, def] of Object.entries(surfaces)) {
    if (!def.deform || !doc.surfaces.has(name)) continue;
    if (chosen.length && !chosen.includes(name)) continue;
    const stack = (doc.recipe.deformations || {})[def.deform.deformation] || [];
    stack.forEach((step, i) => {
      if (step.kind === 'bezier_lattice' || step.kind === 'bspline_lattice') out.push({ deformation: def.deform.deformation, stepIndex: i, step });
    });
  }
  const models = state.selection.filter((s) => s.kind === 'model').map((s) => s.name);
  for (const [name, def] of Object.entries(doc.recipe.models || {})) {
    if (!def.deformation || (models.length && !models.includes(name)) || (chosen.length && !models.length)) continue;
    const stack = (doc.recipe.deformations || {})[def.deformation] || [];
    stack.forEach((step, i) => {
      if ((step.kind === 'bezier_lattice' || step.kind === 'bspline_lattice') && !out.some((o) => o.deformation === def.deformation)) out.push({ deformation: def.deformation, stepIndex: i, step });
    });
  }
  return out;
}

/** The lattice steps' fold-free and volume-ratio figures from the kernel's last answer (certified bounds of det J). */
export function showLatticeFigures(live) {
  const steps = doc.steps.filter((st) => st.kind === 'bezier_lattice' && 'fold_free' in st.figures);
  const kernel = steps.map((st) => `${st.figures.fold_free ? 'fold-free' : 'MAY FOLD'}, volume ratio ${st.figures.volume_ratio_min.toPrecision(3)} … ${st.figures.volume_ratio_max.toPrecision(3)}`).join('; ');
  $('lattice-figures').textContent = `${kernel ? `kernel: ${kernel}` : ''}${live ? `${kernel ? '\n' : ''}live, at the surface: volume ratio ${live[0].toPrecision(3)} … ${live[1].toPrecision(3)}` : ''}`;
}

function activeGlobal() {
  for (const s of selected('surface')) {
    const def = (doc.recipe.surfaces || {})[s];
    const stack = def && def.deform && (doc.recipe.deformations || {})[def.deform.deformation];
    if (stack && stack.length === 3 && stack[0].kind === 'taper') return { deformation: def.deform.deformation, parent: def.deform.surface };
  }
  return null;
}

/** The models a lattice step deforms, with their step: the lattices "keep the volume" applies to. */
function modelLattices() {
  const out = [];
  for (const [name, def] of Object.entries(doc.recipe.models || {})) {
    const stack = def.deformation && (doc.recipe.deformations || {})[def.deformation];
    const i = stack ? stack.findIndex((st) => st.kind === 'bezier_lattice' || st.kind === 'bspline_lattice') : -1;
    if (i >= 0) out.push({ model: name, deformation: def.deformation, stepIndex: i, step: stack[i] });
  }
  return out;
}

/** Each model's volume before and after its stack, and whether a keep held it (the kernel's figures). */
function showModelVolumes() {
  const figures = (doc.reply && doc.reply.model_figures) || {};
  const lines = [];
  for (const l of modelLattices()) {
    const f = figures[l.model];
    if (!f) continue;
    const kept = f.kept.find((k) => k.properties.includes('volume'));
    const change = f.volume_before_mm3 ? (f.volume_after_mm3 / f.volume_before_mm3 - 1) * 100 : 0;
    lines.push(`${l.model}: volume ${f.volume_before_mm3.toFixed(2)} → ${f.volume_after_mm3.toFixed(2)} mm³ (${change >= 0 ? '+' : ''}${change.toPrecision(3)} %)${kept ? `, kept: the other points corrected by up to ${kept.largest_correction_mm.toPrecision(3)} mm` : ''}`);
  }
  $('lattice-volume').textContent = lines.join('\n');
}

/** The Lattice and Taper/Twist/Bend panels, for the selection. */
export function showLatticePanels() {
  const lattices = latticesShown();
  $('lattice-panel').hidden = !lattices.length;
  if (lattices.length) {
    $('lattice-name').textContent = lattices.map((l) => l.deformation).join(', ');
    showLatticeFigures();
  }
  const models = modelLattices();
  $('lattice-keep').hidden = !models.length;
  $('lattice-keep-volume').checked = models.length > 0 && models.every((l) => (l.step.keep || []).includes('volume'));
  showModelVolumes();
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

// ------------------------------------------------------------------------------ direct manipulation
// Shift-press on a surface with the Edit tool: Hsu–Hughes–Kaufman direct manipulation. A cubic
// B-spline lattice of 3 x 3 x 1 cells around the surface is solved so that the surface point
// pressed goes where the pointer goes (the recipe's direct_manipulation step, refitted: a
// B-spline lattice's knot planes cross the surface off its iso-lines).
const pull = { drag: null }; // {surface, deformation, uv, start, group, last} while a point is pulled
export function startDirectManipulation(event) {
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
    { path: `surfaces.${result}`, value: { deform: { surface, deformation, composition: { mode: 'refit', relative_tolerance: 1e-4 } } }, create: true },
  ];
  send(commandOf(changes, `drag ${surface} at (${uv.map((x) => x.toPrecision(4))})`, 'edit', group)).then(({ reply }) => {
    if (reply.op !== 'error') select({ kind: 'surface', name: result }, false);
  });
  pull.drag = { surface, deformation, uv, start, group };
  state.dragging = true;
  canvas.setPointerCapture(event.pointerId);
  controls.enabled = false;
  event.stopImmediatePropagation();
}
/** A pointer move while a surface point is pulled; false when none is. */
export function pullMove(event) {
  const d = pull.drag;
  if (!d) return false;
  const to = draggedTo(d.start, event);
  if (!to) return true;
  d.last = to;
  dragEdit(() => (doc.recipe.deformations && doc.recipe.deformations[d.deformation] ? { changes: { path: `deformations.${d.deformation}[0].moves[0].to`, value: to }, label: `drag ${d.surface} at (${d.uv.map((x) => x.toPrecision(4))})`, group: d.group } : null), event.timeStamp);
  return true;
}
/** The release of a pulled point; false when none is pulled. */
export function pullUp() {
  if (!pull.drag) return false;
  pull.drag = null;
  state.dragging = false;
  controls.enabled = true;
  return true;
}

// ------------------------------------------------------------------------------ buttons and sliders
function buildLattice() {
  const model = selected('model')[0] || (!state.selection.length && !doc.surfaces.size && doc.models.size === 1 ? [...doc.models.keys()][0] : null);
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
  const deform = bspline ? { surface, deformation, composition: { mode: 'refit', relative_tolerance: 1e-4 } } : { surface, deformation };
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
}
function buildGlobal() {
  const surface = targetSurface();
  if (!surface) return;
  const deformation = names.free(doc.recipe, 'global');
  const result = names.free(doc.recipe, `${surface}_global`);
  edit(
    [
      { path: `deformations.${deformation}`, value: names.globalSteps(doc.surfaces.get(surface).points, 0, 0, 0), create: true },
      { path: `surfaces.${result}`, value: { deform: { surface, deformation, composition: { mode: 'refit', relative_tolerance: 1e-4 } } }, create: true },
    ],
    `taper/twist/bend on ${surface}`,
  ).then(({ reply }) => reply.op !== 'error' && select({ kind: 'surface', name: result }));
}

/** Lattice and Taper/Twist/Bend, the global sliders, the strength slider's output. */
export function wireLattice() {
  $('build-lattice').addEventListener('click', buildLattice);
  $('build-global').addEventListener('click', buildGlobal);
  for (const id of ['global-taper', 'global-twist', 'global-bend'])
    $(id).addEventListener('input', (event) => {
      const g = activeGlobal();
      if (!g) return;
      $(id).parentElement.querySelector('output').textContent = $(id).value;
      const values = ['taper', 'twist', 'bend'].map((k) => Number($(`global-${k}`).value));
      const group = sliderGroup(id);
      dragEdit(() => ({ changes: { path: `deformations.${g.deformation}`, value: names.withGlobal(doc.recipe.deformations[g.deformation], ...values) }, label: `${g.deformation} ${id.slice(7)}`, group }), event.timeStamp);
    });
  $('lattice-keep-volume').addEventListener('change', () => {
    const keep = $('lattice-keep-volume').checked;
    const changes = modelLattices().map((l) => (keep ? { path: `deformations.${l.deformation}[${l.stepIndex}].keep`, value: ['volume'], create: true } : { path: `deformations.${l.deformation}[${l.stepIndex}].keep`, remove: true }));
    const unchanged = modelLattices().every((l) => (l.step.keep || []).includes('volume') === keep);
    if (changes.length && !unchanged) edit(changes, keep ? 'keep the volume' : 'let the volume change');
  });
  $('lattice-strength').addEventListener('input', () => ($('lattice-strength').parentElement.querySelector('output').textContent = $('lattice-strength').value));
}
