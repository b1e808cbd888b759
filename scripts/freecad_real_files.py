"""FreeCAD's own reading of every file of tests/data/cad, for scripts/real_files_table.py: faces,
solids, volume of the solids, `isValid` and the free edges (bounded and unbounded), as JSON. FreeCAD reads through its own Part module (on
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
        # Free edges: edges no face uses (a wireframe); bounded ones have a finite range (FreeCAD
        # gives an unbounded line the range +-2e100).
        in_faces = {}
        for f in shape.Faces:
            for e in f.Edges:
                in_faces.setdefault(e.hashCode(), []).append(e)
        free = [e for e in shape.Edges
                if not any(e.isSame(x) for x in in_faces.get(e.hashCode(), []))]
        bounded = [e for e in free if max(abs(e.FirstParameter), abs(e.LastParameter)) < 1e99]
        figures[os.path.basename(path)] = {
            "faces": len(shape.Faces), "solids": len(shape.Solids),
            "volume": sum(s.Volume for s in shape.Solids), "valid": shape.isValid(),
            "free_edges": len(bounded), "unbounded_edges": len(free) - len(bounded)}
    except Exception as e:  # a file FreeCAD cannot read is a figure of the table too
        figures[os.path.basename(path)] = {"error": str(e)}
with open(os.environ.get("CLAY_FREECAD_OUT", "freecad_real_files.json"), "w") as out:
    json.dump(figures, out, indent=1)
