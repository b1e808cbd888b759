#!/usr/bin/env node
// End-to-end test of the built viewer (viewer/dist) in Debian's headless Chromium (/usr/bin/chromium,
// driven by playwright-core; no browser is downloaded). Serves dist at / and a run folder at /run/
// from a node:http server on 127.0.0.1, like `clayform view`.
//
//   npm run test:e2e                      # against a generated fixture (e2e/make_fixture.mjs)
//   npm run test:e2e -- --run DIR         # against a real run folder (clayform run ... --out DIR)
//   options: --dist DIR (default ../dist), --chromium PATH (or $CHROMIUM), --shots DIR (save PNGs)
//
// Expected numbers come from the run folder itself (the manifest and the .bin files read here)
// or, for the fixture, from closed forms; the screenshots are compared pixel by pixel.
import { createServer } from 'node:http';
import { cpSync, createReadStream, existsSync, mkdtempSync, readFileSync, rmSync, statSync, mkdirSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { makeFixture, makePlate, DOME, DEVIATION_MAX } from './make_fixture.mjs';
import { decodePng, differingPixels } from './png.mjs';
import { checker } from './checks.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && args[i + 1] ? args[i + 1] : fallback;
};
const dist = resolve(opt('--dist', join(here, '..', 'dist')));
const executablePath = opt('--chromium', process.env.CHROMIUM || '/usr/bin/chromium');
const shots = opt('--shots', null);
let runDir = opt('--run', null);
let fixtureDir = null;
if (runDir) runDir = resolve(runDir);
else {
  fixtureDir = mkdtempSync(join(tmpdir(), 'clayform-viewer-'));
  makeFixture(fixtureDir);
  runDir = fixtureDir;
}
for (const [what, path] of [['viewer build (npm run build)', join(dist, 'index.html')], ['run manifest', join(runDir, 'view', 'manifest.json')], ['chromium (apt-get install chromium)', executablePath]]) {
  if (!existsSync(path)) {
    console.error(`missing ${what}: ${path}`);
    process.exit(2);
  }
}

// Thresholds: a pixel differs when a channel changes by more than PIXEL_THRESHOLD (of 255). The
// surfaces cover the canvas pixels that differ from the background (the clear colour #30343a) in
// the first shaded picture; a change of mode must change at least MIN_FRACTION_MODE of them, a
// change of stage MIN_FRACTION_STAGE, and the surfaces must cover MIN_COVERAGE of the canvas.
const PIXEL_THRESHOLD = 32;
const MIN_FRACTION_MODE = 0.25;
const MIN_FRACTION_STAGE = 0.03;
const MIN_COVERAGE = 0.02;
const BACKGROUND = [0x30, 0x34, 0x3a];

// ------------------------------------------------------------------ the run, read independently
const manifest = JSON.parse(readFileSync(join(runDir, 'view', 'manifest.json'), 'utf8'));
const ATTR_OFFSET = { gaussian: 6, mean: 7, deviation: 8 }; // in units of R*C floats
/** Vertices of a MESH: rows x cols for a grid, `vertices` for a model's triangle mesh. */
const vertexCount = (mesh) => (mesh.triangles !== undefined ? mesh.vertices : mesh.rows * mesh.cols);
function readAttr(mesh, attr) {
  const buf = readFileSync(join(runDir, 'view', mesh.file));
  const n = vertexCount(mesh);
  const bytes = 36 * n + 12 * (mesh.triangles || 0); // a model's file ends with its uint32 triangles
  if (buf.length !== bytes) throw new Error(`${mesh.file}: ${buf.length} bytes, expected ${bytes}`);
  const out = new Float64Array(n);
  for (let k = 0; k < n; k++) out[k] = buf.readFloatLE(4 * (ATTR_OFFSET[attr] * n + k));
  return out;
}
function quantileOf(sorted, q) {
  const x = q * (sorted.length - 1);
  const i = Math.floor(x);
  const j = Math.min(sorted.length - 1, i + 1);
  return sorted[i] + (sorted[j] - sorted[i]) * (x - i);
}
/** docs/viewer.md: curvature maps use [-R, R], R = max(|p2|, |p98|); deviation [0, max]. */
function expectedRange(meshes, attr) {
  const values = meshes.flatMap((m) => Array.from(readAttr(m, attr))).filter(Number.isFinite).sort((a, b) => a - b);
  const max = values[values.length - 1];
  if (attr === 'deviation') return [0, max > 0 ? max : 1];
  let r = Math.max(Math.abs(quantileOf(values, 0.02)), Math.abs(quantileOf(values, 0.98)));
  if (!(r > 0)) r = Math.max(Math.abs(values[0]), Math.abs(max)) || 1;
  return [-r, r];
}
const finals = manifest.surfaces.map((s) => s.mesh);
const befores = manifest.surfaces.map((s) => (s.stages && s.stages.length ? s.stages[0].before : s.mesh));
const vertices = (meshes) => meshes.reduce((n, m) => n + vertexCount(m), 0);
const hasStages = manifest.surfaces.some((s) => s.stages && s.stages.length);
const empty = manifest.surfaces.length === 0; // a run with no surface: nothing to compare in pictures

// ------------------------------------------------------------------ server on 127.0.0.1
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.css': 'text/css', '.json': 'application/json', '.svg': 'image/svg+xml', '.png': 'image/png' };
function serveFile(res, root, rel) {
  const path = normalize(join(root, rel));
  if (path !== root && !path.startsWith(root + sep)) return false;
  if (!existsSync(path) || !statSync(path).isFile()) return false;
  res.writeHead(200, { 'Content-Type': TYPES[extname(path)] || 'application/octet-stream' });
  createReadStream(path).pipe(res);
  return true;
}
// With the fixture, /broken/ serves the page again with a copy of the run whose first mesh file is
// cut short, to check that the page reports it.
let brokenDir = null;
if (fixtureDir) {
  brokenDir = join(fixtureDir, 'broken');
  cpSync(join(fixtureDir, 'view'), join(brokenDir, 'view'), { recursive: true });
  cpSync(join(fixtureDir, 'report.json'), join(brokenDir, 'report.json'));
  const first = join(brokenDir, 'view', manifest.surfaces[0].mesh.file);
  writeFileSync(first, readFileSync(first).subarray(0, 1000));
}
// /plate/ serves the page with a run holding one flat plate (make_fixture.mjs, makePlate).
const plateDir = mkdtempSync(join(tmpdir(), 'clayform-viewer-plate-'));
makePlate(plateDir);
const server = createServer((req, res) => {
  let url = decodeURIComponent(new URL(req.url, 'http://127.0.0.1').pathname);
  let run = runDir;
  if (brokenDir && url.startsWith('/broken/')) {
    url = url.slice(7);
    run = brokenDir;
  } else if (url.startsWith('/plate/')) {
    url = url.slice(6);
    run = plateDir;
  }
  const ok = url.startsWith('/run/') ? serveFile(res, run, url.slice(5)) : serveFile(res, dist, url === '/' ? 'index.html' : url.slice(1));
  if (!ok) {
    res.writeHead(404, { 'Content-Type': 'text/plain' });
    res.end('not found');
  }
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const base = `http://127.0.0.1:${server.address().port}/`;

// ------------------------------------------------------------------ the tests
const results = [];
const check = checker(results, 4);
function assert(cond, message) {
  if (!cond) throw new Error(message);
}
function near(actual, expected, rel, what) {
  const tol = rel * Math.max(Math.abs(expected), 1e-300);
  assert(Math.abs(actual - expected) <= tol, `${what}: ${actual}, expected ${expected} (rel ${rel})`);
}

const started = Date.now();
const browser = await chromium.launch({
  executablePath,
  headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
const page = await browser.newPage({ viewport: { width: 1100, height: 720 } });
const problems = [];
const requests = [];
page.on('console', (m) => {
  if (m.type() === 'error') problems.push(`console error: ${m.text()}`);
});
page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
page.on('request', (r) => requests.push(r.url()));
page.on('requestfailed', (r) => problems.push(`request failed: ${r.url()} ${r.failure() && r.failure().errorText}`));

const attr = (name) => page.evaluate((n) => document.body.dataset[n], name);
const nextFrames = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
async function waitReady() {
  await page.waitForFunction(() => ['1', 'error'].includes(document.body.dataset.ready), null, { timeout: 60000 });
  const ready = await attr('ready');
  if (ready !== '1') throw new Error(`page error: ${await attr('error')}`);
  await nextFrames();
}
let shotCount = 0;
async function shot(label) {
  // the canvas alone: the legend and notices over it are hidden while the picture is taken
  const png = await page.locator('#view').screenshot({ style: '#legend, #message { visibility: hidden !important; }' });
  if (shots) {
    mkdirSync(shots, { recursive: true });
    writeFileSync(join(shots, `${String(++shotCount).padStart(2, '0')}-${label}.png`), png);
  }
  return decodePng(png);
}
let covered = 0; // canvas pixels the surfaces cover in the first shaded picture
function coverage(img) {
  let n = 0;
  for (let k = 0; k < img.width * img.height; k++) {
    const d = Math.max(...BACKGROUND.map((c, i) => Math.abs(img.rgba[4 * k + i] - c)));
    if (d > 8) n++;
  }
  return n;
}
function differ(a, b, minFraction, what) {
  const n = differingPixels(a, b, PIXEL_THRESHOLD);
  const fraction = n / covered;
  assert(fraction >= minFraction, `${what}: only ${n} pixels (${(100 * fraction).toFixed(2)} % of the ${covered} the surfaces cover) differ, expected at least ${100 * minFraction} %`);
  return `${n} pixels differ, ${(100 * fraction).toFixed(1)} % of the ${covered} the surfaces cover`;
}

let loadMs = 0;
await check('the page loads the run and becomes ready', async () => {
  const t0 = Date.now();
  await page.goto(base, { waitUntil: 'load' });
  await waitReady();
  loadMs = Date.now() - t0;
  return `load to data-ready ${loadMs} ms`;
});

await check('data-surfaces, the panels and the vertices match the manifest', async () => {
  const n = manifest.surfaces.length;
  assert((await attr('surfaces')) === String(n), `data-surfaces ${await attr('surfaces')}, expected ${n}`);
  const names = await page.$$eval('.surface-panel h2 .surface-name', (e) => e.map((x) => x.textContent));
  assert(names.length === n, `${names.length} panels, expected ${n}`);
  manifest.surfaces.forEach((s, i) => assert(names[i] === s.name, `panel ${i} is "${names[i]}", expected "${s.name}"`));
  const figureRows = await page.$$eval('.surface-panel', (ps) => ps.map((p) => p.querySelectorAll(':scope > table.figures tr').length));
  manifest.surfaces.forEach((s, i) => assert(figureRows[i] === Math.max(1, Object.keys(s.figures || {}).length), `panel ${i}: ${figureRows[i]} figure rows`));
  const toggles = await page.$$eval('.stage-toggle', (e) => e.length);
  const stages = manifest.surfaces.reduce((k, s) => k + (s.stages || []).length, 0);
  assert(toggles === stages, `${toggles} stage toggles, expected ${stages}`);
  assert((await attr('vertices')) === String(vertices(finals)), `data-vertices ${await attr('vertices')}, expected ${vertices(finals)}`);
  return `${n} surfaces, ${stages} stages, ${vertices(finals)} vertices`;
});

await check("a model's panel lists its edges' continuity, worst first, against the class-A figures", async () => {
  const models = manifest.surfaces.map((s, i) => [s, i]).filter(([s]) => s.continuity);
  if (models.length === 0) return 'skipped: no model in this run';
  const out = [];
  for (const [s, i] of models) {
    const edges = s.continuity.edges;
    // the class-A figures per the source's class, computed here from the manifest's numbers
    const misses = edges.filter((e) => e.gap_mm > 0.01 ||
      ((e.class === 'G1' || e.class === 'G2') && e.angle_deg > 0.016) ||
      (e.class === 'G2' && e.relative_curvature_jump > 0.01));
    const panel = `.surface-panel[data-surface="${i}"] details.continuity`;
    assert((await page.getAttribute(panel, 'data-misses')) === String(misses.length), `${s.name}: data-misses`);
    const rows = await page.$$eval(`${panel} tr[data-edge]`, (r) => r.map((x) => Number(x.dataset.edge)));
    assert(rows.length === Math.min(20, edges.length), `${s.name}: ${rows.length} edge rows of ${edges.length}`);
    // every edge that misses comes before every edge that does not
    const missed = new Set(misses.map((e) => e.edge));
    const firstKept = rows.findIndex((e) => !missed.has(e));
    assert(firstKept < 0 || rows.slice(firstKept).every((e) => !missed.has(e)), `${s.name}: misses not first`);
    const warned = await page.$$eval(`${panel} td.warn`, (c) => c.length);
    assert((misses.length === 0) === (warned === 0), `${s.name}: ${warned} cells marked for ${misses.length} misses`);
    out.push(`${s.name}: ${edges.length} edges, ${misses.length} off class A`);
  }
  return out.join('; ');
});

let shaded;
await check('zebra mode changes data-mode and the picture', async () => {
  if (empty) return 'skipped: this run has no surface';
  assert((await attr('mode')) === 'shaded', `initial data-mode ${await attr('mode')}`);
  shaded = await shot('shaded');
  covered = coverage(shaded);
  const canvas = shaded.width * shaded.height;
  assert(covered >= MIN_COVERAGE * canvas, `the surfaces cover only ${covered} of ${canvas} pixels`);
  await page.click('#mode-zebra');
  await nextFrames();
  assert((await attr('mode')) === 'zebra', `data-mode ${await attr('mode')} after clicking zebra`);
  const zebra = await shot('zebra');
  return differ(shaded, zebra, MIN_FRACTION_MODE, 'shaded vs zebra');
});

await check('orbiting the camera (mouse drag) redraws the zebra view', async () => {
  if (empty) return 'skipped: this run has no surface';
  const before = await shot('zebra-0');
  const box = await page.locator('#view').boundingBox();
  const x = box.x + box.width / 2, y = box.y + box.height / 2;
  await page.mouse.move(x, y);
  await page.mouse.down();
  await page.mouse.move(x + 60, y + 25, { steps: 5 });
  await page.mouse.up();
  await nextFrames();
  const after = await shot('zebra-orbit');
  return differ(before, after, MIN_FRACTION_STAGE, 'zebra after orbiting');
});

for (const m of ['gaussian', 'mean', 'deviation']) {
  await check(`${m} map: colour range and legend from the data`, async () => {
  if (empty) return 'skipped: this run has no surface';
    await page.click('#fit-all');
    await page.click(`#mode-${m}`);
    await nextFrames();
    assert((await attr('mode')) === m, `data-mode ${await attr('mode')}`);
    const legend = await page.$eval('#legend', (l) => ({ hidden: l.hidden, lo: Number(l.dataset.lo), hi: Number(l.dataset.hi), unit: l.dataset.unit, text: l.textContent }));
    assert(!legend.hidden, 'legend hidden');
    const unit = { gaussian: '1/mm²', mean: '1/mm', deviation: 'mm' }[m];
    assert(legend.unit === unit && legend.text.includes(`(${unit})`), `legend unit "${legend.unit}"`);
    const [lo, hi] = expectedRange(finals, m);
    near(legend.lo, lo, 1e-6, 'legend low end');
    near(legend.hi, hi, 1e-6, 'legend high end');
    const img = await shot(m);
    const note = differ(shaded, img, MIN_FRACTION_MODE, `shaded vs ${m}`);
    if (fixtureDir) {
      const stats = await page.$$eval('.surface-panel .stats', (e) => e.map((s) => [Number(s.dataset.min), Number(s.dataset.max)]));
      const dome = manifest.surfaces.findIndex((s) => s.name === 'dome');
      const hood = manifest.surfaces.findIndex((s) => s.name === 'hood');
      if (m === 'gaussian') stats[dome].forEach((v) => near(v, 1 / (DOME.R * DOME.R), 1e-6, 'dome K (1/R^2)'));
      if (m === 'mean') stats[dome].forEach((v) => near(v, -1 / DOME.R, 1e-6, 'dome H (-1/R, outward normal)'));
      if (m === 'deviation') {
        near(stats[hood][1], DEVIATION_MAX, 1e-6, 'hood max deviation');
        assert(stats[dome][1] === 0, 'dome deviation is not 0');
      }
    }
    return `range ${legend.lo.toExponential(3)} .. ${legend.hi.toExponential(3)} ${unit}; ${note}`;
  });
}

await check('hiding a surface from its panel removes it and sets the colour range from the others', async () => {
  if (manifest.surfaces.length < 2) return 'skipped: needs two surfaces';
  await page.click('#mode-gaussian');
  await nextFrames();
  const all = await shot('gaussian-all');
  await page.uncheck('.surface-panel[data-surface="0"] .surface-visible');
  await nextFrames();
  const rest = await shot('gaussian-without-first');
  const [lo, hi] = expectedRange(finals.slice(1), 'gaussian');
  const legend = await page.$eval('#legend', (l) => [Number(l.dataset.lo), Number(l.dataset.hi)]);
  near(legend[0], lo, 1e-6, 'legend low end without the first surface');
  near(legend[1], hi, 1e-6, 'legend high end without the first surface');
  const note = differ(all, rest, MIN_FRACTION_STAGE, 'hiding the first surface');
  await page.check('.surface-panel[data-surface="0"] .surface-visible');
  await nextFrames();
  return note;
});

await check('the before/after toggle shows the first stage before and changes the picture', async () => {
  if (!hasStages) return 'skipped: this run has no deformation stage';
  await page.click('#mode-shaded');
  await nextFrames();
  const after = await shot('after');
  await page.click('#toggle-before-after');
  await waitReady();
  assert((await attr('stage')) === 'before', `data-stage ${await attr('stage')}`);
  assert((await attr('vertices')) === String(vertices(befores)), `data-vertices ${await attr('vertices')}, expected ${vertices(befores)}`);
  const before = await shot('before');
  const note = differ(after, before, MIN_FRACTION_STAGE, 'after vs before');
  const pressed = await page.$$eval('.stage-toggle', (e) => e.map((t) => t.getAttribute('aria-pressed')));
  manifest.surfaces.flatMap((s) => (s.stages || []).map((_, k) => k === 0)).forEach((first, i) => assert((pressed[i] === 'true') === first, `stage toggle ${i} aria-pressed ${pressed[i]}`));
  // the stage's own toggle brings its after back
  await page.click('.stage-toggle[aria-pressed="true"]');
  await waitReady();
  const toggled = await page.$$eval('.stage-toggle', (e) => e.filter((t) => t.getAttribute('aria-pressed') === 'true').length);
  assert(toggled === pressed.filter((p) => p === 'true').length - 1, 'a stage toggle did not switch back to after');
  await page.click('#toggle-before-after'); // every surface to its final mesh
  await waitReady();
  assert((await attr('stage')) === 'after', `data-stage ${await attr('stage')} after toggling back`);
  assert((await attr('vertices')) === String(vertices(finals)), 'final vertices after toggling back');
  const back = await shot('after-again');
  const same = differingPixels(after, back, PIXEL_THRESHOLD);
  assert(same <= 0.002 * after.width * after.height, `toggling back does not give the same picture (${same} pixels differ)`);
  return note;
});

await check('two quick before/after toggles end on the final surfaces', async () => {
  if (!hasStages) return 'skipped: this run has no deformation stage';
  await page.evaluate(() => {
    const b = document.getElementById('toggle-before-after');
    b.click();
    b.click();
  });
  await waitReady();
  assert((await attr('stage')) === 'after', `data-stage ${await attr('stage')}`);
  assert((await attr('vertices')) === String(vertices(finals)), `data-vertices ${await attr('vertices')}`);
});

await check('URL parameters ?mode=zebra&stage=before', async () => {
  await page.goto(`${base}?mode=zebra&stage=before`, { waitUntil: 'load' });
  await waitReady();
  assert((await attr('mode')) === 'zebra', `data-mode ${await attr('mode')}`);
  assert((await page.getAttribute('#mode-zebra', 'aria-pressed')) === 'true', 'zebra button not pressed');
  if (hasStages) assert((await attr('stage')) === 'before', `data-stage ${await attr('stage')}`);
  assert((await attr('vertices')) === String(vertices(befores)), `data-vertices ${await attr('vertices')}`);
});

await check('URL parameter ?ui=0 shows the picture alone', async () => {
  await page.goto(`${base}?ui=0`, { waitUntil: 'load' });
  await waitReady();
  assert(!(await page.isVisible('#toolbar')), 'toolbar visible with ?ui=0');
  assert(!(await page.isVisible('#panels')), 'panels visible with ?ui=0');
  const box = await page.locator('#view').boundingBox();
  const size = page.viewportSize();
  assert(box && Math.abs(box.width - size.width) <= 1 && Math.abs(box.height - size.height) <= 1,
         `canvas ${JSON.stringify(box)} does not fill the ${size.width} x ${size.height} window`);
});

await check('net and curve overlays can be hidden', async () => {
  if (empty) return 'skipped: this run has no surface';
  await page.goto(`${base}?mode=shaded`, { waitUntil: 'load' });
  await waitReady();
  await page.check('#show-net');
  await page.check('#show-curves');
  await nextFrames();
  const on = await shot('overlays-on');
  await page.uncheck('#show-net');
  await page.uncheck('#show-curves');
  await nextFrames();
  const off = await shot('overlays-off');
  const n = differingPixels(on, off, PIXEL_THRESHOLD);
  const hasNet = manifest.surfaces.some((s) => s.net && s.net.points && s.net.points.length);
  if (hasNet) assert(n > 200, `hiding the net and curves changed only ${n} pixels`);
  return `${n} pixels differ`;
});

await check('zebra stripes are reflections: on a plate they stay put when the camera translates', async () => {
  const other = await browser.newPage({ viewport: { width: 900, height: 650 } });
  other.on('pageerror', (e) => problems.push(`plate page error: ${e.message}`));
  try {
    await other.goto(`${base}plate/?mode=zebra`, { waitUntil: 'load' });
    await other.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 30000 });
    await other.$eval('#zebra-stripes', (e) => {
      e.value = '64';
      e.dispatchEvent(new Event('input'));
    });
    const frames = () => other.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const grab = async () => decodePng(await other.locator('#view').screenshot({ style: '#legend, #message { visibility: hidden !important; }' }));
    await frames();
    const a = await grab();
    const box = await other.locator('#view').boundingBox();
    const x = box.x + box.width / 2, y = box.y + box.height / 2;
    await other.mouse.move(x, y);
    await other.mouse.down({ button: 'right' }); // OrbitControls: pan = translate eye and target together
    await other.mouse.move(x + 70, y + 30, { steps: 5 });
    await other.mouse.up({ button: 'right' });
    await frames();
    const b = await grab();
    // pixels on the plate in both pictures, away from its edges (2 px)
    const W = a.width, H = a.height;
    const onPlate = (img, k) => Math.max(...BACKGROUND.map((c, i) => Math.abs(img.rgba[4 * k + i] - c))) > 8;
    const inside = (img, px, py) => {
      for (let dy = -2; dy <= 2; dy++) for (let dx = -2; dx <= 2; dx++) {
        const qx = px + dx, qy = py + dy;
        if (qx < 0 || qy < 0 || qx >= W || qy >= H || !onPlate(img, qy * W + qx)) return false;
      }
      return true;
    };
    let both = 0, changed = 0, white = 0, black = 0, moved = 0;
    for (let py = 0; py < H; py++) for (let px = 0; px < W; px++) {
      const k = py * W + px;
      if (onPlate(a, k) !== onPlate(b, k)) moved++;
      if (!inside(a, px, py) || !inside(b, px, py)) continue;
      both++;
      const v = a.rgba[4 * k];
      if (v > 200) white++;
      else if (v < 50) black++;
      if (Math.abs(v - b.rgba[4 * k]) > PIXEL_THRESHOLD) changed++;
    }
    assert(moved > 2000, `the plate did not move on the screen (${moved} pixels)`);
    assert(both > 20000, `only ${both} pixels on the plate in both pictures`);
    assert(white > 0.1 * both && black > 0.1 * both, `no stripes to compare: ${white} white, ${black} black of ${both}`);
    assert(changed <= 0.01 * both, `${changed} of ${both} plate pixels changed: the stripes moved with the plate`);
    return `plate moved over ${moved} pixels; of ${both} pixels on it in both pictures (${white} white, ${black} black) ${changed} changed`;
  } finally {
    await other.close();
  }
});

await check('a mesh file cut short is reported, not drawn (fixture only)', async () => {
  if (!brokenDir) return 'skipped: only with the fixture';
  const other = await browser.newPage({ viewport: { width: 800, height: 600 } });
  try {
    await other.goto(`${base}broken/`, { waitUntil: 'load' });
    await other.waitForFunction(() => document.body.dataset.ready !== '0', null, { timeout: 30000 });
    const state = await other.evaluate(() => ({ ready: document.body.dataset.ready, error: document.body.dataset.error, shown: document.getElementById('message').textContent }));
    const m = manifest.surfaces[0].mesh;
    assert(state.ready === 'error', `data-ready ${state.ready}`);
    assert(state.error.includes(m.file) && state.error.includes(String(36 * m.rows * m.cols)), `data-error "${state.error}"`);
    assert(state.shown.includes(state.error), 'the error is not shown on the page');
    return state.error;
  } finally {
    await other.close();
  }
});

await check('no console error, no request outside 127.0.0.1', async () => {
  assert(problems.length === 0, problems.join('\n'));
  const outside = requests.filter((u) => !/^(http:\/\/127\.0\.0\.1:\d+\/|data:|blob:)/.test(u));
  assert(outside.length === 0, `requests outside 127.0.0.1: ${outside.join(', ')}`);
  return `${requests.length} requests`;
});

await browser.close();
server.close();
if (fixtureDir) rmSync(fixtureDir, { recursive: true, force: true });
rmSync(plateDir, { recursive: true, force: true });
const passed = results.filter(Boolean).length;
const failed = results.length - passed;
console.log(`viewer e2e: ${runDir === fixtureDir ? 'fixture' : runDir}; load to data-ready ${loadMs} ms; total ${Date.now() - started} ms`);
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
