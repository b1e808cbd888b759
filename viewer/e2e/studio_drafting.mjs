// Clayform Studio's end-to-end test, part "drafting" (docs/studio.md § Drafting aids; issue #40
// item 4): the grid on the sketch plane at the spacing it snaps to, the snap target shown, the
// pointer's coordinates, orthographic and back views, and an underlay image kept over a reload.
import { assert } from './studio_harness.mjs';
import { dist } from './geometry.mjs';

/** The numbers of the status line's "x 12.5  y -3.0  z 0.0 mm". */
function cursorOf(text) {
  const m = /x (-?[\d.]+)\s+y (-?[\d.]+)\s+z (-?[\d.]+) mm/.exec(text);
  return m ? [Number(m[1]), Number(m[2]), Number(m[3])] : null;
}

export default async function drafting({ check, withEmptyRecipe, figures, shot }) {
  await check('the grid drawn is the grid snapped to; snapping and the pointer are shown; ortho and back views; an underlay kept over a reload', async () => {
    return withEmptyRecipe('drafting', async (dp, k) => {
      const out = {};
      await k.call(() => window.clayStudio.setView('top'));
      await k.idle();
      // The grid's spacing is 1, 2 or 5 x 10^k, its cell the smallest at least 14 px on screen,
      // and the status line says it.
      const d0 = await k.call(() => window.clayStudio.drafting());
      const s = d0.spacing;
      const [a, b] = await k.call((x) => [window.clayStudio.toScreen([0, 0, 0]), window.clayStudio.toScreen([x, 0, 0])], s);
      const cellPx = Math.hypot(b[0] - a[0], b[1] - a[1]);
      const mantissa = s / 10 ** Math.floor(Math.log10(s) + 1e-9);
      assert([1, 2, 5].some((m) => Math.abs(mantissa - m) < 1e-9), `grid spacing ${s} mm is not 1, 2 or 5 x 10^k`);
      assert(cellPx >= 14 - 1e-6 && cellPx < 14 * 2.5 + 1e-6, `a grid cell is ${cellPx} px on screen`);
      assert(d0.gridText === `grid ${s} mm` && d0.gridShown, `the status line says "${d0.gridText}"`);
      out.spacing_mm = s;
      out.cell_px = cellPx;
      // The pointer's coordinates, within a pixel.
      const mmPerPixel = s / cellPx;
      const probe = [37.3 * mmPerPixel, -21.6 * mmPerPixel, 0];
      const at = await k.call((p) => window.clayStudio.toScreen(p), probe);
      await dp.mouse.move(at[0], at[1]);
      const shown = cursorOf((await k.call(() => window.clayStudio.drafting())).cursor);
      assert(shown && dist(shown, probe) <= 1.5 * mmPerPixel, `the status line shows ${shown} for ${probe}`);
      out.cursor_error_mm = dist(shown, probe);
      // Snapping on: 3 px from a grid node, the snap target is shown; a stroke from there to 3 px
      // from another node ends exactly on both, its ends moved by the 3 px shown, no more.
      await dp.check('#snap');
      const nodeA = [3 * s, 2 * s, 0];
      const nodeB = [9 * s, 5 * s, 0];
      const off = [3 * mmPerPixel * 0.6, 3 * mmPerPixel * 0.8, 0];
      const nearA = nodeA.map((x, i) => x + off[i]);
      const nearB = nodeB.map((x, i) => x - off[i]);
      const sa = await k.call((p) => window.clayStudio.toScreen(p), nearA);
      await dp.mouse.move(sa[0], sa[1]);
      const snapText = (await k.call(() => window.clayStudio.drafting())).snap;
      assert(snapText === 'snap: grid node', `3 px from a grid node the status line says "${snapText}"`);
      const mid = nearA.map((x, i) => (x + nearB[i]) / 2 + (i === 1 ? 2 * s : 0));
      await k.draw([nearA, mid, nearB], { steps: 30 });
      const c = (await k.call(() => window.clayStudio.curves())).s1;
      assert(c, 'no curve s1');
      const first = c.points.slice(0, 3);
      const last = c.points.slice(-3);
      assert(dist(first, nodeA) <= 1e-9 && dist(last, nodeB) <= 1e-9, `the stroke's ends ${first} and ${last} are not the grid nodes ${nodeA} and ${nodeB}`);
      // On the plane z = 7 the nodes keep z = 7 (the old snap rounded every coordinate to 10 mm).
      await dp.fill('#sketch-offset', '7');
      await dp.dispatchEvent('#sketch-offset', 'input');
      const lifted = [nodeA, mid, nodeB].map((p) => [p[0] + 12 * s, p[1], 7]);
      const nearLifted = [lifted[0].map((x, i) => x + off[i]), lifted[1], lifted[2].map((x, i) => x - off[i])];
      await k.draw(nearLifted, { steps: 30 });
      const c2 = (await k.call(() => window.clayStudio.curves())).s2;
      assert(c2 && dist(c2.points.slice(0, 3), lifted[0]) <= 1e-9 && dist(c2.points.slice(-3), lifted[2]) <= 1e-9, `on z = 7 the ends are ${c2 && c2.points.slice(0, 3)} and ${c2 && c2.points.slice(-3)}`);
      await dp.fill('#sketch-offset', '0');
      await dp.dispatchEvent('#sketch-offset', 'input');
      await dp.uncheck('#snap');
      await shot('drafting-grid-snap', dp);
      // Orthographic: a point and the point 100 mm above it fall on one pixel in the top view, and
      // lengths along the screen are true; the back view shows +x to the left.
      const perspectiveApart = await k.call(() => {
        const p = window.clayStudio.toScreen([200, 150, 0]);
        const q = window.clayStudio.toScreen([200, 150, 100]);
        return Math.hypot(p[0] - q[0], p[1] - q[1]);
      });
      await dp.click('#projection');
      await k.call(() => window.clayStudio.setView('top'));
      await k.idle();
      const ortho = await k.call(() => {
        const p = window.clayStudio.toScreen([200, 150, 0]);
        const q = window.clayStudio.toScreen([200, 150, 100]);
        const o = window.clayStudio.toScreen([0, 0, 0]);
        const x = window.clayStudio.toScreen([100, 0, 0]);
        const y = window.clayStudio.toScreen([0, 100, 0]);
        return { apart: Math.hypot(p[0] - q[0], p[1] - q[1]), xs: Math.hypot(x[0] - o[0], x[1] - o[1]), ys: Math.hypot(y[0] - o[0], y[1] - o[1]), state: window.clayStudio.drafting() };
      });
      assert(ortho.state.orthographic && (await dp.textContent('#projection')) === 'Ortho', 'the projection did not switch');
      // (to a thousandth of a pixel: the matrices' rounding at a 1000 mm eye distance)
      assert(perspectiveApart > 1 && ortho.apart <= 1e-3, `z = 0 and z = 100 are ${ortho.apart} px apart in the orthographic top view (${perspectiveApart} in perspective)`);
      assert(Math.abs(ortho.xs - ortho.ys) <= 1e-3, `100 mm along x is ${ortho.xs} px, along y ${ortho.ys} px`);
      // the grid follows the orthographic zoom as well
      const orthoCell = await k.call(() => {
        const sp = window.clayStudio.drafting().spacing;
        const o = window.clayStudio.toScreen([0, 0, 0]);
        const x = window.clayStudio.toScreen([sp, 0, 0]);
        return Math.hypot(x[0] - o[0], x[1] - o[1]);
      });
      assert(orthoCell >= 14 - 1e-6 && orthoCell < 35 + 1e-6, `an orthographic grid cell is ${orthoCell} px`);
      await k.call(() => window.clayStudio.setView('back'));
      await k.idle();
      const back = await k.call(() => [window.clayStudio.toScreen([0, 0, 0]), window.clayStudio.toScreen([100, 0, 0]), window.clayStudio.toScreen([0, 0, 100])]);
      assert(back[1][0] < back[0][0] && Math.abs(back[1][1] - back[0][1]) < 1e-3, `from the back, +x runs to ${back[1]} from ${back[0]}`);
      assert(back[2][1] < back[0][1], 'from the back, +z is not up');
      // A stroke drawn in the orthographic front view on plane XZ lies on its drawn points.
      await k.call(() => window.clayStudio.setView('front'));
      await dp.selectOption('#sketch-on', 'xz');
      await k.idle();
      const drawn = [[-80, 0, 10], [0, 0, 60], [90, 0, 20]];
      await k.draw(drawn, { steps: 40 });
      const c3 = (await k.call(() => window.clayStudio.curves())).s3;
      const px = await k.call(() => {
        const o = window.clayStudio.toScreen([0, 0, 0]);
        const x = window.clayStudio.toScreen([100, 0, 0]);
        return 100 / Math.hypot(x[0] - o[0], x[1] - o[1]);
      });
      let yOff = 0;
      for (let i = 1; i < c3.points.length; i += 3) yOff = Math.max(yOff, Math.abs(c3.points[i]));
      assert(yOff <= 1e-9, `the orthographic stroke leaves plane XZ by ${yOff} mm`);
      const ends = [c3.points.slice(0, 3), c3.points.slice(-3)];
      const endOff = Math.max(dist(ends[0], drawn[0]), dist(ends[1], drawn[2]));
      assert(endOff <= 0.5 + 1.5 * px, `the orthographic stroke's ends are ${endOff} mm from the drawn ones`);
      out.ortho_stroke_end_mm = endOff;
      // An underlay: a 200 x 100 image, 400 mm wide on plane XZ, centred at (50, 40).
      const png = await k.call(() => {
        const cv = document.createElement('canvas');
        cv.width = 200;
        cv.height = 100;
        const g = cv.getContext('2d');
        g.fillStyle = '#d0d0d0';
        g.fillRect(0, 0, 200, 100);
        g.strokeStyle = '#203040';
        g.lineWidth = 4;
        g.beginPath();
        g.ellipse(100, 60, 80, 30, 0, 0, 2 * Math.PI);
        g.stroke();
        return cv.toDataURL('image/png').split(',')[1];
      });
      await dp.selectOption('#underlay-plane', 'xz');
      await dp.fill('#underlay-x', '50');
      await dp.fill('#underlay-y', '40');
      await dp.fill('#underlay-width', '400');
      await dp.setInputFiles('#underlay-file', { name: 'side.png', mimeType: 'image/png', buffer: Buffer.from(png, 'base64') });
      await dp.waitForFunction(() => window.clayStudio.drafting().underlay !== null);
      const u = (await k.call(() => window.clayStudio.drafting())).underlay;
      assert(u.plane === 'xz' && u.width === 400 && Math.abs(u.height - 200) < 1e-9 && u.centre[0] === 50 && u.centre[1] === 40, `underlay ${JSON.stringify(u)}`);
      await k.call(() => window.clayStudio.setView('fit'));
      await k.idle();
      await shot('drafting-underlay-ortho', dp);
      // kept over a reload
      await dp.reload();
      await dp.waitForFunction(() => ['1', 'error'].includes(document.body.dataset.ready), null, { timeout: 60000 });
      await dp.waitForFunction(() => window.clayStudio.drafting().underlay !== null, null, { timeout: 10000 });
      const kept = (await k.call(() => window.clayStudio.drafting())).underlay;
      assert(JSON.stringify(kept) === JSON.stringify(u), `after a reload the underlay is ${JSON.stringify(kept)}`);
      await dp.click('#underlay-remove');
      assert((await k.call(() => window.clayStudio.drafting())).underlay === null, 'the underlay was not removed');
      figures.drafting = out;
      return `grid ${s} mm (${cellPx.toFixed(1)} px a cell) snapped to exactly, on z = 7 too; pointer within ${out.cursor_error_mm.toExponential(1)} mm; orthographic top, back and front views; an orthographic stroke's ends ${endOff.toFixed(2)} mm off; underlay 400 x 200 mm kept over a reload`;
    });
  });
}
