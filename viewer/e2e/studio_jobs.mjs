// Clayform Studio's end-to-end test, part "jobs" (docs/studio.md § Long jobs; issue #40 item 6):
// a command that runs over a second shows the kernel's progress and a Cancel; the Cancel stops
// it (nothing changed, said as a warning, not an error), and the page goes on working.
import { copyFileSync, mkdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { assert, here } from './studio_harness.mjs';

export default async function jobs({ check, withStudio, work, figures, shot }) {
  await check('a long run shows its progress and stops at Cancel, changing nothing', async () => {
    // The fender's first run takes 46 s in a Release build: long enough to watch and cancel.
    const dir = join(work, 'jobs');
    mkdirSync(dir);
    copyFileSync(join(here, '..', '..', 'examples', 'recipes', 'fender.json'), join(dir, 'fender.json'));
    return withStudio(
      join(dir, 'fender.json'),
      'jobs',
      async (p, k) => {
        const opened = Date.now();
        await p.waitForFunction(() => window.clayStudio && window.clayStudio.progress().shown, null, { timeout: 30000 });
        const shownAfter = Date.now() - opened;
        // The kernel's progress line (sent once a command has run half a second) names a step.
        await p.waitForFunction(() => / step(s)? done/.test(window.clayStudio.progress().text), null, { timeout: 30000 });
        const line = (await k.call(() => window.clayStudio.progress())).text;
        assert(/^run: \S+ \([a-z_]+\); \d+ steps? done \(\d+\.\d s\)$/.test(line), `the progress line reads "${line}"`);
        await shot('jobs-progress', p);
        const cancelled = await k.call(() => Number(document.body.dataset.cancelled || 0));
        const t0 = Date.now();
        await p.click('#progress-cancel');
        assert((await k.call(() => window.clayStudio.progress())).cancelling, 'Cancel is not shown as pressed');
        await p.waitForFunction((n) => Number(document.body.dataset.cancelled || 0) > n, cancelled, { timeout: 60000 });
        const answered = Date.now() - t0;
        await p.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 10000 });
        const message = await k.call(() => window.clayStudio.message());
        assert(message.shown && message.level === 'warning' && /^cancelled: run stopped, nothing changed/.test(message.text), `the message line reads ${JSON.stringify(message)}`);
        assert(!(await k.call(() => document.body.dataset.error)), 'a cancel was shown as an error');
        await p.waitForFunction(() => !window.clayStudio.progress().shown, null, { timeout: 2000 });
        await shot('jobs-cancelled', p);
        // Nothing changed: the history holds the opening alone; the page goes on answering.
        // Nothing changed: the kernel's recipe is the file's, and the page goes on answering.
        const { reply } = await k.call(() => window.clayStudio.send({ op: 'recipe' }));
        const file = JSON.parse(readFileSync(join(dir, 'fender.json'), 'utf8'));
        assert(reply.op === 'recipe' && JSON.stringify(JSON.parse(reply.text)) === JSON.stringify(file), `after the cancel: ${JSON.stringify(reply).slice(0, 200)}`);
        figures.jobs = { progress_shown_after_ms: shownAfter, progress_line: line, cancel_to_answer_ms: answered };
        return `progress shown after ${shownAfter} ms ("${line}"); Cancel answered in ${answered} ms`;
      },
      { wait: false },
    );
  });
}
