"""A styling recipe driven from Python: the car hood's crease at three heights (docs/python.md).

    python3 examples/python/style_recipe.py [OUT_DIR]

The recipe (examples/recipes/car_hood.json) stays the single source of truth: Python reads it,
changes the target curve's height, runs it in memory, and reads the figures from the report. The
tallest variant is written out (STEP, IGES, glTF, report.json) as `clayform run` would.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import clayform as cf

HERE = Path(__file__).resolve().parent
RECIPE = HERE.parent / "recipes" / "car_hood.json"


def crease_at(document: dict[str, Any], scale: float) -> str:
    """The recipe with its crease line's heights scaled (the target curve's z coordinates)."""
    doc = json.loads(json.dumps(document))
    target = doc["deformations"]["crease_exact"][0]["target"]
    points = doc["curves"][target]["bspline"]["points"]
    base = min(p[2] for p in points)
    for p in points:
        p[2] = base + scale * (p[2] - base)
    return json.dumps(doc)


def main(out: Path | None = None) -> list[dict[str, float]]:
    document = json.loads(RECIPE.read_text())
    rows = []
    result = None
    for scale in (0.5, 1.0, 1.5):
        recipe = cf.Recipe.parse(crease_at(document, scale), str(RECIPE.parent), f"car_hood_{scale}")
        result = recipe.run()
        style = next(s for s in result.steps if s["kind"] == "style")["figures"]
        rows.append({"scale": scale, "key_points": float(style["key_points"]),
                     "target_curve_distance": float(style["target_curve_distance"]),
                     "max_displacement": float(style["max_displacement"]),
                     "locality": float(style["locality"])})
        print(f"crease x{scale}: {style['key_points']} key points, line met to "
              f"{style['target_curve_distance']:.3g} mm, moved up to {style['max_displacement']:.1f} mm")
    if out is not None and result is not None:
        print("wrote", ", ".join(Path(f).name for f in result.write(out)))
    return rows


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else None)
