"""The workbench's parametric features (issue #42): Lattice, Deformed and Style.

Each is a ``Part::FeaturePython`` whose proxy computes its ``Shape`` with Clayform. They work in
``freecadcmd`` (no GUI): the view providers, draggers and commands live in ``gui.py``.

- **Lattice** (``make_lattice``): a Bézier lattice (Sederberg–Parry) or, with more than one cell
  along an axis, a B-spline lattice (Hsu–Hughes–Kaufman) around a shape or some of its faces. Its
  ``Points`` are the design: editable in the property editor, dragged in the 3D view. Its Shape is
  the control net: ``Vertex{n+1}`` is point ``n`` (``lattice.index(i, j, k)`` order).
  ``Continuity`` holds the layers next to the lattice's faces where they are (C0: the boundary
  layer; C1: two layers; C2: three), so a deformed selection of faces meets the rest of the part
  with that continuity across the lattice's faces (the displacement and its first r derivatives
  across a face vanish when the r + 1 layers next to it stay: the Bernstein / B-spline basis);
  moving a held point is refused, naming it.
- **Deformed** (``make_deformed``): a shape deformed by a lattice feature, or by Barr's taper,
  twist or bend (Güdükbay–Özgüç §3.1) along one axis of its bounding box. Exact where the
  composition is (a Bézier lattice, a polynomial taper); otherwise each face refitted within
  ``ToleranceMm`` with a certified bound; ``Profile`` writes for a receiver (docs/brep.md). Its
  report properties: exact and refitted faces, the certified bound, the volume before and after,
  fold-free.
- **Style** (``make_style``): a B-spline face styled by a target curve inside a bound curve
  (Han–De Amicis–Conti), the curves taken from sketches or edges of the document.
"""
from __future__ import annotations

import math
import time
from typing import List, Sequence, Tuple

import FreeCAD as App
import numpy as np
import Part

import clayform as cf

from . import transfer

CONTINUITIES = ["Free", "C0", "C1", "C2"]
KINDS = ["Lattice", "Taper", "Twist", "Bend"]
AXES = ["X", "Y", "Z"]
PROFILES = ["none", "exact", "opencascade", "catia", "class_a", "bicubic"]
STYLE_MODES = ["exact", "paper"]


def _vec(v) -> Tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _add(obj, kind: str, name: str, group: str, doc: str, value=None, read_only: bool = False,
         hidden: bool = False):
    if name not in obj.PropertiesList:
        obj.addProperty(kind, name, group, doc)
        if value is not None:
            setattr(obj, name, value)
    if read_only:
        obj.setEditorMode(name, 1)
    if hidden:
        obj.setEditorMode(name, 2)


class _Proxy:
    """What every feature's proxy shares: its properties set up again when a document is
    reopened (FreeCAD does not call __init__ then), and nothing of its own saved (the state is in
    the properties; FreeCAD 0.20 saves __getstate__, 0.21 and later dumps)."""

    def onDocumentRestored(self, obj):  # noqa: N802 (FreeCAD's name)
        self.setup(obj)

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None

    def dumps(self):
        return None

    def loads(self, state):
        return None


# ---- the source shape, cached per feature ------------------------------------------------------


class _ModelCache:
    """The Clayform model of a source shape and its read's report, read again only when the
    shape's BRep text or its attributes change (a lattice edit recomputes the deformation, not
    the transfer)."""

    def __init__(self):
        self.key = None
        self.model = None
        self.report = None

    def model_of(self, shape, attributes: "transfer.Attributes"):
        text = shape.exportBrepToString()
        key = (hash(text), len(text), repr(attributes))
        if key != self.key:
            self.model, self.report = transfer.model_from_shape(shape, attributes)
            self.key = key
        return self.model, self.report


def _source(link) -> Tuple[object, List[int], object]:
    """(shape, face indices (0-based; empty: all), the linked object) of a PropertyLinkSub value."""
    if link is None:
        raise cf.InvalidArgumentError("no source: link the shape to deform (Source)")
    obj, subs = link
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull():
        raise cf.InvalidArgumentError(
            f"the source '{obj.Label}' has no shape; link an object with a solid or faces")
    subs = [s for s in (subs or []) if s]
    return shape, transfer.face_indices(shape, subs) if subs else [], obj


def _face_names(obj) -> List[str]:
    """A source object's face names, when it carries them (a Deformed feature's FaceNames)."""
    names = list(getattr(obj, "FaceNames", []) or [])
    shape = getattr(obj, "Shape", None)
    return names if shape is not None and len(names) == len(shape.Faces) else []


def source_attributes(obj) -> "transfer.Attributes":
    """What a source object says beside its shape: its label, its faces' names (FaceNames) and,
    with the GUI, its colour and its faces' colours (ShapeColor, DiffuseColor when it has one
    entry per face). freecadcmd has no colours: none are sent."""
    a = transfer.Attributes(name=obj.Label, face_names=_face_names(obj))
    view = getattr(obj, "ViewObject", None) if App.GuiUp else None
    if view is not None and hasattr(view, "ShapeColor"):
        a.colour = tuple(view.ShapeColor[:3])
        diffuse = list(getattr(view, "DiffuseColor", []) or [])
        if len(diffuse) == len(obj.Shape.Faces) and len(diffuse) > 1:
            a.face_colours = [tuple(c[:3]) for c in diffuse]
    return a


# ---- Lattice -----------------------------------------------------------------------------------


def lattice_of(obj):
    """The Clayform lattice a Lattice feature describes (its frame, degrees, cells and Points)."""
    lattice = _rest_lattice(obj)
    if len(obj.Points) != len(lattice.points):
        raise cf.InvalidArgumentError(
            f"{obj.Label}: Points holds {len(obj.Points)} points but its degrees and cells make "
            f"{len(lattice.points)}; recompute the lattice (or set Refit)")
    lattice.points = np.array([[p.x, p.y, p.z] for p in obj.Points], dtype=np.float64)
    return lattice


def held_points(obj) -> List[bool]:
    """Per point: held where it is by Continuity (the layers next to the lattice's faces)."""
    layers = CONTINUITIES.index(obj.Continuity)  # Free 0, C0 1, C1 2, C2 3
    lattice = _rest_lattice(obj)
    n = lattice.counts
    held = [False] * (n[0] * n[1] * n[2])
    for i in range(n[0]):
        for j in range(n[1]):
            for k in range(n[2]):
                edge = min(i, n[0] - 1 - i, j, n[1] - 1 - j, k, n[2] - 1 - k)
                held[lattice.index(i, j, k)] = edge < layers
    return held


def _rest_lattice(obj):
    """The undisplaced lattice of the feature's frame, degrees and cells (Bézier when every axis
    has one cell)."""
    o, s, t, u = (_vec(getattr(obj, n)) for n in ("Origin", "AxisS", "AxisT", "AxisU"))
    cells = (obj.CellsS, obj.CellsT, obj.CellsU)
    degrees = (obj.DegreeS, obj.DegreeT, obj.DegreeU)
    if cells == (1, 1, 1):
        return cf.BezierLattice(o, s, t, u, degrees)
    return cf.BSplineLattice(o, s, t, u, degrees, cells)


def rest_points(obj) -> List[Tuple[float, float, float]]:
    """The lattice's undisplaced points (its frame's regular grid)."""
    return [tuple(p) for p in _rest_lattice(obj).points]


class LatticeFeature(_Proxy):
    """Proxy of a Lattice feature."""

    def __init__(self, obj, source=None, faces: Sequence[str] = ()):
        obj.Proxy = self
        self.setup(obj)
        if source is not None:
            obj.Source = (source, list(faces))
            # Around faces: C2 across the lattice's faces and a margin of 1e-6 (the lattice must
            # hold the points strictly inside), so that the faces' edges on their box stay: with
            # three layers held the map moves a point at s from a lattice face by about
            # 20 s^3 of a point's move (Bernstein), and the box of a face's control points
            # overhangs its edges by about s = 1e-3 (a trimmed plane): 2e-8, below an edge's
            # tolerance.
            obj.Continuity = "C2" if faces else "Free"
            if faces:
                obj.Margin = 1e-6

    def setup(self, obj):
        _add(obj, "App::PropertyLinkSub", "Source", "Lattice",
             "The shape (or some of its faces) the lattice is fitted around")
        for axis, doc in (("S", "x"), ("T", "y"), ("U", "z")):
            _add(obj, "App::PropertyIntegerConstraint", "Degree" + axis, "Lattice",
                 f"Degree of the lattice along its {doc} axis (1..6)", (2, 1, 6, 1))
            _add(obj, "App::PropertyIntegerConstraint", "Cells" + axis, "Lattice",
                 f"Cells along the {doc} axis: 1 everywhere is a Bézier lattice, more a B-spline one",
                 (1, 1, 8, 1))
        _add(obj, "App::PropertyEnumeration", "Continuity", "Lattice",
             "Continuity kept across the lattice's faces: the layers held next to them "
             "(C0 one, C1 two, C2 three; Free none)", CONTINUITIES)
        _add(obj, "App::PropertyFloat", "Margin", "Lattice",
             "Room around the shape's bounding box, as a fraction of its extent", 0.05)
        _add(obj, "App::PropertyVectorList", "Points", "Lattice",
             "The control points (mm), lattice.index(i, j, k) order; edit or drag them")
        for name, doc in (("Origin", "The frame's corner"), ("AxisS", "The frame's x edge"),
                          ("AxisT", "The frame's y edge"), ("AxisU", "The frame's z edge")):
            _add(obj, "App::PropertyVector", name, "Frame", doc + " (mm); set from the source")
        for name in ("LockX", "LockY", "LockZ"):
            _add(obj, "App::PropertyBool", name, "Drag",
                 f"Dragging a point leaves its {name[-1].lower()} where it is", False)
        _add(obj, "App::PropertyBool", "FoldFree", "Report",
             "The Jacobian's Bernstein bounds prove the lattice does not fold", read_only=True)
        _add(obj, "App::PropertyFloat", "VolumeRatioMin", "Report",
             "Smallest Jacobian bound (local volume ratio)", read_only=True)
        _add(obj, "App::PropertyFloat", "VolumeRatioMax", "Report",
             "Largest Jacobian bound (local volume ratio)", read_only=True)
        _add(obj, "App::PropertyInteger", "MovedPoints", "Report",
             "Points away from their rest positions", read_only=True)
        _add(obj, "App::PropertyBool", "Refit", "Lattice",
             "Set to refit the frame around the source and put every point back at rest", False)
        _add(obj, "App::PropertyString", "FrameKey", "Frame",
             "The degrees, cells, margin, faces and source box the frame was fitted for",
             hidden=True)
        self.cache = _ModelCache()


    def fit_frame(self, obj):
        """Sets the frame around the source (Margin) and the Points to rest."""
        shape, faces, src = _source(obj.Source)
        if not obj.Margin > 0:
            raise cf.InvalidArgumentError(
                f"{obj.Label}: Margin {obj.Margin} must be > 0 (the shape's points must lie "
                f"strictly inside the lattice); 1e-6 keeps faces' edges on their box")
        model, report = self.cache.model_of(shape, source_attributes(src))
        degrees = (obj.DegreeS, obj.DegreeT, obj.DegreeU)
        cells = (obj.CellsS, obj.CellsT, obj.CellsU)
        lattice = cf.lattice_around(model, degrees, None if cells == (1, 1, 1) else cells,
                                    obj.Margin, transfer.model_faces(report, faces) if faces else None)
        o, s, t, u = (App.Vector(*x) for x in lattice.frame)
        # Faces that are flat (a top face) give an axis as thin as the margin: a lattice a
        # quarter as thick as it is long, centred on them, so that its points can be moved.
        longest = max(s.Length, t.Length, u.Length)
        axes = []
        for a, unit in zip((s, t, u), (App.Vector(1, 0, 0), App.Vector(0, 1, 0), App.Vector(0, 0, 1))):
            if a.Length < 0.1 * longest:
                grown = (App.Vector(a).normalize() if a.Length > 0 else unit) * (0.25 * longest)
                o = o - (grown - a) * 0.5
                a = grown
            axes.append(a)
        obj.Origin, (obj.AxisS, obj.AxisT, obj.AxisU) = o, axes
        obj.Points = [App.Vector(*p) for p in rest_points(obj)]

    def execute(self, obj):
        if not hasattr(self, "cache"):
            self.setup(obj)
        shape, faces, _ = _source(obj.Source)
        box = shape.BoundBox
        key = repr(((obj.DegreeS, obj.DegreeT, obj.DegreeU), (obj.CellsS, obj.CellsT, obj.CellsU),
                    obj.Margin, faces))
        source_box = repr(tuple(round(x, 9) for x in (box.XMin, box.YMin, box.ZMin, box.XMax,
                                                      box.YMax, box.ZMax)))
        fitted, fitted_box = (obj.FrameKey.split("@", 1) + [""])[:2] if obj.FrameKey else ("", "")
        if obj.Refit or not fitted or obj.AxisS.Length == 0:
            self.fit_frame(obj)
        elif fitted != key:
            # New degrees, cells, margin or faces make a new frame and put every point at rest:
            # moved points would be lost, so that waits for Refit.
            if obj.MovedPoints > 0:
                raise cf.InvalidArgumentError(
                    f"{obj.Label}: {obj.MovedPoints} points are moved, and new degrees, cells, "
                    f"margin or faces refit the frame with every point at rest; set Refit to "
                    f"True to do that, or undo the change")
            self.fit_frame(obj)
        elif fitted_box != source_box and obj.MovedPoints == 0:
            self.fit_frame(obj)  # the source changed and nothing was moved: follow it
        elif len(obj.Points) != len(rest_points(obj)):
            raise cf.InvalidArgumentError(
                f"{obj.Label}: Points holds {len(obj.Points)} points but the lattice has "
                f"{len(rest_points(obj))}; give every point, or set Refit to True")
        obj.FrameKey = key + "@" + source_box
        if obj.Refit:
            obj.Refit = False
        rest = rest_points(obj)
        lattice = lattice_of(obj)
        held = held_points(obj)
        moved = 0
        for n, (p, r) in enumerate(zip(obj.Points, rest)):
            away = (p - App.Vector(*r)).Length > 1e-9 * max(obj.AxisS.Length, 1.0)
            moved += away
            if away and held[n]:
                i, j, k = _ijk(lattice, n)
                raise cf.InvalidArgumentError(
                    f"{obj.Label}: point {n} (i, j, k) = ({i}, {j}, {k}) is held by Continuity "
                    f"{obj.Continuity} (a layer next to the lattice's faces); move an inner "
                    f"point, or set Continuity to a lower order")
        coefficients, _ = lattice.jacobian_constraints()
        obj.FoldFree = bool(min(coefficients) > 0)
        obj.VolumeRatioMin = float(min(coefficients))
        obj.VolumeRatioMax = float(max(coefficients))
        obj.MovedPoints = int(moved)
        obj.Shape = net_shape(lattice)


def _ijk(lattice, n: int) -> Tuple[int, int, int]:
    c = lattice.counts
    for i in range(c[0]):
        for j in range(c[1]):
            for k in range(c[2]):
                if lattice.index(i, j, k) == n:
                    return i, j, k
    raise IndexError(n)


def net_shape(lattice):
    """The control net: a vertex per point (Vertex{n+1} is point n), then the lines between
    neighbours along each axis."""
    pts = [App.Vector(*p) for p in lattice.points]
    c = lattice.counts
    shapes = [Part.Vertex(p) for p in pts]
    for i in range(c[0]):
        for j in range(c[1]):
            for k in range(c[2]):
                a = pts[lattice.index(i, j, k)]
                for di, dj, dk in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
                    if i + di < c[0] and j + dj < c[1] and k + dk < c[2]:
                        b = pts[lattice.index(i + di, j + dj, k + dk)]
                        if (b - a).Length > 0:
                            shapes.append(Part.LineSegment(a, b).toShape())
    return Part.Compound(shapes)


def make_lattice(source, faces: Sequence[str] = (), degrees=None, cells=None,
                 name: str = "Lattice"):
    """A Lattice feature around `source` (a document object with a shape), or around its
    `faces` ("Face3", ...), recomputed. Defaults: a Bézier lattice of degrees (2, 2, 2) around a
    shape; around faces (C2 held: three layers at each side) a B-spline lattice of degrees
    (3, 3, 3) and (4, 4, 4) cells, whose centre point is free."""
    if degrees is None:
        degrees = (3, 3, 3) if faces else (2, 2, 2)
    if cells is None:
        cells = (4, 4, 4) if faces else (1, 1, 1)
    doc = source.Document
    obj = doc.addObject("Part::FeaturePython", name)
    LatticeFeature(obj, source, faces)
    obj.DegreeS, obj.DegreeT, obj.DegreeU = degrees
    obj.CellsS, obj.CellsT, obj.CellsU = cells
    _attach_view(obj, "lattice")
    doc.recompute()
    return obj


def move_point(obj, n: int, to) -> None:
    """Moves point `n` of a Lattice feature to `to` (its locked axes left where they are)."""
    points = list(obj.Points)
    if not 0 <= n < len(points):
        raise cf.InvalidArgumentError(
            f"{obj.Label} has no point {n}; its points are 0..{len(points) - 1}")
    if held_points(obj)[n]:
        i, j, k = _ijk(_rest_lattice(obj), n)
        raise cf.InvalidArgumentError(
            f"{obj.Label}: point {n} (i, j, k) = ({i}, {j}, {k}) is held by Continuity "
            f"{obj.Continuity} (a layer next to the lattice's faces); move an inner point, or "
            f"set Continuity to a lower order")
    p = points[n]
    x, y, z = _vec(to)
    points[n] = App.Vector(p.x if obj.LockX else x, p.y if obj.LockY else y, p.z if obj.LockZ else z)
    obj.Points = points


# ---- Deformed ----------------------------------------------------------------------------------


def _barr_step(kind: str, axis: str, amount: float, box) -> dict:
    """A deformation-stack step for Barr's taper, twist or bend along `axis` of `box` (a FreeCAD
    BoundBox): the region is the box's length along the axis. Taper: `amount` is the scale at the
    far end (1: none), r(z) = 1 + (amount − 1) z / L. Twist: the turn over the length (degrees),
    θ(z) = amount z / L. Bend: the angle the length turns through (degrees), rate = amount / L."""
    a = AXES.index(axis)
    lo = (box.XMin, box.YMin, box.ZMin)
    hi = (box.XMax, box.YMax, box.ZMax)
    length = hi[a] - lo[a]
    if not length > 0:
        raise cf.InvalidArgumentError(
            f"the shape has no extent along {axis}; choose another Axis")
    direction = [0.0, 0.0, 0.0]
    direction[a] = 1.0
    across = [0.0, 0.0, 0.0]
    across[(a + 2) % 3] = 1.0  # X -> Z, Y -> X, Z -> Y
    centre = [(lo[i] + hi[i]) / 2 for i in range(3)]
    if kind in ("Taper", "Twist"):
        origin = list(centre)
        origin[a] = lo[a]
        frame = {"origin": origin, "axis": direction, "reference": across}
        if kind == "Taper":
            if not amount > 0:
                raise cf.InvalidArgumentError(
                    f"Taper's Amount {amount} is the scale at the far end; give a number > 0")
            return {"kind": "taper", "frame": frame, "profile": [1.0, (amount - 1.0) / length]}
        return {"kind": "twist", "frame": frame, "angle": [0.0, math.radians(amount) / length]}
    # The bend's region reaches 5 % of the length beyond the shape at each end: the map is only C0
    # (in its derivatives) at the region's ends, and refit cells that reach such a plane are
    # certified by a first-derivative bound, which a box bent 60 degrees at 0.001 mm does not
    # meet within the refit's limits (measured: 0.0067 mm with the ends 0.05 % away). The shape
    # itself turns through `amount`.
    frame = {"origin": centre, "axis": direction, "reference": across}
    half = 0.55 * length
    return {"kind": "bend", "frame": frame, "y_min": -half, "y_max": half,
            "center": 0.0, "rate": math.radians(amount) / length}


def lattice_step(lattice_obj) -> dict:
    """A Lattice feature as a deformation-stack (and recipe) step, every point given."""
    o, s, t, u = (list(_vec(getattr(lattice_obj, n))) for n in ("Origin", "AxisS", "AxisT", "AxisU"))
    frame = {"origin": o, "s": s, "t": t, "u": u}
    degrees = [lattice_obj.DegreeS, lattice_obj.DegreeT, lattice_obj.DegreeU]
    cells = [lattice_obj.CellsS, lattice_obj.CellsT, lattice_obj.CellsU]
    points = [list(p) for p in lattice_of(lattice_obj).points]
    if cells == [1, 1, 1]:
        return {"kind": "bezier_lattice", "name": lattice_obj.Label, "frame": frame,
                "degrees": degrees, "points": points}
    return {"kind": "bspline_lattice", "name": lattice_obj.Label, "frame": frame,
            "degrees": degrees, "cells": cells, "knots": "clamped", "points": points}


def deformation_step(obj, shape) -> dict:
    """The step a Deformed feature applies, as a recipe step."""
    if obj.Kind == "Lattice":
        return lattice_step(_lattice_feature(obj))
    return _barr_step(obj.Kind, obj.Axis, obj.Amount, shape.BoundBox)


def _lattice_feature(obj):
    if obj.Lattice is None:
        raise cf.InvalidArgumentError(
            f"{obj.Label}: Kind is Lattice but no Lattice is linked; link a Lattice feature "
            f"or choose Taper, Twist or Bend")
    return obj.Lattice


def deformation_of(obj, shape):
    """What a Deformed feature deforms by: the linked lattice itself, or a one-step
    DeformationStack of Barr's taper, twist or bend."""
    if obj.Kind == "Lattice":
        return lattice_of(_lattice_feature(obj))
    step = _barr_step(obj.Kind, obj.Axis, obj.Amount, shape.BoundBox)
    return cf.DeformationStack.from_json(
        _json({"format": "clayform.deformation-stack", "version": 1, "steps": [step]}))


class DeformedFeature(_Proxy):
    """Proxy of a Deformed feature."""

    def __init__(self, obj, source=None, faces: Sequence[str] = (), lattice=None):
        obj.Proxy = self
        self.setup(obj)
        if source is not None:
            obj.Source = (source, list(faces))
        if lattice is not None:
            obj.Lattice = lattice

    def setup(self, obj):
        _add(obj, "App::PropertyLinkSub", "Source", "Deformation",
             "The shape to deform, or some of its faces (the others stay)")
        _add(obj, "App::PropertyLink", "Lattice", "Deformation", "The Lattice feature (Kind Lattice)")
        _add(obj, "App::PropertyEnumeration", "Kind", "Deformation",
             "Lattice, or Barr's taper, twist or bend along Axis", KINDS)
        _add(obj, "App::PropertyEnumeration", "Axis", "Deformation",
             "Taper, twist, bend: the axis of the shape's bounding box they run along", AXES)
        _add(obj, "App::PropertyFloat", "Amount", "Deformation",
             "Taper: scale at the far end; twist: turn over the length (deg); bend: angle (deg)", 0.0)
        _add(obj, "App::PropertyEnumeration", "Profile", "Deformation",
             "The receiver the faces are written for (none: exact, whatever the degree)", PROFILES)
        _add(obj, "App::PropertyFloat", "ToleranceMm", "Deformation",
             "Faces that cannot be exact (B-spline lattice knot planes, twist, bend) are refitted "
             "within this (mm), certified", 0.001)
        _add(obj, "App::PropertyBool", "AllowFold", "Deformation",
             "Deform by a lattice its Jacobian bounds do not prove fold-free", False)
        _add(obj, "App::PropertyStringList", "FaceNames", "Deformation",
             "The faces' names (Clayform keeps them; FreeCAD 0.20 has none)", hidden=True)
        for name, kind, doc in (
                ("ExactFaces", "App::PropertyInteger", "Faces composed exactly"),
                ("RefitFaces", "App::PropertyInteger", "Faces refitted within the tolerance"),
                ("UntouchedFaces", "App::PropertyInteger", "Faces left as they were"),
                ("CertifiedBoundMm", "App::PropertyFloat",
                 "Largest certified distance of a refitted face from the exact map (mm)"),
                ("MaxEdgeGapMm", "App::PropertyFloat", "Largest gap along a shared edge (mm)"),
                ("VolumeBefore", "App::PropertyFloat", "Volume of the source (mm^3), exact"),
                ("VolumeAfter", "App::PropertyFloat", "Volume of the result (mm^3), exact"),
                ("FoldFree", "App::PropertyBool", "The deformation is proven fold-free"),
                ("Seconds", "App::PropertyFloat", "Time of the last recompute (s)"),
                ("Message", "App::PropertyString", "Clayform's report in a line")):
            _add(obj, kind, name, "Report", doc, read_only=True)
        self.cache = _ModelCache()


    def execute(self, obj):
        if not hasattr(self, "cache"):
            self.setup(obj)
        t0 = time.perf_counter()
        shape, faces, src = _source(obj.Source)
        model, read = self.cache.model_of(shape, source_attributes(src))
        result, report = model.deform(
            deformation_of(obj, shape), faces=transfer.model_faces(read, faces) if faces else None, allow_fold=obj.AllowFold,
            profile="" if obj.Profile == "none" else obj.Profile, tolerance_mm=obj.ToleranceMm)
        out, attributes = transfer.shape_from_model(result)
        obj.Shape = out
        obj.FaceNames = attributes.face_names if attributes.face_names else []
        obj.ExactFaces = int(report["faces_exact"])
        obj.RefitFaces = int(report["faces_refit"])
        obj.UntouchedFaces = int(report["faces_untouched"])
        obj.CertifiedBoundMm = float(report["max_certified_bound_mm"])
        obj.MaxEdgeGapMm = float(report["max_edge_gap_mm"])
        obj.VolumeBefore = float(report["volume_before_mm3"])
        obj.VolumeAfter = float(report["volume_after_mm3"])
        obj.FoldFree = bool(report["fold_free"])
        obj.Message = str(report.get("message", ""))
        obj.Seconds = time.perf_counter() - t0
        _apply_colours(obj, attributes)


def _json(x) -> str:
    import json

    return json.dumps(x)


def _apply_colours(obj, attributes) -> None:
    """Face colours onto the view (GUI only: freecadcmd has no ViewObject)."""
    view = getattr(obj, "ViewObject", None)
    if view is None or not attributes.face_colours:
        return
    default = tuple(view.ShapeColor[:3])
    view.DiffuseColor = [tuple(c) if c is not None else default for c in attributes.face_colours]


def make_deformed(source, lattice=None, faces: Sequence[str] = (), kind: str = "Lattice",
                  axis: str = "Z", amount: float = 0.0, name: str = "Deformed"):
    """A Deformed feature: `source` (or its `faces`) deformed by the Lattice feature `lattice`,
    or by Barr's taper, twist or bend (`kind`, `axis`, `amount`), recomputed."""
    doc = source.Document
    obj = doc.addObject("Part::FeaturePython", name)
    DeformedFeature(obj, source, faces, lattice)
    obj.Kind = kind
    obj.Axis = axis
    obj.Amount = amount
    _attach_view(obj, "deformed")
    if App.GuiUp:
        source.ViewObject.Visibility = False
    doc.recompute()
    return obj


# ---- Style -------------------------------------------------------------------------------------


def surface_of_face(face):
    """A face's surface as a Clayform Surface (a B-spline face; others are refused, named)."""
    s = face.Surface
    if not isinstance(s, Part.BSplineSurface):
        raise cf.InvalidArgumentError(
            f"the face's surface is a {type(s).__name__}, not a B-spline; style a B-spline face "
            f"(Part > Convert to NURBS, or a face Clayform has deformed)")
    knots_u = [k for k, m in zip(s.getUKnots(), s.getUMultiplicities()) for _ in range(m)]
    knots_v = [k for k, m in zip(s.getVKnots(), s.getVMultiplicities()) for _ in range(m)]
    if s.isUPeriodic() or s.isVPeriodic():
        raise cf.InvalidArgumentError("a periodic B-spline face cannot be styled yet; "
                                      "make it non-periodic (Part > Convert to NURBS) first")
    poles = s.getPoles()
    weights = s.getWeights()
    nu, nv = len(poles), len(poles[0])
    points = [list(poles[i][j]) for i in range(nu) for j in range(nv)]
    w = [weights[i][j] for i in range(nu) for j in range(nv)]
    rational = any(abs(x - 1.0) > 0 for x in w)
    return cf.Surface((s.UDegree, s.VDegree), knots_u, knots_v,
                      np.array(points, dtype=np.float64),
                      np.array(w, dtype=np.float64) if rational else None)


def bspline_face(surface, face):
    """A Clayform Surface as a FreeCAD face over the parameter range of `face`."""
    u0, u1, v0, v1 = face.ParameterRange
    return part_surface(surface).toShape(u0, u1, v0, v1)


def part_surface(surface):
    """A Clayform Surface as a Part.BSplineSurface (the same knots, poles and weights)."""
    knots_u, knots_v = list(surface.knots_u), list(surface.knots_v)

    def compress(knots):
        ks, ms = [], []
        for k in knots:
            if ks and k == ks[-1]:
                ms[-1] += 1
            else:
                ks.append(k)
                ms.append(1)
        return ks, ms

    ku, mu = compress(knots_u)
    kv, mv = compress(knots_v)
    nu, nv = surface.counts
    pts = surface.points.reshape(nu, nv, 3)
    poles = [[App.Vector(*map(float, pts[i][j])) for j in range(nv)] for i in range(nu)]
    bs = Part.BSplineSurface()
    du, dv = surface.degrees
    if surface.rational:
        w = surface.weights.reshape(nu, nv)
        weights = [[float(w[i][j]) for j in range(nv)] for i in range(nu)]
        bs.buildFromPolesMultsKnots(poles, mu, mv, ku, kv, False, False, du, dv, weights)
    else:
        bs.buildFromPolesMultsKnots(poles, mu, mv, ku, kv, False, False, du, dv)
    return bs


def curve_of(obj):
    """The curve of a sketch or edge object: its one edge (or its edges joined), as a Clayform
    Curve (a B-spline of the edge's own geometry; a line or arc converted exactly)."""
    shape = obj.Shape
    edges = shape.Edges
    if not edges:
        raise cf.InvalidArgumentError(f"'{obj.Label}' has no edge; link a sketch or an edge")
    if len(edges) == 1:
        curve = edges[0].Curve.toBSpline(edges[0].FirstParameter, edges[0].LastParameter)
    else:
        wire = Part.Wire(Part.__sortEdges__(edges))
        curve = wire.approximate(1e-4, 1e-4, 50, 7) if hasattr(wire, "approximate") else None
        if curve is None:
            raise cf.InvalidArgumentError(f"'{obj.Label}' has {len(edges)} edges; join them")
    if curve.isPeriodic():
        curve.setNotPeriodic()
    knots = [k for k, m in zip(curve.getKnots(), curve.getMultiplicities()) for _ in range(m)]
    points = np.array([list(p) for p in curve.getPoles()], dtype=float)
    weights = np.array(curve.getWeights(), dtype=float)
    rational = bool(np.any(weights != 1.0))
    return cf.Curve(curve.Degree, knots, points, weights if rational else None)


class StyleFeature(_Proxy):
    """Proxy of a Style feature."""

    def __init__(self, obj, face=None, target=None, bound=None):
        obj.Proxy = self
        self.setup(obj)
        if face is not None:
            obj.Face = face
        if target is not None:
            obj.Target = target
        if bound is not None:
            obj.Bound = bound

    def setup(self, obj):
        _add(obj, "App::PropertyLinkSub", "Face", "Style", "The B-spline face to style (one face)")
        _add(obj, "App::PropertyLink", "Target", "Style",
             "The target curve: a sketch or an edge the face is pulled to")
        _add(obj, "App::PropertyLink", "Bound", "Style",
             "The closed bound curve (a sketch or edge): only the region inside it moves; "
             "none: the target's support band")
        _add(obj, "App::PropertyEnumeration", "Mode", "Style",
             "exact (key points met, fairness energy) or paper (Han–De Amicis–Conti as printed)",
             STYLE_MODES)
        _add(obj, "App::PropertyFloat", "Lambda", "Style", "Smoothing weight λ", 1.0)
        for name, kind, doc in (
                ("MovedVertices", "App::PropertyInteger", "Control vertices moved"),
                ("TargetDeviationMm", "App::PropertyFloat",
                 "Largest distance from the styled face to the target curve (mm)"),
                ("Outcome", "App::PropertyString", "met, or missed"),
                ("Seconds", "App::PropertyFloat", "Time of the last recompute (s)")):
            _add(obj, kind, name, "Report", doc, read_only=True)


    def execute(self, obj):
        t0 = time.perf_counter()
        if obj.Face is None:
            raise cf.InvalidArgumentError(f"{obj.Label}: no Face; link one B-spline face")
        src, subs = obj.Face
        subs = [s for s in subs if s]
        if len(subs) != 1:
            raise cf.InvalidArgumentError(
                f"{obj.Label}: Face links {len(subs)} sub-elements; link exactly one face")
        k = transfer.face_indices(src.Shape, subs)[0]
        face = src.Shape.Faces[k]
        if obj.Target is None:
            raise cf.InvalidArgumentError(f"{obj.Label}: no Target; link a sketch or an edge")
        parent = surface_of_face(face)
        bound = curve_of(obj.Bound) if obj.Bound is not None else None
        styled, report = cf.style_deform(parent, bound, curve_of(obj.Target), mode=obj.Mode,
                                         lam=obj.Lambda)
        obj.Shape = bspline_face(styled, face)
        obj.MovedVertices = int(report.get("moved_vertices", 0))
        obj.TargetDeviationMm = float(report["target_curve_distance"])
        obj.Outcome = "met" if report["converged"] else "missed"
        obj.Seconds = time.perf_counter() - t0


def make_style(face_object, face: str, target, bound=None, name: str = "Style"):
    """A Style feature on `face` ("Face1") of `face_object`, pulled to `target` inside `bound`."""
    doc = face_object.Document
    obj = doc.addObject("Part::FeaturePython", name)
    StyleFeature(obj, (face_object, [face]), target, bound)
    _attach_view(obj, "style")
    doc.recompute()
    return obj


def _attach_view(obj, kind: str) -> None:
    if App.GuiUp:
        from . import gui

        gui.attach_view(obj, kind)
