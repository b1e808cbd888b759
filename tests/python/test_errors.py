"""Every clay::Error category arrives as its own Python class, including failures inside
OpenCASCADE; messages name the object and the fix."""
from __future__ import annotations

import numpy as np
import pytest

import clayform as cf
from clayform import errors


@pytest.mark.parametrize("category, cls", sorted(errors.BY_CATEGORY.items()))
def test_every_category_has_its_class(category: str, cls: type) -> None:
    with pytest.raises(cls) as e:
        cf._clayform._raise_error(category, f"a {category} message")  # type: ignore[attr-defined]
    assert isinstance(e.value, cf.ClayError)
    assert str(e.value) == f"a {category} message" and e.value.category == category


def test_builtin_bases() -> None:
    assert issubclass(cf.InvalidGeometryError, ValueError)
    assert issubclass(cf.IoError, OSError)
    assert issubclass(cf.InternalError, RuntimeError)


def test_recipe_error_is_the_old_name_of_document_error() -> None:
    # The kernel's category was renamed Document (issue #37): code written against the old name
    # catches the same errors.
    assert cf.RecipeError is cf.DocumentError and issubclass(cf.DocumentError, ValueError)
    with pytest.raises(cf.RecipeError, match="format"):
        cf.Recipe.parse('{"format": "nope"}')


def test_invalid_geometry_names_the_problem() -> None:
    with pytest.raises(cf.InvalidGeometryError, match="knot"):
        cf.Curve(3, [0, 0, 1, 0.5, 1, 1, 1, 1], np.zeros((4, 3)))


def test_missing_file_is_an_io_error(tmp_path) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(cf.IoError, match="does not exist"):
        cf.read_step(str(tmp_path / "missing.step"))


def test_failure_inside_opencascade_is_an_exchange_error(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # Two knots one unit in the last place apart: valid for the kernel, refused by OpenCASCADE's
    # Geom_BSplineSurface constructor (a Standard_ConstructionError, caught and typed).
    k = np.nextafter(0.5, 1.0)
    knots = [0.0] * 4 + [0.5, float(k)] + [1.0] * 4
    pts = np.array([[i, j, (i * j) % 3] for i in range(6) for j in range(6)], dtype=np.float64)
    s = cf.Surface((3, 3), knots, knots, pts)
    with pytest.raises(cf.ExchangeError, match="OpenCASCADE"):
        cf.write_step(s, str(tmp_path / "ulp.step"))
    assert not (tmp_path / "ulp.step").exists()  # nothing half-written


def test_malformed_step_is_refused_before_opencascade(tmp_path) -> None:  # type: ignore[no-untyped-def]
    bad = tmp_path / "bad.step"
    bad.write_text(
        "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=B_SPLINE_SURFACE_WITH_KNOTS('',3,3,((#2)),"
        ".UNSPECIFIED.,.F.,.F.,.F.,(4),(4),(0.,1.),.UNSPECIFIED.);\nENDSEC;\nEND-ISO-10303-21;\n"
    )
    with pytest.raises(cf.ExchangeError, match="dangling"):
        cf.read_step(str(bad))


def test_recipe_problems_are_listed() -> None:
    with pytest.raises(cf.DocumentError, match="format"):
        cf.Recipe.parse('{"format": "nope"}')
    problems = cf.Recipe.check('{"format": "clayform.recipe", "version": 1, "surfaces": 3}')
    assert problems and all({"path", "message", "line", "column"} <= set(p) for p in problems)


def test_out_of_domain_from_compose(bezier_patch: cf.Surface) -> None:
    small = cf.BezierLattice([0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10])
    with pytest.raises(cf.OutOfDomainError):
        small.compose(bezier_patch)


def test_bad_option_is_an_invalid_argument() -> None:
    with pytest.raises(cf.InvalidArgumentError, match="style"):
        cf.fill([], style="wobbly")
