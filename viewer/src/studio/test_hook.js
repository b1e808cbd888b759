// The window hook, for the end-to-end test and for scripting the page: the nets as the kernel sent
// them, the camera, the handles, the latencies and frame times recorded, and a promise for
// "everything answered".
import { doc, state, metrics, busy, send } from './store.js';
import { canvas, camera, renderPending, setView, toScreen, isOrthographic } from './scene.js';
import { gridSpacing, gridNode, underlaySettings, spacingAt } from './drafting.js';
import { previews } from './lattice_preview.js';
import { lastLive } from './sketch.js';
import { handleList } from './handles.js';
import { select } from './select.js';

function plainNet(s) {
  return { degrees: s.degrees, counts: s.counts, knots_u: s.knots_u, knots_v: s.knots_v, points: Array.from(s.points), weights: Array.from(s.weights) };
}

export function installTestHook() {
  window.clayStudio = {
    recipe: () => doc.recipe,
    /** The revision of the recipe the page holds (null while it asks for the text). */
    revision: () => doc.revision,
    history: () => doc.history,
    reply: () => doc.reply,
    /** The last run's step reports (as report.json has them). */
    steps: () => doc.steps,
    surfaces: () => Object.fromEntries([...doc.surfaces].map(([n, s]) => [n, plainNet(s)])),
    befores: () => Object.fromEntries([...doc.befores].map(([n, s]) => [n, plainNet(s)])),
    lastLive: () => lastLive() && { ...lastLive() },
    /** The page's pictures of a lattice drag in progress: per surface, its grid, vertices and the lattice points drawn. */
    previews: () => Object.fromEntries([...previews].map(([n, p]) => [n, { rows: p.prepared.grid.rows, cols: p.prepared.grid.cols, positions: Array.from(p.geometry.getAttribute('position').array), lattice: p.points }])),
    deviations: () => Object.fromEntries([...doc.deviations].map(([n, d]) => [n, { ...d.header, values: Array.from(d.values) }])),
    models: () => Object.fromEntries([...doc.models].map(([n, m]) => [n, { vertices: m.header.vertices, triangles: m.header.triangles, positions: Array.from(m.positions), from: m.faces ? 'model_nets' : 'mesh' }])),
    curves: () => Object.fromEntries([...doc.curves].map(([n, c]) => [n, { degree: c.degree, knots: c.knots, points: Array.from(c.points), weights: Array.from(c.weights) }])),
    camera: () => {
      camera.updateMatrixWorld();
      const rect = canvas.getBoundingClientRect();
      return { projectionInverse: camera.projectionMatrixInverse.elements.slice(), matrixWorld: camera.matrixWorld.elements.slice(), rect: { left: rect.left, top: rect.top, width: rect.width, height: rect.height } };
    },
    toScreen,
    setView,
    /** The drafting aids' state: grid spacing and visibility, the status line's texts, the projection, the underlay. */
    drafting: () => ({
      spacing: gridSpacing(),
      gridShown: document.getElementById('show-grid').checked,
      cursor: document.getElementById('cursor').textContent,
      gridText: document.getElementById('grid-spacing').textContent,
      snap: document.getElementById('snap-target').textContent,
      orthographic: isOrthographic(),
      underlay: underlaySettings(),
    }),
    gridNode,
    spacingAt,
    /** The progress line of a long command: shown, its text, whether its Cancel was pressed. */
    progress: () => ({
      shown: !document.getElementById('progress').hidden,
      text: document.getElementById('progress-text').textContent,
      cancelling: document.getElementById('progress-cancel').disabled,
    }),
    /** The message line: its text and level (error, warning or news). */
    message: () => {
      const m = document.getElementById('message');
      return { shown: !m.hidden, text: m.textContent.replace(/×$/, ''), level: m.classList.contains('error') ? 'error' : m.classList.contains('warning') ? 'warning' : 'news' };
    },
    select: (items) => {
      state.selection = [];
      items.forEach((it) => select(it, true));
    },
    handles: () => handleList().map((h) => ({ kind: h.kind, name: h.name, index: h.index, p: h.p, screen: toScreen(h.p) })),
    metrics,
    /** Sends a command to the kernel as the page does; resolves with {reply} (frames left out). */
    send: (command) => send(command).then(({ reply }) => ({ reply })),
    resetMetrics: () => Object.keys(metrics).forEach((k) => (metrics[k].length = 0)),
    idle: () =>
      new Promise((resolve) => {
        const poll = () => (busy() || renderPending() || previews.size ? setTimeout(poll, 10) : requestAnimationFrame(() => resolve(true)));
        poll();
      }),
  };
}
