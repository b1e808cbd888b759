#!/usr/bin/env python3
"""The table of issue #39: every file of tests/data/cad read (isolated, as `clayform` reads),
stretched by an affine lattice (volume against det(A) x the original) and bulged by a (1, 1, 2)
Bézier lattice, each result checked (brep problems, written as STEP and checked by BRepCheck;
every face at (u, v) against the lattice's map of the original face at the same (u, v)), with the
times, beside FreeCAD's own reading (faces, solids, volume, validity) when its figures are given.
Prints a Markdown table. Usage:
    CLAY_FREECAD_OUT=freecad.json freecadcmd scripts/freecad_real_files.py
    PYTHONPATH=build/python scripts/real_files_table.py [freecad.json]"""
from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import clayform as cf

CAD = Path(__file__).resolve().parents[1] / "tests" / "data" / "cad"
STRETCH = np.diag([1.2, 0.9, 1.1])


def stretched(model: cf.Model) -> cf.BezierLattice:
    lattice = cf.lattice_around(model, degrees=(1, 1, 1))
    origin = np.array(lattice.frame[0])
    lattice.points = (lattice.points - origin) @ STRETCH.T + origin
    return lattice


def bulged(model: cf.Model) -> cf.BezierLattice:
    """The (1, 1, 2) bulge of issue #39: the middle layer pushed out along x by a tenth."""
    lattice = cf.lattice_around(model, degrees=(1, 1, 2))
    lo, hi = (np.array(c) for c in model.bounding_box())
    points = lattice.points
    for i in range(2):
        for j in range(2):
            points[lattice.index(i, j, 1), 0] += (0.1 if i else -0.1) * (hi - lo).max()
    lattice.points = points
    return lattice


def outcome(model: cf.Model, lattice: object, folder: Path, name: str) -> tuple[str, float, object]:
    start = time.perf_counter()
    try:
        result, report = model.deform(lattice, profile="opencascade")
    except cf.ClayError as e:
        return "refused: " + str(e).splitlines()[0][:90], time.perf_counter() - start, None
    check = result.write(folder / f"{name}.step")
    seconds = time.perf_counter() - start
    verdict = "valid" if check["valid"] and not result.problems() else "NOT valid"
    return verdict, seconds, (result, report)


def off_the_map(model: cf.Model, result: cf.Model, lattice: object) -> float:
    """The largest distance, over a 5 x 5 grid of every face's domain (the deformed face's: a
    restricted one is a part of the original's), between the deformed face at (u, v) and the
    lattice's map of the original face at the same (u, v)."""
    if model.is_assembly:  # the deformed model is the flattened one (each placed instance)
        model = model.flattened()
    worst = 0.0
    for k in range(result.face_count):
        before, after = model.face_surface(k), result.face_surface(k)
        (u0, u1), (v0, v1) = after.domain
        for a in np.linspace(0.0, 1.0, 5):
            for b in np.linspace(0.0, 1.0, 5):
                u, v = u0 + a * (u1 - u0), v0 + b * (v1 - v0)
                mapped = lattice.deform_point(before.evaluate(u, v))
                worst = max(worst, float(np.linalg.norm(after.evaluate(u, v) - mapped)))
    return worst


def pointwise(model: cf.Model, deformed: object, lattice: object) -> str:
    """off_the_map, beside the certified bound of faces written in a light form."""
    if deformed is None:
        return "—"
    result, report = deformed
    text = f"{off_the_map(model, result, lattice):.1e}"
    if report["max_certified_bound_mm"] > 0:
        text += f" (bound {report['max_certified_bound_mm']:.1e})"
    return text


def freecad_columns(freecad: dict, name: str, model: cf.Model | None) -> str:
    """FreeCAD's faces / solids, validity, and our volume against FreeCAD's."""
    if not freecad:
        return ""
    f = freecad.get(name)
    if f is None or "error" in f:
        return " | not read | "
    seen = f"{f['faces']} / {f['solids']}, {'valid' if f['valid'] else 'NOT valid'}"
    if model is None or not f["solids"]:
        return f" | {seen} | "
    ours = model.volume_mm3()
    return f" | {seen} | {abs(ours - f['volume']) / f['volume']:.1e}"


def main() -> int:
    freecad = json.loads(Path(sys.argv[1]).read_text()) if len(sys.argv) > 1 else {}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for path in sorted(CAD.iterdir()):
            if path.suffix.lower() not in (".stp", ".step", ".igs", ".iges"):
                continue
            start = time.perf_counter()
            try:
                model, report = cf.read_model(path, isolate=True)
            except cf.ClayError as e:
                rows.append(f"| `{path.name}` | — | refused: {str(e).splitlines()[0][:80]} | | | | | "
                            f"{freecad_columns(freecad, path.name, None)} |")
                continue
            read_s = time.perf_counter() - start
            healing = len(report["healing"])
            problems = len(report["problems"])
            read = "yes" if not problems else f"yes, {problems} problems"
            if healing:
                read += f" ({healing} healing step{'s' if healing > 1 else ''})"
            counts = model.counts
            shape = f"{counts['faces']} / {counts['solids']}"
            if counts["wire_edges"]:
                shape += f" + {counts['wire_edges']} free curve{'s' if counts['wire_edges'] > 1 else ''}"
            if report["left_out"]:
                read += f", left out: {report['left_out'][0][:70]}"
            if counts["faces"] == 0 and counts["wire_edges"] == 0:
                rows.append(f"| `{path.name}` | {shape} | {read} | — | — | — | — | "
                            f"{read_s:.1f}{freecad_columns(freecad, path.name, None)} |")
                continue
            if problems:
                rows.append(f"| `{path.name}` | {shape} | {read} | — | — | — | — | "
                            f"{read_s:.1f}{freecad_columns(freecad, path.name, None)} |")
                continue
            s_lattice, b_lattice = stretched(model), bulged(model)
            s_verdict, s_time, s_result = outcome(model, s_lattice, folder, "s")
            b_verdict, b_time, b_result = outcome(model, b_lattice, folder, "b")
            maps = (f"{pointwise(model, s_result, s_lattice)} / "
                    f"{pointwise(model, b_result, b_lattice)}")
            error = "— (no solid)"
            if counts["solids"] and s_result is not None:
                before = model.volume_mm3()
                after = s_result[0].volume_mm3()
                det = float(np.linalg.det(STRETCH))
                error = f"{abs(after - det * before) / (det * before):.1e}"
            rows.append(
                f"| `{path.name}` | {shape} | {read} | {s_verdict} | "
                f"{b_verdict} | {error} | {maps} | {read_s:.1f} + {s_time:.1f} + {b_time:.1f}"
                f"{freecad_columns(freecad, path.name, model)} |")
            print(rows[-1], file=sys.stderr, flush=True)
    head = ("| file | faces / solids | read | stretched (affine) | bulged (B-spline) | "
            "stretched volume against det × V | faces against the map at the same (u, v), "
            "stretched / bulged (mm) | time read + stretch + bulge (s) |")
    if freecad:
        head += " FreeCAD: faces / solids, validity | volume against FreeCAD's |"
    print(head)
    print("|---" * (head.count("|") - 1) + "|")
    for r in rows:
        print(r)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
