"""NumPy conventions: bitwise round trips, zero copy where promised, TypeError instead of a
silent conversion."""
from __future__ import annotations

import copy

import numpy as np
import pytest

import clayform as cf


def test_surface_points_round_trip_bitwise_and_view(bezier_patch: cf.Surface) -> None:
    pts = np.random.default_rng(1).normal(size=(16, 3)) * 1e3 + 1 / 3
    knots = [0.0] * 4 + [1.0] * 4
    s = cf.Surface((3, 3), knots, knots, pts)
    assert s.points.tobytes() == pts.tobytes()  # bitwise
    view = s.points
    assert view.dtype == np.float64 and view.flags.c_contiguous and view.shape == (16, 3)
    assert np.shares_memory(view, s.points)  # both views of the surface's own storage
    assert not np.shares_memory(view, pts)  # the constructor copies in
    view[5, 2] += 7.0  # writes through
    assert s.points[5, 2] == pts[5, 2] + 7.0
    assert s.knots_u.tobytes() == np.array(knots).tobytes()
    with pytest.raises(ValueError):
        s.knots_u[0] = 1  # knots are a read-only copy: editing them would break invariants


def test_curve_points_and_weights_views() -> None:
    pts = np.array([[0.0, 0, 0], [1, 2, 0], [3, 2, 1], [4, 0, 0]])
    w = np.array([1.0, 0.5, 2.0, 1.0])
    c = cf.Curve(3, [0, 0, 0, 0, 1, 1, 1, 1], pts, w)
    assert c.points.tobytes() == pts.tobytes() and c.weights.tobytes() == w.tobytes()
    assert np.shares_memory(c.points, c.points) and c.rational
    d = copy.copy(c)
    d.points[0, 0] = 9
    assert c.points[0, 0] == 0  # a value type: the copy is independent


def test_evaluate_shapes(bezier_patch: cf.Surface) -> None:
    u = np.linspace(0, 1, 12).reshape(3, 4)
    v = np.linspace(1, 0, 12).reshape(3, 4)
    p = bezier_patch.evaluate(u, v)
    assert p.shape == (3, 4, 3)
    assert np.array_equal(p[1, 2], bezier_patch.evaluate(float(u[1, 2]), float(v[1, 2])))
    g = bezier_patch.evaluate_grid(np.linspace(0, 1, 5), np.linspace(0, 1, 7))
    assert g.shape == (5, 7, 3)
    # (the grid evaluates row by row: equal up to rounding, not bit for bit)
    assert np.allclose(g[2, 3], bezier_patch.evaluate(0.5, 0.5), rtol=0, atol=1e-12)


def test_deform_points_zero_copy_out_and_in_place() -> None:
    lat = cf.BezierLattice([0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100], (2, 2, 2))
    lat.points[lat.index(1, 1, 1)] += [5.0, -3.0, 2.0]
    frozen = lat.freeze()
    pts = np.random.default_rng(2).uniform(0, 100, size=(1000, 3))
    expected = frozen.deform_points(pts)
    out = np.empty_like(pts)
    result = frozen.deform_points(pts, out=out)
    assert result is out and np.shares_memory(result, out)
    assert out.tobytes() == expected.tobytes()
    inplace = pts.copy()
    frozen.deform_points(inplace, out=inplace)
    assert inplace.tobytes() == expected.tobytes()
    # The one-off call freezes internally and gives the same numbers.
    assert lat.deform_points(pts).tobytes() == expected.tobytes()


@pytest.mark.parametrize(
    "bad, kind",
    [
        (np.zeros((4, 3), dtype=np.float32), TypeError),
        (np.zeros((4, 3), dtype=np.int64), TypeError),
        (np.asfortranarray(np.zeros((4, 3))), TypeError),
        (np.zeros((6, 3))[::2], TypeError),
        ([[0.0, 0.0, 0.0]], TypeError),
        (np.zeros((4, 2)), ValueError),
    ],
)
def test_wrong_dtype_or_order_is_refused(bad: object, kind: type) -> None:
    lat = cf.BezierLattice([0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1])
    with pytest.raises(kind) as e:
        lat.deform_points(bad)
    assert "points" in str(e.value)


def test_read_only_out_is_refused() -> None:
    lat = cf.BezierLattice([0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1])
    pts = np.zeros((3, 3))
    out = np.zeros((3, 3))
    out.setflags(write=False)
    with pytest.raises(ValueError, match="read-only"):
        lat.deform_points(pts, out=out)
