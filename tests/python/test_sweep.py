"""Sweeps: paths into the recipe, variants by hash, atomic folders, resume, failures that lose
only themselves, the index and the contact sheet, on local processes and a Dask LocalCluster."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import clayform as cf
from clayform import sweeps

BILLOW = "deformations.shape[1].moves[0].by[1]"
DRAFT = "deformations.shape[0].curve_tolerance"


def spec(examples: Path, values: list) -> dict:
    return {"format": "clayform.sweep", "version": 1, "recipe": str(examples / "recipes" / "sail.json"),
            "grid": {BILLOW: values}}


def test_paths_and_variants(examples: Path) -> None:
    assert sweeps.parse_path("a.b[2].c[0]") == ["a", "b", 2, "c", 0]
    with pytest.raises(ValueError):
        sweeps.parse_path("a..b")
    doc = {"a": {"b": [1, {"c": [5, 6]}]}}
    sweeps.set_path(doc, "a.b[1].c[0]", 9)
    assert doc["a"]["b"][1]["c"][0] == 9
    with pytest.raises(ValueError, match="no key"):
        sweeps.set_path(doc, "a.x", 1)  # a path that is not in the recipe is refused, not added
    grid = sweeps.variants({"grid": {"p": [1, 2], "q": ["a", "b", "c"]}})
    assert len(grid) == 6 and {"p": 2, "q": "c"} in grid
    assert sweeps.variant_id({"p": 1, "q": 2}) == sweeps.variant_id({"q": 2, "p": 1})
    with pytest.raises(ValueError, match="unknown key"):
        cf.sweep({"recipe": "x.json", "grid": {"a": [1]}, "gird": {}}, "out")
    with pytest.raises(ValueError, match="output folder"):
        cf.sweep({"recipe": str(examples / "recipes" / "sail.json"), "grid": {BILLOW: [1]}})


def test_local_sweep_with_a_failure_and_a_crash_then_resume(examples: Path, tmp_path: Path) -> None:
    description = spec(examples, [0, 150, 300, 450])
    description["grid"][DRAFT] = [0.01]
    sets = sweeps.variants(description)
    # One variant raises (a tolerance the recipe refuses), one aborts its process.
    description = {**description, "grid": None}
    del description["grid"]
    description["list"] = sets + [{BILLOW: 0, DRAFT: -1.0}]
    crash = sweeps.variant_id(sets[1])
    seen: list = []
    rows = cf.sweep(description, tmp_path, workers=2, abort=[crash],
                    progress=lambda done, total, row: seen.append((done, total, row["status"])))
    status = {r["id"]: r["status"] for r in rows}
    assert status[crash] == "crashed" and "SIGABRT" in rows[1]["error"]
    assert rows[-1]["status"] == "failed" and "RecipeError" in rows[-1]["error"]
    assert [r["status"] for r in rows].count("ok") == 3 and len(seen) == 5 and seen[-1][0] == 5
    for row in rows:
        folder = tmp_path / row["id"]
        assert folder.is_dir() == (row["status"] == "ok")
    # Each finished variant is the base recipe with its value: the sail's billow, by STEP.
    ok = next(r for r in rows if r["status"] == "ok" and r["parameters"][BILLOW] == 300)
    step = cf.read_step(str(tmp_path / ok["id"] / "sail.step"))[0]
    text = sweeps.recipe_text((examples / "recipes" / "sail.json").read_text(), ok["parameters"])
    direct = cf.Recipe.parse(text, str(examples / "recipes")).run().surfaces["sail"]
    assert step.identical(direct)
    assert json.loads((tmp_path / ok["id"] / "report.json").read_text())["ok"] is True
    # The index and the contact sheet.
    lines = (tmp_path / "index.jsonl").read_text().splitlines()
    assert [json.loads(x)["id"] for x in lines] == [r["id"] for r in rows]
    with open(tmp_path / "index.csv", newline="") as f:
        table = list(csv.DictReader(f))
    assert [t["id"] for t in table] == [r["id"] for r in rows] and table[0]["status"] == "ok"
    assert (tmp_path / "contact_sheet.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # Resume: the finished variants are skipped, the crashed one runs again (and now succeeds).
    again = cf.sweep(description, tmp_path, workers=2, progress=lambda *a: None)
    assert [r["status"] for r in again].count("done") == 3
    assert all(r["volume_mm3"] is None for r in again)  # surfaces only: no solid, no volume
    assert again[1]["status"] == "ok"
    assert again[-1]["status"] == "failed"


def test_dask_local_cluster_sweep(examples: Path, tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    sets = [{BILLOW: 0, DRAFT: 0.01}, {BILLOW: 100, DRAFT: 0.01}, {BILLOW: 200, DRAFT: 0.01},
            {BILLOW: 300, DRAFT: -1.0}]
    description = {"format": "clayform.sweep", "version": 1,
                   "recipe": str(examples / "recipes" / "sail.json"), "list": sets}
    crash = sweeps.variant_id(sets[2])
    rows = cf.sweep(description, tmp_path, executor="dask", workers=2, abort=[crash],
                    progress=lambda *a: None)
    assert [r["status"] for r in rows] == ["ok", "ok", "crashed", "failed"]
    assert "RecipeError" in rows[3]["error"] and "SIGABRT" in rows[2]["error"]
    first = cf.read_step(tmp_path / rows[0]["id"] / "sail.step")[0]
    second = cf.read_step(tmp_path / rows[1]["id"] / "sail.step")[0]
    assert not first.identical(second)
    # The billow's move is along +y: the middle of the sail moves that way.
    u = np.array([0.5]); v = np.array([0.5])
    assert second.evaluate(u, v)[0, 1] > first.evaluate(u, v)[0, 1]
    # Resume on the cluster: the two finished variants are skipped, the crashed one now runs.
    again = cf.sweep(description, tmp_path, executor="dask", workers=2, progress=lambda *a: None)
    assert [r["status"] for r in again] == ["done", "done", "ok", "failed"]


def test_the_command_runs_a_sweep_and_resumes(examples: Path, exe: str, tmp_path: Path) -> None:
    import subprocess

    description = tmp_path / "sweep.json"
    description.write_text(json.dumps(spec(examples, [0, 250])))
    first = subprocess.run([exe, "sweep", str(description), "--out", str(tmp_path / "out")],
                           capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    assert "[2/2]" in first.stderr and "2 variants: 2 done" in first.stdout
    again = subprocess.run([exe, "sweep", str(description), "--out", str(tmp_path / "out")],
                           capture_output=True, text=True)
    assert again.returncode == 0 and again.stderr.count(" done") == 2  # both skipped
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"recipe": str(examples / "recipes" / "sail.json"), "grid": {"nope.x": [1]}}))
    failed = subprocess.run([exe, "sweep", str(bad), "--out", str(tmp_path / "bad")], capture_output=True, text=True)
    assert failed.returncode == 2 and "no key 'nope'" in failed.stderr  # a bad description
