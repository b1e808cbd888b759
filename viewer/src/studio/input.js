// Input routing (docs/studio.md § Keyboard and mouse): the tool chosen (Select/orbit, Sketch, Edit),
// the canvas's pointer events handed to the tool that holds them (sketch.js, handles.js, the
// direct manipulation in lattice.js, a click to select.js), and the keyboard's shortcuts.
import * as THREE from 'three';
import { $, body } from './ui.js';
import { simple } from './store.js';
import { canvas, controls, setView } from './scene.js';
import { toggleBefore } from './display.js';
import { select, pick } from './select.js';
import { inking, sketchDown, sketchMove, sketchUp } from './sketch.js';
import { rebuildHandles, handleDown, handleMove, handleUp } from './handles.js';
import { startDirectManipulation, pullMove, pullUp } from './lattice.js';
import { deleteSelected, save } from './commands.js';

export function setTool(tool) {
  body.dataset.tool = tool;
  document.querySelectorAll('[data-tool]').forEach((b) => b.setAttribute('aria-pressed', String(b.dataset.tool === tool)));
  controls.mouseButtons.LEFT = tool === 'sketch' ? null : THREE.MOUSE.ROTATE;
  $('drag-panel').hidden = tool !== 'edit';
  rebuildHandles();
}

const pointer = { down: null }; // {x, y, button}: where the last press was (a click is a press and a release there)

function onPointerDown(event) {
  pointer.down = { x: event.clientX, y: event.clientY, button: event.button };
  const tool = body.dataset.tool;
  if (event.button !== 0) return;
  if (tool === 'sketch') sketchDown(event);
  else if (tool === 'edit') {
    if (!handleDown(event) && event.shiftKey) startDirectManipulation(event);
  }
}
function onPointerMove(event) {
  if (inking()) sketchMove(event);
  else if (!pullMove(event)) handleMove(event);
}
function onPointerUp(event) {
  const down = pointer.down;
  const click = down && Math.hypot(event.clientX - down.x, event.clientY - down.y) < 4 && down.button === 0;
  pointer.down = null;
  if (inking()) return sketchUp(event);
  if (pullUp()) return;
  if (handleUp(event)) return;
  if (click) select(pick(event.clientX, event.clientY), event.shiftKey);
}

function onKey(e) {
  if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
  const ctrl = e.ctrlKey || e.metaKey;
  if (ctrl && e.key.toLowerCase() === 'z') {
    e.preventDefault();
    simple(e.shiftKey ? 'redo' : 'undo');
  } else if (ctrl && e.key.toLowerCase() === 'y') {
    e.preventDefault();
    simple('redo');
  } else if (ctrl && e.key.toLowerCase() === 's') {
    e.preventDefault();
    save();
  } else if (ctrl) return;
  else if (e.key === 'o') setTool('orbit');
  else if (e.key === 's') setTool('sketch');
  else if (e.key === 'e') setTool('edit');
  else if (e.key === 'b') toggleBefore();
  else if (e.key === 'f') setView('fit');
  else if (['1', '2', '3', '4', '5'].includes(e.key)) setView(['top', 'front', 'side', 'iso', 'back'][Number(e.key) - 1]);
  else if (e.key === 'p') $('projection').click();
  else if (e.key === 'Delete' || e.key === 'Backspace') deleteSelected();
  else if (e.key === 'Escape') select(null);
  else if (['x', 'y', 'z', 'X', 'Y', 'Z'].includes(e.key)) {
    const axis = e.key.toLowerCase();
    const plane = { x: 'yz', y: 'xz', z: 'xy' }[axis];
    $('lattice-lock').value = $('lattice-lock').value === (e.shiftKey ? plane : axis) ? '' : e.shiftKey ? plane : axis;
  }
}

/** The canvas's pointer events (the press in the capture phase, before the orbit controls'), the tool buttons, the keyboard. */
export function wireInput() {
  canvas.addEventListener('pointerdown', onPointerDown, { capture: true });
  canvas.addEventListener('pointermove', onPointerMove);
  canvas.addEventListener('pointerup', onPointerUp);
  document.querySelectorAll('button[data-tool]').forEach((b) => b.addEventListener('click', () => setTool(b.dataset.tool)));
  window.addEventListener('keydown', onKey);
}
