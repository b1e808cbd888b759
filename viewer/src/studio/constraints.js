// Constraints on planar sketches (docs/studio.md § Constraints): the selected strokes (or a
// sketch's curves) become entities of a sketch on their plane, and each button appends a
// constraint; the solver's degrees of freedom and redundant sets are shown, and a conflicting
// constraint is refused with the solver's report.
import * as names from './recipe_edits.js';
import { $, showMessage } from './ui.js';
import { doc, selected, edit } from './store.js';
import { select } from './select.js';

function constrain(type) {
  const curves = selected('curve');
  if (!curves.length || curves.length > 2) return showMessage('select one or two curves drawn on one plane, then a constraint', true);
  const target = names.sketchFor(doc.recipe, curves);
  if (target.reason) return showMessage(target.reason, true);
  const [a, b] = target.entities;
  const nets = curves.map((c) => doc.curves.get(c));
  let constraints = [];
  const changes = [...target.changes];
  if (type === 'fixed') constraints = target.entities.flatMap((e) => [`${e}.start`, `${e}.end`]).map((point) => ({ type: 'fixed', point }));
  else if (type === 'horizontal' || type === 'vertical') {
    // a curve's chord, a construction line from its start to its end (not drawn), along the
    // plane's x or y axis
    for (const e of target.entities) {
      const chord = `${e}_chord`;
      const entities = target.create ? changes[0].value.entities : (doc.recipe.sketches[target.sketch].entities || {});
      if (!entities[chord]) {
        if (target.create) entities[chord] = { line: [`${e}.start`, `${e}.end`] };
        else changes.push({ path: `sketches.${target.sketch}.entities.${chord}`, value: { line: [`${e}.start`, `${e}.end`] }, create: true });
      }
      constraints.push({ type, entity: chord });
    }
  }
  else if (curves.length === 1) {
    if (type !== 'distance') return showMessage('coincident, tangent and curvature join two curves: select two', true);
    constraints = [{ type: 'distance', points: [`${a}.start`, `${a}.end`], value: Number($('constrain-value').value) }];
  } else {
    const [[ea, eb]] = names.nearestEnds(nets[0], nets[1]);
    if (type === 'coincident') constraints = [{ type: 'coincident', points: [`${a}.${ea}`, `${b}.${eb}`] }];
    else if (type === 'distance') constraints = [{ type: 'distance', points: [`${a}.${ea}`, `${b}.${eb}`], value: Number($('constrain-value').value) }];
    else constraints = [{ type, ends: [{ entity: a, end: ea }, { entity: b, end: eb }] }];
  }
  const existing = target.create ? [] : (doc.recipe.sketches[target.sketch].constraints || []);
  if (target.create) changes[0].value.constraints = constraints;
  else changes.push({ path: `sketches.${target.sketch}.constraints`, value: [...existing, ...constraints] });
  edit(changes, `${type} ${target.entities.join(', ')}`).then(({ reply }) => {
    if (reply.op !== 'error') select(null);
  });
}

/** The Constrain panel: shown for one or two curves of one plane, with the solver's figures. */
export function showSketchFigures() {
  const curves = selected('curve');
  const target = curves.length && curves.length <= 2 ? names.sketchFor(doc.recipe, curves) : { reason: 'none' };
  $('constrain-panel').hidden = !!target.reason;
  if (target.reason) return;
  $('constrain-sketch').textContent = target.create ? '(a new sketch)' : target.sketch;
  const step = doc.steps.find((st) => st.path === `sketches.${target.sketch}`);
  $('sketch-figures').textContent = step ? `degrees of freedom ${step.figures.degrees_of_freedom}, ${step.figures.constraints} constraints, redundant sets ${step.figures.redundant_sets}, residual ${Number(step.figures.max_residual).toExponential(1)}` : '';
}

/** The constraint buttons. */
export function wireConstraints() {
  for (const type of ['coincident', 'tangent', 'curvature', 'fixed', 'distance', 'horizontal', 'vertical']) $(`constrain-${type}`).addEventListener('click', () => constrain(type));
}
