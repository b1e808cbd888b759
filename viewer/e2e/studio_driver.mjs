// Driving Clayform Studio from Node (the end-to-end test and the docs' walkthrough): start
// `clayform studio` on a recipe, open its page in Debian's headless Chromium (playwright-core),
// and draw, click and pick with synthesized pointer events through the page's window.clayStudio.
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';
import { curveAt, curveDomain } from './geometry.mjs';

/** Starts `clayform studio RECIPE --port 0`; resolves with {url (with the session's token), port, process} once it prints its address. */
export function startStudio(clayform, recipe) {
  const child = spawn(clayform, ['studio', recipe, '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
  return new Promise((resolve, reject) => {
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/Clayform Studio at (http:\/\/127\.0\.0\.1:(\d+)\/\?token=[0-9a-f]+)/);
      if (m) resolve({ url: m[1], port: Number(m[2]), process: child });
    });
    child.on('exit', (code) => reject(new Error(`clayform studio exited (${code}) before printing its address`)));
    setTimeout(() => reject(new Error('clayform studio printed no address in 20 s')), 20000);
  });
}

/** Headless Chromium with software rendering, as on the CI machine. */
export function launchBrowser(executablePath) {
  return chromium.launch({
    executablePath,
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
}

/** Points from a to b (in a plane whose other coordinate is `fixed`), bowed sideways by `bow` mm. */
export function along(a, b, bow, n = 8, place = (x, y) => [x, y, 0]) {
  return Array.from({ length: n + 1 }, (_, k) => {
    const t = k / n;
    const dx = b[0] - a[0];
    const dy = b[1] - a[1];
    const len = Math.hypot(dx, dy);
    return place(a[0] + t * dx - (bow * 4 * t * (1 - t) * dy) / len, a[1] + t * dy + (bow * 4 * t * (1 - t) * dx) / len);
  });
}

/** The page's studio, driven: call (page.evaluate), idle, lastError, draw, clickAt, clickCurve, openedAt. */
export function studioPage(page) {
  const call = (fn, arg) => page.evaluate(fn, arg);
  const idle = () => call(() => window.clayStudio.idle());
  const lastError = () => call(() => document.body.dataset.error || '');
  /**
   * Draws one stroke through the world points `world` (the pointer follows their screen
   * positions, `steps` moves in all); resolves with the screen path drawn once the kernel answered.
   */
  async function draw(world, { steps = 40 } = {}) {
    const screen = await call((pts) => pts.map((p) => window.clayStudio.toScreen(p)), world);
    const path = [];
    const per = steps / (screen.length - 1);
    for (let k = 0; k < screen.length - 1; k++)
      for (let s = 0; s < per; s++) {
        const f = s / per;
        path.push([screen[k][0] + f * (screen[k + 1][0] - screen[k][0]), screen[k][1] + f * (screen[k + 1][1] - screen[k][1])]);
      }
    path.push(screen[screen.length - 1]);
    await page.mouse.move(...path[0]);
    await page.mouse.down();
    for (const p of path.slice(1)) await page.mouse.move(...p);
    await page.mouse.up();
    await idle();
    const error = await lastError();
    if (error) throw new Error(`the stroke was refused: ${error}`);
    return path;
  }
  async function clickAt(world, shift) {
    const [x, y] = await call((p) => window.clayStudio.toScreen(p), world);
    if (shift) await page.keyboard.down('Shift');
    await page.mouse.click(x, y);
    if (shift) await page.keyboard.up('Shift');
  }
  /** Clicks a curve at 37 % of its parameter range (evaluated here from its net). */
  async function clickCurve(name, shift) {
    const curves = await call(() => window.clayStudio.curves());
    const c = curves[name];
    if (!c) throw new Error(`no curve "${name}" (${Object.keys(curves)})`);
    const [a, b] = curveDomain(c);
    await clickAt(curveAt(c, a + 0.37 * (b - a)), shift);
  }
  /** Opens the page and waits until it has run the recipe. */
  async function open(url) {
    await page.goto(url);
    await page.waitForFunction(() => ['1', 'error'].includes(document.body.dataset.ready), null, { timeout: 60000 });
    if ((await call(() => document.body.dataset.ready)) !== '1') throw new Error(`the page did not start: ${await lastError()}`);
  }
  return { call, idle, lastError, draw, clickAt, clickCurve, open };
}
