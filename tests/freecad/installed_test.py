"""Issue #42: the workbench as scripts/freecad.sh installs it, in freecadcmd with that user's
HOME and nothing on sys.path: FreeCAD finds the Mod folder, its Init.py makes `clayform`
importable and registers the recipe writer; a lattice and a deformation work. Exits 1 when not."""
import os
import sys
import traceback

try:
    import FreeCAD as App
    import Part

    from clayform_freecad import features

    mod = os.path.join(App.getUserAppDataDir(), "Mod", "Clayform")
    assert os.path.isfile(os.path.join(mod, "clayform_path.txt")), f"not installed in {mod}"
    doc = App.newDocument("installed")
    box = doc.addObject("Part::Feature", "Box")
    box.Shape = Part.makeBox(10, 20, 30)
    lat = features.make_lattice(box, degrees=(1, 1, 1))
    deformed = features.make_deformed(box, lat)
    assert deformed.isValid() and abs(deformed.VolumeAfter - 6000) < 1e-9, deformed.State
    print(f"ok: installed in {mod}; a lattice and a deformation recompute (6000 mm^3)")
    sys.stdout.flush()
    os._exit(0)
except Exception:
    traceback.print_exc()
    sys.stdout.flush()
    os._exit(1)
