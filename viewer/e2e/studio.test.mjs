#!/usr/bin/env node
// End-to-end test of Clayform Studio (docs/studio.md) in Debian's headless Chromium, driven by
// playwright-core with synthesized pointer events against a real `clayform studio`:
//   strokes drawn on the XY plane, each fitted curve checked against the drawn path back-projected
//   through the page's camera (here, not by the page); a fill of four of them; a bound and a target
//   drawn and the style applied in exact mode, checked for locality outside the bound and for the
//   target met; a lattice placed and one of its points dragged for 5 s, the surface checked
//   against Sederberg–Parry's FFD evaluated pointwise here; undo and redo; the recipe saved and
//   replayed by `clayform run`, whose STEP file must hold the page's control points bit for bit;
//   a socket from another origin refused. Latencies and frame times come from the page's
//   window.clayStudio hook and are reported (not asserted: they depend on the machine).
//
//   node e2e/studio.test.mjs --clayform PATH [--chromium PATH] [--shots DIR] [--report FILE] [--keep]
import { spawnSync } from 'node:child_process';
import { createServer, request } from 'node:http';
import { copyFileSync, existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { tmpdir, cpus } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { backProject, bsplineFfd, bsplineLatticePoints, curveDomain, curveAt, dist, distanceToCurve, ffd, insidePolygon, latticePoints, quantile, surfaceAt, surfaceDomain } from './geometry.mjs';
import { along, launchBrowser, startStudio, studioPage } from './studio_driver.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && args[i + 1] ? args[i + 1] : fallback;
};
const clayform = resolve(opt('--clayform', process.env.CLAYFORM || '../build/cli/clayform'));
const executablePath = opt('--chromium', process.env.CHROMIUM || '/usr/bin/chromium');
const shots = opt('--shots', null);
const reportFile = opt('--report', null);
// --part runs one group of checks, each on studios of its own, so a slow machine shows which part
// is slow (CTest runs each part as a test of its own); without it, every part.
const parts = ['drawing', 'model', 'regular', 'corners', 'constraints'];
const part = opt('--part', 'all');
if (part !== 'all' && !parts.includes(part)) {
  console.error(`unknown --part ${part}; the parts: ${parts.join(', ')}`);
  process.exit(2);
}
const wants = (p) => part === 'all' || part === p;
for (const [what, path] of [['clayform (cmake --build build)', clayform], ['chromium (apt-get install chromium)', executablePath]]) {
  if (!existsSync(path)) {
    console.error(`missing ${what}: ${path}`);
    process.exit(2);
  }
}

// ------------------------------------------------------------------ STEP: the surfaces' control points
/** Every B_SPLINE_SURFACE_WITH_KNOTS of a STEP file: {degrees, points (u-major)} with the numbers as written. */
function stepSurfaces(text) {
  const entities = new Map();
  for (const m of text.replace(/\r?\n/g, '').matchAll(/#(\d+)\s*=\s*([^;]*);/g)) entities.set(m[1], m[2]);
  const out = [];
  for (const [, body] of entities) {
    const m = body.match(/^B_SPLINE_SURFACE_WITH_KNOTS\('[^']*',(\d+),(\d+),\((.*?)\)\),/);
    if (!m) continue;
    const rows = m[3].split(/\)\s*,\s*\(/).map((r) => r.replace(/[()]/g, '').split(',').map((ref) => ref.trim().slice(1)));
    const points = [];
    for (const row of rows)
      for (const ref of row) {
        const p = entities.get(ref).match(/CARTESIAN_POINT\('[^']*',\(([^)]*)\)\)/);
        points.push(...p[1].split(',').map(Number));
      }
    out.push({ degrees: [Number(m[1]), Number(m[2])], counts: [rows.length, rows[0].length], points });
  }
  return out;
}

// ------------------------------------------------------------------ the studio
const work = mkdtempSync(join(tmpdir(), 'clayform-studio-'));
writeFileSync(join(work, 'drawn.json'), JSON.stringify({ format: 'clayform.recipe', version: 1, name: 'drawn' }));
// The drawing part's studio (the other parts open studios of their own).
const main = wants('drawing') ? await startStudio(clayform, join(work, 'drawn.json')) : null;
const { url, port } = main || {};
const studio = main && main.process;
const token = main ? new URL(url).searchParams.get('token') : null;

const results = [];
const figures = {};
async function check(name, fn) {
  const t0 = Date.now();
  try {
    const note = await fn();
    results.push(true);
    console.log(`ok - ${name}${note ? ` (${note})` : ''} [${Date.now() - t0} ms]`);
  } catch (e) {
    results.push(false);
    console.log(`not ok - ${name}\n    ${String(e && e.stack ? e.stack : e).split('\n').slice(0, 5).join('\n    ')}`);
  }
}
function assert(cond, message) {
  if (!cond) throw new Error(message);
}

const browser = await launchBrowser(executablePath);
const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
const problems = [];
page.on('console', (m) => m.type() === 'error' && problems.push(`console error: ${m.text()}`));
page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
const driver = studioPage(page);
const { idle, lastError, clickAt, clickCurve } = driver;
const studioCall = driver.call;
let shotCount = 0;
async function shot(label) {
  if (!shots) return;
  mkdirSync(shots, { recursive: true });
  await page.screenshot({ path: join(shots, `${String(++shotCount).padStart(2, '0')}-${label}.png`) });
}

/**
 * Runs `fn(page, driver)` on a studio of its own: `clayform studio FILE` and a page open on it
 * (its page errors counted as the test's), closed and stopped afterwards.
 */
async function withStudio(file, label, fn) {
  const studio = await startStudio(clayform, file);
  const other = await browser.newPage({ viewport: { width: 1100, height: 700 } });
  other.on('pageerror', (e) => problems.push(`page error (${label}): ${e.message}`));
  const driver = studioPage(other);
  try {
    await driver.open(studio.url);
    return await fn(other, driver);
  } finally {
    await other.close();
    studio.process.kill();
  }
}

/**
 * withStudio on a new empty recipe NAME.json in a folder of its own, the Sketch tool chosen and
 * snapping off: fn(page, driver).
 */
async function withEmptyRecipe(name, fn) {
  const dir = join(work, name);
  mkdirSync(dir);
  writeFileSync(join(dir, `${name}.json`), JSON.stringify({ format: 'clayform.recipe', version: 1, name }));
  return withStudio(join(dir, `${name}.json`), name, async (other, driver) => {
    await other.click('#tool-sketch');
    await other.uncheck('#snap');
    return fn(other, driver);
  });
}

/** Draws a stroke through world points on the plane z = z0; the drawn path back-projected onto it, here. */
/** The largest distance from `surface` to `map` of `parent` at the same (u, v), on an (n + 1)^2 grid. */
function offPointwise(surface, parent, map, n) {
  const [[u0, u1], [v0, v1]] = surfaceDomain(surface);
  let worst = 0;
  for (let a = 0; a <= n; a++)
    for (let b = 0; b <= n; b++) {
      const u = u0 + ((u1 - u0) * a) / n;
      const v = v0 + ((v1 - v0) * b) / n;
      worst = Math.max(worst, dist(surfaceAt(surface, u, v), map(surfaceAt(parent, u, v))));
    }
  return worst;
}

/**
 * The kernel's deviation map of `name` (window.clayStudio.deviations()) against the distance
 * computed here at its grid: from the surface to `map` applied to its parent, at the same
 * fractions of each domain. Asserts they agree within 1e-9 mm; returns {max, off}.
 */
async function deviationAgainst(call, name, surface, parent, map) {
  const dev = (await call(() => window.clayStudio.deviations()))[name];
  assert(dev && dev.rows > 1 && dev.cols > 1, `no deviation map of ${name}`);
  const [[u0, u1], [v0, v1]] = surfaceDomain(surface);
  const [[a0, a1], [b0, b1]] = surfaceDomain(parent);
  const at = (lo, hi, k, n) => (k === n - 1 ? hi : lo + ((hi - lo) * k) / (n - 1));
  let off = 0;
  for (let i = 0; i < dev.rows; i += 4)
    for (let j = 0; j < dev.cols; j += 4) {
      const here = dist(surfaceAt(surface, at(u0, u1, i, dev.rows), at(v0, v1, j, dev.cols)), map(surfaceAt(parent, at(a0, a1, i, dev.rows), at(b0, b1, j, dev.cols))));
      off = Math.max(off, Math.abs(here - dev.values[i * dev.cols + j]));
    }
  assert(off <= 1e-9, `the deviation map of ${name} is ${off} mm from the distances computed here`);
  return { max: dev.max, off };
}

async function draw(world, { steps = 40, z0 = 0 } = {}) {
  const path = await driver.draw(world, { steps });
  const cam = await studioCall(() => window.clayStudio.camera());
  return path.map(([x, y]) => backProject(cam, x, y, z0));
}
/** Checks a fitted curve against the drawn points: each within the stroke's tolerance (ends: plus how far snapping moved them). */
async function checkStroke(name, drawn) {
  const recipe = await studioCall(() => window.clayStudio.recipe());
  const curves = await studioCall(() => window.clayStudio.curves());
  const stroke = recipe.strokes[name];
  assert(stroke && curves[name], `no stroke or curve "${name}"`);
  const snapStart = dist(stroke.points[0], drawn[0]);
  const snapEnd = dist(stroke.points[stroke.points.length - 1], drawn[drawn.length - 1]);
  let worst = 0;
  drawn.forEach((x, k) => {
    const allowance = k === 0 ? snapStart : k === drawn.length - 1 ? snapEnd : 0;
    const d = distanceToCurve(curves[name], x);
    worst = Math.max(worst, d - allowance);
  });
  assert(worst <= stroke.tolerance * (1 + 1e-9), `curve ${name}: a drawn point is ${worst} mm from the fitted curve, tolerance ${stroke.tolerance}`);
  return { worst, snapStart, snapEnd, control_points: curves[name].weights.length };
}
try {
  if (wants('drawing')) {
    await driver.open(url);
    await studioCall(() => window.clayStudio.setView('top'));
    await page.keyboard.press('s'); // the sketch tool (its key), on plane XY

    const edges = {
      s1: along([-300, -200], [300, -200], -30),
      s2: along([300, -200], [300, 200], 0),
      s3: along([300, 200], [-300, 200], 0),
      s4: along([-300, 200], [-300, -200], 0),
    };
    const drawnEdges = {};
    await check('strokes on the XY plane are fitted within their tolerance of the drawn path, back-projected', async () => {
      const notes = [];
      for (const [name, world] of Object.entries(edges)) {
        drawnEdges[name] = await draw(world);
        const r = await checkStroke(name, drawnEdges[name]);
        notes.push(`${name} ${r.control_points} points, ${r.worst.toExponential(2)} mm`);
      }
      const stroke = await studioCall(() => window.clayStudio.metrics.stroke.map((m) => m.ms));
      figures.stroke_to_curve_ms = { p50: quantile(stroke, 0.5), p95: quantile(stroke, 0.95), n: stroke.length };
      return notes.join('; ');
    });
    await shot('strokes');

    await check('a fill of the four curves, picked with the mouse', async () => {
      await page.click('#tool-orbit');
      await clickCurve('s1', false);
      for (const n of ['s2', 's3', 's4']) await clickCurve(n, true);
      const selected = await page.locator('#selection').textContent();
      assert(['s1', 's2', 's3', 's4'].every((n) => selected.includes(`curve ${n}`)), `selection: ${selected}`);
      await page.click('#build-fill');
      await idle();
      assert(!(await lastError()), await lastError());
      const surfaces = await studioCall(() => window.clayStudio.surfaces());
      assert(surfaces.fill1, `no surface fill1 (${Object.keys(surfaces)})`);
      // the Coons patch's boundary lies on the curves (to the snap of their ends)
      const curves = await studioCall(() => window.clayStudio.curves());
      const s = surfaces.fill1;
      const [[u0, u1], [v0, v1]] = surfaceDomain(s);
      let worst = 0;
      for (let k = 0; k <= 20; k++) {
        const f = k / 20;
        for (const [u, v] of [[u0 + f * (u1 - u0), v0], [u0 + f * (u1 - u0), v1], [u0, v0 + f * (v1 - v0)], [u1, v0 + f * (v1 - v0)]]) {
          const x = surfaceAt(s, u, v);
          worst = Math.max(worst, Math.min(...Object.keys(edges).map((n) => distanceToCurve(curves[n], x))));
        }
      }
      const step = (await studioCall(() => window.clayStudio.reply())).steps.find((st) => st.path === 'surfaces.fill1');
      const snapped = step.figures.snapped_mm || 0;
      assert(worst <= snapped + 1e-6, `the fill's boundary is ${worst} mm off its curves (ends snapped by ${snapped} mm)`);
      figures.fill = { control_points: s.counts[0] * s.counts[1], boundary_off_mm: worst, snapped_mm: snapped };
      return `${s.counts[0]} x ${s.counts[1]} control points, boundary within ${worst.toExponential(2)} mm of the curves`;
    });

    let bound = null;
    await check('a bound and a target drawn, style in exact mode: local, and the target met', async () => {
      await page.click('#tool-sketch');
      const loop = Array.from({ length: 33 }, (_, k) => [160 * Math.cos((2 * Math.PI * k) / 32), 110 * Math.sin((2 * Math.PI * k) / 32), 0]);
      await draw(loop, { steps: 64 });
      await page.fill('#sketch-offset', '40');
      const drawnTarget = await draw(along([-90, -10], [90, -10], 15), { z0: 40 });
      await checkStroke('s6', drawnTarget);
      await page.fill('#sketch-offset', '0');
      await page.click('#tool-orbit');
      await clickCurve('s5', false);
      await clickCurve('s6', true);
      await page.click('#build-style');
      await idle();
      assert(!(await lastError()), await lastError());
      const reply = await studioCall(() => window.clayStudio.reply());
      const step = reply.steps.find((st) => st.kind === 'style');
      assert(step, `no style step in ${reply.steps.map((s) => s.path)}`);
      const f = step.figures;
      assert(f.mode === 'exact' && f.outcome === 'met', `style: mode ${f.mode}, outcome ${f.outcome}: ${step.message}`);
      assert(f.locality === 0, `style: locality ${f.locality}`);
      const surfaces = await studioCall(() => window.clayStudio.surfaces());
      const befores = await studioCall(() => window.clayStudio.befores());
      const styled = surfaces.fill1_styled1;
      const parent = befores.fill1_styled1;
      assert(styled && parent, `no styled surface or its parent (${Object.keys(surfaces)})`);
      // Locality, here: where every control point of the styled net (the parent's, refined by
      // exact mode's knot insertion, then moved) that carries a surface point lies outside the
      // bound, the point did not move.
      const curves = await studioCall(() => window.clayStudio.curves());
      bound = curves.s5;
      const [ba, bb] = curveDomain(bound);
      const polygon = Array.from({ length: 400 }, (_, k) => curveAt(bound, ba + ((bb - ba) * k) / 400));
      const [[u0, u1], [v0, v1]] = surfaceDomain(styled);
      const [p, q] = styled.degrees;
      const [, nv] = styled.counts;
      const span = (knots, deg, n, t) => {
        let k = deg;
        while (k < n - 1 && !(t >= knots[k] && t < knots[k + 1])) k++;
        return k;
      };
      let checked = 0;
      let moved = 0;
      for (let a = 0; a <= 60; a++)
        for (let b = 0; b <= 60; b++) {
          const u = u0 + ((u1 - u0) * a) / 60;
          const v = v0 + ((v1 - v0) * b) / 60;
          const su = span(styled.knots_u, p, styled.counts[0], u);
          const sv = span(styled.knots_v, q, nv, v);
          let outside = true;
          for (let i = su - p; i <= su && outside; i++)
            for (let j = sv - q; j <= sv && outside; j++) {
              const k = i * nv + j;
              if (insidePolygon(polygon, styled.points[3 * k], styled.points[3 * k + 1])) outside = false;
            }
          if (!outside) continue;
          checked++;
          moved = Math.max(moved, dist(surfaceAt(styled, u, v), surfaceAt(parent, u, v)));
        }
      assert(checked > 100, `only ${checked} samples are carried by control points outside the bound`);
      assert(moved <= 1e-9, `a point carried only by control points outside the bound moved ${moved} mm`);
      // the target met: the styled surface passes through the target curve (within the step's
      // curve tolerance, relative to the model's size, as reported)
      figures.style = { key_points: f.key_points, target_deviation: f.target_deviation, target_curve_deviation: f.target_curve_deviation, locality: f.locality, moved_outside_mm: moved, samples_outside: checked, kernel_ms: 1000 * step.seconds };
      return `${f.key_points} key points, target deviation ${f.target_deviation}, curve ${f.target_curve_deviation}; ${checked} samples outside the bound moved ${moved} mm`;
    });
    await shot('styled');

    await check('the target curve dragged by a control point: the style follows, in one history entry', async () => {
      await clickCurve('s6', false);
      await page.click('#tool-edit');
      const handle = (await studioCall(() => window.clayStudio.handles())).find((h) => h.kind === 'curve' && h.name === 's6' && h.index === 1);
      assert(handle, 'no handle of the target curve s6');
      const entries = (await studioCall(() => window.clayStudio.history())).entries.length;
      await page.mouse.move(...handle.screen);
      await page.mouse.down();
      for (let k = 1; k <= 20; k++) await page.mouse.move(handle.screen[0] + k, handle.screen[1] - 2 * k);
      await page.mouse.up();
      await idle();
      assert(!(await lastError()), await lastError());
      const recipe = await studioCall(() => window.clayStudio.recipe());
      assert(!recipe.strokes.s6 && recipe.curves.s6 && recipe.curves.s6.bspline, 'the target stroke did not become a B-spline curve');
      const history = await studioCall(() => window.clayStudio.history());
      assert(history.entries.length === entries + 1, `the drag made ${history.entries.length - entries} history entries`);
      const step = (await studioCall(() => window.clayStudio.reply())).steps.find((st) => st.kind === 'style');
      assert(step.figures.outcome === 'met' && step.figures.locality === 0, `style after the drag: ${step.figures.outcome}, locality ${step.figures.locality}`);
      // the fitted curve's control point moved where the pointer went, in the view plane
      const curves = await studioCall(() => window.clayStudio.curves());
      const moved = dist(curves.s6.points.slice(3, 6), handle.p);
      assert(moved > 1, `the control point moved ${moved} mm`);
      await page.click('#tool-orbit');
      return `control point moved ${moved.toFixed(1)} mm; ${step.figures.key_points} key points, target deviation ${step.figures.target_deviation}`;
    });

    await check('a new target drawn with "restyle while drawing": the surface follows the pen, one history entry', async () => {
      await page.click('#tool-orbit');
      await clickAt([260, 170, 0], false);
      const selected = await page.locator('#selection').textContent();
      assert(selected.includes('surface fill1_styled1'), `selection: ${selected}`);
      const recipe0 = await studioCall(() => window.clayStudio.recipe());
      const style = recipe0.surfaces.fill1_styled1.deform.deformation;
      const entries = (await studioCall(() => window.clayStudio.history())).entries.length;
      await page.check('#style-live');
      await page.fill('#sketch-offset', '40');
      await page.click('#tool-sketch');
      const drawn = await draw(along([-90, 20], [90, 20], -15), { steps: 80, z0: 40 });
      await page.uncheck('#style-live');
      await page.fill('#sketch-offset', '0');
      await page.click('#tool-orbit');
      assert(!(await lastError()), await lastError());
      const live = await studioCall(() => window.clayStudio.lastLive());
      assert(live && live.style === style && live.updates >= 3, `live updates: ${JSON.stringify(live)}`);
      const recipe = await studioCall(() => window.clayStudio.recipe());
      assert(recipe.deformations[style][0].target === live.name, `the style's target is ${recipe.deformations[style][0].target}, not ${live.name}`);
      const history = await studioCall(() => window.clayStudio.history());
      assert(history.entries.length === entries + 1, `the drawing made ${history.entries.length - entries} history entries`);
      const { worst } = await checkStroke(live.name, drawn);
      const step = (await studioCall(() => window.clayStudio.reply())).steps.find((st) => st.kind === 'style');
      assert(step.figures.outcome === 'met' && step.figures.locality === 0, `style after the live target: ${step.figures.outcome}, locality ${step.figures.locality}`);
      // undone: the surface is styled by the earlier target again (the rest of the test goes on from there)
      await page.click('#undo');
      await idle();
      const back = await studioCall(() => window.clayStudio.recipe());
      assert(back.deformations[style][0].target === recipe0.deformations[style][0].target && !back.strokes[live.name], 'undo did not take the live target back');
      return `${live.updates} updates sent while drawing (newest wins), one history entry; the target ${live.name} within ${worst.toExponential(2)} mm of the drawn path; key points met (${step.figures.key_points}), locality 0`;
    });

    await check('analysis modes: zebra and curvature maps, before and after', async () => {
      for (const mode of ['zebra', 'mean', 'gaussian', 'shaded']) {
        await page.click(`button[data-mode="${mode}"]`);
        assert((await page.evaluate(() => document.body.dataset.mode)) === mode, `mode ${mode} not shown`);
        await idle();
        if (mode !== 'shaded') await shot(mode);
      }
      await page.keyboard.press('b');
      await idle();
      await shot('before');
      const pressed = await page.getAttribute('#before-after', 'aria-pressed');
      await page.keyboard.press('b');
      await idle();
      assert(pressed === 'true', 'the before view did not switch on');
    });

    let beforeDrag = null;
    let afterDrag = null;
    await check('a lattice on the styled surface, a point dragged for 5 s: the surface is the pointwise FFD', async () => {
      await clickAt([260, 170, 0], false);
      const selected = await page.locator('#selection').textContent();
      assert(selected.includes('surface fill1_styled1'), `selection: ${selected}`);
      await page.click('#build-lattice');
      await idle();
      assert(!(await lastError()), await lastError());
      beforeDrag = (await studioCall(() => window.clayStudio.surfaces())).fill1_styled1_ffd1;
      assert(beforeDrag, 'no surface fill1_styled1_ffd1');
      const handle = (await studioCall(() => window.clayStudio.handles())).find((h) => h.kind === 'lattice' && h.index.join() === '2,2,1');
      assert(handle, 'no handle of lattice point [2, 2, 1]');
      await studioCall(() => window.clayStudio.resetMetrics());
      await page.mouse.move(...handle.screen);
      await page.mouse.down();
      const t0 = Date.now();
      const n = 150;
      for (let k = 1; k <= n; k++) {
        const f = k / n;
        await page.mouse.move(handle.screen[0] + 60 * f, handle.screen[1] - 45 * f);
        const wait = t0 + (5000 * k) / n - Date.now();
        if (wait > 0) await new Promise((r) => setTimeout(r, wait));
      }
      await page.mouse.up();
      await idle();
      assert(!(await lastError()), await lastError());
      const recipe = await studioCall(() => window.clayStudio.recipe());
      const step = recipe.deformations.lattice1[0];
      const moves = step.moves;
      assert(moves.length === 1 && moves[0].index.join() === '2,2,1', `moves: ${JSON.stringify(moves)}`);
      const surfaces = await studioCall(() => window.clayStudio.surfaces());
      const befores = await studioCall(() => window.clayStudio.befores());
      afterDrag = surfaces.fill1_styled1_ffd1;
      const parent = befores.fill1_styled1_ffd1;
      const points = latticePoints(step);
      const worst = offPointwise(afterDrag, parent, (x) => ffd(step, points, x), 24);
      assert(worst <= 1e-9 * 1000, `the dragged surface is ${worst} mm off the pointwise FFD`);
      // The Deviation mode's map, the kernel's: at its grid, the distance computed here from the
      // surface to the pointwise FFD of its parent.
      const deviation = await deviationAgainst(studioCall, 'fill1_styled1_ffd1', afterDrag, parent, (x) => ffd(step, points, x));
      assert(deviation.max <= 1e-9 * 1000, `the deviation map's largest value is ${deviation.max} mm (exact composition)`);
      await page.click('button[data-mode="deviation"]');
      await idle();
      const legend = await page.locator('#legend').textContent();
      assert(legend.includes('deviation from the pointwise deformation'), `legend: ${legend}`);
      await shot('deviation');
      await page.click('button[data-mode="shaded"]');
      const m = await studioCall(() => ({ dragEnd: window.clayStudio.metrics.dragEnd, drag: window.clayStudio.metrics.drag, preview: window.clayStudio.metrics.preview, frames: window.clayStudio.metrics.frames, kernel: window.clayStudio.metrics.kernel, evaluate: window.clayStudio.metrics.evaluate }));
      // drag to redraw: the pointer move to the frame that shows it (the page's FFD of the parent's
      // samples); kernel confirmation: the pointer move to the kernel's answer (the recipe checked
      // and run, exact composition included); at the release, to the frame of the exact nets
      const halves = (list) => {
        const start = list.length ? list[0].at : 0;
        return [quantile(list.filter((d) => d.at - start < 2500).map((d) => d.ms), 0.95), quantile(list.filter((d) => d.at - start >= 2500).map((d) => d.ms), 0.95)];
      };
      const lat = m.preview.map((d) => d.ms);
      const exact = m.drag.map((d) => d.ms);
      const frameMs = m.frames.filter((x) => x > 0);
      assert(lat.length > 0, 'no drag frame was drawn');
      figures.drag = {
        pointer_moves: n,
        redraws: lat.length,
        latency_ms: { p50: quantile(lat, 0.5), p95: quantile(lat, 0.95), max: Math.max(...lat) },
        latency_p95_first_second_half_ms: halves(m.preview),
        kernel_updates: exact.length,
        kernel_latency_ms: { p50: quantile(exact, 0.5), p95: quantile(exact, 0.95), max: Math.max(...exact) },
        kernel_latency_p95_first_second_half_ms: halves(m.drag),
        release_to_exact_nets_drawn_ms: m.dragEnd.map((d) => d.ms),
        fps: frameMs.length ? 1000 / (frameMs.reduce((a, b) => a + b, 0) / frameMs.length) : 0,
        kernel_ms: { p50: quantile(m.kernel, 0.5), p95: quantile(m.kernel, 0.95) },
        page_evaluation_ms: { p50: quantile(m.evaluate, 0.5), p95: quantile(m.evaluate, 0.95) },
        control_points: afterDrag.counts[0] * afterDrag.counts[1],
        degrees: afterDrag.degrees,
        ffd_deviation_mm: worst,
        deviation_map: { max_mm: deviation.max, off_independent_mm: deviation.off },
      };
      return `${n} pointer moves: ${lat.length} redraws, p95 ${figures.drag.latency_ms.p95.toFixed(0)} ms; ${exact.length} kernel updates, p95 ${figures.drag.kernel_latency_ms.p95.toFixed(0)} ms; ${figures.drag.fps.toFixed(0)} fps; off the FFD by ${worst.toExponential(2)} mm`;
    });
    await shot('lattice');

    const sameNet = (a, b) => a && b && a.points.length === b.points.length && a.points.every((x, i) => x === b.points[i]) && a.knots_u.every((x, i) => x === b.knots_u[i]);
    await check('undo takes the drag back as one step, redo puts it back', async () => {
      const history = await studioCall(() => window.clayStudio.history());
      assert(history.entries[history.position].startsWith('move lattice'), `history: ${history.entries}`);
      await page.keyboard.press('Control+z');
      await idle();
      const undone = (await studioCall(() => window.clayStudio.surfaces())).fill1_styled1_ffd1;
      assert(sameNet(undone, beforeDrag), 'after undo the surface is not the one before the drag');
      await page.click('#redo');
      await idle();
      const redone = (await studioCall(() => window.clayStudio.surfaces())).fill1_styled1_ffd1;
      assert(sameNet(redone, afterDrag), 'after redo the surface is not the dragged one');
      return `${history.entries.length} entries: ${history.entries.join(' | ')}`;
    });

    await check('the saved recipe, run by clayform run, gives the same control points bit for bit', async () => {
      await page.fill('#save-name', 'saved.json');
      await page.click('#save');
      await idle();
      assert(!(await lastError()), await lastError());
      await page.waitForFunction(() => document.getElementById('message').textContent.startsWith('saved'), null, { timeout: 10000 });
      const out = join(work, 'replay');
      const run = spawnSync(clayform, ['run', join(work, 'saved.json'), '--out', out, '--quiet'], { encoding: 'utf8' });
      assert(run.status === 0, `clayform run: ${run.status} ${run.stderr}`);
      const step = readdirSync(out).find((f) => f.endsWith('.step'));
      assert(step, `no STEP file in ${readdirSync(out)}`);
      const written = stepSurfaces(readFileSync(join(out, step), 'utf8'));
      const shown = await studioCall(() => window.clayStudio.surfaces());
      const names = Object.keys(shown);
      assert(written.length === names.length, `${written.length} surfaces in ${step}, the page shows ${names.length}`);
      let compared = 0;
      names.forEach((n, i) => {
        const a = shown[n];
        const b = written[i];
        assert(a.points.length === b.points.length, `${n}: ${a.points.length / 3} control points on the page, ${b.points.length / 3} in ${step}`);
        a.points.forEach((x, k) => assert(x === b.points[k], `${n}: control point coordinate ${k}: ${x} on the page, ${b.points[k]} replayed`));
        compared += a.points.length / 3;
      });
      return `${compared} control points identical`;
    });

    await check('export writes STEP, IGES and glTF, read back and checked', async () => {
      await page.click('#export');
      await page.waitForFunction(() => document.getElementById('message').textContent.startsWith('exported') || document.body.dataset.error, null, { timeout: 60000 });
      assert(!(await lastError()), await lastError());
      const files = readdirSync(join(work, 'drawn-export'));
      for (const ext of ['.step', '.igs', '.glb']) assert(files.some((f) => f.endsWith(ext)), `no ${ext} in ${files}`);
      return files.join(', ');
    });

    await check('a socket from another origin is refused (403), the page keeps its own', async () => {
      const status = (origin) =>
        new Promise((resolvePromise, reject) => {
          const req = request({ host: '127.0.0.1', port, path: `/ws?token=${token}`, headers: { Connection: 'Upgrade', Upgrade: 'websocket', 'Sec-WebSocket-Version': '13', 'Sec-WebSocket-Key': 'dGhlIHNhbXBsZSBub25jZQ==', Host: `127.0.0.1:${port}`, Origin: origin } });
          req.on('response', (res) => {
            res.resume();
            resolvePromise(res.statusCode);
          });
          req.on('upgrade', (res, socket) => {
            socket.destroy();
            resolvePromise(101);
          });
          req.on('error', reject);
          req.end();
        });
      const evil = await status('http://evil.example');
      assert(evil === 403, `Origin http://evil.example: ${evil}`);
      // a page served from another origin tries it in the browser
      const other = createServer((req, res) => {
        res.writeHead(200, { 'Content-Type': 'text/html' });
        res.end('<!doctype html><title>elsewhere</title>');
      });
      await new Promise((r) => other.listen(0, '127.0.0.1', r));
      const elsewhere = await browser.newPage();
      await elsewhere.goto(`http://127.0.0.1:${other.address().port}/`);
      const outcome = await elsewhere.evaluate(
        (wsUrl) =>
          new Promise((r) => {
            const ws = new WebSocket(wsUrl);
            ws.onopen = () => r('open');
            ws.onerror = () => r('refused');
          }),
        `ws://127.0.0.1:${port}/ws?token=${token}`,
      );
      await elsewhere.close();
      other.close();
      assert(outcome === 'refused', `a page from another origin: ${outcome}`);
      return `raw upgrade ${evil}, browser page elsewhere ${outcome}`;
    });

  }
  if (wants('model')) {
    await check('a STEP model opened whole, a lattice placed around it and dragged, saved and replayed', async () => {
      const modelDir = join(work, 'model');
      mkdirSync(modelDir);
      copyFileSync(join(here, '..', '..', 'examples', 'models', 'block.step'), join(modelDir, 'block.step'));
      return withStudio(join(modelDir, 'block.step'), 'model', async (modelPage, m) => {
        const models = await m.call(() => window.clayStudio.models());
        assert(models.block && models.block.triangles > 0, `no mesh of the model: ${Object.keys(models)}`);
        const topBefore = Math.max(...models.block.positions.filter((_, k) => k % 3 === 2));
        // click the model where its mesh is, then Lattice
        const centre = [0, 1, 2].map((e) => {
          const c = models.block.positions.filter((_, k) => k % 3 === e);
          return (Math.min(...c) + Math.max(...c)) / 2;
        });
        await m.clickAt([centre[0], centre[1], topBefore], false);
        const selected = await modelPage.locator('#selection').textContent();
        assert(selected.includes('model block'), `selection: ${selected}`);
        await modelPage.click('#build-lattice');
        await m.idle();
        assert(!(await m.lastError()), await m.lastError());
        const handle = (await m.call(() => window.clayStudio.handles())).find((h) => h.kind === 'lattice' && h.index.join() === '1,1,1');
        assert(handle, 'no lattice handle [1, 1, 1]');
        await modelPage.selectOption('#lattice-lock', 'z');
        await modelPage.mouse.move(...handle.screen);
        await modelPage.mouse.down();
        for (let k = 1; k <= 10; k++) await modelPage.mouse.move(handle.screen[0], handle.screen[1] - 3 * k);
        await modelPage.mouse.up();
        await m.idle();
        assert(!(await m.lastError()), await m.lastError());
        const after = await m.call(() => window.clayStudio.models());
        const topAfter = Math.max(...after.block.positions.filter((_, k) => k % 3 === 2));
        assert(topAfter > topBefore + 1e-6, `the model's top did not rise: ${topBefore} -> ${topAfter}`);
        // Only positions changed, so the kernel sent the faces' nets, not a mesh, and the page moved
        // the nodes of the mesh it held onto them: each node is where Sederberg–Parry's FFD of the
        // lattice in the recipe takes the node's first position.
        assert(after.block.from === 'model_nets', `the model came as a ${after.block.from} frame after the drag`);
        assert(after.block.triangles === models.block.triangles, 'the mesh changed its triangles');
        const recipe = await m.call(() => window.clayStudio.recipe());
        const step = recipe.deformations[recipe.models.block.deformation][0];
        const lattice = latticePoints(step);
        let worstNode = 0;
        for (let k = 0; k < models.block.positions.length; k += 3) {
          const want = ffd(step, lattice, models.block.positions.slice(k, k + 3));
          worstNode = Math.max(worstNode, Math.hypot(...[0, 1, 2].map((e) => after.block.positions[k + e] - want[e])));
        }
        assert(worstNode < 1e-9, `a node of the model is ${worstNode} mm from the pointwise FFD`);
        await modelPage.fill('#save-name', 'block_studio.json');
        await modelPage.click('#save');
        await m.idle();
        const run = spawnSync(clayform, ['run', join(modelDir, 'block_studio.json'), '--out', join(modelDir, 'replay'), '--quiet'], { encoding: 'utf8' });
        assert(run.status === 0, `clayform run: ${run.status} ${run.stderr}`);
        const files = readdirSync(join(modelDir, 'replay'));
        assert(files.includes('block.step'), `replay wrote ${files}`);
        return `${models.block.triangles} triangles; the top rose ${(topAfter - topBefore).toFixed(2)} mm; after the drag the faces' nets only, the nodes ${worstNode.toExponential(1)} mm from the pointwise FFD; replay wrote ${files.filter((f) => f.startsWith('block')).join(', ')}`;
      });
    });

  }
  if (wants('regular')) {
    await check('taper and twist from the sliders against Barr\'s formulas; a surface point pulled by direct manipulation; a B-spline lattice dragged', async () => {
      // a studio on a recipe holding one bicubic patch, 400 x 200 mm with a bump
      const dir = join(work, 'global');
      mkdirSync(dir);
      const knots = [0, 0, 0, 0, 1, 1, 1, 1];
      const points = [];
      for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) points.push([-200 + (400 * i) / 3, -100 + (200 * j) / 3, (i === 1 || i === 2) && (j === 1 || j === 2) ? 30 : 0]);
      writeFileSync(join(dir, 'patch.json'), JSON.stringify({ format: 'clayform.recipe', version: 1, name: 'patch', surfaces: { patch: { bspline: { degrees: [3, 3], knots_u: knots, knots_v: knots, points } } } }));
      return withStudio(join(dir, 'patch.json'), 'global', async (globalPage, g) => {
        await g.clickAt([60, 30, 17], false);
        await globalPage.click('#build-global');
        await g.idle();
        assert(!(await g.lastError()), await g.lastError());
        for (const [id, value] of [['global-taper', 0.3], ['global-twist', 30]]) {
          await globalPage.$eval(`#${id}`, (el, v) => {
            el.value = String(v);
            el.dispatchEvent(new Event('input'));
            el.dispatchEvent(new Event('change'));
          }, value);
          await g.idle();
          assert(!(await g.lastError()), await g.lastError());
        }
        const recipe = await g.call(() => window.clayStudio.recipe());
        const [taper, twist] = recipe.deformations.global1;
        const surfaces = await g.call(() => window.clayStudio.surfaces());
        const befores = await g.call(() => window.clayStudio.befores());
        const shaped = surfaces.patch_global1;
        const parent = befores.patch_global1;
        // Barr (Güdükbay–Özgüç §3.1): local z along the axis, x along the reference, y = z × x;
        // taper r = 1 + c z scales x and y, twist turns them by θ = a z
        const { origin, axis, reference } = taper.frame;
        const yAxis = [axis[1] * reference[2] - axis[2] * reference[1], axis[2] * reference[0] - axis[0] * reference[2], axis[0] * reference[1] - axis[1] * reference[0]];
        const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        const barr = (p) => {
          const d = [0, 1, 2].map((e) => p[e] - origin[e]);
          const x = dot(d, reference);
          const y = dot(d, yAxis);
          const z = dot(d, axis);
          const r = taper.profile[0] + taper.profile[1] * z;
          const t = twist.angle[0] + twist.angle[1] * z;
          const X = r * x * Math.cos(t) - r * y * Math.sin(t);
          const Y = r * x * Math.sin(t) + r * y * Math.cos(t);
          return [0, 1, 2].map((e) => origin[e] + X * reference[e] + Y * yAxis[e] + z * axis[e]);
        };
        const worst = offPointwise(shaped, parent, barr, 20);
        const steps = (await g.call(() => window.clayStudio.reply())).steps.filter((st) => st.path.startsWith('surfaces.patch_global1.steps'));
        const allowed = steps.reduce((sum, st) => sum + (st.figures.tolerance_mm || 0), 0);
        assert(worst <= allowed, `the surface is ${worst} mm from Barr's taper and twist of its parent; the steps' tolerances add to ${allowed} mm`);
        const barrNote = `${worst.toExponential(2)} mm from Barr's formulas (tolerances add to ${allowed.toExponential(2)} mm)`;
        // Direct manipulation: Shift-drag a point of the patch up (z locked); the surface point
        // pressed must end where the pointer took it (Hsu–Hughes–Kaufman), to the refit's tolerance.
        await globalPage.click('#tool-edit');
        await globalPage.selectOption('#lattice-lock', 'z');
        const press = await g.call(() => window.clayStudio.toScreen([-60, 20, 20]));
        await globalPage.keyboard.down('Shift');
        await globalPage.mouse.move(...press);
        await globalPage.mouse.down();
        for (let k = 1; k <= 10; k++) await globalPage.mouse.move(press[0], press[1] - 3 * k);
        await globalPage.mouse.up();
        await globalPage.keyboard.up('Shift');
        await g.idle();
        assert(!(await g.lastError()), await g.lastError());
        const after = await g.call(() => window.clayStudio.recipe());
        const pullName = Object.keys(after.deformations).find((n) => n.startsWith('pull'));
        assert(pullName, `no direct manipulation step: ${Object.keys(after.deformations)}`);
        const move = after.deformations[pullName][0].moves[0];
        const pulledName = Object.keys(after.surfaces).find((n) => after.surfaces[n].deform && after.surfaces[n].deform.deformation === pullName);
        const pulled = (await g.call(() => window.clayStudio.surfaces()))[pulledName];
        const reached = dist(surfaceAt(pulled, move.surface_point[0], move.surface_point[1]), move.to);
        const pullStep = (await g.call(() => window.clayStudio.reply())).steps.find((st) => st.path === `surfaces.${pulledName}.steps[0]`);
        const tolerance = pullStep.figures.tolerance_mm;
        assert(reached <= tolerance, `the pulled point is ${reached} mm from where it was taken (tolerance ${tolerance} mm)`);
        const history = await g.call(() => window.clayStudio.history());
        assert(history.entries.filter((e) => e.startsWith('drag patch_global1')).length === 1, `history: ${history.entries}`);
        const dmNote = `direct manipulation: the point pulled to within ${reached.toExponential(2)} mm of the pointer's target (tolerance ${tolerance.toExponential(2)} mm)`;
        // A B-spline lattice on the pulled patch, a point dragged up: the surface is the pointwise
        // B-spline FFD of its parent (Hsu–Hughes–Kaufman eq. 1), to the refit's tolerance.
        await globalPage.click('#tool-orbit');
        await g.clickAt(surfaceAt(pulled, (surfaceDomain(pulled)[0][0] + surfaceDomain(pulled)[0][1]) / 2, (surfaceDomain(pulled)[1][0] + surfaceDomain(pulled)[1][1]) / 2), false);
        await globalPage.selectOption('#lattice-kind', 'bspline');
        await globalPage.click('#build-lattice');
        await g.idle();
        assert(!(await g.lastError()), await g.lastError());
        const lh = (await g.call(() => window.clayStudio.handles())).find((h) => h.kind === 'lattice' && h.index.join() === '3,3,1');
        assert(lh, 'no B-spline lattice handle [3, 3, 1]');
        await globalPage.mouse.move(...lh.screen);
        await globalPage.mouse.down();
        for (let k = 1; k <= 8; k++) await globalPage.mouse.move(lh.screen[0], lh.screen[1] - 3 * k);
        // while the point is held, the page draws Hsu–Hughes–Kaufman's FFD of the parent's samples
        const drawing = await g.call(() => ({ previews: window.clayStudio.previews(), recipe: window.clayStudio.recipe(), parents: window.clayStudio.befores() }));
        await globalPage.mouse.up();
        await g.idle();
        assert(!(await g.lastError()), await g.lastError());
        const r3 = await g.call(() => window.clayStudio.recipe());
        const latName = Object.keys(r3.deformations).find((n) => r3.deformations[n][0].kind === 'bspline_lattice');
        const latStep = r3.deformations[latName][0];
        assert(latStep.moves.length === 1, `moves: ${JSON.stringify(latStep.moves)}`);
        const latSurface = Object.keys(r3.surfaces).find((n) => r3.surfaces[n].deform && r3.surfaces[n].deform.deformation === latName);
        const shapedB = (await g.call(() => window.clayStudio.surfaces()))[latSurface];
        const parentB = (await g.call(() => window.clayStudio.befores()))[latSurface];
        const latPoints = bsplineLatticePoints(latStep);
        const offB = offPointwise(shapedB, parentB, (x) => bsplineFfd(latStep, latPoints, x), 16);
        const latRep = (await g.call(() => window.clayStudio.reply())).steps.find((st) => st.path === `surfaces.${latSurface}.steps[0]`);
        assert(offB <= latRep.figures.tolerance_mm, `the B-spline lattice's surface is ${offB} mm off the pointwise FFD (tolerance ${latRep.figures.tolerance_mm})`);
        // The picture drawn while the point was held: each sample the pointwise B-spline FFD of
        // the parent's point there (float32 vertices), for the lattice as the recipe then held it.
        const heldName = Object.keys(drawing.previews)[0];
        assert(heldName, 'no picture was drawn while the B-spline lattice point was held');
        const held = drawing.previews[heldName];
        const heldParent = drawing.parents[heldName];
        const heldStep = drawing.recipe.deformations[latName][0];
        const [[pu0, pu1], [pv0, pv1]] = surfaceDomain(heldParent);
        let heldOff = 0;
        let heldScale = 0;
        for (let r = 0; r < held.rows; r += 7)
          for (let c = 0; c < held.cols; c += 7) {
            const u = r === held.rows - 1 ? pu1 : pu0 + ((pu1 - pu0) * r) / (held.rows - 1);
            const v = c === held.cols - 1 ? pv1 : pv0 + ((pv1 - pv0) * c) / (held.cols - 1);
            const want = bsplineFfd(heldStep, held.lattice, surfaceAt(heldParent, u, v));
            const k = r * held.cols + c;
            heldOff = Math.max(heldOff, dist(held.positions.slice(3 * k, 3 * k + 3), want));
            heldScale = Math.max(heldScale, ...want.map(Math.abs));
          }
        assert(held.lattice.length === bsplineLatticePoints(heldStep).length, 'the picture\'s lattice has another size');
        // float32 vertices
        assert(heldOff <= 1e-6 * heldScale, `the picture drawn while dragging is ${heldOff} mm from the pointwise B-spline FFD`);
        // a refit: its deviation map shows the refit's error, as computed here, within its tolerance
        const devB = await deviationAgainst(g.call, latSurface, shapedB, parentB, (x) => bsplineFfd(latStep, latPoints, x));
        assert(devB.max > 0 && devB.max <= latRep.figures.tolerance_mm, `the refit's deviation map: largest ${devB.max} mm (tolerance ${latRep.figures.tolerance_mm})`);
        return `${barrNote}; ${dmNote}; B-spline lattice: ${offB.toExponential(2)} mm off the pointwise FFD (tolerance ${latRep.figures.tolerance_mm.toExponential(2)} mm), its deviation map up to ${devB.max.toExponential(2)} mm, ${devB.off.toExponential(1)} mm from the distances computed here; the picture while dragging ${heldOff.toExponential(1)} mm from the pointwise FFD`;
      });
    });

  }
  if (wants('corners')) {
    await check('a stroke with corners split there into pieces and filled; a stroke mirrored in the plane x = 10', async () => {
      return withEmptyRecipe('corners', async (cp, k) => {
        // a 240 x 160 rectangle in one stroke, from the middle of its bottom side round and back
        const corner = [[-120, -80, 0], [120, -80, 0], [120, 80, 0], [-120, 80, 0]];
        const path = await k.draw([[0, -80, 0], corner[1], corner[2], corner[3], corner[0], [0, -80, 0]], { steps: 200 });
        const cam = await k.call(() => window.clayStudio.camera());
        const drawn = path.map(([x, y]) => backProject(cam, x, y, 0));
        const recipe = await k.call(() => window.clayStudio.recipe());
        const stroke = recipe.strokes.s1;
        assert(stroke && stroke.pieces === 4, `the stroke was written with pieces ${stroke && stroke.pieces}`);
        const curves = await k.call(() => window.clayStudio.curves());
        const pieces = [1, 2, 3, 4].map((i) => curves[`s1.${i}`]);
        assert(pieces.every(Boolean), `curves: ${Object.keys(curves)}`);
        // consecutive pieces share their joint bit for bit, round the closed chain; each joint is a
        // drawn corner (back-projected here), within the stroke's tolerance
        const end = (c, last) => (last ? c.points.slice(-3) : c.points.slice(0, 3));
        let joint = 0;
        pieces.forEach((c, i) => {
          const next = pieces[(i + 1) % 4];
          assert(end(c, true).every((x, e) => x === end(next, false)[e]), `pieces s1.${i + 1} and s1.${((i + 1) % 4) + 1} do not share their joint`);
          const drawnCorner = corner.map((q) => drawn.reduce((best, d) => (dist(d, q) < dist(best, q) ? d : best)));
          joint = Math.max(joint, Math.min(...drawnCorner.map((q) => dist(q, end(c, true)))));
        });
        assert(joint <= stroke.tolerance, `a joint is ${joint} mm from the drawn corner`);
        let off = 0;
        for (const d of drawn) off = Math.max(off, Math.min(...pieces.map((c) => distanceToCurve(c, d))));
        assert(off <= stroke.tolerance, `a drawn point is ${off} mm from the pieces (tolerance ${stroke.tolerance})`);
        // the four pieces filled: the patch's corners are the joints
        await cp.click('#tool-orbit');
        for (let i = 1; i <= 4; i++) await k.clickCurve(`s1.${i}`, i > 1);
        await cp.click('#build-fill');
        await k.idle();
        assert(!(await k.lastError()), await k.lastError());
        const patch = Object.values(await k.call(() => window.clayStudio.surfaces()))[0];
        assert(patch, 'no fill of the pieces');
        const [[u0, u1], [v0, v1]] = surfaceDomain(patch);
        let gap = 0;
        for (const [u, v] of [[u0, v0], [u1, v0], [u0, v1], [u1, v1]]) gap = Math.max(gap, Math.min(...pieces.map((c) => dist(surfaceAt(patch, u, v), end(c, true)))));
        assert(gap <= 1e-9, `a corner of the fill is ${gap} mm from the joints`);
        // mirror in x = 10: the mirrored curve is the stroke's reflected, control point by control point
        await cp.click('#tool-sketch');
        await cp.selectOption('#mirror', 'x');
        await cp.fill('#mirror-at', '10');
        await k.draw(along([20, -30], [80, 30], 10));
        const mirrored = await k.call(() => window.clayStudio.curves());
        const s2 = mirrored.s2;
        const m2 = mirrored.s2_mirror;
        assert(s2 && m2, `curves: ${Object.keys(mirrored)}`);
        let reflection = 0;
        for (let i = 0; i < s2.points.length; i += 3) reflection = Math.max(reflection, dist([20 - s2.points[i], s2.points[i + 1], s2.points[i + 2]], m2.points.slice(i, i + 3)));
        assert(reflection <= 1e-9, `the mirrored curve is ${reflection} mm from the reflection in x = 10`);
        figures.corners = { pieces: 4, joint_mm: joint, off_drawn_mm: off, fill_corner_gap_mm: gap, mirror_mm: reflection };
        return `4 pieces, joints ${joint.toExponential(1)} mm from the drawn corners, drawn points within ${off.toExponential(2)} mm; fill corners on the joints (${gap.toExponential(1)} mm); mirror in x = 10 within ${reflection.toExponential(1)} mm`;
      });
    });

  }
  if (wants('constraints')) {
    await check('constraints on two strokes of a plane (coincident, tangent, a conflict refused, horizontal); a stroke in 3D between two views; revolve about a picked line; a plane at a picked surface point', async () => {
      return withEmptyRecipe('sketch', async (sketchPage, k) => {
        // a button that must be taken: pressed, the kernel's answer awaited, no error
        const press = async (selector) => {
          await sketchPage.click(selector);
          await k.idle();
          assert(!(await k.lastError()), await k.lastError());
        };
        // two strokes whose ends nearly meet at an angle
        await k.draw(along([-300, 0], [-20, 10], 20));
        await k.draw(along([5, 0], [300, 120], -20));
        await sketchPage.click('#tool-orbit');
        await k.clickCurve('s1', false);
        await k.clickCurve('s2', true);
        await press('#constrain-coincident');
        await k.clickCurve('sketch1.s1', false);
        await k.clickCurve('sketch1.s2', true);
        await press('#constrain-tangent');
        const curves = await k.call(() => window.clayStudio.curves());
        const a = curves['sketch1.s1'];
        const b = curves['sketch1.s2'];
        assert(a && b, `no sketch curves: ${Object.keys(curves)}`);
        // here: s1's end and s2's start meet, and their end tangents (last and first control legs) are parallel
        const na = a.weights.length;
        const end = a.points.slice(3 * na - 3, 3 * na);
        const before = a.points.slice(3 * na - 6, 3 * na - 3);
        const start = b.points.slice(0, 3);
        const next = b.points.slice(3, 6);
        const gap = dist(end, start);
        const ta = [0, 1, 2].map((e) => end[e] - before[e]);
        const tb = [0, 1, 2].map((e) => next[e] - start[e]);
        const cross = Math.hypot(ta[1] * tb[2] - ta[2] * tb[1], ta[2] * tb[0] - ta[0] * tb[2], ta[0] * tb[1] - ta[1] * tb[0]) / (Math.hypot(...ta) * Math.hypot(...tb));
        const same = ta[0] * tb[0] + ta[1] * tb[1] + ta[2] * tb[2] > 0;
        assert(gap <= 1e-7 && cross <= 1e-7 && same, `after coincident and tangent: gap ${gap} mm, sin of the angle ${cross}, same direction ${same}`);
        const figures = await sketchPage.locator('#sketch-figures').textContent();
        const step = (await k.call(() => window.clayStudio.reply())).steps.find((st) => st.path === 'sketches.sketch1');
        assert(figures.includes(`degrees of freedom ${step.figures.degrees_of_freedom}`), `panel: "${figures}", report: ${JSON.stringify(step.figures)}`);
        // the distance between the joined ends set to 50 mm conflicts with coincident: refused, nothing changes
        const text = JSON.stringify(await k.call(() => window.clayStudio.recipe()));
        await k.clickCurve('sketch1.s1', false);
        await k.clickCurve('sketch1.s2', true);
        await sketchPage.fill('#constrain-value', '50');
        await sketchPage.click('#constrain-distance');
        await k.idle();
        const error = await k.lastError();
        assert(/conflict/i.test(error), `a conflicting distance was not refused as a conflict: "${error}"`);
        assert(JSON.stringify(await k.call(() => window.clayStudio.recipe())) === text, 'the refused constraint changed the recipe');
        // horizontal: s2's chord along the plane's x axis (XY: world x), the joint kept
        await k.clickCurve('sketch1.s2', false);
        await press('#constrain-horizontal');
        const level = await k.call(() => window.clayStudio.curves());
        const h = level['sketch1.s2'];
        const hn = h.weights.length;
        const rise = Math.abs(h.points[3 * hn - 2] - h.points[1]);
        const ha = level['sketch1.s1'];
        const joint = dist(ha.points.slice(3 * ha.weights.length - 3), h.points.slice(0, 3));
        assert(rise <= 1e-9 && joint <= 1e-7, `after horizontal: the chord rises ${rise} mm, the joint is ${joint} mm apart`);
        const constraintNote = `gap ${gap.toExponential(1)} mm, tangent angle sin ${cross.toExponential(1)}; ${figures}; conflict: ${error.slice(0, 60)}…; horizontal chord rises ${rise.toExponential(1)} mm`;
        // A stroke in 3D between two views: drawn on XY from the top, then again from the front
        // over it; the 3D curve's shadow on XY is the first curve, and it has the heights drawn.
        await k.call(() => window.clayStudio.setView('top'));
        await sketchPage.click('#tool-sketch');
        await sketchPage.selectOption('#sketch-on', 'xy');
        await k.draw(along([-250, -150], [250, -100], 40));
        const flat = (await k.call(() => window.clayStudio.curves())).s3;
        await sketchPage.click('#tool-orbit');
        await k.clickCurve('s3', false);
        await k.call(() => window.clayStudio.setView('front'));
        await sketchPage.click('#tool-sketch');
        await sketchPage.selectOption('#sketch-on', 'over');
        const [t0, t1] = curveDomain(flat);
        const height = (x) => 60 * Math.sin((Math.PI * (x + 250)) / 500);
        const wanted = Array.from({ length: 13 }, (_, i) => {
          const p = curveAt(flat, t0 + ((t1 - t0) * (0.02 + (0.96 * i) / 12)));
          return [p[0], p[1], height(p[0])];
        });
        await k.draw(wanted, { steps: 60 });
        const lifted = (await k.call(() => window.clayStudio.curves())).s3;
        const stroke = (await k.call(() => window.clayStudio.recipe())).strokes.s3;
        assert(!stroke.plane, 'the redrawn stroke still has a plane');
        // its shadow on XY lies on the first curve, and its heights are the ones drawn
        let shadow = 0;
        let heights = 0;
        const [l0, l1] = curveDomain(lifted);
        for (let i = 0; i <= 50; i++) {
          const p = curveAt(lifted, l0 + ((l1 - l0) * i) / 50);
          shadow = Math.max(shadow, distanceToCurve({ ...flat, points: flat.points.map((c, e) => (e % 3 === 2 ? p[2] : c)) }, p));
          heights = Math.max(heights, Math.abs(p[2] - height(p[0])));
        }
        assert(shadow <= 2 * stroke.tolerance + 1, `the 3D curve's shadow is ${shadow} mm off the first curve`);
        assert(heights <= 2 * stroke.tolerance + 2, `the 3D curve's heights are ${heights} mm off the drawn ones`);
        const threeDNote = `3D between two views: shadow within ${shadow.toFixed(2)} mm, heights within ${heights.toFixed(2)} mm`;
        // Revolve about a picked line: a profile and an axis drawn on XZ (front view), both picked.
        await sketchPage.selectOption('#sketch-on', 'xz');
        await sketchPage.fill('#sketch-offset', '0');
        await k.draw(along([250, -150], [250, 150], 0, 8, (x, z) => [x, 0, z]));
        await k.draw(along([320, -120], [320, 120], 30, 8, (x, z) => [x, 0, z]));
        await sketchPage.click('#tool-orbit');
        await k.call(() => window.clayStudio.setView('iso'));
        await k.clickCurve('s5', false);
        await k.clickCurve('s4', true);
        await sketchPage.click('#build-revolve');
        await k.idle();
        assert(!(await k.lastError()), await k.lastError());
        const all = await k.call(() => window.clayStudio.curves());
        const revolved = (await k.call(() => window.clayStudio.surfaces())).revolve1;
        assert(revolved, 'no surface revolve1');
        // every point of the revolved surface is a profile point turned about the axis: its
        // (axial, radial) coordinates lie on the profile's
        const ax = all.s4;
        const nax = ax.weights.length;
        const a0 = ax.points.slice(0, 3);
        const dir = [0, 1, 2].map((e) => ax.points[3 * nax - 3 + e] - a0[e]);
        const len = Math.hypot(...dir);
        const unit = dir.map((x) => x / len);
        const cyl = (q) => {
          const d = [0, 1, 2].map((e) => q[e] - a0[e]);
          const axial = d[0] * unit[0] + d[1] * unit[1] + d[2] * unit[2];
          return [axial, Math.hypot(...d.map((x, e) => x - axial * unit[e]))];
        };
        const [p0, p1] = curveDomain(all.s5);
        const profile = Array.from({ length: 4001 }, (_, i) => cyl(curveAt(all.s5, p0 + ((p1 - p0) * i) / 4000)));
        const [[ru0, ru1], [rv0, rv1]] = surfaceDomain(revolved);
        let offR = 0;
        for (let i = 0; i <= 12; i++)
          for (let j = 0; j <= 12; j++) {
            const c = cyl(surfaceAt(revolved, ru0 + ((ru1 - ru0) * i) / 12, rv0 + ((rv1 - rv0) * j) / 12));
            offR = Math.max(offR, Math.min(...profile.map((q) => Math.hypot(q[0] - c[0], q[1] - c[1]))));
          }
        assert(offR <= 0.1, `the revolved surface is ${offR} mm off the profile turned about the picked axis`);
        // A plane placed at a picked point of the revolved surface; a stroke drawn on it lies in it.
        await sketchPage.click('#tool-sketch');
        await sketchPage.selectOption('#sketch-on', 'picked');
        const at = surfaceAt(revolved, (ru0 + ru1) / 2, (rv0 + rv1) / 2);
        await k.clickAt(at, false);
        const placed = await sketchPage.locator('#message').textContent();
        assert(placed.startsWith('plane placed'), `the plane was not placed: "${placed}"`);
        await k.draw(along([at[0] - 40, at[2] - 40], [at[0] + 40, at[2] + 40], 0, 4, (x, z) => [x, at[1], z]));
        const rec = await k.call(() => window.clayStudio.recipe());
        const last = Object.keys(rec.strokes).pop();
        const pl = rec.strokes[last].plane;
        assert(pl && pl.normal, `stroke ${last} has no picked plane`);
        const drawnOn = (await k.call(() => window.clayStudio.curves()))[last];
        let offPlane = 0;
        const nl = Math.hypot(...pl.normal);
        for (let i = 0; i < drawnOn.weights.length; i++) offPlane = Math.max(offPlane, Math.abs([0, 1, 2].reduce((acc, e) => acc + (drawnOn.points[3 * i + e] - pl.origin[e]) * pl.normal[e], 0)) / nl);
        assert(offPlane <= 1e-9, `the stroke on the picked plane is ${offPlane} mm off it`);
        // the plane's origin is the point pressed on the surface (on its mesh: within the mesh's sag)
        const o = cyl(pl.origin);
        const onSurface = Math.min(...profile.map((q) => Math.hypot(q[0] - o[0], q[1] - o[1])));
        assert(onSurface <= 1, `the picked plane's origin is ${onSurface} mm off the revolved surface`);
        return `${constraintNote}; ${threeDNote}; revolve about a picked line within ${offR.toExponential(1)} mm; stroke on a picked plane ${offPlane.toExponential(1)} mm off it`;
      });
    });

  }
  await check('no page errors', async () => {
    assert(problems.length === 0, problems.join('; '));
  });
} finally {
  await browser.close();
  if (studio) studio.kill();
}

const machine = `${cpus().length} cores, ${cpus()[0] ? cpus()[0].model : 'unknown CPU'}, headless Chromium with software rendering`;
console.log(`# figures (${machine}):`);
console.log(JSON.stringify(figures, null, 1));
if (reportFile) {
  mkdirSync(dirname(resolve(reportFile)), { recursive: true });
  writeFileSync(reportFile, JSON.stringify({ machine, figures }, null, 1));
}
const failed = results.filter((r) => !r).length;
if (!failed && !args.includes('--keep')) rmSync(work, { recursive: true, force: true });
else console.log(`# the studio's folder (recipe, saved recipe, replay, export): ${work}`);
console.log(`${results.length - failed}/${results.length} passed`);
process.exit(failed ? 1 : 0);
