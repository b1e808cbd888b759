"""The workbench's GUI (issue #42): view providers, a Coin dragger on lattice points, the report
panel of a Deformed feature, and the commands. Loaded only when FreeCAD runs with its GUI."""
from __future__ import annotations

from typing import Optional

import FreeCAD as App
import FreeCADGui as Gui
from pivy import coin

import clayform as cf

from . import features, recipe

try:
    from PySide import QtGui  # FreeCAD's PySide shim
except ImportError:  # pragma: no cover
    QtGui = None


# ---- view providers ----------------------------------------------------------------------------


class ViewProviderClayform:
    """Shared view provider: Part's own drawing of the Shape, plus setEdit for the report panel."""

    def __init__(self, vobj, kind: str):
        vobj.Proxy = self
        self.kind = kind

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):  # noqa: N802
        return ""

    def setEdit(self, vobj, mode=0):  # noqa: N802
        if mode != 0:
            return None
        Gui.Control.showDialog(ReportPanel(vobj.Object))
        return True

    def unsetEdit(self, vobj, mode=0):  # noqa: N802
        Gui.Control.closeDialog()
        return True

    def __getstate__(self):
        return {"kind": getattr(self, "kind", "")}

    def __setstate__(self, state):
        self.kind = (state or {}).get("kind", "")

    def dumps(self):
        return self.__getstate__()

    def loads(self, state):
        self.__setstate__(state)


def attach_view(obj, kind: str) -> None:
    """Gives a new feature its view provider and look."""
    vobj = obj.ViewObject
    ViewProviderClayform(vobj, kind)
    if kind == "lattice":
        vobj.LineColor = (0.85, 0.35, 0.1)
        vobj.PointColor = (0.85, 0.35, 0.1)
        vobj.PointSize = 7
        vobj.LineWidth = 1


# ---- the report panel --------------------------------------------------------------------------


def report_lines(obj) -> str:
    """What a feature's report properties say, one per line."""
    lines = []
    for name in obj.PropertiesList:
        if obj.getGroupOfProperty(name) == "Report":
            value = getattr(obj, name)
            if isinstance(value, float):
                value = f"{value:.6g}"
            lines.append(f"{name}: {value}")
    return "\n".join(lines)


class ReportPanel:
    """The task panel of a Clayform feature: its report (exact faces, certified bound, volume
    before and after, fold-free), refreshed by its Recompute button."""

    def __init__(self, obj):
        self.obj = obj
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(f"Clayform: {obj.Label}")
        layout = QtGui.QVBoxLayout(self.form)
        self.label = QtGui.QLabel(report_lines(obj))
        self.label.setTextInteractionFlags(self.label.textInteractionFlags() | 1)
        layout.addWidget(self.label)
        button = QtGui.QPushButton("Recompute")
        button.clicked.connect(self.recompute)
        layout.addWidget(button)

    def recompute(self):
        self.obj.Document.recompute()
        self.label.setText(report_lines(self.obj))

    def accept(self):
        Gui.ActiveDocument.resetEdit()
        return True

    def reject(self):
        Gui.ActiveDocument.resetEdit()
        return True


# ---- dragging a lattice point ------------------------------------------------------------------


class DragSession:
    """A Coin dragger (SoDragPointDragger) on point `n` of a Lattice feature. Moving it moves the
    point (its locked axes stay); releasing it recomputes the document, so the Deformed features
    that use the lattice follow. The dragger's value-changed callback follows its `translation`
    field, so a program (a test) that sets it drags as a mouse does; `finish()` is the release."""

    active: Optional["DragSession"] = None

    def __init__(self, obj, n: int, view=None):
        if DragSession.active is not None:
            DragSession.active.close()
        self.obj, self.n = obj, n
        self.view = view or Gui.ActiveDocument.ActiveView
        held = features.held_points(obj)
        if held[n]:
            raise cf.InvalidArgumentError(
                f"{obj.Label}: point {n} is held by Continuity {obj.Continuity}; drag an inner "
                f"point, or set Continuity to a lower order")
        size = max(obj.AxisS.Length, obj.AxisT.Length, obj.AxisU.Length)
        self.scale = size / 12.0  # the dragger is about one unit wide: a twelfth of the lattice
        self.root = coin.SoSeparator()
        s = coin.SoScale()
        s.scaleFactor.setValue(self.scale, self.scale, self.scale)
        self.root.addChild(s)
        self.dragger = coin.SoDragPointDragger()
        self.root.addChild(self.dragger)
        p = obj.Points[n]
        self.start = App.Vector(p)
        self._set(p)
        # Coin calls value-changed callbacks synchronously when the field is set (a field sensor
        # would wait for the delay queue).
        self.resetting = False
        self.closed = False
        self.dragger.addValueChangedCallback(self._moved)
        self.dragger.addFinishCallback(lambda _data, _dragger: self.finish())
        self.view.getSceneGraph().addChild(self.root)
        DragSession.active = self

    def _set(self, p) -> None:
        self.dragger.translation.setValue(p.x / self.scale, p.y / self.scale, p.z / self.scale)

    def position(self) -> App.Vector:
        t = self.dragger.translation.getValue()
        return App.Vector(t[0] * self.scale, t[1] * self.scale, t[2] * self.scale)

    def _moved(self, _data, _dragger) -> None:
        if self.resetting or self.closed:
            return
        p = self.position()
        o = self.obj
        # Coin's fields are single precision: a coordinate the drag left within its rounding of
        # where it started keeps its double value (a drag along z must not nudge x and y).
        def axis(start, now, lock):
            if lock or abs(now - start) <= 4e-7 * max(abs(start), self.scale):
                return start
            return now

        locked = App.Vector(axis(self.start.x, p.x, o.LockX), axis(self.start.y, p.y, o.LockY),
                            axis(self.start.z, p.z, o.LockZ))
        if (locked - p).Length > 0:
            self.resetting = True
            try:
                self._set(locked)
            finally:
                self.resetting = False
        features.move_point(o, self.n, locked)
        o.recompute()  # the net follows the dragger; the deformation waits for the release

    def finish(self) -> None:
        """The release: the document recomputed with the point where the dragger left it."""
        self.obj.Document.recompute()
        self.start = App.Vector(self.obj.Points[self.n])

    def close(self) -> None:
        # (pivy's removeValueChangedCallback crashes Coin in FreeCAD 0.20: the callback is left on
        # the dragger, which leaves the scene, and told to do nothing.)
        self.closed = True
        self.view.getSceneGraph().removeChild(self.root)
        if DragSession.active is self:
            DragSession.active = None


def selected_lattice_point():
    """(Lattice feature, point index) of the selected lattice vertex, or None."""
    for sel in Gui.Selection.getSelectionEx():
        if isinstance(getattr(sel.Object, "Proxy", None), features.LatticeFeature):
            points = sel.Object.Points
            for name in sel.SubElementNames:
                if name.startswith("Vertex") and name[6:].isdigit():
                    n = int(name[6:]) - 1
                    if n < len(points):
                        return sel.Object, n
                    # A click may pick a net line's end vertex, which sits on a point: the
                    # point nearest it.
                    p = sel.Object.Shape.Vertexes[n].Point
                    return sel.Object, min(range(len(points)), key=lambda m: (points[m] - p).Length)
    return None


# ---- commands ----------------------------------------------------------------------------------


def _selection():
    """(object, face names) of the first selected object with a shape."""
    for sel in Gui.Selection.getSelectionEx():
        if hasattr(sel.Object, "Shape"):
            return sel.Object, [n for n in sel.SubElementNames if n.startswith("Face")]
    return None, []


def _report_error(what: str, e: Exception) -> None:
    App.Console.PrintError(f"Clayform {what}: {e}\n")
    if QtGui is not None:
        QtGui.QMessageBox.warning(Gui.getMainWindow(), f"Clayform {what}", str(e))


class _Command:
    menu = ""
    tip = ""

    def GetResources(self):  # noqa: N802
        return {"MenuText": self.menu, "ToolTip": self.tip}

    def IsActive(self):  # noqa: N802
        return App.ActiveDocument is not None


class LatticeCommand(_Command):
    menu = "Lattice"
    tip = "A lattice around the selected shape or faces (Bézier; cells > 1: B-spline)"

    def Activated(self):  # noqa: N802
        obj, faces = _selection()
        if obj is None:
            _report_error("Lattice", ValueError("select a shape, or some of its faces"))
            return
        try:
            features.make_lattice(obj, faces)
        except Exception as e:
            _report_error("Lattice", e)


class DeformedCommand(_Command):
    menu = "Deformed by lattice"
    tip = "The selected shape (or faces) deformed by the selected lattice, exactly"

    def Activated(self):  # noqa: N802
        lattice, source, faces = None, None, []
        for sel in Gui.Selection.getSelectionEx():
            if isinstance(getattr(sel.Object, "Proxy", None), features.LatticeFeature):
                lattice = sel.Object
            elif hasattr(sel.Object, "Shape"):
                source = sel.Object
                faces = [n for n in sel.SubElementNames if n.startswith("Face")]
        if lattice is not None and source is None and lattice.Source is not None:
            source, faces = lattice.Source[0], [n for n in lattice.Source[1] if n]
        if lattice is None or source is None:
            _report_error("Deformed", ValueError("select a lattice (and the shape or faces)"))
            return
        try:
            features.make_deformed(source, lattice, faces)
        except Exception as e:
            _report_error("Deformed", e)


class BarrCommand(_Command):
    def __init__(self, kind: str, amount: float):
        self.kind, self.amount = kind, amount
        self.menu = kind
        self.tip = f"Barr's {kind.lower()} of the selected shape along Z (edit Axis and Amount)"

    def Activated(self):  # noqa: N802
        obj, faces = _selection()
        if obj is None:
            _report_error(self.kind, ValueError("select a shape"))
            return
        try:
            features.make_deformed(obj, None, faces, kind=self.kind, axis="Z", amount=self.amount,
                                   name=self.kind)
        except Exception as e:
            _report_error(self.kind, e)


class StyleCommand(_Command):
    menu = "Style face"
    tip = "Select a B-spline face, then the target curve (and a closed bound curve)"

    def Activated(self):  # noqa: N802
        face_obj, face, curves = None, None, []
        for sel in Gui.Selection.getSelectionEx():
            faces = [n for n in sel.SubElementNames if n.startswith("Face")]
            if face_obj is None and faces:
                face_obj, face = sel.Object, faces[0]
            else:
                curves.append(sel.Object)
        if face_obj is None or not curves:
            _report_error("Style", ValueError("select a face, then a target (and a bound)"))
            return
        try:
            features.make_style(face_obj, face, curves[0], curves[1] if len(curves) > 1 else None)
        except Exception as e:
            _report_error("Style", e)


class DragPointCommand(_Command):
    menu = "Drag lattice point"
    tip = "Select a lattice's vertex, then drag it (LockX/Y/Z keep axes)"

    def Activated(self):  # noqa: N802
        picked = selected_lattice_point()
        if picked is None:
            _report_error("Drag", ValueError("select a vertex of a lattice"))
            return
        try:
            DragSession(*picked)
        except Exception as e:
            _report_error("Drag", e)


class WriteRecipesCommand(_Command):
    menu = "Write recipes"
    tip = "Write the recipes of the deformations beside the saved document"

    def Activated(self):  # noqa: N802
        try:
            paths = recipe.write_recipes(App.ActiveDocument)
            App.Console.PrintMessage(f"Clayform: wrote {', '.join(map(str, paths))}\n")
        except Exception as e:
            _report_error("Recipes", e)


COMMANDS = {
    "Clayform_Lattice": LatticeCommand(),
    "Clayform_Deformed": DeformedCommand(),
    "Clayform_Taper": BarrCommand("Taper", 0.7),
    "Clayform_Twist": BarrCommand("Twist", 30.0),
    "Clayform_Bend": BarrCommand("Bend", 30.0),
    "Clayform_Style": StyleCommand(),
    "Clayform_DragPoint": DragPointCommand(),
    "Clayform_WriteRecipes": WriteRecipesCommand(),
}


def register_commands() -> None:
    for name, command in COMMANDS.items():
        Gui.addCommand(name, command)
