"""The studio page's own math against the kernel's (issue #37, item 3).

The page evaluates the nets the kernel sends and re-derives a lattice's knots and control points
(viewer/src/studio/lattice_math.js, nurbs.js, ffd_preview.js; e2e/geometry.mjs shares
lattice_math.js). Here Node runs those modules and the figures are compared with the kernel's:
knots and Greville points with BSplineLattice's (its pickled bases and its undisplaced points),
Bézier lattice points with BezierLattice's, the page's FFD of points (the drag preview) with
DeformationStack.deform_points, surface points and unit normals with Surface.evaluate_grid and
Surface.normal, and mean and Gaussian curvature with closed forms (a paraboloid graph as a bicubic
B-spline, a rational sphere patch). Skipped when `node` is missing.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import clayform

SOURCE = Path(os.environ.get("CLAYFORM_SOURCE_DIR", Path(__file__).resolve().parents[2]))
STUDIO = SOURCE / "viewer" / "src" / "studio"
NODE = shutil.which("node")
pytestmark = pytest.mark.skipif(NODE is None, reason="node is not installed (apt-get install nodejs)")

# The page's modules, run by Node on the cases given on stdin; the answers as JSON on stdout.
SCRIPT = """
import { latticeKnots, grevilleAbscissae, latticePoints, bsplineLatticePoints } from '%(studio)s/lattice_math.js';
import { surfaceGrid, sampleParameters } from '%(studio)s/nurbs.js';
import { prepareFfd, applyFfd } from '%(studio)s/ffd_preview.js';
let text = '';
for await (const chunk of process.stdin) text += chunk;
const cases = JSON.parse(text);
const out = { knots: [], lattices: [], ffd: [], surfaces: [] };
for (const [cells, p, kind] of cases.knots) {
  const knots = latticeKnots(cells, p, kind);
  out.knots.push({ knots, greville: grevilleAbscissae(knots, p) });
}
for (const step of cases.lattices) out.lattices.push(step.kind === 'bspline_lattice' ? bsplineLatticePoints(step) : latticePoints(step));
for (const { step, points } of cases.ffd) {
  // the drag preview's sum over the lattice (ffd_preview.js) at these points, as a 1 x n grid
  const n = points.length;
  const grid = { rows: 1, cols: n, position: Float64Array.from(points.flat()), su: new Float64Array(3 * n), sv: new Float64Array(3 * n) };
  const lattice = step.kind === 'bspline_lattice' ? bsplineLatticePoints(step) : latticePoints(step);
  const position = new Float64Array(3 * n);
  applyFfd(prepareFfd(grid, step), lattice, position, new Float64Array(3 * n));
  out.ffd.push({ lattice, knots: step.kind === 'bspline_lattice' ? [0, 1, 2].map((e) => latticeKnots(step.cells[e], step.degrees[e], step.knots || 'clamped')) : null, deformed: Array.from(position) });
}
for (const { net, rows, cols } of cases.surfaces) {
  const g = surfaceGrid(net, rows, cols, Float64Array);
  out.surfaces.push({ u: Array.from(sampleParameters(net.knots_u, net.degrees[0], rows)), v: Array.from(sampleParameters(net.knots_v, net.degrees[1], cols)),
    position: Array.from(g.position), normal: Array.from(g.normal), mean: Array.from(g.mean), gaussian: Array.from(g.gaussian) });
}
process.stdout.write(JSON.stringify(out));
"""


def run_page(cases, tmp_path):
    script = tmp_path / "page_math.mjs"
    script.write_text(SCRIPT % {"studio": STUDIO.as_posix()})
    done = subprocess.run([NODE, str(script)], input=json.dumps(cases), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


FRAME = {"origin": [-120.0, -75.5, 3.25], "s": [240.0, 0.0, 0.0], "t": [0.0, 151.0, 0.0], "u": [0.0, 0.0, 40.5]}
SKEWED = {"origin": [10.0, -20.0, 5.0], "s": [200.0, 30.0, 0.0], "t": [-25.0, 150.0, 10.0], "u": [4.0, -3.0, 60.0]}


def frame_args(frame):
    return [np.asarray(frame[k], dtype=np.float64) for k in ("origin", "s", "t", "u")]


def relative(a, b, scale):
    return float(np.max(np.abs(np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)))) / scale


def test_lattice_knots_greville_points_and_ffd_are_the_kernels(tmp_path):
    # knots and Greville abscissae of every clamped direction the kernel builds
    shapes = [((1, 2, 3), (1, 3, 2)), ((3, 3, 1), (4, 4, 1)), ((2, 4, 3), (5, 2, 6)), ((5, 1, 2), (3, 7, 1))]
    knot_cases = [[c, p, "clamped"] for degrees, cells in shapes for p, c in zip(degrees, cells)]
    knot_cases += [[c, p, "uniform"] for p, c in [(1, 3), (2, 4), (3, 4), (3, 1), (4, 5)]]
    lattice_steps = [{"kind": "bspline_lattice", "frame": SKEWED, "degrees": list(d), "cells": list(c), "knots": "clamped"} for d, c in shapes]
    lattice_steps += [{"kind": "bezier_lattice", "frame": SKEWED, "degrees": list(d)} for d in [(1, 1, 1), (3, 3, 1), (2, 4, 3)]]
    rng = np.random.default_rng(37)
    inside = (np.asarray(FRAME["origin"]) + rng.random((60, 1)) * FRAME["s"] + rng.random((60, 1)) * FRAME["t"] + rng.random((60, 1)) * FRAME["u"]).tolist()
    moves = [{"index": [1, 1, 1], "to": [15.0, -12.0, 60.0]}, {"index": [2, 0, 0], "by": [0.0, 8.0, -5.5]}]
    ffd_steps = [
        {"kind": "bezier_lattice", "frame": FRAME, "degrees": [3, 3, 1], "moves": moves},
        {"kind": "bspline_lattice", "frame": FRAME, "degrees": [3, 3, 1], "cells": [4, 4, 1], "knots": "clamped", "moves": moves},
        {"kind": "bspline_lattice", "frame": FRAME, "degrees": [3, 2, 2], "cells": [3, 4, 2], "knots": "uniform", "moves": moves},
        {"kind": "bspline_lattice", "frame": FRAME, "degrees": [3, 3, 3], "cells": [4, 4, 4], "knots": "uniform"},
    ]
    page = run_page({"knots": knot_cases, "lattices": lattice_steps, "ffd": [{"step": s, "points": inside} for s in ffd_steps], "surfaces": []}, tmp_path)

    worst_knot = 0.0
    worst_greville = 0.0
    worst_point = 0.0
    k = 0
    for degrees, cells in shapes:
        lattice = clayform.BSplineLattice(*frame_args(SKEWED), degrees=degrees, cells=cells)
        bases = lattice.__getstate__()[1]
        for e in range(3):
            degree, knots = bases[e]
            assert degree == degrees[e]
            mine = page["knots"][k]
            k += 1
            assert len(mine["knots"]) == len(knots), (degrees, cells, e)
            worst_knot = max(worst_knot, relative(mine["knots"], knots, 1.0))
            greville = [sum(knots[i + 1 : i + degree + 1]) / degree for i in range(len(knots) - degree - 1)]
            worst_greville = max(worst_greville, relative(mine["greville"], greville, 1.0))
    # uniform knots: (i - p) / cells, as docs/recipe.md says
    for c, p, _ in knot_cases[k:]:
        mine = page["knots"][k]
        k += 1
        worst_knot = max(worst_knot, relative(mine["knots"], [(i - p) / c for i in range(c + 2 * p + 1)], 1.0))
    scale = 250.0  # the frames' size, mm
    for step, mine in zip(lattice_steps, page["lattices"]):
        if step["kind"] == "bspline_lattice":
            lattice = clayform.BSplineLattice(*frame_args(step["frame"]), degrees=tuple(step["degrees"]), cells=tuple(step["cells"]))
        else:
            lattice = clayform.BezierLattice(*frame_args(step["frame"]), degrees=tuple(step["degrees"]))
        n = lattice.counts
        assert len(mine) == n[0] * n[1] * n[2]
        order = [lattice.index(i, j, kk) for i in range(n[0]) for j in range(n[1]) for kk in range(n[2])]
        worst_point = max(worst_point, relative(mine, lattice.points[order], scale))

    # the drag preview's FFD (ffd_preview.js) against the kernel's deform_points for the same lattice
    worst_ffd = 0.0
    for step, mine in zip(ffd_steps, page["ffd"]):
        if step["kind"] == "bspline_lattice":
            kernel_step = {"kind": "bspline_lattice", "name": "page", "enabled": True, "frame": step["frame"], "bases": [{"degree": step["degrees"][e], "knots": mine["knots"][e]} for e in range(3)], "points": mine["lattice"]}
        else:
            kernel_step = {"kind": "bezier_lattice", "name": "page", "enabled": True, "frame": step["frame"], "degrees": step["degrees"], "points": mine["lattice"]}
        stack = clayform.DeformationStack.from_json(json.dumps({"format": "clayform.deformation-stack", "version": 1, "steps": [kernel_step]}))
        kernel = stack.deform_points(np.asarray(inside, dtype=np.float64))
        worst_ffd = max(worst_ffd, relative(np.asarray(mine["deformed"]).reshape(-1, 3), kernel, scale))
        if "moves" not in step:  # undisplaced at the Greville points: the identity (linear precision)
            worst_ffd = max(worst_ffd, relative(np.asarray(mine["deformed"]).reshape(-1, 3), inside, scale))

    print(f"knots {worst_knot:.2e}, Greville {worst_greville:.2e}, lattice points {worst_point:.2e} (relative), FFD {worst_ffd:.2e} (relative to {scale} mm)")
    assert worst_knot <= 1e-15
    assert worst_greville <= 1e-15
    assert worst_point <= 1e-12
    assert worst_ffd <= 1e-12


def greville(knots, p):
    return [sum(knots[i + 1 : i + p + 1]) / p for i in range(len(knots) - p - 1)]


def quadratic_blossom(knots, p):
    """B-spline coefficients of t**2 in degree p: the blossom 2 / (p (p - 1)) sum_{a<b} t_a t_b."""
    out = []
    for i in range(len(knots) - p - 1):
        t = knots[i + 1 : i + p + 1]
        out.append(sum(t[a] * t[b] for a in range(p) for b in range(a + 1, p)) * 2 / (p * (p - 1)))
    return out


def test_surface_points_normals_and_curvature_are_the_kernels(tmp_path):
    # 1. z = a x^2 + b y^2 + c x y over [0, 200]^2 as a bicubic B-spline with interior knots (exact:
    #    x, y linear in u, v at the Greville points, z from the blossoms); H and K in closed form
    L = 200.0
    a, b, c = 0.004, -0.0025, 0.0015
    ku = [0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1]
    kv = [0, 0, 0, 0, 0.5, 1, 1, 1, 1]
    gu, gv = greville(ku, 3), greville(kv, 3)
    qu, qv = quadratic_blossom(ku, 3), quadratic_blossom(kv, 3)
    points = [[L * gu[i], L * gv[j], L * L * (a * qu[i] + b * qv[j] + c * gu[i] * gv[j])] for i in range(len(gu)) for j in range(len(gv))]
    graph = {"degrees": [3, 3], "counts": [len(gu), len(gv)], "knots_u": ku, "knots_v": kv, "points": sum(points, []), "weights": [1.0] * len(points)}
    # 2. a sphere of radius R: a quarter circle (rational quadratic) turned a quarter about z
    R = 100.0
    h = math.sqrt(0.5)
    profile = [(R, 0.0, 1.0), (R, R, h), (0.0, R, 1.0)]  # (radius, z, weight)
    circle = [(1.0, 0.0, 1.0), (1.0, 1.0, h), (0.0, 1.0, 1.0)]
    sphere_points = [[r * cx, r * cy, z] for r, z, _ in profile for cx, cy, _ in circle]
    sphere_weights = [w * wc for _, _, w in profile for _, _, wc in circle]
    quarter = [0, 0, 0, 1, 1, 1]
    sphere = {"degrees": [2, 2], "counts": [3, 3], "knots_u": quarter, "knots_v": quarter, "points": sum(sphere_points, []), "weights": sphere_weights}
    nets = [(graph, 33, 29), (sphere, 25, 25)]
    page = run_page({"knots": [], "lattices": [], "ffd": [], "surfaces": [{"net": n, "rows": r, "cols": cc} for n, r, cc in nets]}, tmp_path)

    worst = {"points": 0.0, "normals": 0.0, "mean": 0.0, "gaussian": 0.0}
    for (net, rows, cols), mine in zip(nets, page["surfaces"]):
        surface = clayform.Surface(
            (net["degrees"][0], net["degrees"][1]), net["knots_u"], net["knots_v"],
            np.asarray(net["points"], dtype=np.float64).reshape(-1, 3), np.asarray(net["weights"], dtype=np.float64))
        u = np.asarray(mine["u"])
        v = np.asarray(mine["v"])
        position = np.asarray(mine["position"]).reshape(rows, cols, 3)
        normal = np.asarray(mine["normal"]).reshape(rows, cols, 3)
        mean = np.asarray(mine["mean"]).reshape(rows, cols)
        gaussian = np.asarray(mine["gaussian"]).reshape(rows, cols)
        scale = float(np.max(np.abs(net["points"])))
        worst["points"] = max(worst["points"], relative(position, surface.evaluate_grid(u, v), scale))
        uu, vv = np.meshgrid(u, v, indexing="ij")
        keep = np.ones((rows, cols), dtype=bool)
        if net is sphere:
            keep[-1, :] = False  # the pole: S_u x S_v vanishes there (no normal, no curvature)
        worst["normals"] = max(worst["normals"], relative(normal[keep], surface.normal(uu[keep], vv[keep]), 1.0))
        if net is graph:
            x, y = position[..., 0], position[..., 1]
            fx, fy = 2 * a * x + c * y, 2 * b * y + c * x
            fxx, fyy, fxy = 2 * a, 2 * b, c
            w = 1 + fx**2 + fy**2
            K = (fxx * fyy - fxy**2) / w**2
            H = ((1 + fy**2) * fxx - 2 * fx * fy * fxy + (1 + fx**2) * fyy) / (2 * w**1.5)
            curvature = 2 * abs(a) + 2 * abs(b) + abs(c)
            worst["mean"] = max(worst["mean"], relative(mean, H, curvature))
            worst["gaussian"] = max(worst["gaussian"], relative(gaussian, K, curvature**2))
        else:
            # |H| = 1/R and K = 1/R^2 everywhere (H's sign is the normal's side)
            worst["mean"] = max(worst["mean"], relative(np.abs(mean[keep]), 1 / R, 1 / R))
            worst["gaussian"] = max(worst["gaussian"], relative(gaussian[keep], 1 / R**2, 1 / R**2))
    print("surfaces: " + ", ".join(f"{k} {x:.2e}" for k, x in worst.items()) + " (relative)")
    assert worst["points"] <= 1e-12
    assert worst["normals"] <= 1e-12
    assert worst["mean"] <= 1e-9
    assert worst["gaussian"] <= 1e-9
