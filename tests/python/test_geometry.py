"""Curves, surfaces, lattices and builders against independent computations: Bernstein
formulas in NumPy, closed forms, pointwise deformation."""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import clayform as cf
from conftest import bernstein


def test_surface_evaluate_matches_bernstein_formula(bezier_patch: cf.Surface) -> None:
    u = np.random.default_rng(4).uniform(0, 1, 50)
    v = np.random.default_rng(5).uniform(0, 1, 50)
    net = bezier_patch.points.reshape(4, 4, 3)
    expected = sum(
        (bernstein(3, i, u) * bernstein(3, j, v))[:, None] * net[i, j] for i in range(4) for j in range(4)
    )
    assert np.max(np.abs(bezier_patch.evaluate(u, v) - expected)) < 1e-12


def test_rational_curve_is_a_circle_quadrant() -> None:
    w = math.sqrt(0.5)
    c = cf.Curve(2, [0, 0, 0, 1, 1, 1], np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]]), np.array([1, w, 1]))
    p = c.evaluate(np.linspace(0, 1, 101))
    assert np.max(np.abs(np.linalg.norm(p, axis=1) - 1)) < 1e-15


def test_lattice_deform_points_matches_sederberg_parry_eq2() -> None:
    origin, s, t, u = np.array([-10.0, 5, 2]), np.array([120.0, 10, 0]), np.array([0.0, 80, 5]), np.array([3.0, 0, 60])
    lat = cf.BezierLattice(origin, s, t, u, (3, 2, 1))
    rng = np.random.default_rng(6)
    lat.points[:] += rng.uniform(-5, 5, size=lat.points.shape)
    local = rng.uniform(0, 1, size=(200, 3))
    x = origin + local @ np.array([s, t, u])
    expected = np.zeros_like(x)
    for i, j, k in itertools.product(range(4), range(3), range(2)):
        weight = bernstein(3, i, local[:, 0]) * bernstein(2, j, local[:, 1]) * bernstein(1, k, local[:, 2])
        expected += weight[:, None] * lat.points[lat.index(i, j, k)]
    assert np.max(np.abs(lat.deform_points(x) - expected)) < 1e-11
    assert np.max(np.abs(np.array(lat.deform_point(x[0])) - expected[0])) < 1e-11


def test_compose_is_exact_against_pointwise(bezier_patch: cf.Surface) -> None:
    lat = cf.BezierLattice([-5, -5, -20], [110, 0, 0], [0, 110, 0], [0, 0, 40], (2, 2, 1))
    lat.points[lat.index(1, 1, 1)] += [0.0, 0.0, 15.0]
    composed, report = lat.compose(bezier_patch)
    assert report["exact"] and report["degree_u"] >= 3
    u, v = np.meshgrid(np.linspace(0, 1, 23), np.linspace(0, 1, 19))
    pointwise = lat.deform_points(bezier_patch.evaluate(u, v).reshape(-1, 3))
    assert np.max(np.abs(composed.evaluate(u, v).reshape(-1, 3) - pointwise)) < 1e-12 * 150


def test_bspline_lattice_identity_when_undisplaced() -> None:
    lat = cf.BSplineLattice([0, 0, 0], [50, 0, 0], [0, 40, 0], [0, 0, 30], (3, 2, 2), (4, 3, 2))
    x = np.random.default_rng(7).uniform(0, 1, size=(100, 3)) * [50, 40, 30]
    assert np.max(np.abs(lat.deform_points(x) - x)) < 1e-12


def test_tessellate_vertices_lie_on_a_plane_with_unit_normals() -> None:
    knots = [0.0] * 3 + [1.0] * 3
    pts = np.array([[x, y, 0.0] for x in (0.0, 30.0, 60.0) for y in (0.0, 5.0, 40.0)])
    vertices, faces, normals = cf.Surface((2, 2), knots, knots, pts).tessellate()
    assert vertices.shape[1] == 3 and faces.dtype == np.int32 and faces.max() < len(vertices)
    assert np.all(vertices[:, 2] == 0) and np.allclose(np.abs(normals[:, 2]), 1)
    area = 0.5 * np.linalg.norm(
        np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]]), axis=1
    ).sum()
    assert area == pytest.approx(60 * 40, rel=1e-12)


def test_revolve_gives_a_cylinder() -> None:
    profile = cf.Curve(1, [0, 0, 1, 1], np.array([[10.0, 0, 0], [10.0, 0, 50]]))
    s, report = cf.revolve(profile, [0, 0, 0], [0, 0, 1])
    assert report["exact"] and s.rational
    u, v = np.meshgrid(np.linspace(0, 1, 31), np.linspace(0, 1, 7))
    p = s.evaluate(u, v).reshape(-1, 3)
    assert np.max(np.abs(np.hypot(p[:, 0], p[:, 1]) - 10)) < 1e-12


def test_fill_of_four_lines_is_bilinear() -> None:
    a, b, c, d = np.array([0.0, 0, 0]), np.array([80.0, 0, 0]), np.array([80.0, 50, 10]), np.array([0.0, 50, 0])
    line = lambda p, q: cf.Curve(1, [0, 0, 1, 1], np.array([p, q]))  # noqa: E731
    s, report = cf.fill([line(a, b), line(b, c), line(c, d), line(d, a)], style="coons")
    assert report["control_points"] >= 4 and report["max_deviation_mm"] < 1e-9
    for corner in (a, b, c, d):
        uv = np.array([0.0, 1.0])
        corners = s.evaluate(*np.meshgrid(uv, uv)).reshape(-1, 3)
        assert np.min(np.linalg.norm(corners - corner, axis=1)) < 1e-9


def test_fit_stroke_follows_the_drawn_points() -> None:
    t = np.linspace(0, 1, 200)
    pts = np.stack([100 * t, 20 * np.sin(3 * t), np.zeros_like(t)], axis=1)
    curves, report = cf.fit_stroke(pts, tolerance_mm=0.05)
    assert report["converged"] and len(curves) == 1 and report["max_deviation_mm"] <= 0.05
    dense = curves[0].evaluate(np.linspace(0, 1, 4001))
    gaps = np.min(np.linalg.norm(pts[:, None, :] - dense[None, :, :], axis=2), axis=1)
    assert gaps.max() <= 0.05 + 0.03  # sampled closest points: within the tolerance and the step


def test_sketch_solves_a_right_angle() -> None:
    sk = cf.Sketch()
    plane = sk.add_plane([0, 0, 0], [0, 0, 1])
    p0 = sk.add_point([0, 0, 0], plane)
    p1 = sk.add_point([50, 3, 0], plane)
    p2 = sk.add_point([4, 40, 0], plane)
    l1, l2 = sk.add_line(p0, p1), sk.add_line(p0, p2)
    sk.fixed(p0)
    sk.horizontal(l1)
    sk.perpendicular(l1, l2)
    sk.distance(p0, p1, mm=60.0)
    report = sk.solve()
    assert report["converged"] and report["degrees_of_freedom"] == 1
    a, b, c = (np.array(sk.position(k)) for k in (p0, p1, p2))
    assert abs(np.linalg.norm(b - a) - 60) < 1e-9 and abs((b - a) @ (c - a)) < 1e-9 * 60 * 40
    assert abs(b[1]) < 1e-9


def test_style_deform_exact_meets_the_target_line() -> None:
    knots = [0.0] * 4 + [i / 6 for i in range(1, 6)] + [1.0] * 4
    pts = np.array([[100 * i / 8, 100 * j / 8, 0.0] for i in range(9) for j in range(9)])
    plate = cf.Surface((3, 3), knots, knots, pts)
    theta = np.linspace(0, 2 * np.pi, 40)[:-1]
    ring = np.stack([50 + 35 * np.cos(theta), 50 + 35 * np.sin(theta), np.zeros_like(theta)], axis=1)
    bound = cf.fit_stroke(np.vstack([ring, ring[:1]]), tolerance_mm=0.05)[0][0]
    x = np.linspace(35, 65, 13)
    target = cf.fit_stroke(np.stack([x, np.full_like(x, 50), 8 * np.sin(np.pi * (x - 35) / 30)], axis=1), tolerance_mm=0.01)[0][0]
    styled, report = cf.style_deform(plate, bound, target, mode="exact", curve_tolerance=1e-4)
    assert report["locality"] == 0.0
    samples = target.evaluate(np.linspace(0, 1, 201))
    u, v = np.meshgrid(np.linspace(0, 1, 401), np.linspace(0, 1, 401))
    dense = styled.evaluate(u, v).reshape(-1, 3)
    miss = max(np.min(np.linalg.norm(dense - p, axis=1)) for p in samples)
    assert miss < 0.2  # sampled closest points at a 0.25 mm grid: the line lies on the surface
    assert report["target_curve_distance"] <= 1e-4 * 150
    # The rings figure (docs/deform.md § Rings): a push changes the curvature, so it turns at least once.
    assert isinstance(report["curvature_waves"], int) and report["curvature_waves"] >= 1
    # The studio's calm default, 5 % best effort: reached here, and calm (the first net rings).
    _, calm = cf.style_deform(plate, bound, target, mode="exact", net_convergence=0.05, net_convergence_best_effort=True)
    assert calm["net_change"] <= 0.05
    assert calm["curvature_waves"] <= 4 < report["curvature_waves"]
    # 1 % is out of reach (a halving stops shrinking the change near 2 %): best effort keeps the
    # finest net's result and says how far it got (without it, ToleranceNotMetError: style_test.cpp).
    _, effort = cf.style_deform(plate, bound, target, mode="exact", net_convergence=0.01, net_convergence_best_effort=True)
    assert 0.01 < effort["net_change"] < 0.05
    assert effort["knots_inserted"] > calm["knots_inserted"]
