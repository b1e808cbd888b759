"""Whole models from Python: read with trims and bodies, meshed, deformed by a recipe's stack as
`clayform deform` does, written and read back."""
from __future__ import annotations

import copy
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import clayform as cf


def test_read_inspect_mesh_and_write(examples: Path, tmp_path: Path) -> None:
    model, report = cf.read_model(examples / "models" / "block.step")
    counts = model.counts
    assert counts["solids"] == 1 and counts["faces"] == report["counts"]["faces"] > 6
    assert counts["inner_loops"] >= 2  # the two through holes
    assert model.problems() == [] and not model.is_assembly
    # The volume from the exact faces against the block's closed form is too involved (fillets,
    # holes, pocket); against the box it must be smaller, and positive.
    assert 0 < model.volume_mm3() < 60 * 40 * 20
    vertices, triangles, face = model.tessellate()
    assert triangles.shape[1] == 3 and len(face) == len(triangles) and face.max() < counts["faces"]
    # The mesh's enclosed volume (divergence theorem) agrees with the exact one.
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    mesh_volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
    assert mesh_volume == pytest.approx(model.volume_mm3(), rel=2e-3)
    # Every mesh node lies on its face's surface (closest point on a dense sample).
    s = model.face_surface(int(face[0]))
    assert s.degrees[0] >= 1
    check = model.write(tmp_path / "block.step")
    assert check["valid"] and check["volume_mm3"] == pytest.approx(model.volume_mm3(), rel=1e-9)
    again, _ = cf.read_model(tmp_path / "block.step")
    assert again.counts == counts
    for k in range(counts["faces"]):
        assert again.face_surface(k).identical(model.face_surface(k))
    twin = copy.copy(model)
    assert twin.counts == counts


def test_deform_model_as_the_command_does(examples: Path, exe: str, tmp_path: Path) -> None:
    recipe = cf.Recipe.load(examples / "recipes" / "block_model.json")
    model, _ = cf.read_model(examples / "models" / "block.step")
    lifted, report = recipe.deform_model(model, "lift")
    assert report["faces_exact"] > 0 and report["fold_free"] and report["max_edge_gap_mm"] < 1e-6
    # A smooth map composed exactly keeps every tangent edge tangent (the fillets), and every
    # sharp one sharp.
    assert len(report["continuity"]) == 42
    for edge in report["continuity"]:
        if edge["angle_deg_before"] < 1e-6:
            assert edge["angle_deg"] < 1e-6
        else:
            assert edge["angle_deg"] > 1
    assert lifted.volume_mm3() > model.volume_mm3()  # the lattice raises the top
    lifted.write(tmp_path / "py.step")
    subprocess.run([exe, "deform", str(examples / "models" / "block.step"), "--recipe",
                    str(examples / "recipes" / "block_model.json"), "--deformation", "lift",
                    "--out", str(tmp_path / "cli"), "--quiet"], check=True)
    # The command's report.json carries the same continuity, per edge with the source's figures.
    written = json.loads((tmp_path / "cli" / "report.json").read_text())["model"]["continuity"]
    assert written["shared_edges"] == 42 and len(written["edges"]) == 42
    for edge, ours_edge in zip(written["edges"], report["continuity"]):
        assert edge["edge"] == ours_edge["edge"]
        assert edge["angle_deg"] == pytest.approx(ours_edge["angle_deg"], abs=1e-9)
        assert edge["before"]["angle_deg"] == pytest.approx(ours_edge["angle_deg_before"], abs=1e-9)
    ours, _ = cf.read_model(tmp_path / "py.step")
    theirs, _ = cf.read_model(tmp_path / "cli" / "block.step")
    assert ours.counts == theirs.counts
    for k in range(ours.counts["faces"]):
        assert ours.face_surface(k).identical(theirs.face_surface(k))


def test_model_errors(tmp_path: Path) -> None:
    with pytest.raises(cf.IoError):
        cf.read_model(tmp_path / "none.step")
    with pytest.raises(cf.InvalidArgumentError, match="no face 99"):
        model, _ = cf.read_model(Path(__file__).parents[2] / "examples" / "models" / "block.step")
        model.face_surface(99)
