// Clayform Studio's end-to-end test, part "regular": taper and twist from the sliders against
// Barr's formulas, a surface point pulled by direct manipulation (Hsu–Hughes–Kaufman), a B-spline
// lattice dragged (the surface and the page's picture while dragging against the pointwise FFD).
import { mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { bsplineFfd, bsplineLatticePoints, dist, surfaceAt, surfaceDomain } from './geometry.mjs';
import { assert, deviationAgainst, offPointwise } from './studio_harness.mjs';

export default async function regular({ work, check, withStudio }) {
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
