// The harness of Clayform Studio's end-to-end test (studio.test.mjs and its parts, studio_*.mjs):
// the command line, a work folder, headless Chromium with the main page (its console and page
// errors counted), `check` (one numbered result each), screenshots, studios of their own for a
// part (withStudio, withEmptyRecipe), the stroke helpers and the independent checks the parts
// share (a surface against a pointwise map, the kernel's deviation map against distances computed
// here), and the report at the end.
import { existsSync, mkdirSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { tmpdir, cpus } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { backProject, dist, distanceToCurve, surfaceAt, surfaceDomain } from './geometry.mjs';
import { launchBrowser, startStudio, studioPage } from './studio_driver.mjs';
import { checker } from './checks.mjs';

export const here = dirname(fileURLToPath(import.meta.url));

/** Every B_SPLINE_SURFACE_WITH_KNOTS of a STEP file: {degrees, points (u-major)} with the numbers as written. */
export function stepSurfaces(text) {
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

export function assert(cond, message) {
  if (!cond) throw new Error(message);
}

/** The largest distance from `surface` to `map` of `parent` at the same (u, v), on an (n + 1)^2 grid. */
export function offPointwise(surface, parent, map, n) {
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
export async function deviationAgainst(call, name, surface, parent, map) {
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

/** Draws a stroke through world points on the plane z = z0 with `driver`; the drawn path back-projected onto it, here. */
export async function draw(driver, world, { steps = 40, z0 = 0 } = {}) {
  const path = await driver.draw(world, { steps });
  const cam = await driver.call(() => window.clayStudio.camera());
  return path.map(([x, y]) => backProject(cam, x, y, z0));
}
/** Checks a fitted curve against the drawn points: each within the stroke's tolerance (ends: plus how far snapping moved them). */
export async function checkStroke(driver, name, drawn) {
  const recipe = await driver.call(() => window.clayStudio.recipe());
  const curves = await driver.call(() => window.clayStudio.curves());
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
  assert(worst <= stroke.tolerance_mm * (1 + 1e-9), `curve ${name}: a drawn point is ${worst} mm from the fitted curve, tolerance ${stroke.tolerance_mm}`);
  return { worst, snapStart, snapEnd, control_points: curves[name].weights.length };
}

/**
 * The command line checked (exits 2 on a missing program or an unknown part), the work folder, the
 * browser and the main page: {part, wants(p), clayform, work, browser, page, driver, check, shot,
 * withStudio, withEmptyRecipe, figures, problems, finish()}.
 */
export async function openHarness(parts) {
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
  const part = opt('--part', 'all');
  if (part !== 'all' && !parts.includes(part)) {
    console.error(`unknown --part ${part}; the parts: ${parts.join(', ')}`);
    process.exit(2);
  }
  for (const [what, path] of [['clayform (cmake --build build)', clayform], ['chromium (apt-get install chromium)', executablePath]]) {
    if (!existsSync(path)) {
      console.error(`missing ${what}: ${path}`);
      process.exit(2);
    }
  }
  const work = mkdtempSync(join(tmpdir(), 'clayform-studio-'));

  const results = [];
  const figures = {};
  const check = checker(results, 5);

  const browser = await launchBrowser(executablePath);
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const problems = [];
  page.on('console', (m) => m.type() === 'error' && problems.push(`console error: ${m.text()}`));
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  const driver = studioPage(page);
  let shotCount = 0;
  /** A screenshot into --shots (of the main page, or of `target`, a studio of withStudio's). */
  async function shot(label, target = page) {
    if (!shots) return;
    mkdirSync(shots, { recursive: true });
    await target.screenshot({ path: join(shots, `${String(++shotCount).padStart(2, '0')}-${label}.png`) });
  }

  /**
   * Runs `fn(page, driver)` on a studio of its own: `clayform studio FILE` and a page open on it
   * (its page errors counted as the test's), closed and stopped afterwards. With `wait` false,
   * fn starts as soon as the page is loaded, before its first run has been answered.
   */
  async function withStudio(file, label, fn, { wait = true } = {}) {
    const studio = await startStudio(clayform, file);
    const other = await browser.newPage({ viewport: { width: 1100, height: 700 } });
    other.on('pageerror', (e) => problems.push(`page error (${label}): ${e.message}`));
    other.on('crash', () => problems.push(`the page crashed (${label})`));
    const driver = studioPage(other);
    try {
      if (wait) await driver.open(studio.url);
      else await other.goto(studio.url);
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

  /** The figures printed and written to --report, the work folder removed unless a check failed (or --keep); exits. */
  function finish() {
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
  }

  return { part, wants: (p) => part === 'all' || part === p, clayform, work, browser, page, driver, check, shot, withStudio, withEmptyRecipe, figures, problems, finish };
}
