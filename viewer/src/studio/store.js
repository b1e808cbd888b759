// The state the tools share (docs/studio.md, "The page's modules"): the document the last run gave
// (recipe, nets, history), the selection, the analysis mode, before/after, whether a drag is in
// progress, the latencies recorded; and the one way to the kernel, the link, with the edit
// commands built on it. Each tool keeps the rest of its state in its own module.
import { Link } from './link.js';

// What the last run gave: the recipe, its final surfaces' nets (and their parents before their
// first step), every named curve's net, the history.
export const doc = { recipe: {}, surfaces: new Map(), befores: new Map(), curves: new Map(), models: new Map(), deviations: new Map(), history: { entries: [], position: 0 }, steps: [], reply: null, revision: null };

export const state = {
  selection: [], // [{kind: 'curve' | 'surface' | 'model', name}]
  mode: 'shaded', // the analysis view: shaded, zebra, mean, gaussian, deviation
  showBefore: false, // each deformed surface's parent before its first step
  dragging: false, // a handle, a surface point or a stroke held (frame times are recorded)
};

/** The latencies and frame times the end-to-end test reads (window.clayStudio.metrics). */
export const metrics = { drag: [], dragEnd: [], preview: [], stroke: [], frames: [], kernel: [], evaluate: [] };

/** The names of the selected items of one kind, in selection order. */
export function selected(kind) {
  return state.selection.filter((s) => s.kind === kind).map((s) => s.name);
}

// ------------------------------------------------------------------------------ the kernel
// The session's token (docs/studio.md "Security"): from the address `clayform studio` printed;
// the server also keeps it in a cookie, so a reload without it still connects.
const pageToken = new URLSearchParams(location.search).get('token');
const socketUrl = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws${pageToken ? `?token=${encodeURIComponent(pageToken)}` : ''}`;
const connection = { link: null, drags: 0 };

/** Opens the socket: replies go to onReply(reply, frames, meta), a close to onClose(event). */
export function connect(onReply, onClose) {
  connection.link = new Link(socketUrl, onReply, onClose);
  return connection.link.opened;
}
/** Whether a command waits for its answer. */
export const busy = () => !!(connection.link && connection.link.busy);
/** Sends a command; resolves with {reply, frames}. */
export const send = (command, inputAt) => connection.link.send(command, inputAt);
/** The command waiting for its answer ({op, sentAt, progress}), or null (Link.running). */
export const running = () => (connection.link ? connection.link.running : null);
/** Cancels the command waiting for its answer: it is answered "cancelled", nothing changed. */
export const cancelRunning = () => connection.link && connection.link.cancel();
/** Drops a drag update that waits to be sent. */
export const cancelDrag = () => connection.link.cancelDrag();

/** An edit command: one change ({path, value} or {path, remove}) or several, one history entry. */
export function commandOf(changes, label, kind, group) {
  const command = Array.isArray(changes) ? { op: 'edit', label, changes } : { op: 'edit', label, ...changes };
  if (group) command.group = group;
  Object.defineProperty(command, 'kind', { value: kind, enumerable: false });
  return command;
}
/** Sends an edit as one entry of the history. */
export function edit(changes, label, kind = 'edit', inputAt = performance.now()) {
  return send(commandOf(changes, label, kind), inputAt);
}
/**
 * A drag update: `build()` gives {changes, label} from the document as it is when the update is
 * sent (at most one is in flight; a newer one replaces a waiting one).
 */
export function dragEdit(build, inputAt) {
  return connection.link.drag(() => {
    const b = build();
    if (!b) return null;
    const command = commandOf(b.changes, b.label, 'drag', b.group);
    if (b.nets === false) command.nets = false;
    return command;
  }, inputAt);
}
// The updates of one drag (a handle, a slider) share a group: the kernel keeps them as one
// history entry.
export const newGroup = () => `drag ${++connection.drags}`;
/** A command without fields (run, undo, redo). */
export function simple(op) {
  const command = { op };
  Object.defineProperty(command, 'kind', { value: op, enumerable: false });
  return send(command);
}
