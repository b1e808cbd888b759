"""Lossless transfer between FreeCAD's Part shapes and Clayform's models (issue #42).

The geometry travels as OpenCASCADE's BRep text (``Shape.exportBrepToString()`` and
``clayform.read_brep``; ``Model.to_brep()`` and ``Shape.importBrepFromString``): FreeCAD and
Clayform run on the same OpenCASCADE 7.6, and the text keeps every double to the last bit. What
BRep cannot hold travels beside it: the object's label (the body's name), its colour and its
faces' colours, in ``Shape.Faces`` order, and the faces' names (FreeCAD 0.20 has none of its own:
they are kept in a feature's ``FaceNames`` property, so that a model read from STEP keeps them
through FreeCAD).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

import clayform as cf

Colour = Tuple[float, float, float]


@dataclass
class Attributes:
    """What travels beside the BRep text: the shape's name and colour, and per face (in
    ``Shape.Faces`` order) a colour (None: the shape's) and a name ("": unnamed)."""

    name: str = ""
    colour: Optional[Colour] = None
    face_colours: List[Optional[Colour]] = field(default_factory=list)
    face_names: List[str] = field(default_factory=list)


def _rgb(c) -> Optional[Colour]:
    """FreeCAD colours are (r, g, b) or (r, g, b, a) in [0, 1]; Clayform's (r, g, b)."""
    if c is None:
        return None
    return (float(c[0]), float(c[1]), float(c[2]))


def model_from_shape(shape, attributes: Optional[Attributes] = None, isolate: bool = True):
    """A Clayform ``Model`` (and the read's report) from a FreeCAD ``Part.Shape``, exactly.

    ``attributes``' face lists, when given, must have one entry per face of ``shape``.
    ``report["shape_faces"][j]`` is model face j's index in ``Shape.Faces`` (``model_faces``
    maps a selection). Raises ``clayform.ClayError`` (``ExchangeError`` for an unreadable
    shape)."""
    if shape is None or shape.isNull():
        raise cf.InvalidArgumentError(
            "model_from_shape: the shape is empty; select an object that has a shape")
    a = attributes or Attributes()
    return cf.read_brep(
        shape.exportBrepToString(),
        name=a.name,
        colour=_rgb(a.colour),
        face_colours=[_rgb(c) for c in a.face_colours] or None,
        face_names=list(a.face_names) or None,
        isolate=isolate,
    )


def model_faces(report, shape_faces: Sequence[int]) -> List[int]:
    """The model's faces (indices) that came from the given faces of the shape (0-based indices
    into ``Shape.Faces``), by the read's ``report["shape_faces"]``: the model numbers its faces
    solids first and holds a face two solids share twice."""
    wanted = set(shape_faces)
    return [j for j, k in enumerate(report["shape_faces"]) if k in wanted]


def shape_from_model(model) -> Tuple[object, Attributes]:
    """A FreeCAD ``Part.Shape`` from a Clayform ``Model``, exactly, with its attributes (face
    colours and names in the new shape's ``Shape.Faces`` order)."""
    import Part  # FreeCAD's; imported here so that the rest of this module loads without it

    text = model.to_brep()
    shape = Part.Shape()
    shape.importBrepFromString(text["brep"], False)
    return shape, Attributes(
        name=text["name"],
        colour=text["colour"],
        face_colours=list(text["face_colours"]),
        face_names=list(text["face_names"]),
    )


def face_indices(shape, sub_names: Sequence[str]) -> List[int]:
    """FreeCAD sub-element names ("Face3") as 0-based face indices of ``shape``; refuses anything
    that is not a face of it, naming it."""
    out = []
    count = len(shape.Faces)
    for name in sub_names:
        if not name.startswith("Face") or not name[4:].isdigit():
            raise cf.InvalidArgumentError(
                f"'{name}' is not a face; select faces (Face1, Face2, ...) or the whole object")
        k = int(name[4:]) - 1
        if not 0 <= k < count:
            raise cf.InvalidArgumentError(
                f"'{name}' is not a face of the shape (it has {count}); select one of its faces")
        out.append(k)
    return out
