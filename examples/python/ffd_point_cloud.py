"""A PyGeM-style free-form deformation of a point cloud, NumPy in and out (docs/python.md).

    python3 examples/python/ffd_point_cloud.py [OUT_DIR]

A cloud of 200,000 points on an ellipsoid is wrapped in a Bezier lattice (Sederberg-Parry); the
top layer of control points is pushed up and squeezed, and the cloud is deformed in place,
without a copy. The same lattice, composed exactly with a NURBS surface, gives a patch that
agrees with the deformed points (what PyGeM's CAD mode cannot do without cracks).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import numpy.typing as npt

import clayform as cf


def ellipsoid_cloud(n: int, seed: int = 1) -> npt.NDArray[np.float64]:
    """n points on an ellipsoid of semi-axes 60 x 40 x 25 mm (C order, float64)."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return np.ascontiguousarray(d * np.array([60.0, 40.0, 25.0]))


def main(out: Path | None = None) -> dict[str, float]:
    cloud = ellipsoid_cloud(200_000)
    original = cloud.copy()
    lattice = cf.BezierLattice([-65, -45, -30], [130, 0, 0], [0, 90, 0], [0, 0, 60], (2, 2, 3))
    for i in range(3):
        for j in range(3):
            top = lattice.index(i, j, 3)
            lattice.points[top, 2] += 15.0  # lift the top layer
            lattice.points[top, :2] *= 0.8  # and squeeze it towards the axis
    frozen = lattice.freeze()
    frozen.deform_points(cloud, out=cloud)  # in place: the array is read and written, never copied

    # The same deformation of a NURBS patch through the cloud's equator, composed exactly.
    knots = [0.0] * 3 + [1.0] * 3
    patch = cf.Surface((2, 2), knots, knots,
                       np.array([[x, y, 0.0] for x in (-50.0, 0.0, 50.0) for y in (-30.0, 0.0, 30.0)]))
    composed, report = lattice.compose(patch)
    u, v = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41))
    gap = float(np.max(np.abs(composed.evaluate(u, v).reshape(-1, 3)
                              - frozen.deform_points(np.ascontiguousarray(patch.evaluate(u, v).reshape(-1, 3))))))
    figures = {
        "points": float(len(cloud)),
        "max_displacement_mm": float(np.max(np.linalg.norm(cloud - original, axis=1))),
        "top_lift_mm": float(cloud[:, 2].max() - original[:, 2].max()),
        "patch_degree": float(report["degree_u"]),
        "patch_vs_points_mm": gap,
    }
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        np.save(out / "deformed_cloud.npy", cloud)
        cf.write_step(composed, out / "patch.step")
        (out / "patch.png").write_bytes(cf.render_png(composed))
    for key, value in figures.items():
        print(f"{key}: {value:.6g}")
    return figures


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else None)
