#!/usr/bin/env python3
"""Writes examples/recipes/tank.json: a motorcycle fuel-tank top panel as a new stylist's first
session saves it from the studio (issue #38): four freehand strokes, a Coons fill, one style step
in exact mode, then one (3, 3, 1) Bezier lattice, and every composition setting at its default.

    python3 examples/recipes/tools/tank.py [output folder, default examples/recipes]

The lattice's exact composition with the styled net would have degree 21 x 21 and millions of
control points; under the default budget (degree 15, 10,000 control points) the step yields its
certified bicubic light form instead, and the exact net is never built.

Python 3 standard library only; the recipe file, not this script, is the reference.
"""
import json
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(HERE)

rng = random.Random(38)
LENGTH, WIDTH = 560.0, 360.0


def jitter(points, amount=0.5):
    """Hand jitter: every drawn point off by up to `amount` mm in each coordinate."""
    return [[round(c + rng.uniform(-amount, amount), 2) for c in p] for p in points]


def top(x, y):
    """The tank's crown (z, mm) over the plan point (x, y): 110 mm high mid-length on the centre
    line, falling to the sides and, less, to the front and rear."""
    return 110 * math.sin(math.pi * (0.15 + 0.7 * x / LENGTH)) * math.cos(0.9 * math.pi * y / WIDTH)


def stroke_x(y, n=40, reverse=False):
    xs = [LENGTH * k / n for k in range(n + 1)]
    if reverse:
        xs.reverse()
    return jitter([[x, y + 12 * math.sin(math.pi * x / LENGTH) * (1 if y > 0 else -1), top(x, y)]
                   for x in xs])


def stroke_y(x, n=24, reverse=False):
    ys = [-WIDTH / 2 + WIDTH * k / n for k in range(n + 1)]
    if reverse:
        ys.reverse()
    return jitter([[x, y, top(x, y)] for y in ys])


# The four edges drawn round the panel, each from where the last ended (the fill snaps ends
# that nearly meet).
left = stroke_x(-WIDTH / 2)
rear = stroke_y(LENGTH)
right = stroke_x(WIDTH / 2, reverse=True)
front = stroke_y(0.0, reverse=True)

# The bound: a loop drawn round the knee area, 80 mm above the panel (projected onto it); the
# target: a spine line drawn along the middle, 4 mm above the crown at its ends and 14 mm
# over its middle.
bound = jitter([[300 + 190 * math.cos(t), 95 * math.sin(t), 200]
                for t in [2 * math.pi * k / 40 for k in range(40)]], 0.4)
bound.append(bound[0][:])
spine = jitter([[x, 0.0, top(x, 0.0) + 4 + 10 * math.sin(math.pi * (x - 170) / 260)]
                for x in [170 + 260 * k / 24 for k in range(25)]], 0.3)

recipe = {
    "format": "clayform.recipe",
    "version": 1,
    "name": "tank",
    "description": (
        "A motorcycle fuel-tank top panel (560 x 360 mm) as a new stylist's first studio session "
        "saves it (issue #38): four freehand strokes and a Coons fill, a style step in exact mode "
        "(Han, De Amicis & Conti 2007) raising a spine line inside a bound drawn round the knee "
        "area, then a (3, 3, 1) Bezier lattice (Sederberg & Parry 1986) that pinches the knee "
        "recesses. Every composition setting is the default: the lattice's exact composition "
        "would have degree 21 x 21 and millions of control points, so under the default budget "
        "(degree 15, 10,000 control points) it yields its certified bicubic light form."),
    "units": "mm",
    "strokes": {
        "left": {"points": left, "tolerance_mm": 1.0},
        "rear": {"points": rear, "tolerance_mm": 1.0},
        "right": {"points": right, "tolerance_mm": 1.0},
        "front": {"points": front, "tolerance_mm": 1.0},
        "spine": {"points": spine, "tolerance_mm": 1.0},
        "bound_drawn": {"points": bound, "tolerance_mm": 1.0},
    },
    "curves": {
        "bound": {"project": {"curve": "bound_drawn", "surface": "panel", "tolerance_mm": 0.01}},
    },
    "surfaces": {
        "panel": {"fill": {"curves": ["left", "rear", "right", "front"], "style": "coons",
                           "join": "snap", "gap_tolerance": 3}},
        "styled": {"deform": {"surface": "panel", "deformation": "spine"}},
        "tank": {"deform": {"surface": "styled", "deformation": "knees"}},
    },
    "deformations": {
        "spine": [
            {"kind": "style", "name": "spine", "target": "spine", "bound": "bound",
             "mode": "exact", "curve_tolerance": 1e-4, "max_refinements": 8},
        ],
        "knees": [
            {"kind": "bezier_lattice", "name": "knees",
             "frame": {"origin": [-30, -220, -20], "s": [620, 0, 0], "t": [0, 440, 0],
                       "u": [0, 0, 160]},
             "degrees": [3, 3, 1],
             "moves": [{"index": [2, 0, 0], "by": [0, 18, 0]}, {"index": [2, 0, 1], "by": [0, 18, -6]},
                       {"index": [2, 3, 0], "by": [0, -18, 0]}, {"index": [2, 3, 1], "by": [0, -18, -6]},
                       {"index": [1, 1, 1], "by": [0, 0, 8]}, {"index": [1, 2, 1], "by": [0, 0, 8]}]},
        ]
    },
    "exports": {"tank": {"surfaces": ["tank"]}},
}

path = os.path.join(OUT, "tank.json")
with open(path, "w") as f:
    json.dump(recipe, f, indent=1)
    f.write("\n")
print("wrote", path)
