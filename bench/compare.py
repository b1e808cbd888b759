#!/usr/bin/env python3
"""Before/after benchmark comparison in one interleaved run.

Runs the same Google Benchmark programs from two build trees alternately (before, after, before,
after, ...), so that machine load and frequency drift hit both sides alike, and prints a Markdown
table of the median real time per benchmark, the ratio after / before of the medians and of the
fastest rounds, and the spread of each side (max / min over the rounds). On a shared VM other
tenants only ever add time, so the fastest round is the least disturbed one: when the spread is
large, the ratio of minima is the steadier figure. The raw JSON of every run goes to --out.

  bench/compare.py BEFORE_BUILD AFTER_BUILD [--rounds 5] [--bench deform --filter 'threads:1']

A benchmark present on one side only is listed without a ratio. Exit status 0; the numbers are
for a person to judge (docs/perf/).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys


def run(program, filt, out_file):
    cmd = [program, f"--benchmark_out={out_file}", "--benchmark_out_format=json"]
    if filt:
        cmd.append(f"--benchmark_filter={filt}")
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(out_file) as f:
        data = json.load(f)
    return {b["name"]: b["real_time"] * {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
            for b in data["benchmarks"] if b.get("run_type", "iteration") == "iteration"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--bench", action="append", help="bench_<name> to run (repeatable); default: all four")
    ap.add_argument("--filter", action="append", help="--benchmark_filter per --bench, in order")
    ap.add_argument("--rounds", type=int, default=5)
    # The raw JSON goes to the build tree by default: results worth keeping are moved under
    # bench/results/ with the perf diary (docs/perf/) that reads them.
    ap.add_argument("--out", default=os.path.join("build", "bench", "compare"))
    a = ap.parse_args()
    benches = a.bench or ["evaluate", "deform", "compose", "style"]
    filters = (a.filter or []) + [""] * len(benches)
    os.makedirs(a.out, exist_ok=True)
    times = {}  # (bench, name) -> {"before": [...], "after": [...]}
    for r in range(a.rounds):
        for bench, filt in zip(benches, filters):
            for side, tree in (("before", a.before), ("after", a.after)):
                program = os.path.join(tree, "bench", f"bench_{bench}")
                result = run(program, filt, os.path.join(a.out, f"{bench}-{side}-{r}.json"))
                for name, t in result.items():
                    times.setdefault((bench, name), {"before": [], "after": []})[side].append(t)
        print(f"round {r + 1}/{a.rounds} done", file=sys.stderr)

    def fmt(t):
        for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
            if t >= scale:
                return f"{t / scale:.3g} {unit}"
        return f"{t:.3g} s"

    print("| benchmark | before (median) | after (median) | after / before | after / before (fastest) "
          "| spread before | spread after |")
    print("|---|---|---|---|---|---|---|")
    for (bench, name), sides in times.items():
        b, f = sides["before"], sides["after"]
        mb = statistics.median(b) if b else None
        mf = statistics.median(f) if f else None
        ratio = f"{mf / mb:.3f}" if mb and mf else "—"
        fastest = f"{min(f) / min(b):.3f}" if b and f else "—"
        spread = lambda xs: f"{max(xs) / min(xs):.3f}" if xs else "—"
        print(f"| {bench}: {name} | {fmt(mb) if mb else '—'} | {fmt(mf) if mf else '—'} | {ratio} | {fastest} "
              f"| {spread(b)} | {spread(f)} |")


if __name__ == "__main__":
    main()
