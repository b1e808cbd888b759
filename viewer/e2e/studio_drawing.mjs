// Clayform Studio's end-to-end test, part "drawing" (docs/studio.md, the walkthrough): strokes drawn
// on the XY plane, each fitted curve checked against the drawn path back-projected through the
// page's camera (here, not by the page); a fill of four of them; a bound and a target drawn and the
// style applied in exact mode, checked for locality outside the bound and for the target met; the
// target dragged and redrawn with "restyle while drawing"; the analysis modes; a lattice placed and
// one of its points dragged for 5 s, the surface checked against Sederberg–Parry's FFD evaluated
// pointwise here; undo and redo; the recipe saved and replayed by `clayform run`, whose STEP file
// must hold the page's control points bit for bit; export; a socket from another origin refused.
import { spawnSync } from 'node:child_process';
import { createServer, request } from 'node:http';
import { readFileSync, readdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { curveDomain, curveAt, dist, distanceToCurve, ffd, insidePolygon, latticePoints, quantile, surfaceAt, surfaceDomain } from './geometry.mjs';
import { along, startStudio } from './studio_driver.mjs';
import { assert, checkStroke as checkStrokeOn, deviationAgainst, draw as drawOn, offPointwise, stepSurfaces } from './studio_harness.mjs';

export default async function drawing({ clayform, work, browser, page, driver, check, shot, figures }) {
  writeFileSync(join(work, 'drawn.json'), JSON.stringify({ format: 'clayform.recipe', version: 1, name: 'drawn' }));
  // this part's studio (the other parts open studios of their own)
  const main = await startStudio(clayform, join(work, 'drawn.json'));
  const { url, port } = main;
  const token = new URL(url).searchParams.get('token');
  const { idle, lastError, clickAt, clickCurve } = driver;
  const studioCall = driver.call;
  const draw = (world, options) => drawOn(driver, world, options);
  const checkStroke = (name, drawn) => checkStrokeOn(driver, name, drawn);
  try {
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
      figures.style = { key_points: f.key_points, target_deviation: f.target_deviation, target_curve_deviation: f.target_curve_deviation, locality: f.locality, moved_outside_mm: moved, samples_outside: checked, kernel_ms: 1000 * step.seconds, curvature_waves: f.curvature_waves };
      return `${f.key_points} key points, target deviation ${f.target_deviation}, curve ${f.target_curve_deviation}; ${checked} samples outside the bound moved ${moved} mm; curvature waves ${f.curvature_waves}`;
    });
    await shot('styled');

    await check('the Style panel\'s net convergence: 5 % converges as far as it goes (best effort), off styles on the first net again', async () => {
      const figuresAt = async (value) => {
        await page.selectOption('#style-convergence', value);
        await idle();
        assert(!(await lastError()), await lastError());
        const recipe = await studioCall(() => window.clayStudio.recipe());
        const written = Object.values(recipe.deformations).find((st) => st[0].kind === 'style')[0];
        assert(written.net_convergence === Number(value) && written.net_convergence_best_effort === Number(value) > 0, `convergence ${value} wrote ${JSON.stringify(written)}`);
        const step = (await studioCall(() => window.clayStudio.reply())).steps.find((st) => st.kind === 'style');
        return { waves: step.figures.curvature_waves, net_change: step.figures.net_change, knots: step.figures.knots_inserted, ms: 1000 * step.seconds };
      };
      const calm = await figuresAt('0.05');
      const shown = await page.locator('#style-figures').textContent();
      assert(shown.includes('net convergence: last halving'), `the Style panel shows: ${shown}`);
      const off = await figuresAt('0');
      assert(off.net_change === null, `convergence off measured a net change ${off.net_change}`);
      assert(Number.isFinite(calm.net_change) && calm.knots > off.knots, `5 %: ${JSON.stringify(calm)}, off ${JSON.stringify(off)}`);
      figures.style_convergence = { off, calm };
      return `first net: ${off.waves} curvature waves, ${off.knots} knots inserted, ${off.ms.toFixed(0)} ms; 5 % best effort: ${calm.waves} waves, net change ${calm.net_change.toPrecision(2)}, ${calm.knots} knots, ${calm.ms.toFixed(0)} ms`;
    });

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
    await check('a lattice on the styled surface, a point dragged for 5 s: the surface is the pointwise FFD within its certified bound', async () => {
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
      // Exact, or (above the composition's budget) a certified light form: the step's report says
      // which and its bound, and the page says so too.
      const report = (await studioCall(() => window.clayStudio.steps())).find((s) => s.path === 'surfaces.fill1_styled1_ffd1.steps[0]');
      assert(report, 'no report of the lattice step');
      const light = report.figures.composition === 'light';
      const bound = light ? report.figures.max_deviation_mm : 0;
      const worst = offPointwise(afterDrag, parent, (x) => ffd(step, points, x), 24);
      assert(worst <= bound + 1e-9 * 1000, `the dragged surface is ${worst} mm off the pointwise FFD (${report.figures.composition}, bound ${bound} mm)`);
      const form = await page.textContent('#form');
      assert(form.includes(`fill1_styled1_ffd1: ${light ? 'light form' : 'exact'}`), `the page says: ${form}`);
      // The Deviation mode's map, the kernel's: at its grid, the distance computed here from the
      // surface to the pointwise FFD of its parent.
      const deviation = await deviationAgainst(studioCall, 'fill1_styled1_ffd1', afterDrag, parent, (x) => ffd(step, points, x));
      assert(deviation.max <= bound + 1e-9 * 1000, `the deviation map's largest value is ${deviation.max} mm (bound ${bound} mm)`);
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

    await check('export for the chosen receiver (bicubic) writes STEP, IGES and glTF, read back and checked', async () => {
      await page.selectOption('#export-profile', 'bicubic');
      await page.click('#export');
      await page.waitForFunction(() => document.getElementById('message').textContent.startsWith('exported') || document.body.dataset.error, null, { timeout: 60000 });
      assert(!(await lastError()), await lastError());
      const message = await page.textContent('#message');
      assert(message.includes('for bicubic, within'), `the message does not name the profile and bound: ${message}`);
      const files = readdirSync(join(work, 'drawn-export'));
      for (const ext of ['.step', '.igs', '.glb']) assert(files.some((f) => f.endsWith(ext)), `no ${ext} in ${files}`);
      const report = JSON.parse(readFileSync(join(work, 'drawn-export', 'report.json'), 'utf8'));
      assert(report.exports[0].profile === 'bicubic', `report.json says ${report.exports[0].profile}`);
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
  } finally {
    main.process.kill();
  }
}
