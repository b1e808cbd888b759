#!/usr/bin/env python3
"""The Python binding's figures (issue #22), in one run, written as JSON (docs/perf/python.md):

    PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py [--out build/bench/python.json]
        [--sweep-variants 64]

- FFD of 1 M points from a NumPy array (FrozenLattice.deform_points, 1 and 2 threads, a
  displaced tricubic Bezier lattice) against bench_deform's `rows` benchmark of the same work,
  run in the same invocation, medians of both: the ratio should be at most 1.2;
- the overhead of a small call (one surface point, one lattice point) in microseconds;
- the GIL: two Python threads each running long calls on 2 cores against one thread doing both
  calls' work in turn (speed-up >= 1.7 asked);
- a sweep of the sail's variants on a Dask LocalCluster with 1 and 2 workers (speed-up), and the
  Dask overhead per variant against the local process executor with 1 worker.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Callable, Dict, List

import numpy as np

import clayform as cf

ROOT = Path(__file__).resolve().parents[1]


def skewed_lattice() -> cf.BezierLattice:
    # bench/frames.hpp's skewed frame, and the same kind of displacement (uniform +-8 mm).
    lat = cf.BezierLattice([-120.0, 35.0, 10.0], [300.0, 20.0, -10.0], [40.0, 180.0, 15.0], [-10.0, 25.0, 90.0], (3, 3, 3))
    lat.points[:] += np.random.default_rng(7).uniform(-8, 8, size=lat.points.shape)
    return lat


def points_in_frame(n: int) -> np.ndarray:
    local = np.random.default_rng(11).uniform(0, 1, size=(n, 3))
    frame = np.array([[300.0, 20.0, -10.0], [40.0, 180.0, 15.0], [-10.0, 25.0, 90.0]])
    return np.ascontiguousarray(np.array([-120.0, 35.0, 10.0]) + local @ frame)


def median_seconds(f: Callable[[], Any], seconds: float = 3.0, least: int = 5) -> float:
    f()  # warm up
    times: List[float] = []
    start = time.perf_counter()
    while len(times) < least or time.perf_counter() - start < seconds:
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def cpp_rows(threads: int, bench: Path) -> float:
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([str(bench), f"--benchmark_filter=^rows/points:1000000/threads:{threads}/bspline:0/",
                        f"--benchmark_out={out.name}", "--benchmark_out_format=json", "--benchmark_min_time=0.6",
                        "--benchmark_repetitions=5"],
                       check=True, capture_output=True)
        result = json.load(open(out.name))
    (row,) = [b for b in result["benchmarks"] if b.get("aggregate_name") == "median"]
    assert row["time_unit"] == "ms"
    return float(row["real_time"]) / 1e3


def ffd(bench: Path) -> Dict[str, Any]:
    frozen = skewed_lattice().freeze()
    pts = points_in_frame(1_000_000)
    out = np.empty_like(pts)
    figures: Dict[str, Any] = {}
    for threads in (1, 2):
        python = median_seconds(lambda: frozen.deform_points(pts, out=out, threads=threads))
        new_array = median_seconds(lambda: frozen.deform_points(pts, threads=threads))
        cpp = cpp_rows(threads, bench)
        figures[f"threads_{threads}"] = {
            "python_ms": python * 1e3,
            "python_new_array_ms": new_array * 1e3,
            "cpp_ms": cpp * 1e3,
            "ratio": python / cpp,
            "ratio_new_array": new_array / cpp,
        }
    return figures


def small_calls() -> Dict[str, Any]:
    knots = [0.0] * 4 + [1.0] * 4
    s = cf.Surface((3, 3), knots, knots, np.random.default_rng(1).normal(size=(16, 3)))
    lat = skewed_lattice()
    frozen = lat.freeze()
    x = [10.0, 80.0, 40.0]
    n = 200_000

    def per_call(f: Callable[[], Any]) -> float:
        t = time.perf_counter()
        for _ in range(n):
            f()
        return (time.perf_counter() - t) / n * 1e6

    return {
        "surface_evaluate_point_us": per_call(lambda: s.evaluate(0.5, 0.5)),
        "frozen_lattice_deform_point_us": per_call(lambda: frozen.deform_point(x)),
        "noop_python_call_us": per_call(lambda: None),
    }


def gil() -> Dict[str, Any]:
    frozen = skewed_lattice().freeze()
    pts = [points_in_frame(2_000_000) for _ in range(2)]
    outs = [np.empty_like(p) for p in pts]
    rounds = 5

    def work(k: int) -> None:
        for _ in range(rounds):
            frozen.deform_points(pts[k], out=outs[k], threads=1)

    t = time.perf_counter()
    work(0)
    work(1)
    one = time.perf_counter() - t
    threads = [threading.Thread(target=work, args=(k,)) for k in (0, 1)]
    t = time.perf_counter()
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    two = time.perf_counter() - t
    return {"one_thread_s": one, "two_threads_s": two, "speedup": one / two}


def sweep(variants: int) -> Dict[str, Any]:
    values = list(np.linspace(0, 630, variants))
    spec = {"format": "clayform.sweep", "version": 1, "recipe": str(ROOT / "examples" / "recipes" / "sail.json"),
            "grid": {"deformations.shape[1].moves[0].by[1]": [round(float(v), 3) for v in values]}}
    figures: Dict[str, Any] = {"variants": variants}
    for name, executor, workers in (("local_1", "local", 1), ("dask_1", "dask", 1), ("dask_2", "dask", 2)):
        with tempfile.TemporaryDirectory() as out:
            t = time.perf_counter()
            rows = cf.sweep(spec, out, executor=executor, workers=workers, progress=lambda *a: None)
            figures[f"{name}_s"] = time.perf_counter() - t
            assert all(r["status"] == "ok" for r in rows), rows
            figures[f"{name}_variant_mean_s"] = statistics.mean(float(r["seconds"]) for r in rows)
    figures["dask_speedup_2_over_1"] = figures["dask_1_s"] / figures["dask_2_s"]
    figures["dask_overhead_per_variant_s"] = (figures["dask_1_s"] - figures["local_1_s"]) / variants
    return figures


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", default=str(ROOT / "build" / "bench" / "python.json"))
    parser.add_argument("--bench-deform", default=str(ROOT / "build" / "bench" / "bench_deform"))
    parser.add_argument("--sweep-variants", type=int, default=64)
    a = parser.parse_args()
    result = {
        "context": {"cpus": os.cpu_count(), "python": sys.version.split()[0], "numpy": np.__version__,
                    "date": time.strftime("%Y-%m-%d %H:%M:%S")},
        "ffd_1m_points": ffd(Path(a.bench_deform)),
        "small_calls": small_calls(),
        "gil_two_threads": gil(),
        "sweep_sail": sweep(a.sweep_variants),
    }
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(result, indent=1))
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
