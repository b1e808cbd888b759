#!/usr/bin/env node
// End-to-end test of Clayform Studio (docs/studio.md) in Debian's headless Chromium, driven by
// playwright-core with synthesized pointer events against a real `clayform studio`, in parts, each
// a file of its own on the shared harness (studio_harness.mjs):
//   drawing      strokes, fill, style, lattice drag, undo, save, replay, export, origins (studio_drawing.mjs)
//   model        a STEP model opened, a lattice dragged, saved, replayed (studio_model.mjs)
//   regular      taper, twist, direct manipulation, B-spline lattice (studio_regular.mjs)
//   corners      strokes split at corners, mirror (studio_corners.mjs)
//   constraints  constraints, 3D strokes, revolve, picked planes (studio_constraints.mjs)
//   drafting     the grid snapped to, the pointer's coordinates, ortho and back views, an underlay (studio_drafting.mjs)
//   jobs         a long run's progress line and its Cancel (studio_jobs.mjs)
//   design       40 strokes drawn as a hand draws, a fill, a constraint, a style, a lattice (studio_design.mjs)
// Geometry is checked here, not by the page (geometry.mjs). Latencies and frame times come from
// the page's window.clayStudio hook and are reported (not asserted: they depend on the machine).
//
//   node e2e/studio.test.mjs --clayform PATH [--part NAME] [--chromium PATH] [--shots DIR] [--report FILE] [--keep]
import { openHarness, assert } from './studio_harness.mjs';
import drawing from './studio_drawing.mjs';
import model from './studio_model.mjs';
import regular from './studio_regular.mjs';
import corners from './studio_corners.mjs';
import constraints from './studio_constraints.mjs';
import drafting from './studio_drafting.mjs';
import jobs from './studio_jobs.mjs';
import design from './studio_design.mjs';

const parts = { drawing, model, regular, corners, constraints, drafting, jobs, design };
const h = await openHarness(Object.keys(parts));
try {
  for (const [name, run] of Object.entries(parts)) if (h.wants(name)) await run(h);
  await h.check('no page errors', async () => {
    assert(h.problems.length === 0, h.problems.join('; '));
  });
} finally {
  await h.browser.close();
}
h.finish();
