"""Clayform: an exact NURBS surface styling kernel, NumPy first (docs/python.md).

Curves, surfaces and lattices are value classes whose control points are (n, 3) float64 NumPy
views into their own storage; bulk inputs are read in place (a wrong dtype or order raises
TypeError, never a silent copy); long calls release the GIL; surfaces, lattices and recipes
pickle. Errors are typed (clayform.errors). Sweeps of recipe variants: clayform.sweep(spec, out) (clayform.sweeps).
"""
from __future__ import annotations

from . import errors, sweeps
from ._clayform import (
    BezierLattice,
    BSplineLattice,
    Curve,
    DeformationStack,
    FrozenLattice,
    Model,
    Recipe,
    RunResult,
    Sketch,
    Surface,
    fill,
    fit_stroke,
    loft,
    read_iges,
    read_model,
    read_step,
    recipe_path,
    refit_surface,
    fit_to_profile,
    render_png,
    revolve,
    style_deform,
    write_gltf,
    write_iges,
    write_step,
)
from .errors import (
    ClayError,
    DegreeLimitError,
    ExchangeError,
    InternalError,
    InvalidArgumentError,
    InvalidGeometryError,
    IoError,
    OutOfDomainError,
    DocumentError,
    RecipeError,
    ToleranceNotMetError,
)
from .sweeps import run as sweep

__all__ = [
    "BezierLattice",
    "BSplineLattice",
    "ClayError",
    "Curve",
    "DeformationStack",
    "DegreeLimitError",
    "ExchangeError",
    "FrozenLattice",
    "InternalError",
    "InvalidArgumentError",
    "InvalidGeometryError",
    "IoError",
    "Model",
    "OutOfDomainError",
    "Recipe",
    "DocumentError",
    "RecipeError",
    "RunResult",
    "Sketch",
    "Surface",
    "ToleranceNotMetError",
    "errors",
    "fill",
    "fit_stroke",
    "loft",
    "read_iges",
    "read_model",
    "read_step",
    "recipe_path",
    "refit_surface",
    "fit_to_profile",
    "render_png",
    "revolve",
    "style_deform",
    "sweep",
    "sweeps",
    "write_gltf",
    "write_iges",
    "write_step",
]
