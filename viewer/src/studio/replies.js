// The kernel's replies (docs/studio.md § The socket): an error or a message shown; a run's reply
// and its frames made the document (nets, curves, models moved onto their faces' nets, deviation
// maps), then every view redrawn; and the start: the socket opened and the recipe run.
import { meshOnNets } from './nurbs.js';
import { applyChanges } from './recipe_edits.js';
import { $, body, showMessage, clearError } from './ui.js';
import { doc, state, metrics, connect, busy, send, simple } from './store.js';
import { dirty, setView } from './scene.js';
import { rebuildSurfaces, rebuildCurves } from './display.js';
import { previewEnding, finishPreview } from './lattice_preview.js';
import { clearInk } from './sketch.js';
import { rebuildHandles } from './handles.js';
import { showPanels, showReport, showHistory } from './panels.js';

const session = { restoredShown: false }; // the autosave's continuation said once

/** The recipe's whole text and its revision, from a run, an undo or redo, or the "recipe" op. */
function holdText(reply) {
  doc.recipe = JSON.parse(reply.text);
  doc.revision = reply.revision;
}

function onReply(reply, frames, meta) {
  const receivedAt = performance.now();
  if (reply.op === 'error' && reply.category === 'cancelled') {
    // the stylist's own Cancel (or a newer page): not an error, nothing changed
    showMessage(`cancelled: ${meta.command.op} stopped, nothing changed`, 'warning');
    body.dataset.error = '';
    body.dataset.cancelled = String(Number(body.dataset.cancelled || 0) + 1);
    return;
  }
  if (reply.op === 'error') {
    showMessage(`${reply.category}: ${reply.message}`, true);
    body.dataset.error = reply.message;
    return;
  }
  body.dataset.error = '';
  clearError();
  if (reply.op === 'saved') {
    showMessage(`saved ${reply.file}`);
    return;
  }
  if (reply.op === 'exported') {
    const worst = Math.max(0, ...reply.bounds_mm.map((b) => (b === null ? Infinity : b)));
    const within = worst > 0 ? `, within ${Number.isFinite(worst) ? `${worst.toPrecision(3)} mm` : 'an unbounded distance'} of the exact` : ', exact';
    showMessage(`exported ${reply.files.join(', ')} into ${reply.folder} for ${reply.profile}${within}${reply.valid ? ' (read back and checked)' : ''}`);
    return;
  }
  if (reply.op === 'recipe') {
    holdText(reply);
    return;
  }
  if (!('steps' in reply)) return;
  metrics.kernel.push(reply.seconds * 1000);
  doc.reply = reply;
  doc.steps = reply.steps;
  doc.history = reply.history;
  // Said once: the session continues an autosave (the studio restarted after a crash or
  // Ctrl-C), or the last autosave failed (the edit itself was applied).
  if (reply.history.restored && !session.restoredShown) {
    session.restoredShown = true;
    showMessage(`continued the autosave ${reply.history.restored.file}: ${reply.history.restored.entries} history entries (start clayform studio with --fresh to begin from the recipe file)`);
  }
  if (reply.history.autosave_problem) showMessage(`autosave failed: ${reply.history.autosave_problem}`, true);
  if (typeof reply.text === 'string') holdText(reply);
  else if (Array.isArray(reply.changes)) {
    // An edit's reply carries its changes, not the whole text (which grew every reply with the
    // recipe): applied to the revision held, or the text asked for when the page holds another.
    const next = reply.from_revision === doc.revision ? applyChanges(doc.recipe, reply.changes) : null;
    if (next) {
      doc.recipe = next;
      doc.revision = reply.revision;
    } else {
      doc.revision = null;
      setTimeout(() => send({ op: 'recipe' }));
    }
  }
  if (reply.nets === false) {
    // a drag update the page draws itself: the kernel's figures and history only
    metrics.drag.push({ at: performance.now(), ms: performance.now() - meta.inputAt });
    showReport();
    showHistory();
    return;
  }
  const meshes = doc.models;
  // What the kernel did not send again (reply.kept) is what the page holds already: the same
  // objects, so their drawings are kept too (display.js); only what changed is new.
  const held = { surfaces: doc.surfaces, befores: doc.befores, curves: doc.curves, models: doc.models, deviations: doc.deviations };
  doc.surfaces = new Map();
  doc.befores = new Map();
  doc.curves = new Map();
  doc.models = new Map();
  doc.deviations = new Map();
  let lost = false;
  for (const [kind, names] of Object.entries(reply.kept || {}))
    for (const name of names) {
      const value = held[kind] && held[kind].get(name);
      if (value) doc[kind].set(name, value);
      else lost = true;
    }
  if (lost) setTimeout(() => send({ op: 'run' })); // the page lost something: ask for everything
  for (const f of frames) {
    const h = f.header;
    if (h.kind === 'mesh') doc.models.set(h.name, f);
    else if (h.kind === 'deviation') doc.deviations.set(h.name, f);
    else if (h.kind === 'model_nets') {
      // only the faces' control points changed: the mesh the page holds, evaluated on them
      const mesh = meshes.get(h.name);
      const t0 = performance.now();
      if (mesh) doc.models.set(h.name, { ...mesh, ...meshOnNets(mesh, f.faces), faces: f.faces });
      else setTimeout(() => send({ op: 'run' })); // no mesh to move: ask for everything
      metrics.evaluate.push(performance.now() - t0);
    }
    else if (h.kind === 'curve') doc.curves.set(h.name, { degree: h.degree, knots: h.knots, rational: h.rational, points: f.points, weights: f.weights });
    else (h.before ? doc.befores : doc.surfaces).set(h.name, { degrees: h.degrees, counts: h.counts, knots_u: h.knots_u, knots_v: h.knots_v, rational: h.rational, points: f.points, weights: f.weights });
  }
  state.selection = state.selection.filter((s) => (s.kind === 'curve' ? doc.curves.has(s.name) : s.kind === 'surface' ? doc.surfaces.has(s.name) : s.kind === 'model' ? doc.models.has(s.name) : true));
  if (previewEnding() && !busy()) finishPreview();
  else rebuildSurfaces();
  rebuildCurves();
  clearInk(meta.command);
  rebuildHandles();
  showPanels();
  showReport();
  showHistory();
  const kind = meta.command.kind;
  dirty((drawnAt) => {
    if (kind === 'drag') metrics.drag.push({ at: drawnAt, ms: drawnAt - meta.inputAt });
    if (kind === 'drag-end') metrics.dragEnd.push({ at: drawnAt, ms: drawnAt - meta.inputAt });
    // a stroke's latency in parts: the kernel's run, the rest until the reply was here (fit,
    // socket, the server's reply), the page's drawing after it (`ms`, the render issued), and on
    // the screen: the next frame starts once this one is committed (in software compositing,
    // once its picture has been read back from the renderer: 55 ms with a styled surface in view)
    if (kind === 'stroke') {
      const m = { at: drawnAt, ms: drawnAt - meta.inputAt, kernel: 1000 * reply.seconds, received: receivedAt - meta.inputAt, shown: null };
      metrics.stroke.push(m);
      requestAnimationFrame(() => (m.shown = performance.now() - meta.inputAt));
    }
    body.dataset.rendered = String(Number(body.dataset.rendered || 0) + 1);
  });
}

/** Opens the socket, runs the recipe, and shows it (body.dataset.ready: 1, or closed, or error). */
export async function start() {
  const opened = connect(onReply, (event) => {
    // A newer page (a reload, another tab) takes the session over at once: this one is told
    // so, and a reload here takes it back; otherwise the server is gone.
    const takenOver = event && /another page/.test(event.reason || '');
    showMessage(takenOver ? 'another page took this studio session over; reload this page to take it back' : 'the connection to clayform studio closed; restart it and reload the page', true);
    body.dataset.ready = 'closed';
  });
  try {
    await opened;
  } catch (e) {
    showMessage(`${e.message}: is clayform studio running?`, true);
    body.dataset.ready = 'error';
    return;
  }
  const { reply } = await simple('run');
  if (reply.op === 'error' && reply.category !== 'cancelled') showMessage(reply.message, true);
  $('run-title').textContent = `Clayform Studio — ${doc.recipe.name || reply.recipe || 'untitled'}`;
  $('save-name').value = `${doc.recipe.name || 'studio'}.json`;
  // a recipe with geometry is seen from the side, an empty one from the top (to sketch on XY)
  setView(doc.surfaces.size || doc.curves.size || doc.models.size ? 'iso' : 'top');
  body.dataset.ready = '1';
}
