// The page's few DOM helpers: an element by id, the body (whose data attributes carry the tool,
// the mode and the test's flags), the message line, a slider's value and its output.

import { newGroup } from './store.js';

export const body = document.body;
export const $ = (id) => document.getElementById(id);

// The message line: an error stays, anything else goes after 4 s.
const messageBox = $('message');
const message = { timer: null };
export function showMessage(text, isError) {
  messageBox.hidden = !text;
  messageBox.textContent = text || '';
  messageBox.classList.toggle('error', !!isError);
  clearTimeout(message.timer);
  if (text && !isError) message.timer = setTimeout(() => showMessage(''), 4000);
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
