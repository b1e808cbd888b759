// The page's few DOM helpers: an element by id, the body (whose data attributes carry the tool,
// the mode and the test's flags), the message line, a slider's value and its output.

import { newGroup } from './store.js';

export const body = document.body;
export const $ = (id) => document.getElementById(id);

// The message line (issue #40): a message stays until it is read (its × closes it) or a newer
// one replaces it, so an export's result is there when the stylist comes back; an error also goes
// when the next command succeeds (clearError). The line lets pointer events through to the view
// below it, but for its ×.
const messageBox = $('message');
const messageText = document.createElement('span');
const messageClose = document.createElement('button');
messageClose.textContent = '×';
messageClose.title = 'Close this message';
messageClose.className = 'message-close';
messageBox.append(messageText, messageClose);
messageClose.addEventListener('click', () => showMessage(''));
/** Shows `text` (empty: hides the line); kind true or 'error', 'warning', or nothing for news. */
export function showMessage(text, kind) {
  const level = kind === true ? 'error' : kind || '';
  messageBox.hidden = !text;
  messageText.textContent = text || '';
  messageBox.classList.toggle('error', level === 'error');
  messageBox.classList.toggle('warning', level === 'warning');
}
/** Hides the line when it shows an error (a command has just succeeded). */
export function clearError() {
  if (messageBox.classList.contains('error')) showMessage('');
}

/** A slider set from the recipe (not while the user holds it), its output beside it. */
export function setSlider(id, value) {
  if (document.activeElement === $(id)) return;
  $(id).value = value;
  $(id).parentElement.querySelector('output').textContent = String(value);
}

// A slider's moves until it is let go ("change") are one drag.
const sliderGroups = {};
export function sliderGroup(id) {
  if (!sliderGroups[id]) {
    sliderGroups[id] = newGroup();
    $(id).addEventListener('change', () => delete sliderGroups[id], { once: true });
  }
  return sliderGroups[id];
}
