"""Deformation stacks from their JSON form and certified refits, against closed forms."""
from __future__ import annotations

import json
import pickle

import numpy as np
import pytest

import clayform as cf


def taper_twist() -> cf.DeformationStack:
    return cf.DeformationStack.from_json(json.dumps({
        "format": "clayform.deformation-stack", "version": 1,
        "steps": [
            {"kind": "taper", "name": "taper", "frame": {"origin": [0, 0, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]},
             "profile": [1.0, 0.01]},
            {"kind": "twist", "name": "twist", "frame": {"origin": [0, 0, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]},
             "angle": [0.0, 0.02]},
        ]}))


def test_stack_matches_barrs_formulas() -> None:
    stack = taper_twist()
    assert stack.kinds == ["taper", "twist"]
    p = np.random.default_rng(3).uniform(-20, 20, size=(500, 3))
    # Barr (Gudukbay-Ozguc 3.1.1-2): taper r = 1 + 0.01 z scales x, y; twist turns by 0.02 z rad.
    r = 1 + 0.01 * p[:, 2]
    theta = 0.02 * p[:, 2]
    x, y = r * p[:, 0], r * p[:, 1]
    expected = np.stack([x * np.cos(theta) - y * np.sin(theta), x * np.sin(theta) + y * np.cos(theta), p[:, 2]], axis=1)
    assert np.max(np.abs(stack.deform_points(p) - expected)) < 1e-12
    assert np.max(np.abs(np.array(stack.deform_point(p[0])) - expected[0])) < 1e-12


def test_stack_pickles_bit_for_bit_and_refits_certified(bezier_patch: cf.Surface) -> None:
    stack = taper_twist()
    back = pickle.loads(pickle.dumps(stack))
    assert back.to_json() == stack.to_json()
    refit, report = stack.refit(bezier_patch, tolerance_mm=1e-3)
    assert report["certified"] and report["certified_bound_mm"] <= 1e-3
    u, v = np.meshgrid(np.linspace(0, 1, 31), np.linspace(0, 1, 29))
    pointwise = stack.deform_points(np.ascontiguousarray(bezier_patch.evaluate(u, v).reshape(-1, 3)))
    assert np.max(np.linalg.norm(refit.evaluate(u, v).reshape(-1, 3) - pointwise, axis=1)) <= report["certified_bound_mm"]


def test_refit_surface_and_errors(bezier_patch: cf.Surface) -> None:
    light, report = cf.refit_surface(bezier_patch, relative_tolerance=1e-6)
    assert report["certified"] and light.degrees == (3, 3)
    u, v = np.meshgrid(np.linspace(0, 1, 23), np.linspace(0, 1, 23))
    assert np.max(np.linalg.norm(light.evaluate(u, v) - bezier_patch.evaluate(u, v), axis=2)) <= report["certified_bound_mm"]
    with pytest.raises(cf.ToleranceNotMetError):
        cf.refit_surface(bezier_patch, relative_tolerance=1e-12, degree=1, max_control_points=16)
    with pytest.raises(cf.DocumentError, match="format"):
        cf.DeformationStack.from_json('{"format": "nope"}')
