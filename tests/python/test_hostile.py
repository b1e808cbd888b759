"""Hostile and careless calls (issue #36): threads racing a sketch's solve, unbounded sizes,
overlapping outputs, indexes outside a lattice, NaN and infinite points, wrong types, a folded
lattice on a solid. Each is refused with a typed error that names the argument, never a crash or
a silently wrong result."""
from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import clayform as cf


def chain_sketch(n: int) -> cf.Sketch:
    """A planar chain of n lines, each end fixed to the next start, lengths and angles set: a solve
    that takes long enough for another thread to run beside it."""
    sk = cf.Sketch()
    plane = sk.add_plane([0, 0, 0], [0, 0, 1])
    points = [sk.add_point([10.0 * k, (k % 2) * 3.0, 0], plane) for k in range(n + 1)]
    lines = [sk.add_line(points[k], points[k + 1]) for k in range(n)]
    sk.fixed(points[0])
    for k, line in enumerate(lines):
        sk.distance(points[k], points[k + 1], mm=10.0 + (k % 3))
    return sk


def test_sketch_solve_while_another_thread_adds_never_crashes() -> None:
    # The solve ran without the GIL on the sketch itself; adding points from another thread
    # reallocated what it read and killed the interpreter (SIGSEGV, 3 of 3 runs).
    sk = chain_sketch(600)  # about 50 ms a solve here
    outcomes: list = []
    stop = threading.Event()

    def solver() -> None:
        for _ in range(6):
            try:
                outcomes.append(sk.solve()["converged"])
            except cf.InvalidArgumentError as e:
                assert "while solve() ran in another thread" in str(e)
                outcomes.append("refused")
        stop.set()

    def adder() -> None:
        # A few hundred free points while the solves run (each solve solves what it copied; an
        # unbounded adder would make the later solves' problems grow without end).
        for k in range(300):
            if stop.is_set():
                break
            sk.add_point([1000.0 + k, 0, 0])
            time.sleep(0.001)

    threads = [threading.Thread(target=solver), threading.Thread(target=adder)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert len(outcomes) == 6
    assert "refused" in outcomes  # the adder ran during a solve: its result was not applied
    # Alone again, it solves and its points meet the constraints.
    report = sk.solve()
    assert report["converged"]
    a, b = np.array(sk.position(0)), np.array(sk.position(1))
    assert abs(np.linalg.norm(b - a) - 10.0) < 1e-8


def test_tessellate_sizes_are_bounded(bezier_patch: cf.Surface) -> None:
    for per_span, max_samples in [(10**9, 161), (8, 10**9), (10**9, 10**9), (0, 161), (8, 16)]:
        with pytest.raises(cf.InvalidArgumentError, match=r"must be in \[1, 4096\] and \[17, 4097\]"):
            bezier_patch.tessellate(per_span=per_span, max_samples=max_samples)
    vertices, faces, normals = bezier_patch.tessellate(per_span=4096, max_samples=257)
    assert len(vertices) == 257 * 257 and np.isfinite(vertices).all()  # one span: 257 samples


def lattice() -> cf.BezierLattice:
    return cf.BezierLattice([0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10], (2, 2, 3))


def test_lattice_index_is_checked() -> None:
    lat = lattice()
    assert lat.index(2, 2, 3) == len(lat.points) - 1
    for bad in [(0, 0, 4), (3, 0, 0), (0, -1, 0)]:
        with pytest.raises(IndexError, match="outside the lattice's 3 x 3 x 4 points"):
            lat.index(*bad)


def test_deform_points_refuses_partial_overlap_and_allows_in_place() -> None:
    lat = lattice()
    lat.points[lat.index(1, 1, 1)] += [1.0, 2.0, 3.0]
    rng = np.random.default_rng(7)
    base = rng.uniform(0, 10, size=(200, 3))
    expected = lat.deform_points(base)
    # in place: the same memory
    a = base.copy()
    lat.deform_points(a, out=a)
    assert np.array_equal(a, expected)
    # a window shifted by one row over the same buffer would read rows already written
    buffer = np.concatenate([base, np.zeros((1, 3))])
    with pytest.raises(ValueError, match="overlaps points without being points itself"):
        lat.deform_points(buffer[:-1], out=buffer[1:])
    assert np.array_equal(buffer[:-1], base)  # nothing written


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_points_are_refused(bad: float) -> None:
    lat = lattice()
    points = np.zeros((5, 3))
    points[3, 1] = bad
    with pytest.raises(ValueError, match="row 3 is not finite"):
        lat.deform_points(points)
    with pytest.raises(ValueError, match="row 3 is not finite"):
        lat.freeze().deform_points(points)
    stack = cf.DeformationStack.from_json(json.dumps({
        "format": "clayform.deformation-stack", "version": 1,
        "steps": [{"kind": "twist", "name": "twist",
                   "frame": {"origin": [0, 0, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]},
                   "angle": [0.0, 0.02]}]}))
    with pytest.raises(ValueError, match="row 3 is not finite"):
        stack.deform_points(points)
    with pytest.raises(ValueError, match="finite"):
        cf.BezierLattice([0, bad, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10])


def test_wrong_types_name_the_argument() -> None:
    with pytest.raises(TypeError, match="origin: expected 3 numbers"):
        cf.BezierLattice("abc", [10, 0, 0], [0, 10, 0], [0, 0, 10])  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="s: expected 3 numbers"):
        cf.BezierLattice([0, 0, 0], {"x": 1}, [0, 10, 0], [0, 0, 10])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="origin: expected 3 coordinates, got 2"):
        cf.BezierLattice([0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10])


def folding_recipe(examples: Path, tmp_path: Path, allow: bool) -> Path:
    # A trilinear lattice around the block whose +x bottom corner is pulled through the -x one:
    # its Jacobian changes sign, so the deformed solid would intersect itself.
    recipe = {
        "format": "clayform.recipe", "version": 1, "name": "fold",
        "deformations": {"fold": [{
            "kind": "bezier_lattice", "frame": {"origin": [-5, -5, -5], "s": [70, 0, 0], "t": [0, 50, 0], "u": [0, 0, 30]},
            "degrees": [1, 1, 1], "moves": [{"index": [1, 0, 0], "to": [-60, -5, -5]}]}]},
        "models": {"block": {"import": str(examples / "models" / "block.step"), "deformation": "fold"}},
    }
    if allow:
        recipe["models"]["block"]["allow_fold"] = True
    path = tmp_path / ("fold_allowed.json" if allow else "fold.json")
    path.write_text(json.dumps(recipe))
    return path


def test_a_folded_lattice_fails_the_model_unless_allowed(examples: Path, tmp_path: Path) -> None:
    model, _ = cf.read_model(examples / "models" / "block.step")
    recipe = cf.Recipe.load(folding_recipe(examples, tmp_path, False))
    with pytest.raises(cf.InvalidGeometryError, match="may fold space"):
        recipe.deform_model(model, "fold")
    with pytest.raises(cf.InvalidGeometryError, match="allow_fold"):
        recipe.run()
    folded, report = recipe.deform_model(model, "fold", allow_fold=True)
    assert report["fold_free"] is False
    # allowed in the recipe itself too
    allowed = cf.Recipe.load(folding_recipe(examples, tmp_path, True))
    result = allowed.run()
    assert result is not None


def test_a_denormal_coordinate_is_refused_by_the_check(examples: Path, tmp_path: Path) -> None:
    doc = json.loads((examples / "recipes" / "sail.json").read_text())
    doc["curves"]["luff"]["line"]["from"][0] = 5e-324
    path = tmp_path / "denormal.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(cf.DocumentError, match=r"curves\.luff\.line\.from\[0\].*denormal"):
        cf.Recipe.load(path)


def test_four_threads_run_one_recipe_into_one_folder(examples: Path, tmp_path: Path) -> None:
    # They staged in one temporary folder named after the process and failed (issue #36); each
    # run now stages in a folder of its own and the last to finish leaves a complete output.
    recipe = cf.Recipe.load(examples / "recipes" / "sail.json")  # about 1 s a run: they overlap
    out = tmp_path / "same"
    errors: list = []

    def run() -> None:
        try:
            recipe.run(out)
        except Exception as e:  # noqa: BLE001 - any failure is the finding
            errors.append(repr(e))

    threads = [threading.Thread(target=run) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    assert errors == []
    names = sorted(p.name for p in out.iterdir())
    assert "report.json" in names and any(n.endswith(".step") for n in names)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no staging left
