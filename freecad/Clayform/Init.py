# Clayform workbench, run by FreeCAD at start-up with and without its GUI (freecadcmd): makes the
# `clayform` kernel importable and writes a saved document's recipes beside it (docs/freecad.md).
import FreeCAD

try:
    # Importing the package puts the kernel on sys.path (clayform_path.txt).
    from clayform_freecad import recipe as _clayform_recipe

    _clayform_recipe.register()
except Exception as _e:  # FreeCAD must start even when the kernel is missing: say why
    FreeCAD.Console.PrintWarning(f"Clayform workbench: {_e}\n")
