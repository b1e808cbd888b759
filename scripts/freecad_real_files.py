"""FreeCAD's own reading of every file of tests/data/cad, for scripts/real_files_table.py: faces,
solids, volume of the solids and `isValid`, as JSON. FreeCAD reads through its own Part module (on
OpenCASCADE), independently of Clayform. Usage:
    CLAY_FREECAD_OUT=freecad.json freecadcmd scripts/freecad_real_files.py"""
import glob
import json
import os

import Part

CAD = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "tests", "data", "cad")

figures = {}
for path in sorted(glob.glob(os.path.join(CAD, "*"))):
    if not path.lower().endswith((".stp", ".step", ".igs", ".iges")):
        continue
    try:
        shape = Part.Shape()
        shape.read(path)
        figures[os.path.basename(path)] = {
            "faces": len(shape.Faces), "solids": len(shape.Solids),
            "volume": sum(s.Volume for s in shape.Solids), "valid": shape.isValid()}
    except Exception as e:  # a file FreeCAD cannot read is a figure of the table too
        figures[os.path.basename(path)] = {"error": str(e)}
with open(os.environ.get("CLAY_FREECAD_OUT", "freecad_real_files.json"), "w") as out:
    json.dump(figures, out, indent=1)
