"""Issue #42: the time from a lattice edit to the recomputed shape in FreeCAD, on a 50-face part.

Run in freecadcmd after a Release build (docs/freecad.md § Figures has the last run):
    CLAY_WORKBENCH=freecad/Clayform CLAY_PYTHONPATH=build/python freecadcmd bench/freecad_recompute.py

The part: a 120 x 60 x 20 mm plate with 44 through holes (6 planes + 44 cylinders = 50 faces),
filleted nowhere, read through the workbench's transfer like any Part shape. A Bézier lattice of
degrees (3, 2, 1) around it; each edit moves one top point of the lattice (a different one each
time, up and down by 2 mm) and recomputes the document, as the property editor or a drag's release
does. Printed: the cold first recompute (the source transferred once, then cached), then per edit
the wall time of doc.recompute() and the Deformed feature's own Seconds (transfer back included),
their median, min and max over the edits, and the reference in the same run: FreeCAD recomputing
a Part::Thickness of the same plate (an OCCT operation of a similar kind on the same part).
"""
import os
import statistics
import sys
import time

sys.path.insert(0, os.environ["CLAY_WORKBENCH"])
sys.path.insert(0, os.environ["CLAY_PYTHONPATH"])

import FreeCAD as App  # noqa: E402
import Part  # noqa: E402

from clayform_freecad import features  # noqa: E402

EDITS = int(os.environ.get("CLAY_EDITS", "12"))


def plate():
    shape = Part.makeBox(120, 60, 20)
    holes = []
    for i in range(11):
        for j in range(4):
            holes.append(Part.makeCylinder(3, 20, App.Vector(10 + 10 * i, 12 + 12 * j, 0)))
    return shape.cut(Part.makeCompound(holes))


def main():
    doc = App.newDocument("bench")
    src = doc.addObject("Part::Feature", "Plate")
    src.Shape = plate()
    faces = len(src.Shape.Faces)
    t0 = time.perf_counter()
    lat = features.make_lattice(src, degrees=(3, 2, 1))
    deformed = features.make_deformed(src, lat)
    cold = time.perf_counter() - t0
    assert deformed.isValid(), deformed.State
    lattice = features.lattice_of(lat)
    top = [lattice.index(i, j, 1) for i in range(1, 3) for j in range(0, 3)]
    walls, own, exact = [], [], []
    for e in range(EDITS):
        n = top[e % len(top)]
        dz = 2.0 if (e // len(top)) % 2 == 0 else -2.0
        features.move_point(lat, n, lat.Points[n] + App.Vector(0, 0, dz))
        t = time.perf_counter()
        doc.recompute()
        walls.append(time.perf_counter() - t)
        own.append(deformed.Seconds)
        exact.append(deformed.ExactFaces)
        assert deformed.isValid() and not deformed.Shape.isNull(), deformed.State
    thick = doc.addObject("Part::Thickness", "Thickness")
    top_face = max(range(faces), key=lambda k: src.Shape.Faces[k].CenterOfMass.z)
    thick.Faces = (src, [f"Face{top_face + 1}"])
    thick.Value = -1.0
    refs = []
    for e in range(3):
        thick.Value = -1.0 - 0.1 * e
        t = time.perf_counter()
        doc.recompute()
        refs.append(time.perf_counter() - t)

    def line(name, xs):
        return (f"{name}: median {statistics.median(xs) * 1000:.0f} ms, min {min(xs) * 1000:.0f}, "
                f"max {max(xs) * 1000:.0f} ({len(xs)} runs)")

    print(f"part: {faces} faces; Deformed: {min(exact)}-{max(exact)} faces exact per edit (the last "
          f"edit puts the lattice back at rest: {deformed.UntouchedFaces} untouched), "
          f"{len(deformed.Shape.Faces)} faces out, valid {deformed.Shape.isValid()}")
    print(f"first recompute (lattice + deformation, source transferred): {cold * 1000:.0f} ms")
    print(line("lattice edit -> recomputed shape (doc.recompute wall time)", walls))
    print(line("  of which the Deformed feature (transfer, deform, transfer back)", own))
    print(line("reference: FreeCAD's Part::Thickness of the same plate (OCCT)", refs))
    sys.stdout.flush()
    os._exit(0)


main()
