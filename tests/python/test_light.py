"""Budgets, light forms and receiver profiles from Python (issue #38): a lattice's exact
composition refused before it is built when above a limit, and a surface made to conform to a
receiver, checked against the surface itself in NumPy."""
from __future__ import annotations

import numpy as np
import pytest

import clayform as cf


def test_compose_refuses_above_its_net_before_building_it(bezier_patch: cf.Surface) -> None:
    lat = cf.BezierLattice([-5, -5, -20], [110, 0, 0], [0, 110, 0], [0, 0, 40], (2, 2, 1))
    lat.points[lat.index(1, 1, 1)] += [0.0, 0.0, 15.0]
    composed, report = lat.compose(bezier_patch)
    size = composed.counts[0] * composed.counts[1]
    # at its own size it goes through, one below it is refused with the predicted size
    lat.compose(bezier_patch, max_control_points=size)
    with pytest.raises(cf.DegreeLimitError, match=f"would have up to {size} control points"):
        lat.compose(bezier_patch, max_control_points=size - 1)
    with pytest.raises(cf.DegreeLimitError, match="above the limit 2"):
        lat.compose(bezier_patch, max_degree=2)


def dense_bicubic(n: int = 40) -> cf.Surface:
    knots = [0.0] * 3 + list(np.linspace(0, 1, n - 2)) + [1.0] * 3
    g = np.linspace(0, 100, n)
    pts = np.array([[x, y, 20 * np.sin(0.03 * x) * np.sin(0.03 * y)] for x in g for y in g])
    return cf.Surface((3, 3), knots, knots, pts)


def test_fit_to_profile_class_a_within_its_certified_bound() -> None:
    dense = dense_bicubic()
    light, report = cf.fit_to_profile(dense, "class_a", tolerance_mm=0.05, name="surface 'panel'")
    assert report["refitted"] and not report["elevated"]
    assert light.degrees == (5, 5)
    assert max(light.counts) <= 32
    u, v = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 37))
    gap = np.max(np.linalg.norm(light.evaluate(u, v) - dense.evaluate(u, v), axis=-1))
    assert gap <= report["bound_mm"] <= 0.05
    # a conforming surface comes back as it is
    same, same_report = cf.fit_to_profile(light, "class_a")
    assert not same_report["refitted"] and same_report["bound_mm"] == 0
    assert np.array_equal(same.points, light.points)


def test_fit_to_profile_refuses_what_cannot_conform() -> None:
    with pytest.raises(cf.InvalidArgumentError, match="no receiver profile \"alias\""):
        cf.fit_to_profile(dense_bicubic(8), "alias")
    with pytest.raises(cf.ToleranceNotMetError, match="surface 'panel' does not conform to the class_a profile"):
        cf.fit_to_profile(dense_bicubic(60), "class_a", tolerance_mm=1e-9, name="surface 'panel'")
