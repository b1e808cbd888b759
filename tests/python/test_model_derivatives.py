"""A whole model's exact derivatives with respect to a lattice's points (issue #41,
docs/optimisation.md): the Jacobian of every face as SciPy sparse matrices, the model at other
points, mass properties and their gradients against central differences, volume-keeping moves,
the lattice's Jacobian coefficients as constraints, and a folded lattice refused."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse

import clayform as cf


def block(examples: Path) -> cf.Model:
    model, _ = cf.read_model(examples / "models" / "block.step")
    return model.flattened()


def lattice_for(model: cf.Model, seed: int = 3) -> cf.BezierLattice:
    lo, hi = (np.array(c) for c in model.bounding_box())
    pad = 0.1 * (hi - lo)
    size = hi - lo + 2 * pad
    lat = cf.BezierLattice(lo - pad, [size[0], 0, 0], [0, size[1], 0], [0, 0, size[2]], (2, 2, 1))
    lat.points += np.random.default_rng(seed).normal(scale=1.0, size=lat.points.shape)
    return lat


def five_point(f, h: float) -> float:  # type: ignore[no-untyped-def]
    return float((8 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12 * h))


def test_every_face_is_its_sparse_matrix_times_the_lattice_points(examples: Path) -> None:
    model = block(examples)
    lat = lattice_for(model)
    j = lat.model_jacobian(model)
    assert j.lattice_points == len(lat.points) and len(j.faces) == model.face_count
    fixed = j.model
    for f, c in enumerate(j.faces):
        assert scipy.sparse.isspmatrix_csr(c)
        assert np.max(np.abs(c @ lat.points - fixed.face_surface(f).points)) < 1e-12 * 80
    # Each face is the pointwise FFD of the original (independent of the composition).
    original = model.face_surface(5)
    (u0, u1), (v0, v1) = original.domain
    u, v = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 7))
    expected = lat.deform_points(np.ascontiguousarray(original.evaluate(u, v).reshape(-1, 3)))
    assert np.max(np.abs(fixed.face_surface(5).evaluate(u, v).reshape(-1, 3) - expected)) < 1e-11 * 80
    # The points of a face at (u, v): the Jacobian against the pointwise FFD's central differences.
    uv = np.column_stack([u.ravel(), v.ravel()])
    b = j.face_point_jacobian(5, uv)
    x = np.ascontiguousarray(original.evaluate(u, v).reshape(-1, 3))
    for point in (0, 7, 13):
        plus, minus = lat.__copy__(), lat.__copy__()
        plus.points[point, 0] += 1.0
        minus.points[point, 0] -= 1.0
        d = (plus.deform_points(x) - minus.deform_points(x))[:, 0] / 2
        assert np.max(np.abs(b[:, point].toarray().ravel() - d)) < 1e-12


def test_mass_properties_and_their_gradients_against_differences(examples: Path) -> None:
    model = block(examples)
    p = model.mass_properties()
    assert p["volume_mm3"] == pytest.approx(model.volume_mm3(), rel=1e-13)
    assert p["inertia_mm5"].shape == (3, 3) and p["centroid_mm"].shape == (3,)
    lat = lattice_for(model, seed=5)
    j = lat.model_jacobian(model)
    g = j.mass_property_gradients()
    assert g["volume_gradient"].shape == (len(lat.points), 3)
    assert g["centroid_gradient"].shape == (3, len(lat.points), 3)
    assert g["inertia_gradient"].shape == (6, len(lat.points), 3)
    direction = np.random.default_rng(8).normal(size=lat.points.shape)

    def at(h: float) -> dict:  # type: ignore[type-arg]
        return j.mass_properties(lat.points + h * direction)

    dv = five_point(lambda h: at(h)["volume_mm3"], 0.05)  # exact: V is cubic in the points
    assert np.sum(g["volume_gradient"] * direction) == pytest.approx(dv, rel=1e-10)
    for i in range(3):
        dc = five_point(lambda h: at(h)["centroid_mm"][i], 0.01)
        assert np.sum(g["centroid_gradient"][i] * direction) == pytest.approx(dc, rel=1e-8, abs=1e-10)
    # The values at other points agree with the deformed model's own.
    moved = lat.points + 0.3 * direction
    assert j.mass_properties(moved)["volume_mm3"] == pytest.approx(j.deformed(moved).volume_mm3(), rel=1e-13)


def test_a_drag_keeps_the_volume(examples: Path) -> None:
    model = block(examples)
    lat = lattice_for(model, seed=1)
    j = lat.model_jacobian(model)
    v0 = j.mass_properties()["volume_mm3"]
    moved = lat.points.copy()
    moved[lat.index(2, 1, 1)] += [4.0, 1.0, 3.0]
    points, report = j.keep_properties(moved, volume_mm3=v0, held=[lat.index(2, 1, 1)])
    assert np.array_equal(points[lat.index(2, 1, 1)], moved[lat.index(2, 1, 1)])
    assert abs(j.deformed(points).volume_mm3() / v0 - 1) < 1e-12
    assert report["iterations"] <= 5 and report["volume_error"] < 1e-13
    with pytest.raises(cf.InvalidArgumentError, match="nothing to keep"):
        j.keep_properties(moved)


def test_surface_area_its_bound_and_gradient(examples: Path) -> None:
    model = block(examples)
    a = model.surface_area()
    assert a["bound_mm2"] < 1e-10 * a["area_mm2"]
    assert np.sum(a["faces_mm2"]) == pytest.approx(a["area_mm2"], rel=1e-15)
    lat = lattice_for(model, seed=4)
    j = lat.model_jacobian(model)
    g = j.surface_area()
    assert g["area_gradient"].shape == (len(lat.points), 3)
    direction = np.random.default_rng(2).normal(size=lat.points.shape)
    da = five_point(lambda h: j.surface_area(lat.points + h * direction)["area_mm2"], 0.01)
    assert np.sum(g["area_gradient"] * direction) == pytest.approx(da, rel=1e-9)
    # Homogeneous of degree 2 in the points: a scaling about any point gives 2 A.
    scaling = lat.points - lat.points.mean(axis=0)
    assert np.sum(g["area_gradient"] * scaling) == pytest.approx(2 * g["area_mm2"], rel=1e-12)


def test_a_drag_keeps_a_fixed_face_and_a_symmetry_plane(examples: Path) -> None:
    model = block(examples)
    lo, hi = (np.array(c) for c in model.bounding_box())
    pad = 0.1 * (hi - lo)
    size = hi - lo + 2 * pad
    lat = cf.BezierLattice(lo - pad, [size[0], 0, 0], [0, size[1], 0], [0, 0, size[2]], (2, 2, 1))
    j = lat.model_jacobian(model)
    bottom = int(np.argmin([j.model.face_surface(f).points[:, 2].max() for f in range(len(j.faces))]))
    middle = (lo + hi) / 2
    v0 = j.mass_properties()["volume_mm3"]
    moved = lat.points.copy()
    dragged = lat.index(2, 1, 1)
    moved[dragged] += [3.0, 0.0, 4.0]
    points, report = j.keep_properties(
        moved, volume_mm3=v0, held=[dragged], fixed_faces=[bottom],
        symmetry_planes=[(middle, [0.0, 1.0, 0.0])])
    assert report["linear_error_mm"] < 1e-12 * 80
    after = j.deformed(points)
    assert np.max(np.abs(after.face_surface(bottom).points - j.model.face_surface(bottom).points)) < 1e-12 * 80
    assert abs(after.volume_mm3() / v0 - 1) < 1e-12
    # y displacements mirror across the middle plane: point (i, k, l) and (i, 2 - k, l)
    d = points - lat.points
    for i in range(3):
        for layer in range(2):
            a, b = d[lat.index(i, 0, layer)], d[lat.index(i, 2, layer)]
            assert np.allclose([a[0], -a[1], a[2]], b, atol=1e-12 * 80)
    with pytest.raises(cf.InvalidArgumentError, match="symmetry_planes"):
        j.keep_properties(moved, volume_mm3=v0, symmetry_planes=[(middle,)])


def test_jacobian_constraints_and_a_folded_lattice(examples: Path) -> None:
    model = block(examples)
    lat = lattice_for(model, seed=2)
    values, gradient = lat.jacobian_constraints()
    assert gradient.shape == (len(values), 3 * len(lat.points)) and values.min() > 0
    direction = np.random.default_rng(4).normal(size=lat.points.shape)

    def coefficients(h: float) -> np.ndarray:
        moved = lat.__copy__()
        moved.points = lat.points + h * direction
        return moved.jacobian_constraints()[0]

    d = (8 * (coefficients(0.1) - coefficients(-0.1)) - (coefficients(0.2) - coefficients(-0.2))) / 1.2
    assert np.max(np.abs(gradient @ direction.ravel() - d)) < 1e-10 * np.max(np.abs(d))
    folded = lat.__copy__()
    folded.points[folded.index(2, 1, 1), 0] -= 200.0  # through its neighbours
    with pytest.raises(cf.InvalidGeometryError, match="allow_fold=True"):
        folded.model_jacobian(model)
    assert folded.model_jacobian(model, allow_fold=True).lattice_points == len(lat.points)
