"""Sweeps of recipe variants: one description, every variant run, an index and a contact sheet.

A sweep description (JSON, or the same dict in Python; docs/sweeps.md):

    {"format": "clayform.sweep", "version": 1,
     "recipe": "sail.json",                       # the base recipe, relative to the description
     "grid": {"deformations.billow[0].moves[0].by[1]": [0, 150, 300],
              "deformations.styling[0].lambda": [0.5, 1.0]}}
    # or "list": [{"deformations.styling[0].lambda": 0.5}, ...]

Each parameter is a JSON path into the recipe (keys joined by ".", list items as "[i]") and its
values; "grid" runs every combination, "list" the given ones. Every variant runs in its own
process (OpenCASCADE's STEP writer is not thread-safe, and a variant that crashes loses only
itself) and writes its STEP, IGES, glTF, report.json, thumbnail.png and variant.json into
OUT/<id>, where id is a hash of its parameters. Folders appear whole (written beside, then
renamed), so a re-run skips the variants already done and a killed sweep resumes. The sweep
writes OUT/index.csv and OUT/index.jsonl (each variant's figures: deviation, volume ratios,
fold-free, time, status) and OUT/contact_sheet.png.

Executors: "local" (processes on this machine, the default) and "dask" (a
distributed.LocalCluster, or an existing cluster at `scheduler`, e.g. "tcp://host:8786").
"""
from __future__ import annotations

import base64
import concurrent.futures
import csv
import hashlib
import itertools
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Optional, Tuple, Union

Params = Dict[str, Any]
Spec = Dict[str, Any]

#: Written into each finished variant's folder, last: its presence marks the variant done.
VARIANT_FILE = "variant.json"
INDEX_FIELDS = [
    "id",
    "status",
    "seconds",
    "deviation_mm",
    "volume_mm3",
    "volume_ratio_min",
    "volume_ratio_max",
    "fold_free",
    "control_points",
    "error",
    "parameters",
]
_TOKEN = re.compile(r"([^.\[\]]+)|\[(\d+)\]")


def parse_path(path: str) -> List[Union[str, int]]:
    """'deformations.billow[0].moves[1].by[2]' -> ['deformations', 'billow', 0, 'moves', 1, 'by', 2]."""
    parts: List[Union[str, int]] = []
    pos = 0
    for m in _TOKEN.finditer(path):
        if m.start() != pos and path[pos:m.start()] != ".":
            break
        parts.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
        pos = m.end()
    if not parts or pos != len(path):
        raise ValueError(f"sweep: parameter path {path!r} is not keys joined by '.' with list items as [i]")
    return parts


def set_path(document: Any, path: str, value: Any) -> None:
    """Sets the value at a JSON path of the recipe; the path must exist (no silent additions)."""
    parts = parse_path(path)
    node = document
    for depth, key in enumerate(parts):
        where = path if depth == len(parts) - 1 else "".join(
            f"[{p}]" if isinstance(p, int) else (("." if i else "") + p) for i, p in enumerate(parts[: depth + 1])
        )
        if isinstance(key, int):
            if not isinstance(node, list) or key >= len(node):
                raise ValueError(f"sweep: {where}: the recipe has no list item there")
        elif not isinstance(node, dict) or key not in node:
            raise ValueError(f"sweep: {where}: the recipe has no key {key!r} there")
        if depth == len(parts) - 1:
            node[key] = value
        else:
            node = node[key]


def variants(spec: Spec) -> List[Params]:
    """The parameter sets of a description: every combination of "grid", or the "list"."""
    if ("grid" in spec) == ("list" in spec):
        raise ValueError('sweep: give either "grid" (values per path) or "list" (parameter sets)')
    if "grid" in spec:
        grid: Dict[str, List[Any]] = spec["grid"]
        if not grid or any(not isinstance(v, list) or not v for v in grid.values()):
            raise ValueError('sweep: "grid" maps each path to a non-empty list of values')
        keys = list(grid)
        return [dict(zip(keys, combo)) for combo in itertools.product(*(grid[k] for k in keys))]
    items: List[Params] = spec["list"]
    if not items or any(not isinstance(p, dict) for p in items):
        raise ValueError('sweep: "list" is a non-empty list of {path: value} objects')
    return [dict(p) for p in items]


def variant_id(params: Params) -> str:
    """The folder name of a variant: the first 16 hex digits of SHA-256 of its parameters."""
    text = json.dumps(params, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_spec(spec: Union[str, "os.PathLike[str]", Spec]) -> Tuple[Spec, str, Path]:
    """The description, the base recipe's text and the folder its imports are resolved in."""
    if isinstance(spec, (str, os.PathLike)):
        path = Path(spec)
        document = json.loads(path.read_text())
        base = path.parent
    else:
        document = dict(spec)
        base = Path.cwd()
    if document.get("format", "clayform.sweep") != "clayform.sweep" or document.get("version", 1) != 1:
        raise ValueError('sweep: expected "format": "clayform.sweep", "version": 1')
    unknown = sorted(set(document) - {"format", "version", "description", "recipe", "grid", "list", "out"})
    if unknown:
        raise ValueError(f"sweep: unknown key(s) {', '.join(unknown)}; the description takes format, version, "
                         "description, recipe, grid or list, out")
    recipe = document.get("recipe")
    if recipe is None:
        raise ValueError('sweep: "recipe" names the base recipe file')
    recipe_path = Path(recipe) if Path(recipe).is_absolute() else base / recipe
    return document, recipe_path.read_text(), recipe_path.parent


def recipe_text(base_text: str, params: Params) -> str:
    """The base recipe with the variant's values set."""
    document = json.loads(base_text)
    for path, value in params.items():
        set_path(document, path, value)
    return json.dumps(document, indent=1)


def _figures(report: Dict[str, Any]) -> Dict[str, Any]:
    """The index figures of one run's report."""
    deviation = 0.0
    ratios: List[float] = []
    fold: Optional[bool] = None
    points = 0
    volume: Optional[float] = None
    for step in report.get("steps", []):
        f = step.get("figures", {})
        if isinstance(f.get("max_deviation_mm"), (int, float)):
            deviation = max(deviation, float(f["max_deviation_mm"]))
        for key in ("volume_ratio_min", "volume_ratio_max"):
            if isinstance(f.get(key), (int, float)):
                ratios.append(float(f[key]))
        if isinstance(f.get("fold_free"), bool):
            fold = f["fold_free"] if fold is None else (fold and f["fold_free"])
        if step.get("kind") == "export" and isinstance(f.get("control_points"), int):
            points += f["control_points"]
        if step.get("kind") == "model" and isinstance(f.get("volume_after_mm3"), (int, float)):
            volume = (volume or 0.0) + float(f["volume_after_mm3"])
    return {
        "deviation_mm": deviation,
        "volume_mm3": volume,
        "volume_ratio_min": min(ratios) if ratios else None,
        "volume_ratio_max": max(ratios) if ratios else None,
        "fold_free": fold,
        "control_points": points,
    }


def run_variant_here(text: str, base_dir: str, out_dir: str) -> Dict[str, Any]:
    """Runs one variant in this process, writing its outputs and a thumbnail into out_dir."""
    from . import Recipe, render_png  # the extension, imported where the variant runs

    start = time.perf_counter()
    recipe = Recipe.parse(text, base_dir)
    result = recipe.run(out_dir)
    finals = [result.surfaces[name] for name in recipe.final_surfaces]
    Path(out_dir, "thumbnail.png").write_bytes(render_png(finals, width=320, height=240))
    return {"status": "ok", "seconds": time.perf_counter() - start, **_figures(result.report)}


def run_variant_isolated(job: Dict[str, Any]) -> Dict[str, Any]:
    """Runs one variant in a child process and returns its figures and files (as base64), so
    that it works the same on this machine and on a Dask worker elsewhere. A variant that raises
    is "failed" with its message; one that kills its process is "crashed" with the signal."""
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="clayform-variant-") as tmp:
        env = dict(os.environ)
        if job.get("abort"):
            env["CLAYFORM_SWEEP_ABORT"] = "1"
        child = subprocess.run(
            [sys.executable, "-m", "clayform.sweeps", "--run-variant"],
            input=json.dumps({"text": job["text"], "base_dir": job["base_dir"], "out": tmp}),
            capture_output=True,
            text=True,
            env=env,
        )
        seconds = time.perf_counter() - start
        if child.returncode < 0:
            name = signal.Signals(-child.returncode).name
            return {"status": "crashed", "seconds": seconds, "error": f"the variant's process died ({name})"}
        try:
            answer: Dict[str, Any] = dict(json.loads(child.stdout.strip().splitlines()[-1]))
        except (IndexError, json.JSONDecodeError):
            tail = child.stderr.strip().splitlines()[-1:] or [f"exit code {child.returncode}"]
            return {"status": "crashed", "seconds": seconds, "error": tail[0]}
        if answer["status"] == "ok":
            files: Dict[str, str] = {}
            for path in Path(tmp).rglob("*"):
                if path.is_file():
                    files[str(path.relative_to(tmp))] = base64.b64encode(path.read_bytes()).decode()
            answer["files"] = files
        answer["seconds"] = seconds
        return answer


def _child_main() -> int:
    """`python -m clayform.sweeps --run-variant`: one variant, its job on stdin, one JSON line out."""
    job = json.loads(sys.stdin.read())
    if os.environ.get("CLAYFORM_SWEEP_ABORT") == "1":
        os.abort()  # fault injection for the tests: a variant that kills its process
    try:
        answer = run_variant_here(job["text"], job["base_dir"], job["out"])
    except Exception as e:  # noqa: BLE001 - every failure is the variant's result
        answer = {"status": "failed", "error": f"{type(e).__name__}: {e}"}
    print(json.dumps(answer))
    return 0


def _store(out: Path, vid: str, params: Params, answer: Dict[str, Any]) -> Dict[str, Any]:
    """Writes a finished variant's folder atomically and returns its index row."""
    row: Dict[str, Any] = {field: answer.get(field) for field in INDEX_FIELDS}
    row.update(id=vid, parameters=params)
    if answer["status"] != "ok":
        return row
    staging = Path(tempfile.mkdtemp(prefix=f".{vid}-", dir=out))
    for name, data in answer["files"].items():
        target = staging / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(base64.b64decode(data))
    (staging / VARIANT_FILE).write_text(json.dumps(row, indent=1))
    final = out / vid
    if final.exists():
        shutil.rmtree(final)
    os.rename(staging, final)
    return row


def _done(out: Path, vid: str) -> Optional[Dict[str, Any]]:
    path = out / vid / VARIANT_FILE
    if not path.exists():
        return None
    row: Dict[str, Any] = dict(json.loads(path.read_text()))
    row["status"] = "done"  # finished by an earlier run: skipped
    return row


def _write_index(out: Path, rows: List[Dict[str, Any]]) -> None:
    with open(out / ".index.jsonl", "w") as f:
        for row in rows:
            f.write(json.dumps(row) + "\n")
    os.replace(out / ".index.jsonl", out / "index.jsonl")
    with open(out / ".index.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=INDEX_FIELDS)
        writer.writeheader()
        for row in rows:
            writer.writerow({**row, "parameters": json.dumps(row["parameters"], sort_keys=True)})
    os.replace(out / ".index.csv", out / "index.csv")


def contact_sheet(out: Union[str, "os.PathLike[str]"], rows: List[Dict[str, Any]], columns: int = 4) -> Path:
    """OUT/contact_sheet.png: each variant's thumbnail in a grid, labelled by its parameters
    (failed variants as a grey tile with their status)."""
    from PIL import Image, ImageDraw  # python3-pil

    folder = Path(out)
    paths = sorted({p for row in rows for p in row["parameters"]})

    def label(path: str) -> str:
        # The shortest tail of the path (in "."-parts) that no other parameter's path ends with.
        parts = path.split(".")
        for n in range(1, len(parts) + 1):
            tail = ".".join(parts[-n:])
            if not any(q != path and q.endswith(tail) for q in paths):
                return tail
        return path

    tile_w, tile_h, label_h = 320, 240, 16 * 3
    count = max(len(rows), 1)
    cols = min(columns, count)
    sheet = Image.new("RGB", (cols * tile_w, -(-count // cols) * (tile_h + label_h)), "white")
    draw = ImageDraw.Draw(sheet)
    for k, row in enumerate(rows):
        x, y = (k % cols) * tile_w, (k // cols) * (tile_h + label_h)
        thumb = folder / row["id"] / "thumbnail.png"
        if thumb.exists():
            sheet.paste(Image.open(thumb).convert("RGB").resize((tile_w, tile_h)), (x, y))
        else:
            draw.rectangle((x, y, x + tile_w - 1, y + tile_h - 1), fill=(200, 200, 200))
            draw.text((x + 8, y + tile_h // 2), str(row["status"]), fill="black")
        lines = [f"{label(p)} = {v}" for p, v in row["parameters"].items()][:2]
        lines.append(f"{row['id'][:8]}  {row['status']}")
        for i, line in enumerate(lines):
            draw.text((x + 6, y + tile_h + 2 + 15 * i), line[:48], fill="black")
    path = folder / "contact_sheet.png"
    staging = folder / ".contact_sheet.png"
    sheet.save(staging, format="PNG")
    os.replace(staging, path)
    return path


def run(
    spec: Union[str, "os.PathLike[str]", Spec],
    out: Union[str, "os.PathLike[str]", None] = None,
    executor: str = "local",
    workers: int = 2,
    scheduler: Optional[str] = None,
    progress: Optional[Callable[[int, int, Dict[str, Any]], None]] = None,
    abort: Iterable[str] = (),
) -> List[Dict[str, Any]]:
    """Runs every variant of the description into OUT (see the module's doc); returns the index
    rows in the description's order. Without `out`, the description's "out" (relative to its
    folder) is used. `executor` is "local" or "dask" (`scheduler` an address of
    an existing cluster, else a LocalCluster of `workers` processes). `progress(done, total, row)`
    is called as variants finish (default: a line on stderr). `abort` lists variant ids whose
    process is made to abort (fault injection for tests)."""
    document, base_text, base_dir = load_spec(spec)
    if out is None:
        if "out" not in document:
            raise ValueError('sweep: give the output folder (out=..., --out) or "out" in the description')
        spec_dir = Path(spec).parent if isinstance(spec, (str, os.PathLike)) else Path.cwd()
        out = spec_dir / document["out"]
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    sets = variants(document)
    ids = [variant_id(p) for p in sets]
    if len(set(ids)) != len(ids):
        raise ValueError("sweep: two variants have the same parameters")
    rows: Dict[str, Dict[str, Any]] = {}
    jobs: Dict[str, Dict[str, Any]] = {}
    for vid, params in zip(ids, sets):
        done = _done(folder, vid)
        if done is not None:
            rows[vid] = done
            continue
        jobs[vid] = {
            "text": recipe_text(base_text, params),
            "base_dir": str(base_dir),
            "abort": vid in set(abort),
        }
    report = progress or _print_progress
    finished = len(rows)
    for vid in ids:
        if vid in rows:
            report(finished, len(ids), rows[vid])

    def accept(vid: str, answer: Dict[str, Any]) -> None:
        nonlocal finished
        rows[vid] = _store(folder, vid, sets[ids.index(vid)], answer)
        finished += 1
        report(finished, len(ids), rows[vid])

    if jobs and executor == "local":
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
            futures = {pool.submit(run_variant_isolated, job): vid for vid, job in jobs.items()}
            for future in concurrent.futures.as_completed(futures):
                accept(futures[future], future.result())
    elif jobs and executor == "dask":
        _run_dask(jobs, accept, workers, scheduler)
    elif executor not in ("local", "dask"):
        raise ValueError(f'sweep: executor {executor!r} is not "local" or "dask"')
    ordered = [rows[vid] for vid in ids]
    _write_index(folder, ordered)
    contact_sheet(folder, ordered)
    return ordered


def _run_dask(
    jobs: Dict[str, Dict[str, Any]],
    accept: Callable[[str, Dict[str, Any]], None],
    workers: int,
    scheduler: Optional[str],
) -> None:
    import importlib

    # python3-distributed has no type information: used through Any.
    dask: Any = importlib.import_module("distributed")
    Client, LocalCluster, as_completed = dask.Client, dask.LocalCluster, dask.as_completed
    cluster = None
    if scheduler is None:
        # One thread per worker process: each runs one variant at a time (in its own child).
        cluster = LocalCluster(n_workers=max(1, workers), threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    else:
        client = Client(scheduler)
    try:
        futures = {
            client.submit(run_variant_isolated, job, key=f"clayform-variant-{vid}", pure=False): vid
            for vid, job in jobs.items()
        }
        for future in as_completed(futures):
            vid = futures[future]
            try:
                answer = future.result()
            except Exception as e:  # noqa: BLE001 - a lost worker loses only this variant
                answer = {"status": "crashed", "seconds": None, "error": f"{type(e).__name__}: {e}"}
            accept(vid, answer)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _print_progress(done: int, total: int, row: Dict[str, Any]) -> None:
    seconds = row.get("seconds")
    took = f" {seconds:.2f} s" if isinstance(seconds, (int, float)) else ""
    error = f": {row['error']}" if row.get("error") else ""
    print(f"[{done}/{total}] {row['id']} {row['status']}{took}{error}", file=sys.stderr, flush=True)


def main(argv: Optional[List[str]] = None) -> int:
    """`python -m clayform.sweeps SPEC --out DIR [--executor local|dask] [--workers N]
    [--scheduler tcp://HOST:8786]` (what `clayform sweep` runs)."""
    import argparse

    args = list(sys.argv[1:] if argv is None else argv)
    if args == ["--run-variant"]:
        return _child_main()
    parser = argparse.ArgumentParser(prog="clayform sweep", description="Run every variant of a sweep.")
    parser.add_argument("spec", help="the sweep description (JSON)")
    parser.add_argument("--out", required=True, help="the output folder (re-runs skip finished variants)")
    parser.add_argument("--executor", choices=["local", "dask"], default="local")
    parser.add_argument("--workers", type=int, default=2, help="processes (local) or Dask workers (LocalCluster)")
    parser.add_argument("--scheduler", help="address of an existing Dask scheduler (implies --executor dask)")
    a = parser.parse_args(args)
    try:
        rows = run(a.spec, a.out, "dask" if a.scheduler else a.executor, a.workers, a.scheduler)
    except (ValueError, OSError) as e:
        print(f"clayform sweep: {e}", file=sys.stderr)
        return 2
    bad = [r for r in rows if r["status"] not in ("ok", "done")]
    print(f"{len(rows)} variants: {len(rows) - len(bad)} done, {len(bad)} failed; index {Path(a.out) / 'index.csv'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
