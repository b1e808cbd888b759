// Clayform Studio's end-to-end test, part "constraints" (docs/studio.md § Constraints, § Strokes in
// 3D, § A plane at a picked surface point): constraints on two strokes of a plane (coincident,
// tangent, a conflict refused, horizontal); a stroke in 3D between two views; revolve about a
// picked line; a plane at a picked surface point.
import { curveAt, curveDomain, dist, distanceToCurve, surfaceAt, surfaceDomain } from './geometry.mjs';
import { along } from './studio_driver.mjs';
import { assert } from './studio_harness.mjs';

export default async function constraints({ check, withEmptyRecipe }) {
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
      assert(shadow <= 2 * stroke.tolerance_mm + 1, `the 3D curve's shadow is ${shadow} mm off the first curve`);
      assert(heights <= 2 * stroke.tolerance_mm + 2, `the 3D curve's heights are ${heights} mm off the drawn ones`);
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
