#!/usr/bin/env node
// The walkthrough of docs/studio.md, played in headless Chromium against `clayform studio`: a car
// hood styled from scratch. Five sections drawn on XZ planes and skinned, a bound drawn on the
// surface and a crease target on a plane, the style applied in exact mode, the target dragged,
// a lattice placed and dragged, the recipe saved and exported. Writes a picture per step
// (docs/pictures/studio-*.png) and fails, naming the step, when one does not work.
//
//   node e2e/studio_walkthrough.mjs --clayform PATH [--out DIR] [--chromium PATH]
import { mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { along, launchBrowser, startStudio, studioPage } from './studio_driver.mjs';

const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && args[i + 1] ? args[i + 1] : fallback;
};
const clayform = resolve(opt('--clayform', '../build/cli/clayform'));
const out = resolve(opt('--out', '../docs/pictures'));
const executablePath = opt('--chromium', process.env.CHROMIUM || '/usr/bin/chromium');
mkdirSync(out, { recursive: true });

const work = mkdtempSync(join(tmpdir(), 'clayform-walkthrough-'));
writeFileSync(join(work, 'hood.json'), JSON.stringify({ format: 'clayform.recipe', version: 1, name: 'hood' }));
const studio = await startStudio(clayform, join(work, 'hood.json'));
const browser = await launchBrowser(executablePath);
const page = await browser.newPage({ viewport: { width: 1200, height: 720 } });
const s = studioPage(page);
let failed = false;
async function step(what, fn) {
  try {
    await fn();
    await s.idle();
    const error = await s.lastError();
    if (error) throw new Error(error);
    console.log(`ok - ${what}`);
  } catch (e) {
    console.log(`not ok - ${what}: ${e.message}`);
    failed = true;
    throw e;
  }
}
const picture = (name) => page.screenshot({ path: join(out, `studio-${name}.png`) });
const view = (v) => s.call((x) => window.clayStudio.setView(x), v);

// The hood's height over the plan, 1200 x 800 mm (the car_hood example's shape).
const height = (x, y) => 80 * (1 - (x / 700) ** 2) * (1 - (y / 500) ** 2) + 0.05 * x - 20;

try {
  await s.open(studio.url);
  await step('five sections drawn on XZ planes (Sketch, plane XZ at y = -400 ... 400, front view)', async () => {
    await view('front');
    await page.click('#tool-sketch');
    await page.selectOption('#sketch-on', 'xz');
    for (const y of [-400, -200, 0, 200, 400]) {
      await page.fill('#sketch-offset', String(y));
      const points = Array.from({ length: 13 }, (_, k) => {
        const x = -600 + 100 * k;
        return [x, y, height(x, y)];
      });
      await s.draw(points, { steps: 48 });
    }
    await view('iso');
    await picture('sketch');
  });
  await step('the sections skinned (Select, click them in order with Shift, Skin)', async () => {
    await page.click('#tool-orbit');
    await s.clickCurve('s1', false);
    for (const n of ['s2', 's3', 's4', 's5']) await s.clickCurve(n, true);
    await page.click('#build-skin');
  });
  await step('a bound drawn on the surface and a crease target on the plane y = -50', async () => {
    await view('top');
    await page.click('#tool-sketch');
    await page.selectOption('#sketch-on', 'surface');
    const ellipse = Array.from({ length: 33 }, (_, k) => {
      const a = (2 * Math.PI * k) / 32;
      const x = 350 * Math.cos(a);
      const y = 250 * Math.sin(a);
      return [x, y, height(x, y)];
    });
    await s.draw(ellipse, { steps: 64 });
    await view('front');
    await page.selectOption('#sketch-on', 'xz');
    await page.fill('#sketch-offset', '-50');
    await s.draw(along([-180, 70], [180, 70], 80, 12, (x, z) => [x, -50, z]), { steps: 40 });
    await page.fill('#sketch-offset', '0');
  });
  await step('the style in exact mode (Select the bound, Shift-click the target, Style)', async () => {
    await view('iso');
    await page.click('#tool-orbit');
    await s.clickCurve('s6', false);
    await s.clickCurve('s7', true);
    await page.click('#build-style');
    await s.idle();
    await picture('style');
  });
  await step('reflection lines, mean and Gaussian curvature, before', async () => {
    await page.click('button[data-mode="zebra"]');
    await s.idle();
    await picture('zebra');
    await page.click('button[data-mode="mean"]');
    await s.idle();
    await picture('mean');
    await page.click('button[data-mode="gaussian"]');
    await s.idle();
    await picture('gaussian');
    await page.click('button[data-mode="shaded"]');
    await page.click('#before-after');
    await s.idle();
    await picture('before');
    await page.click('#before-after');
    await s.idle();
  });
  await step('the target dragged by its middle control point (Edit)', async () => {
    await s.clickCurve('s7', false);
    await page.click('#tool-edit');
    const handles = await s.call(() => window.clayStudio.handles());
    const h = handles.filter((x) => x.name === 's7')[Math.floor(handles.filter((x) => x.name === 's7').length / 2)];
    await page.mouse.move(...h.screen);
    await page.mouse.down();
    for (let k = 1; k <= 15; k++) await page.mouse.move(h.screen[0], h.screen[1] - k);
    await page.mouse.up();
    await s.idle();
    await picture('target-drag');
  });
  await step('a lattice on the styled hood, its front edge lifted (Select the hood, Lattice, Edit)', async () => {
    await page.click('#tool-orbit');
    await s.clickAt([520, 330, height(520, 330)], false);
    await page.click('#build-lattice');
    await s.idle();
    const handles = await s.call(() => window.clayStudio.handles());
    const h = handles.find((x) => x.kind === 'lattice' && x.index.join() === '3,1,1');
    await page.selectOption('#lattice-lock', 'z');
    await page.mouse.move(...h.screen);
    await page.mouse.down();
    for (let k = 1; k <= 20; k++) await page.mouse.move(h.screen[0], h.screen[1] - 2 * k);
    await page.mouse.up();
    await s.idle();
    await picture('lattice');
    // the kernel's deviation map of the lattice step: exact composition, so rounding only
    await page.click('button[data-mode="deviation"]');
    await s.idle();
    await picture('deviation');
    await page.click('button[data-mode="shaded"]');
  });
  await step('saved and exported', async () => {
    await page.fill('#save-name', 'hood_styled.json');
    await page.click('#save');
    await s.idle();
    await page.click('#export');
    await page.waitForFunction(() => document.getElementById('message').textContent.startsWith('exported'), null, { timeout: 120000 });
    const recipe = JSON.parse(readFileSync(join(work, 'hood_styled.json'), 'utf8'));
    console.log(`# saved hood_styled.json: ${Object.keys(recipe.strokes).length} strokes, surfaces ${Object.keys(recipe.surfaces).join(', ')}`);
  });
} catch {
  // reported by step()
} finally {
  await browser.close();
  studio.process.kill();
}
console.log(`# pictures in ${out}`);
if (!failed) rmSync(work, { recursive: true, force: true });
else console.log(`# the walkthrough's folder: ${work}`);
process.exit(failed ? 1 : 0);
