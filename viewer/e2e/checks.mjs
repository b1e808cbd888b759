// One TAP-style check runner for the end-to-end tests (viewer.test.mjs, studio_harness.mjs):
// `check(name, fn)` runs fn, prints "ok - name (note) [ms]" or "not ok - name" with the first
// lines of the error's stack, and records the outcome in `results`.

/** A check function bound to a results list; `stackLines` lines of a failure's stack are shown. */
export function checker(results, stackLines = 5) {
  return async function check(name, fn) {
    const t0 = Date.now();
    try {
      const note = await fn();
      results.push(true);
      console.log(`ok - ${name}${note ? ` (${note})` : ''} [${Date.now() - t0} ms]`);
    } catch (e) {
      results.push(false);
      console.log(`not ok - ${name}\n    ${String(e && e.stack ? e.stack : e).split('\n').slice(0, stackLines).join('\n    ')}`);
    }
  };
}
