"""Clayform's FreeCAD workbench (issue #42): Lattice, Deformed and Style features that deform and
style Part shapes exactly with the `clayform` kernel; docs/freecad.md.

`clayform` is found on sys.path, or through `clayform_path.txt` beside this package (written by
scripts/freecad.sh: the folder of the built package)."""
from __future__ import annotations

import sys
from pathlib import Path

_path_file = Path(__file__).resolve().parent.parent / "clayform_path.txt"
if _path_file.is_file():
    for line in _path_file.read_text().splitlines():
        if line.strip() and line.strip() not in sys.path:
            sys.path.insert(0, line.strip())

__all__ = ["features", "transfer", "recipe"]
