#!/usr/bin/env python3
"""Writes the paper-figure recipes of examples/recipes/ (sail, car_hood, bump, bottle, tongue).

    python3 examples/recipes/tools/paper_figures.py [output folder, default examples/recipes]

Python 3 standard library only. The numbers are rounded to 0.1 um so the recipes stay readable;
weights and knots are written in full. The recipe files, not this script, are the reference
(the tests read them).
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


# ---- JSON layout: objects one key a line, number arrays and points on one line -----------------

def num(x):
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    if x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return repr(x)


def flat(value):
    """Numbers, strings and arrays of them on one line."""
    if isinstance(value, (bool, int, float)):
        return num(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(flat(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(json.dumps(k) + ": " + flat(v) for k, v in value.items()) + "}"
    raise TypeError(value)


def is_number_list(value):
    return isinstance(value, list) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)


def layout(value, indent=0):
    pad = "  " * indent
    if isinstance(value, dict):
        if not value:
            return "{}"
        one = flat(value)
        if len(one) + len(pad) <= 96 and not any(isinstance(v, (dict, list)) and len(flat(v)) > 60
                                                   for v in value.values()):
            return one
        items = [pad + "  " + json.dumps(k) + ": " + layout(v, indent + 1) for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list):
        one = flat(value)
        if len(one) + len(pad) <= 96 or is_number_list(value):
            return one
        if all(is_number_list(v) for v in value):  # rows of points: several a line
            cells = [flat(v) for v in value]
            lines, line = [], ""
            for c in cells:
                if line and len(pad) + 2 + len(line) + len(c) + 2 > 100:
                    lines.append(line.rstrip())
                    line = ""
                line += c + ", "
            lines.append(line.rstrip(", "))
            return "[\n" + ",\n".join(pad + "  " + l.rstrip(",") for l in lines) + "\n" + pad + "]"
        return "[\n" + ",\n".join(pad + "  " + layout(v, indent + 1) for v in value) + "\n" + pad + "]"
    return flat(value)


def write(folder, name, recipe):
    path = os.path.join(folder, name + ".json")
    with open(path, "w") as f:
        f.write(layout(recipe) + "\n")
    print("wrote", path)


# ---- small geometry helpers ---------------------------------------------------------------------

def r4(p):
    """A point rounded to 0.1 um (design numbers; weights and knots are written exactly)."""
    return [round(c, 4) + 0.0 for c in p]


def clamped_knots(degree, spans):
    return [0.0] * (degree + 1) + [i / spans for i in range(1, spans)] + [1.0] * (degree + 1)


def greville(degree, knots):
    n = len(knots) - degree - 1
    return [sum(knots[i + 1:i + degree + 1]) / degree for i in range(n)]


def ellipse(center, a_axis, b_axis):
    """Exact rational quadratic ellipse (the 9-point circle mapped affinely): center + cos a + sin b."""
    w = math.sqrt(0.5)
    unit = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1), (1, 0)]
    points = [[center[d] + c * a_axis[d] + s * b_axis[d] for d in range(3)] for c, s in unit]
    return {"bspline": {"degree": 2, "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
                        "points": points, "weights": [1, w, 1, w, 1, w, 1, w, 1]}}


def bezier3(p0, p1, p2, p3):
    return {"bspline": {"degree": 3, "knots": [0, 0, 0, 0, 1, 1, 1, 1], "points": [p0, p1, p2, p3]}}


def header(name, description):
    return {"format": "clayform.recipe", "version": 1, "name": name, "description": description,
            "units": "mm"}


# ---- 1. sail -------------------------------------------------------------------------------------

def sail():
    head, tack, clew = [0.0, 0.0, 5000.0], [0.0, 0.0, 0.0], [2000.0, 0.0, 0.0]
    # Leech: clew to head with a roach (outward in the sail plane) and some twist (y).
    d = [head[i] - clew[i] for i in range(3)]
    length = math.hypot(d[0], d[2])
    outward = [-d[2] / length, 0.0, d[0] / length]  # perpendicular to the chord, away from the luff
    if outward[0] < 0:
        outward = [-c for c in outward]
    knots = clamped_knots(3, 8)
    leech = []
    for t in greville(3, knots):
        roach = 380.0 * math.sin(math.pi * t)
        leech.append([clew[i] + t * d[i] + roach * outward[i] for i in range(3)])
        leech[-1][1] = 110.0 * math.sin(math.pi * t)
        leech[-1] = r4(leech[-1])
    # Foot: tack to clew with a shelf (y) and a slight round (z).
    foot_knots = clamped_knots(3, 6)
    foot = [r4([2000.0 * x, 190.0 * math.sin(math.pi * x), -40.0 * math.sin(math.pi * x)])
            for x in greville(3, foot_knots)]
    r = header("sail", (
        "A 5 m sail: filled from its luff, foot and leech (Coons, three curves, the head a collapsed "
        "side), styled by a bound and a target curve (Han, De Amicis & Conti 2007, Fig. 8(a): a sail "
        "shaped by a target curve; exact target mode) and given a billow by a Bezier lattice "
        "(Sederberg & Parry 1986, eq. (2)), composed exactly: the result is one NURBS surface equal "
        "to the pointwise deformation to rounding."))
    r["composition"] = {"mode": "exact"}
    r["curves"] = {
        "luff": {"line": {"from": head, "to": tack}},
        "foot": {"bspline": {"degree": 3, "knots": foot_knots, "points": foot}},
        "leech": {"bspline": {"degree": 3, "knots": knots, "points": leech}},
        # The bound: an ellipse 1400 x 3600 mm beside the sail, projected onto it.
        "draft_bound": ellipse([700, 600, 2300], [700, 0, 0], [0, 0, 1800]),
        # The target: the draft line, up to ~200 mm off the sail at 45 % of its height.
        "draft_line": bezier3([330, 150, 2300], [520, 330, 2420], [840, 330, 2420], [1050, 150, 2300]),
    }
    r["surfaces"] = {
        "flat_sail": {"fill": {"curves": ["luff", "foot", "leech"], "style": "coons"}},
        "sail": {"deform": {"surface": "flat_sail", "deformation": "shape"}},
    }
    # Billow: a (2, 1, 1) Bezier lattice (s chord x, t thickness y, u height z), deepest low in the
    # sail; the luff lies on the face s = 0 whose control points stay, so it stays on the mast.
    # Composed degree 3 x (2 + 1 + 1) = 12.
    moves = []
    for j in (0, 1):  # both thickness layers alike: a pure y shear, volume kept (Jacobian 1)
        moves.append({"index": [1, j, 0], "by": [0, 300, 0]})
        moves.append({"index": [1, j, 1], "by": [0, 120, 0]})
        moves.append({"index": [2, j, 0], "by": [0, 120, 0]})
    r["deformations"] = {"shape": [
        {"kind": "style", "name": "draft", "target": "draft_line", "bound": "draft_bound",
         "mode": "exact", "key_points_per_row": 2, "curve_tolerance": 0.01},
        {"kind": "bezier_lattice", "name": "billow",
         "frame": {"origin": [0, -400, -300], "s": [2600, 0, 0], "t": [0, 1000, 0], "u": [0, 0, 5600]},
         "degrees": [2, 1, 1], "moves": moves},
    ]}
    r["exports"] = {"sail": {"surfaces": ["sail"], "formats": ["step", "iges", "glb"]}}
    return r


# ---- 2. car hood ---------------------------------------------------------------------------------

def hood_height(x, y):
    """The crowned hood of examples/06: 1200 x 800 mm, 80 mm crown, 0.05 slope toward the screen."""
    return 80.0 * (1 - (x / 700.0) ** 2) * (1 - (y / 500.0) ** 2) + 0.05 * x


def car_hood():
    r = header("car_hood", (
        "A car hood about 1200 x 800 mm skinned through five sections, then a crease (character "
        "line) put in by a bound and a target curve (Han, De Amicis & Conti 2007, Figs. 9-10: with a "
        "predefined local region the deformation stays inside the bound). The same stack is run in "
        "the paper's force mode and in the exact target mode: two surfaces from one parent."))
    # Five sections along the car (x), stationed across it (y): u runs along the car.
    knots = clamped_knots(3, 9)
    curves = {}
    stations = [-400.0, -200.0, 0.0, 200.0, 400.0]
    for n, y in enumerate(stations):
        pts = [r4([-600.0 + 1200.0 * g, y, hood_height(-600.0 + 1200.0 * g, y)]) for g in greville(3, knots)]
        curves["section_%d" % n] = {"bspline": {"degree": 3, "knots": knots, "points": pts}}
    # The bound: an ellipse 700 x 500 mm drawn 150 mm above the hood (projected onto it).
    curves["crease_bound"] = ellipse([0, 0, 150], [350, 0, 0], [0, 250, 0])
    # The target: a character line along the car, off the centre, rising ~60 mm above the hood.
    curves["crease"] = bezier3([-180, -60, 70], [-60, -40, 150], [60, -40, 150], [180, -60, 70])
    r["curves"] = curves
    r["surfaces"] = {
        "hood": {"skin": {"sections": ["section_%d" % n for n in range(len(stations))]}},
        "hood_exact": {"deform": {"surface": "hood", "deformation": "crease_exact"}},
        "hood_paper": {"deform": {"surface": "hood", "deformation": "crease_paper"}},
    }
    step = {"kind": "style", "name": "crease", "target": "crease", "bound": "crease_bound"}
    r["deformations"] = {
        "crease_exact": [dict(step, mode="exact")],
        "crease_paper": [dict(step, mode="paper")],
    }
    r["exports"] = {
        "hood_exact": {"surfaces": ["hood_exact"]},
        "hood_paper": {"surfaces": ["hood_paper"]},
    }
    return r


# ---- 3. flat-topped bump -------------------------------------------------------------------------

BUMP_HEIGHT = 40.0
BUMP_PARAMS = [0.35, 0.425, 0.5, 0.575, 0.65]  # x, y = -60, -30, 0, 30, 60 mm


def bump():
    r = header("bump", (
        "A flat-topped bump by direct manipulation (Hsu, Hughes & Kaufman 1992, Fig. 1(b)): a 5 x 5 "
        "grid of points of a 400 x 400 mm sheet is pulled to the same height, 40 mm, and the "
        "least-squares lattice (eq. (5)) puts the control points where a flat top needs them - not "
        "in a plane; the top is flat over the 120 mm square the points span. Cubic B-spline lattice, "
        "border planes locked (C1 with the sheet around), composed exactly."))
    r["surfaces"] = {
        "sheet": {"bspline": {"degrees": [1, 1], "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
                              "points": [[-200, -200, 0], [-200, 200, 0], [200, -200, 0], [200, 200, 0]]}},
        "bump": {"deform": {"surface": "sheet", "deformation": "flat_top"}},
    }
    locked = [[i, j, k] for i in range(9) for j in range(9) for k in range(2)
              if i in (0, 1, 7, 8) or j in (0, 1, 7, 8)]
    moves = [{"surface_point": [u, v], "to": r4([-200 + 400 * u, -200 + 400 * v, BUMP_HEIGHT])}
             for u in BUMP_PARAMS for v in BUMP_PARAMS]
    r["deformations"] = {"flat_top": [{
        "kind": "direct_manipulation", "name": "flat top",
        "lattice": {"kind": "bspline_lattice",
                    "frame": {"origin": [-200, -200, -40], "s": [400, 0, 0], "t": [0, 400, 0],
                              "u": [0, 0, 120]},
                    "degrees": [3, 3, 1], "cells": [6, 6, 1], "knots": "clamped"},
        "moves": moves, "locked": locked}]}
    r["exports"] = {"bump": {"surfaces": ["bump"]}}
    return r


# ---- 4. bottle -----------------------------------------------------------------------------------

BOTTLE_SCALE = [1.0, 1.0, 1.0, 0.4, 1.0, 1.0, 1.0]  # radius factor per lattice plane k (waist at k = 3)


def bottle():
    r = header("bottle", (
        "A Coke-bottle-like body of revolution (exact rational, three revolved profile pieces: base, "
        "body, neck) whose body is pinched at the waist by a Bezier lattice (Sederberg & Parry 1986, "
        "Figs. 13 and 23): the lattice's corners are scaled toward the axis plane by plane, so the "
        "body stays a surface of revolution; the two planes at each end stay (C1 with the base and "
        "the neck, which lie outside the lattice and are not touched). Composed exactly: the rational "
        "surface stays rational."))
    r["curves"] = {
        "base_profile": {"bspline": {"degree": 3, "knots": clamped_knots(3, 3),
                                     "points": [[0, 0, 0], [18, 0, 0], [30, 0, 0], [33, 0, 6],
                                                [33, 0, 30], [33, 0, 60]]}},
        "body_profile": {"line": {"from": [33, 0, 60], "to": [33, 0, 170]}},
        "neck_profile": {"bspline": {"degree": 3, "knots": clamped_knots(3, 3),
                                     "points": [[33, 0, 170], [33, 0, 195], [30, 0, 215], [15, 0, 232],
                                                [13, 0, 245], [13, 0, 262]]}},
    }
    axis = {"point": [0, 0, 0], "direction": [0, 0, 1]}
    r["surfaces"] = {
        "base": {"revolve": {"profile": "base_profile", "axis": axis}},
        "body": {"revolve": {"profile": "body_profile", "axis": axis}},
        "neck": {"revolve": {"profile": "neck_profile", "axis": axis}},
        "waist": {"deform": {"surface": "body", "deformation": "pinch"}},
    }
    n = len(BOTTLE_SCALE) - 1
    moves = []
    for k, f in enumerate(BOTTLE_SCALE):
        if f == 1.0:
            continue
        z = 60.0 + 110.0 * k / n
        for i in (0, 1):
            for j in (0, 1):
                moves.append({"index": [i, j, k], "to": [f * (-40 + 80 * i), f * (-40 + 80 * j), z]})
    r["deformations"] = {"pinch": [{
        "kind": "bezier_lattice", "name": "waist",
        "frame": {"origin": [-40, -40, 60], "s": [80, 0, 0], "t": [0, 80, 0], "u": [0, 0, 110]},
        "degrees": [1, 1, n], "moves": moves}]}
    r["exports"] = {"bottle": {"surfaces": ["base", "waist", "neck"]}}
    return r


# ---- 5. tongue -----------------------------------------------------------------------------------

def tongue_height(x, y):
    return 20.0 + 0.05 * x - 160.0 * (y / 450.0 - 0.5) ** 2 + 15.0 * math.sin(math.pi * x / 600.0)


def tongue():
    r = header("tongue", (
        "A tongue straddling two C1 bicubic patches (Sederberg & Parry 1986, Figs. 17-18): one "
        "B-spline lattice over both patches, only its middle control points moved, the two planes "
        "at every face left in place (C1 with the undeformed space, section 3.1); the same stack "
        "applied to both patches, composed exactly: the deformed patches still meet and stay "
        "tangent-continuous across their shared edge."))
    ys = [150.0 * j for j in range(4)]  # x and y linear in the parameters: low composed degrees
    a = [[r4([100.0 * i, y, tongue_height(100.0 * i, y)]) for y in ys] for i in range(4)]
    b = [[r4([300.0 + 100.0 * i, y, tongue_height(300.0 + 100.0 * i, y)]) for y in ys] for i in range(4)]
    b[0] = [list(p) for p in a[3]]
    # C1 across x = 300: B's second column mirrors A's third about the shared edge.
    b[1] = [[2 * a[3][j][d] - a[2][j][d] for d in range(3)] for j in range(4)]
    bez = [0, 0, 0, 0, 1, 1, 1, 1]

    def patch(rows):
        return {"bspline": {"degrees": [3, 3], "knots_u": bez, "knots_v": bez,
                            "points": [p for row in rows for p in row]}}
    r["surfaces"] = {
        "left": patch(a), "right": patch(b),
        "left_tongue": {"deform": {"surface": "left", "deformation": "tongue"}},
        "right_tongue": {"deform": {"surface": "right", "deformation": "tongue"}},
    }
    moves = []
    for i in (3, 4, 5):
        for j in (2, 3, 4):
            centre = (i, j) == (4, 3)
            for k in (0, 1):
                moves.append({"index": [i, j, k], "by": [30, 0, 150 if centre else 90]})
    r["deformations"] = {"tongue": [{
        "kind": "bspline_lattice", "name": "tongue",
        "frame": {"origin": [0, 0, -60], "s": [600, 0, 0], "t": [0, 450, 0], "u": [0, 0, 160]},
        "degrees": [3, 3, 1], "cells": [6, 4, 1], "knots": "clamped", "moves": moves}]}
    r["exports"] = {"tongue": {"surfaces": ["left_tongue", "right_tongue"]}}
    return r


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(HERE)
    for name, make in [("sail", sail), ("car_hood", car_hood), ("bump", bump), ("bottle", bottle),
                       ("tongue", tongue)]:
        write(folder, name, make())


if __name__ == "__main__":
    main()
