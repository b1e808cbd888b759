"""Builds examples/models/g2_block.step with FreeCAD's Part module: a 60 x 40 x 20 mm block (in
[0, 60] x [0, 40] x [0, 20], as block.step) whose faces meet in the three ways issue #38's check
tells apart (tests/freecad/edge_continuity.py):

  * G2 (curvature-continuous): the two corners at x = 60 are plan-view blends, each
    line -> cubic transition -> circular arc (R 8) -> cubic transition -> line. A transition is a
    cubic Bezier whose first three control points lie on the line (curvature 0 where it leaves
    the line: P0, P1, P2 collinear) and whose end meets the arc with the arc's tangent and
    curvature 1 / R (k(1) = (2/3) h / a^2 for a cubic, a = |P3 - P2|, h the distance of P2's
    predecessor P1 from the tangent at P3); the other transition is its mirror image across the
    corner's bisector. Extruded along z, the side faces meet along 8 straight vertical G2 edges:
    4 line | transition (k = 0 on both sides) and 4 transition | arc (k = 1/8 on both sides).
  * G1 (tangent, curvature jumps): the two corners at x = 0 are sharp and filleted by OCC's
    rolling-ball fillet (Part fillet, r 5: vertical cylinders), and the top edge of the through
    hole is filleted (r 1.5: a torus between the top plane and the hole's cylinder).
  * creases: the remaining edges at about 90 degrees.
Plus a through hole (r 4 at (15, 20), filleted at its top) and a plain through hole (r 3 at
(42, 20)).

    freecadcmd tests/freecad/make_g2_block.py [OUT.step] [no_hole_fillet]
    (default examples/models/g2_block.step in this script's repository; no_hole_fillet: a variant
    without the torus)
"""

import importlib
import math
import os
import sys


def _import_part():
    # freecadcmd has FreeCAD and Part on its path; python3 finds them in FreeCAD's lib folder.
    try:
        importlib.import_module("Part")
    except ImportError:
        sys.path.append(os.environ.get("FREECAD_LIB", "/usr/lib/freecad-python3/lib"))
    freecad = importlib.import_module("FreeCAD")
    return freecad, importlib.import_module("Part")


LENGTH, WIDTH, HEIGHT = 60.0, 40.0, 20.0
R = 8.0                     # the corner arcs' radius at x = 60
PHI = math.radians(20)      # the angle each transition turns through
LEG0, LEG = 2.5, 2.5        # |P1 - P0| and |P3 - P2| of the transition


def transition_points():
    """The cubic transition leaving the line y = 0 at the origin heading +x, as 2D points
    P0..P3, and the arc's centre: curvature 0 at P0, 1 / R and tangent angle PHI at P3."""
    # P1, P2 on the x axis (k(0) = 0); P3 = P2 + LEG (cos PHI, sin PHI) (the tangent at the end);
    # k(1) = (2/3) * dist(P1, tangent line at P3) / LEG^2 = 1/R with dist = (x2 - x1) sin PHI.
    x1 = LEG0
    x2 = x1 + 1.5 * LEG * LEG / (R * math.sin(PHI))
    p = [(0.0, 0.0), (x1, 0.0), (x2, 0.0),
         (x2 + LEG * math.cos(PHI), LEG * math.sin(PHI))]
    centre = (p[3][0] - R * math.sin(PHI), p[3][1] + R * math.cos(PHI))
    return p, centre


def bezier_curvature(p, s):
    """Signed curvature of a planar cubic Bezier at s (for the printed check)."""
    def d1(s):
        return [3 * ((1 - s) ** 2 * (p[1][i] - p[0][i]) + 2 * (1 - s) * s * (p[2][i] - p[1][i]) +
                     s * s * (p[3][i] - p[2][i])) for i in (0, 1)]

    def d2(s):
        return [6 * ((1 - s) * (p[2][i] - 2 * p[1][i] + p[0][i]) +
                     s * (p[3][i] - 2 * p[2][i] + p[1][i])) for i in (0, 1)]
    a, b = d1(s), d2(s)
    return (a[0] * b[1] - a[1] * b[0]) / (a[0] ** 2 + a[1] ** 2) ** 1.5


def main():
    FreeCAD, Part = _import_part()
    V = FreeCAD.Vector
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, "..", "..", "examples", "models", "g2_block.step")
    hole_fillet = True
    for i, a in enumerate(sys.argv):
        if os.path.basename(a) == "make_g2_block.py":
            for w in sys.argv[i + 1:]:
                if w == "no_hole_fillet":  # a variant without the torus
                    hole_fillet = False
                else:
                    out = w
    out = os.path.abspath(out)

    p, c = transition_points()
    inset = c[0] + c[1]  # the corner's bisector through c meets y = 0 at x = inset
    ks = [bezier_curvature(p, s / 10) for s in range(11)]
    print("transition: control points %s, arc centre %s, inset %.4f mm; curvature from %.3g to "
          "%.6g (1/R = %.6g), monotone: %s" %
          ([(round(x, 4), round(y, 4)) for x, y in p], (round(c[0], 4), round(c[1], 4)), inset,
           ks[0], ks[-1], 1 / R, all(b >= a for a, b in zip(ks, ks[1:]))))

    def corner(vertex, heading):
        """The blended corner at `vertex` entered heading `heading` (unit 2D, turning left by
        90 degrees): edges transition, arc, transition; returns (edges, start, end)."""
        hx, hy = heading
        nx, ny = -hy, hx  # left normal

        def place(q):  # local (along, left) relative to the corner's entry point
            x0 = vertex[0] - inset * hx
            y0 = vertex[1] - inset * hy
            return V(x0 + q[0] * hx + q[1] * nx, y0 + q[0] * hy + q[1] * ny, 0)

        def reflect(q):
            dx, dy = q[0] - c[0], q[1] - c[1]
            dot = (-dx + dy) / math.sqrt(2)
            rx = 2 * dot * (-1 / math.sqrt(2)) - dx
            ry = 2 * dot * (1 / math.sqrt(2)) - dy
            return (c[0] + rx, c[1] + ry)

        t1 = Part.BezierCurve()
        t1.setPoles([place(q) for q in p])
        t2 = Part.BezierCurve()
        t2.setPoles([place(reflect(q)) for q in reversed(p)])
        # the arc from t1's end to t2's start, through its middle (on the bisector)
        mid_local = (c[0] + R * math.sqrt(0.5), c[1] - R * math.sqrt(0.5))
        arc = Part.Arc(place(p[3]), place(mid_local), place(reflect(p[3])))
        return ([t1.toShape(), arc.toShape(), t2.toShape()], place(p[0]),
                place(reflect(p[0])))

    br, br_a, br_b = corner((LENGTH, 0.0), (1.0, 0.0))    # bottom right: +x -> +y
    tr, tr_a, tr_b = corner((LENGTH, WIDTH), (0.0, 1.0))  # top right: +y -> -x
    edges = [Part.LineSegment(V(0, 0, 0), br_a).toShape()] + br + \
            [Part.LineSegment(br_b, tr_a).toShape()] + tr + \
            [Part.LineSegment(tr_b, V(0, WIDTH, 0)).toShape(),
             Part.LineSegment(V(0, WIDTH, 0), V(0, 0, 0)).toShape()]
    wire = Part.Wire(edges)
    assert wire.isClosed(), "the outline is not closed"
    solid = Part.Face(wire).extrude(V(0, 0, HEIGHT))

    # G1: the sharp corners at x = 0, filleted (vertical edges through (0, 0) and (0, 40))
    sharp = [e for e in solid.Edges
             if abs(e.BoundBox.XMax) < 1e-9 and e.BoundBox.ZLength > HEIGHT - 1e-9]
    assert len(sharp) == 2, "expected 2 sharp vertical edges, got %d" % len(sharp)
    solid = solid.makeFillet(5.0, sharp)

    # holes: r 4 at (15, 20) with its top edge filleted (a torus), r 3 at (42, 20) plain
    hole1 = Part.makeCylinder(4.0, HEIGHT + 2, V(15, 20, -1), V(0, 0, 1))
    hole2 = Part.makeCylinder(3.0, HEIGHT + 2, V(42, 20, -1), V(0, 0, 1))
    solid = solid.cut(hole1).cut(hole2)
    solid = Part.Solid(solid.Shells[0]) if solid.ShapeType != "Solid" and solid.Shells else solid
    top_circle = [e for e in solid.Edges
                  if abs(e.BoundBox.ZMin - HEIGHT) < 1e-9 and abs(e.BoundBox.ZMax - HEIGHT) < 1e-9
                  and abs(e.BoundBox.Center.x - 15) < 1e-6 and abs(e.BoundBox.Center.y - 20) < 1e-6
                  and e.BoundBox.XLength < 8.0 + 1e-6]
    assert len(top_circle) >= 1, "the hole's top edge was not found"
    if hole_fillet:
        solid = solid.makeFillet(1.5, top_circle)
    if solid.ShapeType == "Compound" and len(solid.Solids) == 1:
        solid = solid.Solids[0]

    print("g2_block: %s, %d solid(s), %d faces, %d edges, volume %.6f mm3, box %s" %
          ("valid" if solid.isValid() else "NOT VALID", len(solid.Solids), len(solid.Faces),
           len(solid.Edges), solid.Volume, solid.BoundBox))
    for i, f in enumerate(solid.Faces):
        print("  face %2d: %s" % (i, f.Surface.TypeId))
    os.makedirs(os.path.dirname(out), exist_ok=True)
    solid.exportStep(out)
    print("wrote", out)
    return 0 if solid.isValid() else 1


if __name__ == "__main__" or os.path.basename(sys.argv[0] if sys.argv else "") == \
        "make_g2_block.py":
    sys.exit(main())
