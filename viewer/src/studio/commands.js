// The toolbar's commands that are no tool of their own: Fill, Skin and Revolve from the selected
// curves, Delete, undo and redo, Save (with an export of what is shown) and Export.
import * as names from './recipe_edits.js';
import { $, showMessage } from './ui.js';
import { doc, selected, edit, send, simple } from './store.js';
import { select } from './select.js';

function buildFill() {
  const curves = selected('curve');
  if (curves.length < 2 || curves.length > 4) return showMessage('select 2 to 4 curves that meet end to end, then Fill', true);
  const name = names.free(doc.recipe, 'fill');
  const tolerance = Number($('stroke-tolerance').value) || 0.5;
  edit({ path: `surfaces.${name}`, value: { fill: { curves, join: 'snap', gap_tolerance: 2 * tolerance } }, create: true }, `fill ${name}`).then(() => select(null));
}
function buildSkin() {
  const curves = selected('curve');
  if (curves.length < 2) return showMessage('select 2 or more section curves in order, then Skin', true);
  const name = names.free(doc.recipe, 'skin');
  edit({ path: `surfaces.${name}`, value: { skin: { sections: curves } }, create: true }, `skin ${name}`).then(() => select(null));
}
function buildRevolve() {
  const curves = selected('curve');
  if (curves.length < 1 || curves.length > 2) return showMessage('select the profile curve (and a second curve whose chord is the axis, or choose a world axis), then Revolve', true);
  let axis = { point: [0, 0, 0], direction: { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] }[$('revolve-axis').value] };
  if (curves.length === 2) {
    // the axis: the second curve's chord, from its start to its end
    const c = doc.curves.get(curves[1]);
    const n = c.weights.length;
    const a = [c.points[0], c.points[1], c.points[2]];
    const b = [c.points[3 * n - 3], c.points[3 * n - 2], c.points[3 * n - 1]];
    const d = b.map((x, e) => x - a[e]);
    if (Math.hypot(...d) === 0) return showMessage(`the axis curve "${curves[1]}" is closed: its chord has no direction`, true);
    axis = { point: a, direction: d };
  }
  const name = names.free(doc.recipe, 'revolve');
  edit({ path: `surfaces.${name}`, value: { revolve: { profile: curves[0], axis } }, create: true }, `revolve ${name}`).then(() => select(null));
}

export function deleteSelected() {
  const curves = selected('curve');
  if (!curves.length) return showMessage('select a curve to delete', true);
  // a piece of a stroke split at its corners goes with its stroke
  const paths = new Set(curves.map((n) => (names.strokeOf(doc.recipe, n) ? `strokes.${names.strokeOf(doc.recipe, n)}` : `curves.${n}`)));
  const changes = [...paths].map((path) => ({ path, remove: true }));
  edit(changes, `delete ${curves.join(', ')}`).then(({ reply }) => reply.op !== 'error' && select(null));
}

export async function save() {
  const file = $('save-name').value.trim();
  if (!file) return showMessage('give a file name to save the recipe to', true);
  // the saved recipe exports what is shown, so `clayform run` writes it
  const finals = [...doc.surfaces.keys()];
  const exports = doc.recipe.exports || {};
  const covered = Object.values(exports).some((e) => finals.every((n) => (e.surfaces || []).includes(n)));
  if (finals.length && !covered) {
    const { reply } = await edit({ path: `exports.${names.free(doc.recipe, doc.recipe.name || 'studio')}`, value: { surfaces: finals }, create: true }, 'export what is shown');
    if (reply.op === 'error') return;
  }
  return send({ op: 'save', file });
}

/** The build buttons, Delete, history, Save and Export. */
export function wireCommands() {
  $('build-fill').addEventListener('click', buildFill);
  $('build-skin').addEventListener('click', buildSkin);
  $('build-revolve').addEventListener('click', buildRevolve);
  $('delete').addEventListener('click', deleteSelected);
  $('undo').addEventListener('click', () => simple('undo'));
  $('redo').addEventListener('click', () => simple('redo'));
  $('save').addEventListener('click', save);
  $('export').addEventListener('click', () =>
    send({ op: 'export', folder: `${doc.recipe.name || 'studio'}-export`, profile: $('export-profile').value }),
  );
}
