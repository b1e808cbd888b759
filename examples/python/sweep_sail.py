"""A sweep of the sail's billow with its contact sheet (docs/sweeps.md).

    python3 examples/python/sweep_sail.py OUT_DIR [--dask]

Six variants of examples/recipes/sail.json: the billow lattice's two middle moves at three and
two values. Each variant's STEP, IGES, glTF and report land in OUT_DIR/<id>; OUT_DIR/index.csv
lists their figures and OUT_DIR/contact_sheet.png shows them side by side. Run it again and the
finished variants are skipped. With --dask the variants run on a Dask LocalCluster.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import clayform as cf

HERE = Path(__file__).resolve().parent

SPEC: dict[str, Any] = {
    "format": "clayform.sweep",
    "version": 1,
    "recipe": str(HERE.parent / "recipes" / "sail.json"),
    "grid": {
        "deformations.shape[1].moves[0].by[1]": [0, 200, 400],
        "deformations.shape[1].moves[3].by[1]": [0, 300],
    },
}


def main(out: Path, dask: bool = False) -> list[dict[str, Any]]:
    rows = cf.sweep(SPEC, out, executor="dask" if dask else "local", workers=2)
    for row in rows:
        print(row["id"], row["status"], row["parameters"], f"{row['control_points']} control points")
    print("contact sheet:", out / "contact_sheet.png")
    return rows


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: sweep_sail.py OUT_DIR [--dask]")
    main(Path(sys.argv[1]), "--dask" in sys.argv[2:])
