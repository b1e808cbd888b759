"""Pickling through a separate process, recipes in Python against the command, the GIL, and the
run cache."""
from __future__ import annotations

import json
import pickle
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

import clayform as cf

CHILD = r"""
import pickle, sys
import numpy as np
surface, lattice, recipe = pickle.load(sys.stdin.buffer)
u, v = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 7))
result = recipe.run()
pickle.dump((surface.evaluate(u, v), lattice.deform_points(surface.points.copy()),
             result.surfaces["sail"], surface), sys.stdout.buffer)
"""


def test_pickle_round_trip_through_another_process(bezier_patch: cf.Surface, examples: Path) -> None:
    lattice = cf.BSplineLattice([-5, -5, -30], [110, 0, 0], [0, 110, 0], [0, 0, 60], (2, 2, 2), (3, 2, 1))
    lattice.points[7] += [1.0, 2.0, 3.0]
    recipe = cf.Recipe.load(str(examples / "recipes" / "sail.json"))
    data = pickle.dumps((bezier_patch, lattice, recipe))
    out = subprocess.run([sys.executable, "-c", CHILD], input=data, capture_output=True, check=True)
    points, deformed, sail, back = pickle.loads(out.stdout)
    u, v = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 7))
    assert points.tobytes() == bezier_patch.evaluate(u, v).tobytes()
    assert deformed.tobytes() == lattice.deform_points(bezier_patch.points.copy()).tobytes()
    assert back.identical(bezier_patch)
    assert sail.identical(recipe.run().surfaces["sail"])


def test_python_and_the_command_write_the_same_step_geometry(examples: Path, exe: str, tmp_path: Path) -> None:
    recipe = examples / "recipes" / "sail.json"
    result = cf.Recipe.load(str(recipe)).run(tmp_path / "py")
    subprocess.run([exe, "run", str(recipe), "--out", str(tmp_path / "cli"), "--quiet"], check=True)
    ours = cf.read_step(str(tmp_path / "py" / "sail.step"))
    theirs = cf.read_step(str(tmp_path / "cli" / "sail.step"))
    assert len(ours) == len(theirs) == 1 and ours[0].identical(theirs[0])
    assert result.report["ok"] is True and result.report["recipe"] == "sail"
    assert (tmp_path / "py" / "report.json").exists() and (tmp_path / "py" / "sail.igs").exists()


def test_long_calls_release_the_gil() -> None:
    # While one thread deforms millions of points, the main thread keeps running: with the GIL
    # held its loop would stall for the whole call.
    lat = cf.BezierLattice([0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], (3, 3, 3)).freeze()
    pts = np.random.default_rng(0).uniform(0, 1, size=(2_000_000, 3))
    out = np.empty_like(pts)
    call = [0.0, 0.0]

    def work() -> None:
        call[0] = time.perf_counter()
        for _ in range(3):
            lat.deform_points(pts, out=out, threads=1)
        call[1] = time.perf_counter()

    worker = threading.Thread(target=work)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        sum(range(200))
    worker.join()
    inside = [t for t in ticks if call[0] <= t <= call[1]]
    duration = call[1] - call[0]
    assert len(inside) > 10, f"the main thread ran {len(inside)} times during a {duration:.2f} s call"
    assert max(np.diff(inside)) < duration / 3


def test_a_run_cache_takes_unchanged_steps_bit_for_bit(examples: Path) -> None:
    # Issue #40: a second run with the same RunCache takes every step; an edit of the sail's
    # lattice (its stack's second step) re-runs only the lattice, the style before it taken from
    # the cache, and every result equals a run without cache.
    text = (examples / "recipes" / "sail.json").read_text()
    base = str(examples / "recipes")
    cache = cf.RunCache()
    first = cf.Recipe.parse(text, base).run(cache=cache)
    assert not any(s["reused"] for s in first.steps)
    assert cache.counts["kept"] == 8  # five curves, two surfaces and the sail's stack's first step
    again = cf.Recipe.parse(text, base).run(cache=cache)
    assert all(s["reused"] for s in again.steps if not s["path"].startswith("exports."))
    assert cache.counts["reused"] == 7
    doc = json.loads(text)
    doc["deformations"]["shape"][1]["moves"][0]["by"][1] = 350
    edited = json.dumps(doc)
    cached = cf.Recipe.parse(edited, base).run(cache=cache)
    whole = cf.Recipe.parse(edited, base).run()
    assert {s["path"] for s in cached.steps if not s["reused"] and not s["path"].startswith("exports.")} == {
        "surfaces.sail.steps[1]"}
    for name, surface in whole.surfaces.items():
        assert np.array_equal(cached.surfaces[name].points, surface.points)
        assert np.array_equal(cached.surfaces[name].weights, surface.weights)
    for name, curve in whole.curves.items():
        assert np.array_equal(cached.curves[name].points, curve.points)
    small = cf.RunCache(capacity_bytes=16)  # holds none of them: nothing kept, nothing wrong
    assert np.array_equal(cf.Recipe.parse(text, base).run(cache=small).surfaces["sail"].points,
                          first.surfaces["sail"].points)
    assert small.counts["entries"] == 0
