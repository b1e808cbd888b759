"""Shared fixtures of the Python tests (run by CTest: tests/python/CMakeLists.txt sets
PYTHONPATH to the built package and CLAYFORM_EXE / CLAYFORM_EXAMPLES)."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import clayform as cf

EXAMPLES = Path(os.environ.get("CLAYFORM_EXAMPLES", Path(__file__).parents[2] / "examples"))
EXE = os.environ.get("CLAYFORM_EXE", "clayform")


def bernstein(n: int, i: int, t: np.ndarray) -> np.ndarray:
    """B_i^n(t), computed from the binomial formula (independent of the kernel)."""
    from math import comb

    return comb(n, i) * t**i * (1 - t) ** (n - i)


@pytest.fixture
def bezier_patch() -> cf.Surface:
    """A bicubic Bezier patch over [0, 100]^2 with a bump, full-precision coordinates."""
    rng = np.random.default_rng(3)
    pts = np.array(
        [[100 * i / 3, 100 * j / 3, 10 * np.sin(i + 2 * j) + rng.uniform(-1, 1)] for i in range(4) for j in range(4)]
    )
    knots = [0.0] * 4 + [1.0] * 4
    return cf.Surface((3, 3), knots, knots, pts)


@pytest.fixture
def examples() -> Path:
    return EXAMPLES


@pytest.fixture
def exe() -> str:
    return EXE
