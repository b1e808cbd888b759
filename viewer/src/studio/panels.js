// The side panels: the tools' panels for the selection (Constrain, Style, Lattice, Taper/Twist/
// Bend), the history (current entry, undone ones), the report of the last run's steps and the
// status line of latencies.
import { $ } from './ui.js';
import { doc, metrics } from './store.js';
import { showSketchFigures } from './constraints.js';
import { showStylePanel } from './style.js';
import { showLatticePanels } from './lattice.js';
import { formShown } from './forms.js';

export function showPanels() {
  showSketchFigures();
  showStylePanel();
  showLatticePanels();
}

export function showHistory() {
  const list = $('history');
  list.replaceChildren(
    ...doc.history.entries.map((label, i) => {
      const li = document.createElement('li');
      li.textContent = label;
      if (i === doc.history.position) li.className = 'current';
      else if (i > doc.history.position) li.className = 'undone';
      return li;
    }),
  );
  $('undo').disabled = doc.history.position <= 0;
  $('redo').disabled = doc.history.position >= doc.history.entries.length - 1;
}

export function showReport() {
  const wanted = doc.steps.filter((s) => s.path.startsWith('surfaces.') || s.path.startsWith('strokes.'));
  const box = $('report');
  box.replaceChildren(
    ...wanted.slice(-8).map((s) => {
      const d = document.createElement('details');
      d.open = s.path.includes('.steps[') || s.warning;
      const summary = document.createElement('summary');
      summary.textContent = `${s.path} (${s.kind}) ${(1000 * s.seconds).toFixed(1)} ms${s.warning ? ' ⚠' : ''}`;
      const table = document.createElement('table');
      table.className = 'figures';
      for (const [k, v] of Object.entries(s.figures)) {
        const tr = table.insertRow();
        tr.insertCell().textContent = k;
        tr.insertCell().textContent = typeof v === 'number' ? (Number.isInteger(v) ? String(v) : v.toPrecision(4)) : String(v);
      }
      d.append(summary, table);
      return d;
    }),
  );
  $('form').textContent = formShown(doc.steps);
  const redraw = metrics.preview[metrics.preview.length - 1];
  const kernel = metrics.drag[metrics.drag.length - 1];
  $('status').textContent = `kernel ${doc.reply ? (1000 * doc.reply.seconds).toFixed(0) : '-'} ms${redraw ? `, drag to redraw ${redraw.ms.toFixed(0)} ms` : ''}${kernel ? `, drag to kernel answer ${kernel.ms.toFixed(0)} ms` : ''}`;
}

