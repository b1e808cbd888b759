"""The recipe of what the workbench did, written beside the document (issue #42).

For a document ``/path/part.FCStd``, the folder ``/path/part.clayform/`` holds, per Deformed
feature ``D``: ``D-source.step`` (its source, written by Clayform with the faces' names and
colours) and ``D.json``, a recipe that ``clayform run D.json --out OUT`` replays into the same
deformed model (docs/recipe.md § Models; docs/freecad.md); per Style feature ``S``: ``S.json``,
its face's surface and curves given exactly and the style step, the styled surface exported. Written when the document is saved
(``RecipeWriter``, a document observer the workbench's Init.py registers: ``register()``) or by ``write_recipes(doc)``.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import List

import FreeCAD as App

import clayform as cf

from . import features, transfer


def recipe_folder(doc) -> Path:
    """The folder beside a saved document where its recipes go."""
    if not doc.FileName:
        raise cf.InvalidArgumentError(f"the document '{doc.Label}' is not saved; save it, then its recipes "
                         f"are written beside it")
    path = Path(doc.FileName)
    return path.with_name(path.stem + ".clayform")


def _is_deformed(obj) -> bool:
    return isinstance(getattr(obj, "Proxy", None), features.DeformedFeature)


def recipe_of(obj, source_file: str, face_names: List[str]) -> dict:
    """The recipe replaying Deformed feature `obj` on `source_file` (relative to the recipe)."""
    shape, faces, _ = features._source(obj.Source)
    step = features.deformation_step(obj, shape)
    step.setdefault("name", obj.Kind.lower())
    model = {"import": source_file, "deformation": "deformation", "formats": ["step"]}
    if faces:
        model["faces"] = [face_names[k] for k in faces]
    if obj.Profile != "none":
        model["profile"] = obj.Profile
    if obj.AllowFold:
        model["allow_fold"] = True
    recipe = {
        "format": "clayform.recipe",
        "version": 1,
        "name": obj.Name,
        "description": f"FreeCAD document '{obj.Document.Label}', feature '{obj.Label}': "
                       f"{obj.Kind} of '{obj.Source[0].Label}', written by the Clayform workbench",
        "units": "mm",
        "deformations": {"deformation": [step]},
        "models": {obj.Name: model},
    }
    if obj.ToleranceMm > 0:
        recipe["composition"] = {"mode": "refit", "tolerance_mm": obj.ToleranceMm}
    return recipe


def recipe_face_names(names: List[str]) -> List[str]:
    """Faces are chosen by name in a recipe, so each needs one of its own: an unnamed face is
    named after its FreeCAD sub-element ("Face3"), and a name already taken (STEP files repeat
    names; a real face may be called "Face3") gets " #2", " #3", ... until it is unique."""
    out, taken = [], set()
    for k, name in enumerate(names):
        base = name or f"Face{k + 1}"
        unique, n = base, 1
        while unique in taken:
            n += 1
            unique = f"{base} #{n}"
        taken.add(unique)
        out.append(unique)
    return out


def write_recipe(obj, folder: Path) -> Path:
    """Writes Deformed feature `obj`'s source and recipe into `folder`; returns the recipe."""
    folder.mkdir(parents=True, exist_ok=True)
    shape, _, src = features._source(obj.Source)
    names = recipe_face_names(features._face_names(src) or [""] * len(shape.Faces))
    attributes = features.source_attributes(src)
    attributes.face_names = names
    model, _ = transfer.model_from_shape(shape, attributes)
    source = folder / f"{obj.Name}-source.step"
    model.write(source)
    path = folder / f"{obj.Name}.json"
    path.write_text(json.dumps(recipe_of(obj, source.name, names), indent=2) + "\n")
    return path


def _is_style(obj) -> bool:
    return isinstance(getattr(obj, "Proxy", None), features.StyleFeature)


def _curve_json(curve) -> dict:
    c = {"degree": int(curve.degree), "knots": [float(k) for k in curve.knots],
         "points": [[float(x) for x in p] for p in curve.points]}
    if curve.rational:
        c["weights"] = [float(w) for w in curve.weights]
    return {"bspline": c}


def style_recipe_of(obj) -> dict:
    """The recipe replaying Style feature `obj`: its face's surface and the curves given exactly
    (B-splines), the style step with the feature's mode and λ, the styled surface exported."""
    src, subs = obj.Face
    face = src.Shape.Faces[transfer.face_indices(src.Shape, [s for s in subs if s])[0]]
    parent = features.surface_of_face(face)
    surface = {"degrees": [int(d) for d in parent.degrees],
               "knots_u": [float(k) for k in parent.knots_u],
               "knots_v": [float(k) for k in parent.knots_v],
               "points": [[float(x) for x in p] for p in parent.points]}
    if parent.rational:
        surface["weights"] = [float(w) for w in parent.weights.reshape(-1)]
    step = {"kind": "style", "name": obj.Label, "target": "target", "mode": obj.Mode,
            "lambda": obj.Lambda}
    curves = {"target": _curve_json(features.curve_of(obj.Target))}
    if obj.Bound is not None:
        curves["bound"] = _curve_json(features.curve_of(obj.Bound))
        step["bound"] = "bound"
    return {
        "format": "clayform.recipe",
        "version": 1,
        "name": obj.Name,
        "description": f"FreeCAD document '{obj.Document.Label}', feature '{obj.Label}': "
                       f"{src.Label}.{subs[0]} styled, written by the Clayform workbench",
        "units": "mm",
        "curves": curves,
        "surfaces": {"parent": {"bspline": surface},
                     "styled": {"deform": {"surface": "parent", "deformation": "style"}}},
        "deformations": {"style": [step]},
        "exports": {obj.Name: {"surfaces": ["styled"], "formats": ["step"]}},
    }


def write_recipes(doc) -> List[Path]:
    """Writes the recipe of every Deformed and Style feature of a saved document; returns their
    paths."""
    folder = recipe_folder(doc)
    out, failed = [], []
    for obj in doc.Objects:
        try:
            if _is_deformed(obj):
                out.append(write_recipe(obj, folder))
            elif _is_style(obj):
                folder.mkdir(parents=True, exist_ok=True)
                path = folder / f"{obj.Name}.json"
                path.write_text(json.dumps(style_recipe_of(obj), indent=2) + "\n")
                out.append(path)
        except Exception as e:  # one feature's failure leaves the others' recipes written
            failed.append(f"{obj.Label}: {e}")
    if failed:
        raise cf.InvalidArgumentError(
            f"the recipes of {len(failed)} feature(s) were not written (the others were): "
            + "; ".join(failed) + "; recompute them without errors, then save again")
    return out


class RecipeWriter:
    """A document observer: writes a saved document's recipes beside it."""

    def slotFinishSaveDocument(self, doc, filename):  # noqa: N802 (FreeCAD's name)
        try:
            if any(_is_deformed(o) or _is_style(o) for o in doc.Objects):
                written = write_recipes(doc)
                App.Console.PrintMessage(
                    f"Clayform: {len(written)} recipe(s) written to {recipe_folder(doc)}\n")
        except Exception as e:  # a failed recipe must not fail the save: say it
            App.Console.PrintError(f"Clayform: the recipes were not written: {e}\n")


_writer = None


def register() -> None:
    """Registers the recipe writer with FreeCAD once (FreeCAD's Init.py of the workbench calls
    it); a module-level reference keeps it alive."""
    global _writer
    if _writer is None:
        _writer = RecipeWriter()
        App.addDocumentObserver(_writer)
