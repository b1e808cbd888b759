# Clayform workbench, GUI part: the Clayform menu and toolbar (docs/freecad.md).
import FreeCADGui


class ClayformWorkbench(FreeCADGui.Workbench):
    MenuText = "Clayform"
    ToolTip = "Exact free-form deformation and styling of Part shapes (Clayform kernel)"

    def Initialize(self):  # noqa: N802
        from clayform_freecad import gui

        gui.register_commands()
        names = list(gui.COMMANDS)
        self.appendToolbar("Clayform", names)
        self.appendMenu("Clayform", names)

    def GetClassName(self):  # noqa: N802
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(ClayformWorkbench())
