// Long jobs (issue #40 item 6; docs/studio.md § Long jobs): a command that has waited a second
// for its answer shows, under the message line, what the kernel is doing (its progress lines: the
// step being built, the steps done) and how long it has run, with a Cancel. The kernel stops the
// command at its next check (between steps and inside the long loops: an exact composition's
// patches, a refit's rounds, a model's faces, the files written) and answers "cancelled":
// nothing changed.
import { $ } from './ui.js';
import { running, cancelRunning } from './store.js';

/** A command shows the progress line once it has waited this long (ms). */
export const progressAfterMs = 1000;

const names = { edit: 'edit', run: 'run', export: 'export', undo: 'undo', redo: 'redo', fit: 'stroke fit', save: 'save' };

/** The progress line's text for a running command `r` (Link.running) at time `now` (ms). */
export function progressText(r, now) {
  const seconds = ((now - r.sentAt) / 1000).toFixed(1);
  const p = r.progress;
  const doing = p ? `: ${p.doing}; ${p.steps_done} step${p.steps_done === 1 ? '' : 's'} done` : '';
  return `${names[r.op] || r.op}${doing} (${seconds} s)`;
}

const job = { sentAt: null }; // the command the line shows (its Cancel pressed once)

function update() {
  const r = running();
  const show = !!r && performance.now() - r.sentAt >= progressAfterMs;
  $('progress').hidden = !show;
  if (!show) return;
  if (job.sentAt !== r.sentAt) {
    job.sentAt = r.sentAt;
    $('progress-cancel').disabled = false;
    $('progress-cancel').textContent = 'Cancel';
  }
  $('progress-text').textContent = progressText(r, performance.now());
}

/** The progress line and its Cancel. */
export function wireJobs() {
  $('progress-cancel').addEventListener('click', () => {
    cancelRunning();
    $('progress-cancel').disabled = true;
    $('progress-cancel').textContent = 'Cancelling…';
  });
  setInterval(update, 200);
}
