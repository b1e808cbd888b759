// Style (docs/studio.md, step 5): the selected surface deformed by a bound and a target curve; the
// Style panel's λ, key points per row, relaxation, smoothing and mode re-run the step live (a
// slider's moves until it is let go are one history entry); and "restyle while drawing", where the
// stroke being drawn is the style's target.
import * as names from './recipe_edits.js';
import { $, showMessage, setSlider, sliderGroup } from './ui.js';
import { doc, selected, edit, dragEdit } from './store.js';
import { select, targetSurface } from './select.js';
import { styleSummary } from './forms.js';

/** The style step's deformation of the selected surface, or null. */
export function activeStyle() {
  for (const s of selected('surface')) {
    const def = (doc.recipe.surfaces || {})[s];
    const stack = def && def.deform && (doc.recipe.deformations || {})[def.deform.deformation];
    if (stack && stack[0] && stack[0].kind === 'style') return def.deform.deformation;
  }
  return null;
}

/** The selected styled surface's style step report (its figures), or null. */
function styleStep() {
  for (const s of selected('surface')) {
    const step = doc.steps.find((st) => st.kind === 'style' && st.path.startsWith(`surfaces.${s}.`));
    if (step) return step;
  }
  return null;
}

/** The Style panel, for the selection: the step's settings and the kernel's figures. */
export function showStylePanel() {
  const style = activeStyle();
  $('style-panel').hidden = !style;
  if (!style) return;
  const step = doc.recipe.deformations[style][0];
  const exact = step.mode === 'exact';
  $('style-name').textContent = style;
  $('style-mode').value = step.mode || 'paper';
  setSlider('style-lambda', step.lambda ?? 1);
  setSlider('style-kpr', step.key_points_per_row ?? 1);
  $('style-relaxation').checked = step.relaxation ?? true;
  $('style-smoothing').checked = step.smoothing ?? true;
  $('style-continuity').value = step.continuity || 'G1';
  $('style-convergence').value = String(step.net_convergence ?? 0);
  // the exact mode's settings; the paper's relaxation and smoothing
  $('style-continuity').disabled = $('style-convergence').disabled = !exact;
  $('style-relaxation').disabled = $('style-smoothing').disabled = exact;
  const report = styleStep();
  const summary = report ? styleSummary(report.figures) : { text: '', warning: '' };
  $('style-figures').textContent = summary.text;
  $('style-warning').textContent = summary.warning;
  $('style-warning').hidden = !summary.warning;
}

/** The changes that make `stroke` the style's target under the live stroke's name (one history entry). */
export function liveTarget(live, stroke) {
  live.updates++;
  return {
    changes: [
      { path: `strokes.${live.name}`, value: stroke, create: true },
      { path: `deformations.${live.style}[0].target`, value: live.name },
    ],
    label: `restyle ${live.style}: target ${live.name} drawn`,
  };
}

function buildStyle() {
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

/** Style, and the Style panel's fields. */
export function wireStyle() {
  $('build-style').addEventListener('click', buildStyle);
  styleField('style-lambda', 'lambda', (e) => Number(e.value));
  styleField('style-kpr', 'key_points_per_row', (e) => Number(e.value));
  styleField('style-relaxation', 'relaxation', (e) => e.checked);
  styleField('style-smoothing', 'smoothing', (e) => e.checked);
  styleField('style-mode', 'mode', (e) => e.value);
  styleField('style-continuity', 'continuity', (e) => e.value);
  // Net convergence, best effort when on: the panel's styles keep the finest net's result (with a
  // warning) where the shape stops converging, instead of failing (off: no rounds at all).
  $('style-convergence').addEventListener('input', (event) => {
    const style = activeStyle();
    if (!style) return;
    const value = Number($('style-convergence').value);
    const at = `deformations.${style}[0]`;
    const changes = [
      { path: `${at}.net_convergence`, value, create: true },
      { path: `${at}.net_convergence_best_effort`, value: value > 0, create: true },
    ];
    dragEdit(() => ({ changes, label: `${style} net convergence`, group: sliderGroup('style-convergence') }), event.timeStamp);
  });
}
