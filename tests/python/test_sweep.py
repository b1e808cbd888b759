"""Sweeps: paths into the recipe, variants by hash, atomic folders, resume, failures that lose
only themselves, the index and the contact sheet, on local processes and a Dask LocalCluster;
descriptions refused up front, killed sweeps and storage errors (issue #36, items 15-18)."""
from __future__ import annotations

import csv
import errno
import itertools
import json
import re
import os
import resource
import signal
import subprocess
import time
import uuid
from pathlib import Path
from typing import Callable, List

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
    # The kernel's grammar, the studio's: each malformed path names its rule.
    for bad, rule in [("", "is empty"), ("a.", 'ends with "."'), (".a", "empty key"),
                      ("a[x]", "malformed list index"), ("a[1", "[ without ]"), ("a]", "] without ["),
                      ("a[0]b", "right after a list index"), ("[0]", "starts with a list index"),
                      ("a[99999999999999999999999]", "too large")]:
        with pytest.raises(sweeps.SpecError, match=re.escape(rule)):
            sweeps.parse_path(bad)
    assert cf.recipe_path("x[0][1].y") == ["x", 0, 1, "y"]
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
    assert rows[-1]["status"] == "failed" and "DocumentError" in rows[-1]["error"]
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


def test_variants_on_one_process_share_the_steps_before_the_swept_one(examples: Path, tmp_path: Path) -> None:
    # Issue #40: a sweep whose variants share a prefix computes it once (per variant process).
    # The sail's curves, fill and exact style come before the swept lattice move: one worker
    # runs the three variants in one process, the first computing every step, the next two
    # taking those from its RunCache.
    description = spec(examples, [0, 150, 300])
    rows = cf.sweep(description, tmp_path, workers=1, progress=lambda *a: None)
    assert [r["status"] for r in rows] == ["ok", "ok", "ok"]
    steps = json.loads((tmp_path / rows[0]["id"] / "report.json").read_text())["steps"]
    kinds = [s["kind"] for s in steps]
    upstream = kinds.index("style") + 1  # every step up to the style, which the lattice deforms
    assert rows[0]["steps_reused"] == 0
    assert all(r["steps_reused"] >= upstream for r in rows[1:]), [r["steps_reused"] for r in rows]
    # ... and what they give is what a fresh run gives, bit for bit.
    for row in rows[1:]:
        text = sweeps.recipe_text((examples / "recipes" / "sail.json").read_text(), row["parameters"])
        direct = cf.Recipe.parse(text, str(examples / "recipes")).run().surfaces["sail"]
        assert cf.read_step(str(tmp_path / row["id"] / "sail.step"))[0].identical(direct)
    # The index carries the count.
    with open(tmp_path / "index.csv", newline="") as f:
        assert [t["steps_reused"] for t in csv.DictReader(f)] == [str(r["steps_reused"]) for r in rows]


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
    assert "DocumentError" in rows[3]["error"] and "SIGABRT" in rows[2]["error"]
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


def index_ids(out: Path) -> List[str]:
    """The ids index.jsonl lists, checked against index.csv (same ids, same order)."""
    ids = [json.loads(line)["id"] for line in (out / "index.jsonl").read_text().splitlines()]
    with open(out / "index.csv", newline="") as f:
        assert [row["id"] for row in csv.DictReader(f)] == ids
    return ids


def test_a_huge_grid_is_refused_before_anything_is_built(examples: Path, exe: str, tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    # 12 paths x 10 values: 10^12 variants in a description of under a kilobyte.
    paths = [f"deformations.shape[1].moves[{i % 4}].by[{i // 4}]" for i in range(12)]
    huge = {"format": "clayform.sweep", "version": 1, "recipe": str(examples / "recipes" / "sail.json"),
            "grid": {p: list(range(10)) for p in paths}}
    assert sweeps.count_variants(huge) == 10**12

    def no_product(*args: object) -> None:
        raise AssertionError("the variants were built")

    with monkeypatch.context() as m:  # counted, never built
        m.setattr(itertools, "product", no_product)
        with pytest.raises(sweeps.SpecError, match=r"1,000,000,000,000 variants \(10 × 10 × .*\), more than the "
                                                   r"limit of 10,000"):
            cf.sweep(huge, tmp_path / "out", progress=lambda *a: None)
    assert not (tmp_path / "out").exists()
    # The limit is a documented constant: 10,000 variants pass, 10,001 do not (a list as well).
    assert sweeps.MAX_VARIANTS == 10_000
    limit = {**huge, "grid": {p: list(range(10)) for p in paths[:4]}}
    assert sweeps.count_variants(limit) == 10_000 and sweeps.load_spec(limit)[0] == limit
    listed = {"recipe": huge["recipe"], "list": [{BILLOW: k} for k in range(10_001)]}
    with pytest.raises(sweeps.SpecError, match=r"10,001 variants \(list items\), more than the limit of 10,000"):
        sweeps.load_spec(listed)
    # From the command: exit 2, one line naming the description, the count and the limit. (The
    # address space is capped so that a sweep that did build them fails fast instead of the OOM killer.)
    description = tmp_path / "huge.json"
    description.write_text(json.dumps(huge))
    capped = subprocess.run([exe, "sweep", str(description), "--out", str(tmp_path / "out")], capture_output=True,
                            text=True, preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30)))
    assert capped.returncode == 2, capped.stderr
    assert capped.stderr.splitlines() == [f"sweep: {description}: 1,000,000,000,000 variants (10 × 10 × 10 × 10 × "
                                          "10 × 10 × 10 × 10 × 10 × 10 × 10 × 10 values), more than the limit of "
                                          "10,000 (clayform.sweeps.MAX_VARIANTS); give fewer values, or split the "
                                          "sweep into several descriptions"]
    assert not (tmp_path / "out").exists()


BAD_DESCRIPTIONS = {  # test id: (the description, with SAIL and BILLOW filled in; the message's words)
    "not-json": ("{not json", "the description is not JSON (Expecting property name enclosed in double quotes "
                              "at line 1, column 2)"),
    "not-an-object": ("[1, 2]", 'expected a JSON object {"format": "clayform.sweep"'),
    "grid-not-a-map": ('{"recipe": SAIL, "grid": [1, 2]}', '"grid" maps each path to a non-empty list of values'),
    "grid-value-not-a-list": ('{"recipe": SAIL, "grid": {"BILLOW": 5}}', '"grid": BILLOW: give a non-empty list'),
    "grid-and-list": ('{"recipe": SAIL, "grid": {"BILLOW": [1]}, "list": []}', 'give either "grid"'),
    "list-item-not-a-map": ('{"recipe": SAIL, "list": [1]}', '"list"[0]: expected a {path: value} object'),
    "recipe-not-a-string": ('{"recipe": 5, "grid": {"BILLOW": [1]}}', '"recipe" names the base recipe file'),
    "recipe-missing": ('{"recipe": "missing.json", "grid": {"BILLOW": [1]}}', '"recipe": cannot read'),
    "version-2": ('{"recipe": SAIL, "grid": {"BILLOW": [1]}, "version": 2}', 'expected "format": "clayform.sweep"'),
    "out-not-a-string": ('{"recipe": SAIL, "grid": {"BILLOW": [1]}, "out": 5}', '"out" is a string'),
    "path-not-in-recipe": ('{"recipe": SAIL, "grid": {"BILLOW.x": [1]}}', "BILLOW.x: the recipe has no key 'x' there"),
    "path-malformed": ('{"recipe": SAIL, "grid": {"a..b": [1]}}', "parameter path \"a..b\" has an empty key"),
    "same-variant-twice": ('{"recipe": SAIL, "grid": {"BILLOW": [1, 1]}}', "variants 1 and 2 have the same parameters"),
}


@pytest.mark.parametrize("case", list(BAD_DESCRIPTIONS))
def test_a_bad_description_exits_2_with_one_line(examples: Path, exe: str, tmp_path: Path, case: str) -> None:
    text, message = BAD_DESCRIPTIONS[case]
    description = tmp_path / "bad.json"
    sail = json.dumps(str(examples / "recipes" / "sail.json"))
    description.write_text(text.replace("SAIL", sail).replace("BILLOW", BILLOW))
    failed = subprocess.run([exe, "sweep", str(description), "--out", str(tmp_path / "out")], capture_output=True,
                            text=True)
    assert failed.returncode == 2  # not 1, "some variants failed": nothing ran
    lines = failed.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"sweep: {description}: "), failed.stderr  # no traceback
    assert message.replace("BILLOW", BILLOW) in lines[0]
    assert not (tmp_path / "out").exists()  # refused before anything is written


def test_a_recipe_of_models_only_sweeps_with_pictures(examples: Path, tmp_path: Path) -> None:
    # block_model.json has models and no surfaces: every variant ran and then failed "render: no
    # surfaces" at the thumbnail. Its models are drawn instead, and their volumes indexed.
    lift = "deformations.lift[0].moves[0].to[2]"
    description = {"format": "clayform.sweep", "version": 1,
                   "recipe": str(examples / "recipes" / "block_model.json"), "grid": {lift: [31, 40]}}
    rows = cf.sweep(description, tmp_path, workers=2, progress=lambda *a: None)
    assert [r["status"] for r in rows] == ["ok", "ok"], rows
    # Lifting the top further adds volume (both models are summed; only the lifted one changes).
    assert rows[1]["volume_mm3"] > rows[0]["volume_mm3"] > 0
    from PIL import Image

    for row in rows:
        assert (tmp_path / row["id"] / "block_lifted.step").is_file()
        with Image.open(tmp_path / row["id"] / "thumbnail.png") as picture:
            assert picture.size == (320, 240)
            pixels = np.asarray(picture.convert("RGB"), dtype=int)
        drawn = (pixels.sum(axis=2) < 3 * 250).mean()  # not background
        assert 0.1 < drawn < 0.9
    assert (tmp_path / "contact_sheet.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def variant_processes(mark: str) -> List[int]:
    """Live variant processes started under the environment mark (zombies have no environment)."""
    found = []
    for proc in Path("/proc").iterdir():
        if proc.name.isdigit():
            try:
                environ = (proc / "environ").read_bytes().split(b"\0")
                if f"CLAYFORM_TEST_MARK={mark}".encode() in environ and b"--run-variant" in (proc / "cmdline").read_bytes():
                    found.append(int(proc.name))
            except OSError:
                pass
    return found


def wait_for(condition: Callable[[], bool], seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_a_killed_sweep_leaves_no_process_no_temporary_and_an_index(examples: Path, exe: str, tmp_path: Path,
                                                                   sig: int) -> None:
    description = tmp_path / "sweep.json"
    description.write_text(json.dumps(spec(examples, [0, 100, 200, 300])))
    out, tmp, mark = tmp_path / "out", tmp_path / "tmp", uuid.uuid4().hex
    tmp.mkdir()  # the sweep's TMPDIR: whatever it would leave in /tmp lands here
    env = {**os.environ, "TMPDIR": str(tmp), "CLAYFORM_TEST_MARK": mark}
    sweep = subprocess.Popen([exe, "sweep", str(description), "--out", str(out), "--workers", "1"], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # Kill it after the first variant finished (its folder in place and indexed: the sweep
        # renames the folder, then writes the index, and a SIGKILL between the two, which a loaded
        # machine widened, leaves the index to the next run), while the second runs.
        def indexed() -> bool:
            folders = {p.parent.name for p in out.glob("*/variant.json")}
            index = out / "index.jsonl"  # (index.csv follows it: read with index_ids below)
            return bool(folders) and index.exists() and folders <= {
                json.loads(line)["id"] for line in index.read_text().splitlines()}

        assert wait_for(lambda: indexed() and bool(variant_processes(mark)), 60)
        running = variant_processes(mark)
        sweep.send_signal(sig)
        _, stderr = sweep.communicate(timeout=30)
    finally:
        if sweep.poll() is None:
            sweep.kill()
    assert len(running) == 1
    # No variant process outlives the sweep (a SIGKILLed one included: they die with it).
    assert wait_for(lambda: not variant_processes(mark), 0.5), variant_processes(mark)
    assert list(tmp.iterdir()) == []  # no clayform-variant-* folder (nor anything else) in TMPDIR
    finished = sorted(p.parent.name for p in out.glob("*/variant.json"))
    assert len(finished) >= 1 and sorted(index_ids(out)) == finished  # the index lists what finished
    staging = [p.name for p in out.iterdir() if p.name.startswith(".staging-")]
    if sig == signal.SIGTERM:
        assert sweep.returncode == 128 + signal.SIGTERM
        assert stderr.splitlines()[-1] == (f"sweep: stopped by SIGTERM: {len(finished)} of 4 variants finished, "
                                           f"indexed in {out / 'index.csv'}; run it again to resume")
        assert staging == [] and not (out / "contact_sheet.png").exists()
    else:
        assert sweep.returncode == -signal.SIGKILL
        assert len(staging) <= 1  # the killed variant's, in OUT, not /tmp; the next run removes it
    again = subprocess.run([exe, "sweep", str(description), "--out", str(out)], capture_output=True, text=True,
                           env=env)
    assert again.returncode == 0, again.stderr
    assert again.stderr.count(" done") == len(finished) and again.stderr.count(" ok ") == 4 - len(finished)
    assert not [p for p in out.iterdir() if p.name.startswith(".staging-")] and len(index_ids(out)) == 4
    assert list(tmp.iterdir()) == []


def test_a_storage_error_stops_the_sweep_at_once(examples: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # As root, a read-only folder still takes writes: the full disk is simulated at the rename
    # that moves the second finished variant into place.
    description = spec(examples, [0, 100, 200, 300])
    ids = [sweeps.variant_id(p) for p in sweeps.variants(description)]
    started: list = []
    moved: list = []
    refused: list = []
    real_run, real_rename = sweeps.run_variant_isolated, sweeps._rename

    def counting(job: dict, children: object = None, process: object = None) -> dict:
        started.append(job)
        return real_run(job, children, process)  # type: ignore[arg-type]

    def full_disk(src: str, dst: str) -> None:
        if Path(dst).name in ids:
            if moved:
                refused.append(str(dst))
                raise OSError(errno.ENOSPC, "No space left on device", str(dst))
            moved.append(Path(dst).name)
        real_rename(src, dst)

    monkeypatch.setattr(sweeps, "run_variant_isolated", counting)
    monkeypatch.setattr(sweeps, "_rename", full_disk)
    with pytest.raises(sweeps.StorageError) as caught:
        cf.sweep(description, tmp_path, workers=1, progress=lambda *a: None)
    error = caught.value
    assert isinstance(error, OSError) and error.errno == errno.ENOSPC and error.filename == refused[0]
    assert str(error).startswith(f"sweep: {refused[0]}: No space left on device; the sweep stopped: 1 of 4 "
                                 f"variants finished, indexed in {tmp_path / 'index.csv'}; free some space")
    # The pending variants did not run: the first, the refused one and at most the one the
    # worker had started meanwhile (killed); never the fourth.
    assert len(refused) == 1 and 2 <= len(started) <= 3
    # Nothing half-written stays: no staging folder, no temporary, no contact sheet.
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([".sweep.lock", moved[0], "index.csv", "index.jsonl"])
    assert index_ids(tmp_path) == moved
    monkeypatch.undo()
    again = cf.sweep(description, tmp_path, workers=2, progress=lambda *a: None)
    assert sorted(r["status"] for r in again) == ["done", "ok", "ok", "ok"]


def test_the_command_stops_on_a_storage_error_naming_the_folder(examples: Path, exe: str, tmp_path: Path) -> None:
    # A real storage error, as root too: files may not grow past 200 kB (EFBIG), which the sail's
    # IGES file and view meshes do. Every variant would meet it: the first stops the sweep.
    description = tmp_path / "sweep.json"
    description.write_text(json.dumps(spec(examples, [0, 100, 200, 300])))
    out = tmp_path / "out"
    limited = subprocess.run([exe, "sweep", str(description), "--out", str(out), "--workers", "1"],
                             capture_output=True, text=True,
                             preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000)))
    assert limited.returncode == 2, limited.stderr
    lines = limited.stderr.splitlines()
    assert lines[-1].startswith(f"sweep: {out}: File too large; the sweep stopped: 0 of 4 variants finished, "
                                f"indexed in {out / 'index.csv'}; raise the file size limit (ulimit -f)")
    assert "Traceback" not in limited.stderr and not [x for x in lines if x.startswith("[")]  # none reported
    assert sorted(p.name for p in out.iterdir()) == [".sweep.lock", "index.csv", "index.jsonl"]
    assert index_ids(out) == []
