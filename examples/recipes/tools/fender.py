#!/usr/bin/env python3
"""Writes examples/recipes/fender.json: the worked designer example of docs/styling.md (issue #21).

    python3 examples/recipes/tools/fender.py [output folder, default examples/recipes]

A car's front-fender side panel, about 1 m long and 420 mm high, built the way a stylist works:
- three freehand strokes (rocker, shoulder, front edge) with hand jitter (a fixed seed), fitted;
- the rear edge, where the door cut runs, as a constrained planar sketch: a B-spline whose ends are
  fixed where the strokes end and whose ends leave square to the rocker and the shoulder;
- a Coons fill that snaps the stroke ends that nearly meet (gap_tolerance 3 mm);
- a style step: a closed stroke drawn beside the panel and projected onto it as bound, and the
  flare's line drawn in space, rising 25 mm outboard, as target (exact mode, the net refined until
  the shape changes by less than 0.5 % when it is halved once more);
- the styled surface rebuilt to a tenth of a millimetre (a dense exact net, made light before the
  next operation);
- a Bezier lattice that wraps the nose inward, its exact composition above the default budget, so
  the step yields its certified bicubic light form.

Python 3 standard library only; the recipe file, not this script, is the reference.
"""
import json
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(HERE)

rng = random.Random(21)


def jitter(points, amount=0.6):
    """Hand jitter: every drawn point off by up to `amount` mm in each coordinate."""
    return [[round(c + rng.uniform(-amount, amount), 2) for c in p] for p in points]


def r(p):
    return [round(c, 3) for c in p]


LENGTH, HEIGHT, CUT = 1000.0, 420.0, 40.0


def crown(x, z):
    """How far the panel stands outboard (y) at (x, z): 18 mm at the rocker's middle, 28 mm at the
    shoulder's, 0 at the front and rear edges."""
    return math.sin(math.pi * x / LENGTH) * (18 + 10 * z / HEIGHT)


# Rocker (bottom, z = 0) from the front (x = 0) to the rear, the shoulder (top) from the door cut
# back to the front, the front edge from the top down; their ends are drawn up to 1.5 mm off the
# corners (the fill snaps them).
rocker = jitter([[x, crown(x, 0), 2 * math.sin(math.pi * x / LENGTH)]
                 for x in [LENGTH * k / 40 for k in range(41)]])
rocker[0], rocker[-1] = [0.6, 0.5, -0.7], [LENGTH - 0.4, -0.9, 0.8]
top = LENGTH - CUT
shoulder = jitter([[x, 28 * math.sin(math.pi * x / top), HEIGHT + 10 * math.sin(math.pi * x / top)]
                   for x in [top * (40 - k) / 40 for k in range(41)]])
shoulder[0], shoulder[-1] = [top + 0.9, 0.7, HEIGHT - 0.5], [1.0, -0.6, HEIGHT + 0.4]
front = jitter([[-8 * math.sin(math.pi * z / HEIGHT), 0, z]
                for z in [HEIGHT * (20 - k) / 20 for k in range(21)]])
front[0], front[-1] = [-0.8, 0.9, HEIGHT - 0.6], [-0.5, -0.7, 0.9]

# The door cut, a constrained planar sketch in the plane y = 0 (sketch coordinates (a, b) =
# (x - LENGTH, z)): a cubic B-spline from the rocker's end to the shoulder's start, leaving the
# rocker square to it and meeting the shoulder level, held by two construction lines (a vertical
# sill below it and a level header above it, tangent to it at its ends). The solver moves the
# cubic's control points; the sketch keeps 2 degrees of freedom (how full the cut is).
rear = {
    "plane": {"origin": [LENGTH, 0, 0], "x_axis": [1, 0, 0], "y_axis": [0, 0, 1]},
    "points": {"s0": [0, -55], "s1": [2, 1], "h1": [-95, HEIGHT + 4]},
    "entities": {
        "cut": {"bspline": {"degree": 3, "knots": [0, 0, 0, 0, 1, 1, 1, 1],
                            "points": [[LENGTH + 2, 0, 1], [LENGTH + 6, 0, 150],
                                       [LENGTH - 10, 0, 330], [top, 0, HEIGHT]]}},
        "sill": {"line": ["s0", "s1"]},
        "header": {"line": ["cut.end", "h1"]},
    },
    "constraints": [
        {"type": "fixed", "point": "s0"},
        {"type": "vertical", "entity": "sill"},
        {"type": "distance", "points": ["s0", "s1"], "value": 55},
        {"type": "tangent", "ends": [{"entity": "sill", "end": "end"},
                                     {"entity": "cut", "end": "start"}]},
        {"type": "fixed", "point": "cut.end"},
        {"type": "horizontal", "entity": "header"},
        {"type": "tangent", "ends": [{"entity": "cut", "end": "end"},
                                     {"entity": "header", "end": "start"}]},
        {"type": "distance", "points": ["cut.end", "h1"], "value": 90},
    ],
}

# The bound: a closed loop drawn round the flare, 60 mm off the panel (it is projected onto it),
# and the flare's line drawn across it.
bound = jitter([[480 + 330 * math.cos(t), 60, 205 + 140 * math.sin(t)]
                for t in [2 * math.pi * k / 48 for k in range(48)]], 0.5)
bound.append(bound[0][:])
# The flare's line, drawn in space: along an arch across the bound, rising from the panel at its
# ends to 25 mm outboard (the panel stands out along +y) over its middle.
def arch_point(s):
    x = 250 + 460 * s
    z = 140 + 130 * math.sin(math.pi * s)
    return [x, crown(x, z) + 25 * math.sin(math.pi * s), z]


flare = jitter([arch_point(k / 24) for k in range(25)], 0.5)

recipe = {
    "format": "clayform.recipe",
    "version": 1,
    "name": "fender",
    "description": (
        "A front-fender side panel (1 m x 420 mm) built as a stylist works (docs/styling.md): "
        "three noisy strokes and a constrained planar sketch for the door cut, a Coons fill that "
        "snaps the ends that nearly meet, a style step (Han, De Amicis & Conti 2007) with a bound "
        "drawn beside the panel and projected onto it and a flare line rising 25 mm outboard as "
        "target, exact mode on a net refined until the shape converges, the result rebuilt to a "
        "tenth of a millimetre, a Bezier lattice (Sederberg & Parry 1986) that wraps the nose, "
        "its exact composition above the default budget, so the step is its certified bicubic "
        "light form, exported for a class-A receiver (degree 5, 32 x 32 control points, knots "
        "where the error is)."),
    "units": "mm",
    "composition": {"mode": "exact"},
    "strokes": {
        "rocker": {"points": rocker, "tolerance_mm": 1.0},
        "shoulder": {"points": shoulder, "tolerance_mm": 1.0},
        "front": {"points": front, "tolerance_mm": 1.0},
        "flare_line": {"points": flare, "tolerance_mm": 1.0},
        "bound_drawn": {"points": bound, "tolerance_mm": 1.0},
    },
    "sketches": {"rear": rear},
    "curves": {
        "bound": {"project": {"curve": "bound_drawn", "surface": "panel", "tolerance_mm": 0.01}},
    },
    "surfaces": {
        "panel": {"fill": {"curves": ["rocker", "rear.cut", "shoulder", "front"], "style": "coons",
                           "join": "snap", "gap_tolerance": 3}},
        "styled": {"deform": {"surface": "panel", "deformation": "flare"}},
        # The converged style result is a dense exact bicubic (about 178,000 control points); a
        # lattice composed with it exactly would be far denser still, so it is rebuilt to a
        # tenth of a millimetre first, as a stylist rebuilds before the next operation.
        "styled_net": {"rebuild": {"surface": "styled", "relative_tolerance": 1e-4}},
        "fender": {"deform": {"surface": "styled_net", "deformation": "nose"}},
    },
    "deformations": {
        "flare": [
            {"kind": "style", "name": "flare", "target": "flare_line", "bound": "bound",
             "mode": "exact", "curve_tolerance": 1e-4, "net_convergence": 0.005,
             "max_refinements": 8},
        ],
        "nose": [
            {"kind": "bezier_lattice", "name": "nose",
             "frame": {"origin": [-40, -80, -20], "s": [1120, 0, 0], "t": [0, 240, 0],
                       "u": [0, 0, 480]},
             "degrees": [3, 1, 1],
             "moves": [{"index": [0, 0, 0], "by": [0, -25, 0]}, {"index": [0, 1, 0], "by": [0, -25, 0]},
                       {"index": [0, 0, 1], "by": [0, -25, 0]}, {"index": [0, 1, 1], "by": [0, -25, 0]},
                       {"index": [1, 0, 0], "by": [0, -8, 0]}, {"index": [1, 1, 0], "by": [0, -8, 0]},
                       {"index": [1, 0, 1], "by": [0, -8, 0]}, {"index": [1, 1, 1], "by": [0, -8, 0]}]},
        ]
    },
    "exports": {"fender": {"surfaces": ["fender"], "profile": "class_a"}},
}

path = os.path.join(OUT, "fender.json")
with open(path, "w") as f:
    json.dump(recipe, f, indent=1)
    f.write("\n")
print("wrote", path)
