"""Exact derivatives of deformed geometry with respect to the lattice points (issue #41,
docs/optimisation.md): the Jacobian of a composed surface's control points as a SciPy sparse
matrix, against the composition it claims, the pointwise deformation and central differences."""
from __future__ import annotations

import numpy as np
import scipy.sparse

import clayform as cf


def moved_lattice() -> cf.BezierLattice:
    lat = cf.BezierLattice([-5, -5, -20], [110, 0, 0], [0, 110, 0], [0, 0, 40], (2, 2, 1))
    lat.points[lat.index(1, 1, 1)] += [3.0, -2.0, 15.0]
    return lat


def test_the_jacobian_maps_the_lattice_points_to_the_composed_control_points(bezier_patch: cf.Surface) -> None:
    lat = moved_lattice()
    composed, jacobian = lat.composition_jacobian(bezier_patch)
    assert scipy.sparse.isspmatrix_csr(jacobian)
    assert jacobian.shape == (len(composed.points), len(lat.points))
    assert np.max(np.abs(jacobian @ lat.points - composed.points)) < 1e-12 * 150
    u, v = np.meshgrid(np.linspace(0, 1, 23), np.linspace(0, 1, 19))
    pointwise = lat.deform_points(bezier_patch.evaluate(u, v).reshape(-1, 3))
    assert np.max(np.abs(composed.evaluate(u, v).reshape(-1, 3) - pointwise)) < 1e-12 * 150


def test_the_jacobian_equals_central_differences_and_keeps_its_form(bezier_patch: cf.Surface) -> None:
    # Moving lattice point J by h along an axis moves the composed control points by h C[:, J]
    # along it: central differences of the composed points (the same fixed form at every value).
    lat = moved_lattice()
    composed, jacobian = lat.composition_jacobian(bezier_patch)
    h = 1.0
    for row, axis in [(lat.index(1, 1, 1), 2), (lat.index(0, 2, 0), 0), (lat.index(2, 1, 1), 1)]:
        plus, minus = cf.BezierLattice.__copy__(lat), cf.BezierLattice.__copy__(lat)
        plus.points[row, axis] += h
        minus.points[row, axis] -= h
        up, _ = plus.composition_jacobian(bezier_patch)
        down, _ = minus.composition_jacobian(bezier_patch)
        assert up.points.shape == down.points.shape == composed.points.shape
        difference = (up.points[:, axis] - down.points[:, axis]) / (2 * h)
        column = jacobian[:, row].toarray().ravel()
        assert np.max(np.abs(difference - column)) < 1e-10 * max(1.0, np.max(np.abs(column)))
        others = np.delete(np.arange(3), axis)
        assert np.max(np.abs(up.points[:, others] - down.points[:, others])) < 1e-9


def test_influence_matrix_is_the_jacobian_of_deformed_points() -> None:
    # A mesh's nodes or a surface's points at given (u, v): deformed = B @ lattice.points, for
    # both kinds of lattice, B written nowhere else than eq. (2) / HHK eq. (1) in the kernel and
    # checked here against the deformation itself and against central differences.
    rng = np.random.default_rng(41)
    bspline = cf.BSplineLattice([0, 0, 0], [50, 0, 0], [0, 40, 0], [0, 0, 30], (3, 2, 2), (4, 3, 2))
    for lat in (moved_lattice(), bspline):
        lat.points[:] += rng.uniform(-2, 2, size=lat.points.shape)
        corner, edges = np.array(lat.frame[0]), np.array(lat.frame[1:])
        x = corner + rng.uniform(0.02, 0.98, size=(200, 3)) @ edges
        b = lat.influence_matrix(x)
        assert scipy.sparse.isspmatrix_csr(b) and b.shape == (200, len(lat.points))
        assert np.max(np.abs(b @ lat.points - lat.deform_points(x))) < 1e-11
        row = len(lat.points) // 2
        plus = type(lat).__copy__(lat)
        plus.points[row, 1] += 0.5
        difference = (plus.deform_points(x) - lat.deform_points(x))[:, 1] / 0.5
        assert np.max(np.abs(difference - b[:, row].toarray().ravel())) < 1e-10
        g = rng.uniform(-1, 1, size=x.shape)
        adjoint = lat.influence_transpose_product(x, g)
        assert adjoint.shape == lat.points.shape
        assert np.max(np.abs(adjoint - b.T @ g)) < 1e-12 * np.max(np.abs(adjoint))


def test_bspline_lattice_jacobian_of_a_sheet_split_at_its_knot_planes() -> None:
    # A sheet whose x follows u and y follows v meets the lattice's knot planes along iso-lines.
    lat = cf.BSplineLattice([0, 0, 0], [100, 0, 0], [0, 80, 0], [0, 0, 40], (3, 2, 2), (3, 2, 1))
    lat.points[:] += np.random.default_rng(5).uniform(-3, 3, size=lat.points.shape)
    knots = [0.0] * 4 + [0.5] + [1.0] * 4
    pts = np.array([[5 + 90 * i / 4, 6 + 68 * j / 4, 20 + 5 * np.sin(i + j)] for i in range(5) for j in range(5)])
    sheet = cf.Surface((3, 3), knots, knots, pts)
    composed, jacobian = lat.composition_jacobian(sheet)
    assert np.max(np.abs(jacobian @ lat.points - composed.points)) < 1e-12 * 150
    u, v = np.meshgrid(np.linspace(0, 1, 17), np.linspace(0, 1, 13))
    pointwise = lat.deform_points(sheet.evaluate(u, v).reshape(-1, 3))
    assert np.max(np.abs(composed.evaluate(u, v).reshape(-1, 3) - pointwise)) < 1e-12 * 150
    assert jacobian.nnz < jacobian.shape[0] * jacobian.shape[1]
