"""Shape optimisation on exact CAD with scipy.optimize and exact derivatives (docs/optimisation.md).

    python3 examples/python/optimise_block.py [OUT_DIR]

A real STEP part (the filleted block with two holes and a pocket, 60 x 40 x 20 mm) sits in a
Bezier lattice of degrees (2, 2, 1); the design variables are the moves of the lattice's top
layer (9 points, x, y and z: 27 variables; the base stays). SLSQP finds the smallest change of
them that gives the block 8 % more volume
and a top 2.5 mm higher at its middle, keeps its thickness (no point of the top face sinks) and
keeps the lattice fold-free (every Bernstein coefficient of its Jacobian >= 0.2). Every
iteration's part is written as STEP and read back valid.

It runs twice, in one process: with the exact derivatives of the kernel (the volume's gradient,
the Jacobians of points and of the lattice's Jacobian coefficients), and with SciPy's finite
differences; it prints both runs' iterations, evaluations and time.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import scipy.optimize  # type: ignore[import]  # Debian's SciPy 1.10 ships no type stubs

import clayform as cf

HERE = Path(__file__).resolve().parent
Array = npt.NDArray[np.float64]


class Problem:
    """The block, its lattice and the constraints' values and exact gradients in x (the top layer's
    moves, point after point, x y z)."""

    def __init__(self, out: Path | None) -> None:
        model, _ = cf.read_model(HERE.parent / "models" / "block.step")
        self.model = model.flattened()
        lo, hi = (np.array(c) for c in self.model.bounding_box())
        pad = 0.05 * (hi - lo)
        size = hi - lo + 2 * pad
        self.lattice = cf.BezierLattice(lo - pad, [size[0], 0, 0], [0, size[1], 0], [0, 0, size[2]], (2, 2, 1))
        self.rest = self.lattice.points.copy()
        self.top = [self.lattice.index(i, j, 1) for i in range(3) for j in range(3)]
        self.jacobian = self.lattice.model_jacobian(self.model)
        self.volume0 = float(self.jacobian.mass_properties()["volume_mm3"])
        # The top face: the flat one (its control points at one z) highest up.
        fixed = self.jacobian.model
        flat = [f for f in range(fixed.face_count) if np.ptp(fixed.face_surface(f).points[:, 2]) < 1e-9]
        top_face = max(flat, key=lambda f: float(fixed.face_surface(f).points[0, 2]))
        surface = fixed.face_surface(top_face)
        (u0, u1), (v0, v1) = surface.domain
        grid = np.array([(u, v) for u in np.linspace(u0, u1, 5) for v in np.linspace(v0, v1, 5)])
        # z of the top face's points as a linear map of the lattice points (exact, constant).
        self.top_points = self.jacobian.face_point_jacobian(top_face, grid)
        self.middle = 12  # the grid's centre
        self.top_z0 = self.top_points @ self.rest[:, 2]
        self.out = out
        self.writes = 0
        self.all_valid = True

    def points(self, x: Array) -> Array:
        p = self.rest.copy()
        p[self.top] += x.reshape(-1, 3)
        return p

    def volume(self, x: Array) -> float:
        return float(self.jacobian.mass_properties(self.points(x))["volume_mm3"])

    def volume_gradient(self, x: Array) -> Array:
        g = self.jacobian.mass_property_gradients(self.points(x))["volume_gradient"]
        return np.asarray(g[self.top].ravel())

    def top_z(self, x: Array) -> Array:
        return np.asarray(self.top_points @ self.points(x)[:, 2])

    def top_z_gradient(self, x: Array) -> Array:
        d = np.zeros((self.top_points.shape[0], 3 * len(self.top)))
        d[:, 2::3] = self.top_points[:, self.top].toarray()  # z moves the points' z only
        return d

    def folds(self, x: Array) -> Array:
        lattice = self.lattice.__copy__()
        lattice.points = self.points(x)
        values, _ = lattice.jacobian_constraints()
        return np.asarray(values - 0.2)

    def folds_gradient(self, x: Array) -> Array:
        lattice = self.lattice.__copy__()
        lattice.points = self.points(x)
        _, gradient = lattice.jacobian_constraints()
        return np.asarray(gradient[:, [3 * t + c for t in self.top for c in range(3)]].toarray())

    def write(self, x: Array) -> None:
        """The iteration's part as STEP, read back and checked (BRepCheck)."""
        if self.out is None:
            return
        check = self.jacobian.deformed(self.points(x)).write(self.out / f"iteration_{self.writes:02d}.step")
        self.all_valid = self.all_valid and bool(check["valid"])
        self.writes += 1


def solve(problem: Problem, exact: bool) -> dict[str, Any]:
    counts = {"volume": 0, "gradient": 0}

    def volume(x: Array) -> float:
        counts["volume"] += 1
        return problem.volume(x) / problem.volume0 - 1.08

    def volume_gradient(x: Array) -> Array:
        counts["gradient"] += 1
        return problem.volume_gradient(x) / problem.volume0

    constraints: list[dict[str, Any]] = [
        {"type": "eq", "fun": volume},
        {"type": "eq", "fun": lambda x: problem.top_z(x)[problem.middle] - problem.top_z0[problem.middle] - 2.5},
        {"type": "ineq", "fun": lambda x: problem.top_z(x) - problem.top_z0},
        {"type": "ineq", "fun": problem.folds},
    ]
    if exact:
        constraints[0]["jac"] = volume_gradient
        constraints[1]["jac"] = lambda x: problem.top_z_gradient(x)[problem.middle]
        constraints[2]["jac"] = problem.top_z_gradient
        constraints[3]["jac"] = problem.folds_gradient
    problem.writes = 0
    start = time.perf_counter()
    result = scipy.optimize.minimize(
        lambda x: float(x @ x), np.zeros(3 * len(problem.top)), jac=lambda x: 2 * x, method="SLSQP",
        constraints=constraints, callback=problem.write, options={"ftol": 1e-12, "maxiter": 100})
    seconds = time.perf_counter() - start
    x = result.x
    return {
        "success": bool(result.success),
        "iterations": int(result.nit),
        "volume_evaluations": counts["volume"],
        "gradient_evaluations": counts["gradient"],
        "seconds": seconds,
        "volume_error": abs(problem.volume(x) / (1.08 * problem.volume0) - 1),
        "height_error_mm": abs(problem.top_z(x)[problem.middle] - problem.top_z0[problem.middle] - 2.5),
        "x": x,
    }


def main(out: Path | None = None) -> dict[str, float]:
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    problem = Problem(out)
    exact = solve(problem, exact=True)
    steps_written = problem.writes
    differences = solve(problem, exact=False)
    final = problem.jacobian.deformed(problem.points(exact["x"]))
    if out is not None:
        final.write(out / "optimised_block.step")
    figures = {
        "exact_success": float(exact["success"]),
        "exact_iterations": float(exact["iterations"]),
        "exact_volume_evaluations": float(exact["volume_evaluations"]),
        "exact_gradient_evaluations": float(exact["gradient_evaluations"]),
        "exact_seconds": exact["seconds"],
        "exact_volume_error": exact["volume_error"],
        "exact_height_error_mm": exact["height_error_mm"],
        "fd_success": float(differences["success"]),
        "fd_iterations": float(differences["iterations"]),
        "fd_volume_evaluations": float(differences["volume_evaluations"]),
        "fd_seconds": differences["seconds"],
        "fd_volume_error": differences["volume_error"],
        "solutions_apart_mm": float(np.max(np.abs(exact["x"] - differences["x"]))),
        "largest_move_mm": float(np.max(np.abs(exact["x"]))),
        "steps_written": float(steps_written),
        "all_steps_valid": float(problem.all_valid),
        "volume_mm3": float(final.mass_properties()["volume_mm3"]),
        "volume0_mm3": problem.volume0,
    }
    for key, value in figures.items():
        print(f"{key}: {value:.6g}")
    return figures


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else None)
