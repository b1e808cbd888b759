// Clayform Studio's end-to-end test, part "model" (docs/studio.md § Opening a STEP model): a STEP
// model opened whole, a lattice placed around it and dragged (the nodes moved onto the faces' new
// nets, checked against Sederberg–Parry's FFD here), saved and replayed by `clayform run`; the
// drag keeping the model's volume (issue #41).
import { spawnSync } from 'node:child_process';
import { copyFileSync, mkdirSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { ffd, latticePoints } from './geometry.mjs';
import { assert, here } from './studio_harness.mjs';

export default async function model({ clayform, work, check, withStudio }) {
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
      // Issue #40: a z-locked drag in the Top view, the axis along the line of sight, threw a
      // lattice point to z = 857 mm. Now the pointer's height moves it a pixel's size per pixel,
      // and x and y stay exactly what they were.
      await modelPage.click('button[data-view="top"]');
      await m.idle();
      const top = (await m.call(() => window.clayStudio.handles())).find((h) => h.kind === 'lattice' && h.index.join() === '1,1,1');
      await modelPage.mouse.move(...top.screen);
      await modelPage.mouse.down();
      for (let k = 1; k <= 10; k++) await modelPage.mouse.move(top.screen[0] + 2 * k, top.screen[1] - 3 * k);
      await modelPage.mouse.up();
      await m.idle();
      assert(!(await m.lastError()), await m.lastError());
      const locked = await m.call(() => window.clayStudio.recipe());
      const lockedStep = locked.deformations[locked.models.block.deformation][0];
      const move = lockedStep.moves.find((mv) => mv.index.join() === '1,1,1');
      assert(move && move.to, `no move of [1, 1, 1]: ${JSON.stringify(lockedStep.moves)}`);
      assert(move.to[0] === top.p[0] && move.to[1] === top.p[1], `x, y moved under a z lock: ${top.p} -> ${move.to}`);
      const height = Math.hypot(...lockedStep.frame.u);
      const rise = move.to[2] - top.p[2];
      assert(rise > 0 && rise < 0.5 * height, `a 30-pixel z-locked drag in the Top view moved the point by ${rise} mm (lattice ${height} mm high)`);
      // Issue #41: the panel shows the model's volume change; with "keep the volume" ticked the
      // kernel corrects the points not dragged, the volume stays to 1e-12, and a new drag keeps it.
      const free = (await m.call(() => window.clayStudio.reply())).model_figures.block;
      const freeChange = free.volume_after_mm3 / free.volume_before_mm3 - 1;
      assert(Math.abs(freeChange) > 1e-4, `the drags did not change the volume: ${JSON.stringify(free)}`);
      assert((await modelPage.locator('#lattice-volume').textContent()).includes('block: volume'), 'no volume in the lattice panel');
      await modelPage.check('#lattice-keep-volume');
      await m.idle();
      assert(!(await m.lastError()), await m.lastError());
      const ticked = await m.call(() => window.clayStudio.recipe());
      assert(JSON.stringify(ticked.deformations[ticked.models.block.deformation][0].keep) === '["volume"]', 'the step has no keep');
      const kept = (await m.call(() => window.clayStudio.reply())).model_figures.block;
      assert(Math.abs(kept.volume_after_mm3 / kept.volume_before_mm3 - 1) < 1e-12, `kept volume ${kept.volume_before_mm3} -> ${kept.volume_after_mm3}`);
      assert(kept.kept.length === 1 && kept.kept[0].largest_correction_mm > 0, `kept: ${JSON.stringify(kept.kept)}`);
      assert((await modelPage.locator('#lattice-volume').textContent()).includes('kept'), 'the panel does not say the volume is kept');
      const again = (await m.call(() => window.clayStudio.handles())).find((h) => h.kind === 'lattice' && h.index.join() === '2,2,1');
      await modelPage.mouse.move(...again.screen);
      await modelPage.mouse.down();
      for (let k = 1; k <= 10; k++) await modelPage.mouse.move(again.screen[0] + 2 * k, again.screen[1] + 2 * k);
      await modelPage.mouse.up();
      await m.idle();
      assert(!(await m.lastError()), await m.lastError());
      const dragged = (await m.call(() => window.clayStudio.reply())).model_figures.block;
      const draggedRecipe = await m.call(() => window.clayStudio.recipe());
      assert(draggedRecipe.deformations[draggedRecipe.models.block.deformation][0].moves.some((mv) => mv.index.join() === '2,2,1'), 'the second drag moved nothing');
      assert(Math.abs(dragged.volume_after_mm3 / dragged.volume_before_mm3 - 1) < 1e-12, `after a kept drag: ${dragged.volume_before_mm3} -> ${dragged.volume_after_mm3}`);
      return `${models.block.triangles} triangles; the top rose ${(topAfter - topBefore).toFixed(2)} mm; after the drag the faces' nets only, the nodes ${worstNode.toExponential(1)} mm from the pointwise FFD; replay wrote ${files.filter((f) => f.startsWith('block')).join(', ')}; a z-locked drag in the Top view rose ${rise.toFixed(2)} mm, x and y kept exactly; volume ${(freeChange * 100).toFixed(2)} % free, kept to ${Math.abs(dragged.volume_after_mm3 / dragged.volume_before_mm3 - 1).toExponential(1)} after two drags (points corrected by up to ${kept.kept[0].largest_correction_mm.toFixed(2)} mm)`;
    });
  });
}
