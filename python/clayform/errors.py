"""Clayform's exceptions: one class per category of the kernel's clay::Error.

Every class derives from ClayError, and from the built-in exception a Python user would expect
(ValueError for bad arguments and geometry, OSError for files, RuntimeError for kernel bugs), so
`except ValueError` keeps working. `category` names the kernel's category.
"""
from __future__ import annotations


class ClayError(Exception):
    """Any error raised by the Clayform kernel. The message names the object and the fix."""

    category: str = "internal"


class InvalidArgumentError(ClayError, ValueError):
    """A parameter or option outside its documented range."""

    category = "invalid_argument"


class InvalidGeometryError(ClayError, ValueError):
    """Geometry that breaks an invariant (knots, counts, weights, NaN)."""

    category = "invalid_geometry"


class OutOfDomainError(ClayError, ValueError):
    """A parameter outside the object's domain (or a surface outside a lattice)."""

    category = "out_of_domain"


class DegreeLimitError(ClayError, ValueError):
    """A degree above what an exchange format or algorithm supports."""

    category = "degree_limit"


class IoError(ClayError, OSError):
    """A file could not be read, written or renamed."""

    category = "io"


class ExchangeError(ClayError):
    """A STEP/IGES/glTF translation failed (OpenCASCADE refused, crashed or produced invalid
    geometry)."""

    category = "exchange"


class DocumentError(ClayError, ValueError):
    """A malformed JSON document (a recipe, a deformation stack, a studio autosave) or a reference
    in it to a missing object; the message lists every problem."""

    category = "document"


#: DocumentError's name until issue #37 (the kernel's category is not the recipe
#: library's); kept so that `except RecipeError` goes on catching the same errors.
RecipeError = DocumentError


class ToleranceNotMetError(ClayError):
    """A result missed its tolerance: a failure, not a warning."""

    category = "tolerance_not_met"


class InternalError(ClayError, RuntimeError):
    """A kernel bug: please report it with the input that caused it."""

    category = "internal"


#: The class of each kernel category, by its name.
BY_CATEGORY = {
    cls.category: cls
    for cls in (
        InvalidArgumentError,
        InvalidGeometryError,
        OutOfDomainError,
        DegreeLimitError,
        IoError,
        ExchangeError,
        DocumentError,
        ToleranceNotMetError,
        InternalError,
    )
}
