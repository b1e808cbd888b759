"""Sweeps of recipe variants: one description, every variant run, an index and a contact sheet.

A sweep description (JSON, or the same dict in Python; docs/sweeps.md):

    {"format": "clayform.sweep", "version": 1,
     "recipe": "sail.json",                       # the base recipe, relative to the description
     "grid": {"deformations.billow[0].moves[0].by[1]": [0, 150, 300],
              "deformations.styling[0].lambda": [0.5, 1.0]}}
    # or "list": [{"deformations.styling[0].lambda": 0.5}, ...]

Each parameter is a JSON path into the recipe (keys joined by ".", list items as "[i]") and its
values; "grid" runs every combination, "list" the given ones. The description is checked whole
before anything runs or is written (shape, paths, at most MAX_VARIANTS variants counted without
building them): SpecError, one line naming its file and the fix. Variants run in variant
processes, one variant at a time each (OpenCASCADE's STEP writer is not thread-safe; a crash
loses only the variant it ran, and the next starts a new process); a process is kept for the
worker's next variants with one RunCache, so the steps variants share (a surface built before the
swept lattice) are computed once per process. It dies with the sweep (even a SIGKILLed one) and
writes into OUT/.staging-<id>-<random>; the sweep
adds variant.json and renames the folder into OUT/<id> (id: a hash of the parameters), so a re-run
skips finished variants. OUT/index.csv and OUT/index.jsonl are rewritten (temporary, then rename)
as variants finish; OUT/contact_sheet.png once all have run. A storage error stops the sweep at
once (StorageError, naming the path), SIGINT/SIGTERM/SIGHUP cleanly (Interrupted): the index
lists what finished and no staging folder stays.

Executors: "local" (processes on this machine, the default) and "dask" (a
distributed.LocalCluster, or an existing cluster at `scheduler`, e.g. "tcp://host:8786").
"""
from __future__ import annotations

import base64
import concurrent.futures
import contextlib
import csv
import errno
import fcntl
import hashlib
import io
import itertools
import json
import math
import os
import re
import shutil
import signal
import sys
import tempfile
import threading
import time
import warnings
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, Iterator, List, Optional, Set, Tuple, Union

from ._clayform import recipe_path
from ._variant_process import _Children, _child_main, _VariantProcess, run_variant_isolated, run_variant_on_worker
from .errors import InvalidArgumentError

if sys.argv[:1] == ["-m"]:
    # `python3 -m clayform.sweeps` (what `clayform sweep` runs): the package imports this module
    # before runpy runs it as __main__, and runpy warns about that on stderr, which should carry
    # only the sweep's own lines. Both copies are this file; nothing is shared between them.
    warnings.filterwarnings("ignore", message=r"'clayform\.sweeps' found in sys\.modules", category=RuntimeWarning)

Params = Dict[str, Any]
Spec = Dict[str, Any]

#: The most variants one description may give (grid: the product of its lists' lengths, counted
#: before any is built). Larger sweeps are refused: split them into several descriptions, or pass
#: run(..., max_variants=N) from Python.
MAX_VARIANTS = 10_000
#: Written into each finished variant's folder, last: its presence marks the variant done.
VARIANT_FILE = "variant.json"
#: Variants per contact sheet page (contact_sheet.png, contact_sheet_2.png, ...).
SHEET_TILES = 100
INDEX_FIELDS = ["id", "status", "seconds", "deviation_mm", "volume_mm3", "volume_ratio_min", "volume_ratio_max",
                "fold_free", "control_points", "steps_reused", "error", "parameters"]
_STAGING = ".staging-"
_LOCK = ".sweep.lock"
#: Every rename into OUT goes through here (a seam for the tests' storage faults).
_rename = os.replace
class SpecError(ValueError):
    """A sweep description that cannot run, found before anything runs or is written. The
    message is one line: "sweep: SPEC: what is wrong and the fix" (SPEC the description's file;
    no SPEC for a description given as a dict)."""

    def __init__(self, detail: str, spec: Optional[str] = None) -> None:
        self.detail = " ".join(detail.split())
        self.spec = spec
        super().__init__(f"sweep: {spec}: {self.detail}" if spec else f"sweep: {self.detail}")


class StorageError(OSError):
    """Writing into the output folder failed (errno, strerror and filename as OSError has them).
    The sweep stopped at once: no other variant was started, the staging folders are gone and the
    index lists the variants that finished (unless writing it failed too; the message says)."""

    def __init__(self, cause: OSError, path: str, finished: int, total: int, index: str) -> None:
        super().__init__(cause.errno, cause.strerror or str(cause), path)
        self.finished = finished
        self.total = total
        fix = {
            errno.ENOSPC: "free some space",
            errno.EDQUOT: "free some space or raise the quota",
            errno.EFBIG: "raise the file size limit (ulimit -f) or use a file system that takes larger files",
        }.get(cause.errno or 0, "make the folder writable or choose another output folder")
        self.message = (
            f"sweep: {path}: {self.strerror}; the sweep stopped: {finished} of {total} variants "
            f"finished, {index}; {fix}, then run it again (finished variants are skipped)"
        )

    def __str__(self) -> str:
        return self.message


class Interrupted(KeyboardInterrupt):
    """The sweep was stopped by a signal (SIGINT, SIGTERM, SIGHUP) after killing its running
    variants, removing their staging folders and writing the index of what finished."""

    def __init__(self, signum: int, message: str) -> None:
        super().__init__(message)
        self.signum = signum
        self.message = message


class FolderInUse(RuntimeError):
    """Another sweep is writing into the same output folder."""


def parse_path(path: str) -> List[Union[str, int]]:
    """'deformations.billow[0].moves[1].by[2]' -> ['deformations', 'billow', 0, 'moves', 1, 'by', 2]:
    the kernel's grammar (clayform.recipe_path), the one the studio's edits use."""
    if not isinstance(path, str):
        raise SpecError(f"parameter path {path!r} is not a string of keys joined by '.' with list items as [i]")
    try:
        return recipe_path(path)
    except InvalidArgumentError as e:
        raise SpecError(f"parameter {e}") from None


def _walk(document: Any, path: str) -> Tuple[Any, Union[str, int]]:
    """The container and key of a JSON path of the recipe; every part must exist."""
    parts = parse_path(path)
    node = document
    for depth, key in enumerate(parts):
        where = path if depth == len(parts) - 1 else "".join(
            f"[{p}]" if isinstance(p, int) else (("." if i else "") + p) for i, p in enumerate(parts[: depth + 1])
        )
        if isinstance(key, int):
            if not isinstance(node, list) or key >= len(node):
                raise SpecError(f"{where}: the recipe has no list item there")
        elif not isinstance(node, dict) or key not in node:
            raise SpecError(f"{where}: the recipe has no key {key!r} there")
        if depth == len(parts) - 1:
            return node, key
        node = node[key]
    raise AssertionError("unreachable")


def set_path(document: Any, path: str, value: Any) -> None:
    """Sets the value at a JSON path of the recipe; the path must exist (no silent additions)."""
    node, key = _walk(document, path)
    node[key] = value


def count_variants(spec: Spec, limit: Optional[int] = None) -> int:
    """How many variants a description gives, without building them (the product of the grid's
    list lengths, or the list's length), after checking the shape of "grid" or "list"; more than
    `limit` are refused."""
    if ("grid" in spec) == ("list" in spec):
        raise SpecError('give either "grid" (values per path) or "list" (parameter sets), not both')
    if "grid" in spec:
        grid = spec["grid"]
        if not isinstance(grid, dict) or not grid:
            raise SpecError('"grid" maps each path to a non-empty list of values, e.g. {"a.b[0]": [1, 2]}')
        for path, values in grid.items():
            parse_path(path)
            if not isinstance(values, list) or not values:
                raise SpecError(f'"grid": {path}: give a non-empty list of values, e.g. [1, 2]')
        count, what = math.prod(len(v) for v in grid.values()), " × ".join(str(len(v)) for v in grid.values()) + " values"
    else:
        items = spec["list"]
        if not isinstance(items, list) or not items:
            raise SpecError('"list" is a non-empty list of {path: value} objects')
        for k, p in enumerate(items):
            if not isinstance(p, dict):
                raise SpecError(f'"list"[{k}]: expected a {{path: value}} object')
            for path in p:
                parse_path(path)
        count, what = len(items), "list items"
    if limit is not None and count > limit:
        raise SpecError(f"{count:,} variants ({what}), more than the limit of "
                        f"{limit:,} (clayform.sweeps.MAX_VARIANTS); give fewer values, or split the sweep into "
                        "several descriptions")
    return count


def variants(spec: Spec, limit: int = MAX_VARIANTS) -> List[Params]:
    """The parameter sets of a description: every combination of "grid", or the "list". Refuses
    more than `limit` variants before building any."""
    count_variants(spec, limit)
    if "grid" in spec:
        grid: Dict[str, List[Any]] = spec["grid"]
        keys = list(grid)
        return [dict(zip(keys, combo)) for combo in itertools.product(*(grid[k] for k in keys))]
    return [dict(p) for p in spec["list"]]


def variant_id(params: Params) -> str:
    """The folder name of a variant: the first 16 hex digits of SHA-256 of its parameters."""
    text = json.dumps(params, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _read_json(path: Path, what: Optional[str]) -> Any:
    """A JSON file: the description (what None: its path starts the message) or one it names."""
    name = f"{what}: {path}" if what else "the description"
    try:
        return json.loads(path.read_bytes().decode("utf-8"))
    except OSError as e:
        raise SpecError(f"{what}: cannot read {path} ({e.strerror or e})" if what else
                        f"cannot read it ({e.strerror or e})") from None
    except UnicodeDecodeError:
        raise SpecError(f"{name} is not UTF-8 text") from None
    except json.JSONDecodeError as e:
        raise SpecError(f"{name} is not JSON ({e.msg} at line {e.lineno}, column {e.colno})") from None


def load_spec(spec: Union[str, "os.PathLike[str]", Spec], limit: int = MAX_VARIANTS) -> Tuple[Spec, str, Path]:
    """The checked description, the base recipe's text and the folder its imports are resolved in.
    Raises SpecError (one line naming the description's file) for anything that cannot run."""
    try:
        return _load(spec, limit)
    except SpecError as e:
        if not isinstance(spec, (str, os.PathLike)) or e.spec is not None:
            raise
        raise SpecError(e.detail, os.fspath(spec)) from None


def _load(spec: Union[str, "os.PathLike[str]", Spec], limit: int) -> Tuple[Spec, str, Path]:
    if isinstance(spec, (str, os.PathLike)):
        path = Path(spec)
        document = _read_json(path, None)
        base = path.parent
    elif isinstance(spec, dict):
        document, base = dict(spec), Path.cwd()
    else:
        raise SpecError(f"give the description as a JSON file's path or a dict, not {type(spec).__name__}")
    if not isinstance(document, dict):
        raise SpecError('expected a JSON object {"format": "clayform.sweep", "version": 1, "recipe": ..., "grid": ...}')
    version = document.get("version", 1)
    if document.get("format", "clayform.sweep") != "clayform.sweep" or type(version) is not int or version != 1:
        raise SpecError('expected "format": "clayform.sweep", "version": 1')
    unknown = sorted(set(document) - {"format", "version", "description", "recipe", "grid", "list", "out"}, key=str)
    if unknown:
        raise SpecError(f"unknown key(s) {', '.join(map(str, unknown))}; the description takes format, version, "
                        "description, recipe, grid or list, out")
    for key in ("description", "out"):
        if key in document and not isinstance(document[key], str):
            raise SpecError(f'"{key}" is a string')
    count_variants(document, limit)  # before anything is built
    recipe = document.get("recipe")
    if not isinstance(recipe, str) or not recipe:
        raise SpecError('"recipe" names the base recipe file (relative to the description)')
    recipe_path = Path(recipe) if Path(recipe).is_absolute() else base / recipe
    base_recipe = _read_json(recipe_path, '"recipe"')
    if not isinstance(base_recipe, dict):
        raise SpecError(f'"recipe": {recipe_path} is not a recipe (a JSON object)')
    swept = document["grid"] if "grid" in document else {p: None for item in document["list"] for p in item}
    for key in swept:
        _walk(base_recipe, key)  # a path the recipe lacks is refused now, not in every variant
    return document, recipe_path.read_text(encoding="utf-8"), recipe_path.parent


def recipe_text(base_text: str, params: Params) -> str:
    """The base recipe with the variant's values set."""
    document = json.loads(base_text)
    for path, value in params.items():
        set_path(document, path, value)
    return json.dumps(document, indent=1)


def _store(out: Path, vid: str, params: Params, answer: Dict[str, Any], staging: Optional[Path] = None) -> Dict[str, Any]:
    """Moves a finished variant's folder into place whole and returns its index row: the files
    are in staging/<vid> (or, from a remote worker, in answer["files"], written into a new
    staging folder first); variant.json is added last, then the folder is renamed into out/<vid>."""
    row: Dict[str, Any] = {**{field: answer.get(field) for field in INDEX_FIELDS}, "id": vid, "parameters": params}
    if answer["status"] != "ok":
        return row
    if staging is None:
        staging = Path(tempfile.mkdtemp(prefix=f"{_STAGING}{vid}-", dir=out))
    try:
        folder = staging / vid
        for name, data in answer.get("files", {}).items():
            target = folder / name
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(base64.b64decode(data))
        (folder / VARIANT_FILE).write_text(json.dumps(row, indent=1))
        final = out / vid
        if final.exists():
            shutil.rmtree(final)  # a folder without variant.json: not a finished variant
        _rename(folder, final)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return row


def _done(out: Path, vid: str) -> Optional[Dict[str, Any]]:
    path = out / vid / VARIANT_FILE
    try:
        row: Dict[str, Any] = dict(json.loads(path.read_text()))
    except (OSError, ValueError, TypeError):
        return None  # not finished (or not readable): it runs again
    row["status"] = "done"  # finished by an earlier run: skipped
    return row


def _umask() -> int:
    status = re.search(r"^Umask:\s*([0-7]+)", Path("/proc/self/status").read_text(), re.M)  # Linux >= 4.7
    return int(status.group(1), 8) if status else 0o022


def _write_atomic(path: Path, data: Union[str, bytes]) -> None:
    """Writes a file of OUT beside itself (with the mode open() would give), then renames it
    into place."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            os.fchmod(f.fileno(), 0o666 & ~_umask())
            f.write(data.encode() if isinstance(data, str) else data)
        _rename(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


class _Index:
    """OUT/index.jsonl and OUT/index.csv: the finished variants in the description's order,
    rewritten as they finish (each row serialized once; rewrites are throttled to a twentieth
    of the time, so a sweep of thousands does not spend it rewriting)."""

    def __init__(self, folder: Path, ids: List[str]) -> None:
        self.folder, self.ids = folder, ids
        self.lines: Dict[str, Tuple[str, str]] = {}
        self.next_write = 0.0

    def add(self, row: Dict[str, Any]) -> None:
        buffer = io.StringIO()
        csv.DictWriter(buffer, fieldnames=INDEX_FIELDS, extrasaction="ignore").writerow(
            {**row, "parameters": json.dumps(row["parameters"], sort_keys=True)})
        self.lines[row["id"]] = (json.dumps(row) + "\n", buffer.getvalue())

    def write(self, soon: bool = False) -> None:
        if soon and time.perf_counter() < self.next_write:
            return
        start = time.perf_counter()
        rows = [self.lines[vid] for vid in self.ids if vid in self.lines]
        _write_atomic(self.folder / "index.jsonl", "".join(r[0] for r in rows))
        header = io.StringIO()
        csv.DictWriter(header, fieldnames=INDEX_FIELDS).writeheader()
        _write_atomic(self.folder / "index.csv", header.getvalue() + "".join(r[1] for r in rows))
        self.next_write = time.perf_counter() + 20 * (time.perf_counter() - start)


def contact_sheet(out: Union[str, "os.PathLike[str]"], rows: List[Dict[str, Any]], columns: int = 4) -> Path:
    """OUT/contact_sheet.png: each variant's thumbnail in a grid, labelled by its parameters
    (failed variants as a grey tile with their status), SHEET_TILES a page: more variants go on
    contact_sheet_2.png, contact_sheet_3.png, ... Returns the first page's path."""
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

    def page(rows: List[Dict[str, Any]], path: Path) -> None:
        tile_w, tile_h, label_h = 320, 240, 16 * 3
        count = max(len(rows), 1)
        cols = min(columns, count)
        sheet = Image.new("RGB", (cols * tile_w, -(-count // cols) * (tile_h + label_h)), "white")
        draw = ImageDraw.Draw(sheet)
        for k, row in enumerate(rows):
            x, y = (k % cols) * tile_w, (k // cols) * (tile_h + label_h)
            thumb = folder / row["id"] / "thumbnail.png"
            if thumb.exists():
                with Image.open(thumb) as picture:
                    sheet.paste(picture.convert("RGB").resize((tile_w, tile_h)), (x, y))
            else:
                draw.rectangle((x, y, x + tile_w - 1, y + tile_h - 1), fill=(200, 200, 200))
                missing = "no picture" if row["status"] in ("ok", "done") else str(row["status"])
                draw.text((x + 8, y + tile_h // 2), missing, fill="black")
            lines = [f"{label(p)} = {v}" for p, v in row["parameters"].items()][:2]
            lines.append(f"{row['id'][:8]}  {row['status']}")
            for i, line in enumerate(lines):
                draw.text((x + 6, y + tile_h + 2 + 15 * i), line[:48], fill="black")
        buffer = io.BytesIO()
        sheet.save(buffer, format="PNG")
        _write_atomic(path, buffer.getvalue())

    pages = [rows[k:k + SHEET_TILES] for k in range(0, max(len(rows), 1), SHEET_TILES)]
    names = ["contact_sheet.png"] + [f"contact_sheet_{n}.png" for n in range(2, len(pages) + 1)]
    for chunk, name in zip(pages, names):
        page(chunk, folder / name)
    for old in folder.glob("contact_sheet_*.png"):  # pages of an earlier, longer sweep
        if old.name not in names:
            with contextlib.suppress(OSError):
                old.unlink()
    return folder / names[0]


@contextlib.contextmanager
def _lock(folder: Path, total: int) -> Iterator[None]:
    """Creates OUT; one sweep at a time in it (flock on OUT/.sweep.lock, released by the kernel
    even when the sweep is killed). Under it, what a killed sweep left (staging folders,
    temporaries) is removed."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        handle = open(folder / _LOCK, "a+")
    except OSError as e:
        raise StorageError(e, str(e.filename or folder), 0, total, "nothing was written") from None
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise FolderInUse(f"sweep: {folder}: another sweep is writing into this folder; wait for it "
                              "to end or choose another output folder") from None
        for leftover in folder.iterdir():
            name = leftover.name
            if name.startswith(_STAGING) or re.fullmatch(r"\.[0-9a-f]{16}-.*", name):
                shutil.rmtree(leftover, ignore_errors=True)
            elif re.fullmatch(r"\.(index\.(csv|jsonl)|contact_sheet(_\d+)?\.png)\..*\.tmp", name):
                with contextlib.suppress(OSError):
                    leftover.unlink()
        yield
    finally:
        handle.close()


@contextlib.contextmanager
def _stop_on_signals(children: _Children) -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP stop the sweep cleanly (children killed, index written)
    instead of ending Python wherever it is. Only in the main thread, restored afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous: Dict[int, Any] = {}
    try:
        for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            previous[s] = signal.signal(s, lambda signum, frame: children.stop(signum))
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler if handler is not None else signal.SIG_DFL)


def run(
    spec: Union[str, "os.PathLike[str]", Spec],
    out: Union[str, "os.PathLike[str]", None] = None,
    executor: str = "local",
    workers: int = 2,
    scheduler: Optional[str] = None,
    progress: Optional[Callable[[int, int, Dict[str, Any]], None]] = None,
    abort: Iterable[str] = (),
    max_variants: int = MAX_VARIANTS,
) -> List[Dict[str, Any]]:
    """Runs every variant of the description into OUT (see the module's doc); returns the index
    rows in the description's order. Without `out`, the description's "out" (relative to its
    folder) is used. `executor` is "local" or "dask" (`scheduler` an address of
    an existing cluster, else a LocalCluster of `workers` processes). `progress(done, total, row)`
    is called as variants finish (default: a line on stderr). `abort` lists variant ids whose
    process is made to abort (fault injection for tests). Raises SpecError (nothing run or
    written), StorageError, FolderInUse or Interrupted (see the module's doc)."""
    if executor not in ("local", "dask"):
        raise ValueError(f'sweep: executor {executor!r} is not "local" or "dask"')
    where = os.fspath(spec) if isinstance(spec, (str, os.PathLike)) else None
    document, base_text, base_dir = load_spec(spec, max_variants)
    if out is None:
        if "out" not in document:
            raise SpecError('give the output folder (out=..., --out) or "out" in the description', where)
        spec_dir = Path(spec).parent if isinstance(spec, (str, os.PathLike)) else Path.cwd()
        out = spec_dir / document["out"]
    sets = variants(document, max_variants)
    try:
        ids = [variant_id(p) for p in sets]
    except (TypeError, ValueError) as e:
        raise SpecError(f"a value is not JSON ({e})", where) from None
    first: Dict[str, int] = {}
    for k, vid in enumerate(ids):
        if vid in first:
            raise SpecError(f"variants {first[vid] + 1} and {k + 1} have the same parameters "
                            f"({json.dumps(sets[k], sort_keys=True)[:200]}); give each value once", where)
        first[vid] = k
    folder = Path(out)
    children = _Children()
    with _lock(folder, len(ids)), _stop_on_signals(children):
        sweep = _Sweep(folder, ids, sets, base_text, base_dir, set(abort), children,
                       progress or _print_progress, progress is None)
        rows = sweep.run(executor, workers, scheduler)
    if children.signum is not None:  # checked once the handlers are back: no signal goes unseen
        name = signal.Signals(children.signum).name
        raise Interrupted(children.signum, f"sweep: stopped by {name}: {len(rows)} of {len(ids)} variants "
                                           f"finished, {sweep.index_note}; run it again to resume")
    return rows


class _Sweep:
    """One run of a checked description into a locked output folder."""

    def __init__(self, folder: Path, ids: List[str], sets: List[Params], base_text: str, base_dir: Path,
                 abort: Set[str], children: _Children, report: Callable[[int, int, Dict[str, Any]], None],
                 chatty: bool) -> None:
        self.folder, self.ids, self.sets = folder, ids, dict(zip(ids, sets))
        self.base_text, self.base_dir, self.abort = base_text, str(base_dir), abort
        self.children, self.report, self.chatty = children, report, chatty
        self.rows: Dict[str, Dict[str, Any]] = {}
        self.index = _Index(folder, ids)
        self.failure: Optional[Tuple[OSError, str]] = None
        self.index_note = ""

    def job(self, vid: str, stage: Optional[Path]) -> Dict[str, Any]:
        return {"text": recipe_text(self.base_text, self.sets[vid]), "base_dir": self.base_dir,
                "abort": vid in self.abort, "stage": str(stage / vid) if stage else None}

    def staging(self, vid: str) -> Optional[Path]:
        """A new staging folder in OUT for a variant about to start; None once the sweep stopped."""
        with self.children.lock:
            if self.children.stopped:
                return None
            path = Path(tempfile.mkdtemp(prefix=f"{_STAGING}{vid}-", dir=self.folder))
            self.children.stagings.add(path)
            return path

    def drop(self, staging: Optional[Path]) -> None:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
            with self.children.lock:
                self.children.stagings.discard(staging)

    def fail(self, error: OSError, path: str) -> None:
        """A storage error: stop everything now."""
        if self.failure is None:
            self.failure = (error, path)
        self.children.stop()

    def accept(self, vid: str, answer: Dict[str, Any], staging: Optional[Path]) -> None:
        status = answer.get("status")
        try:
            if self.failure is not None or (self.children.stopped and status in ("crashed", "stopped")):
                return  # killed, or never run, because the sweep stopped: not a result
            if status == "storage":  # met by the variant's process: OUT is named
                code = answer.get("errno") or errno.EIO
                self.fail(OSError(code, answer.get("error") or os.strerror(code)), str(self.folder))
                return
            row = self.rows[vid] = _store(self.folder, vid, self.sets[vid], answer, staging)
            self.index.add(row)
            self.index.write(soon=True)
        except OSError as e:
            self.fail(e, str(e.filename or self.folder))
            return
        finally:
            self.drop(staging)
        self.report(len(self.rows), len(self.ids), row)

    def run(self, executor: str, workers: int, scheduler: Optional[str]) -> List[Dict[str, Any]]:
        todo: List[str] = []
        for vid in self.ids:
            done = _done(self.folder, vid)
            if done is None:
                todo.append(vid)
            else:
                self.rows[vid] = done
                self.index.add(done)
        if self.chatty:
            print(f"sweep: {_count(len(self.ids), 'variant')}, {len(self.ids) - len(todo)} finished earlier, "
                  f"{len(todo)} to run ({executor}, {_count(max(1, workers), 'worker')}) into {self.folder}",
                  file=sys.stderr, flush=True)
        for k, vid in enumerate(vid for vid in self.ids if vid in self.rows):
            self.report(k + 1, len(self.ids), self.rows[vid])
        try:
            if todo and executor == "local":
                self.run_local(todo, workers)
            elif todo:
                self.run_dask(todo, workers, scheduler)
        finally:
            self.children.stop()
            for staging in list(self.children.stagings):
                self.drop(staging)
            self.index_note = self.finish_index()
        ordered = [self.rows[vid] for vid in self.ids if vid in self.rows]
        if self.failure is None and self.children.signum is None:
            try:
                contact_sheet(self.folder, ordered)
            except OSError as e:
                self.failure = (e, str(e.filename or self.folder))
        if self.failure is not None:
            raise StorageError(*self.failure, len(self.rows), len(self.ids), self.index_note)
        return ordered

    def finish_index(self) -> str:
        try:
            self.index.write()
            return f"indexed in {self.folder / 'index.csv'}"
        except OSError as e:
            if self.failure is None:
                self.failure = (e, str(e.filename or self.folder))
            return f"and the index could not be written ({e.strerror or e}): their folders hold variant.json"

    def run_local(self, todo: List[str], workers: int) -> None:
        # each worker thread's variant process, kept for its next variants
        kept = threading.local()
        processes: List[_VariantProcess] = []

        def one(vid: str) -> Tuple[Dict[str, Any], Optional[Path]]:
            staging = self.staging(vid)  # OSError: a storage error
            if staging is None:
                return {"status": "stopped", "seconds": None}, None
            try:
                job = self.job(vid, staging)
            except Exception as e:  # noqa: BLE001 - the paths were checked: not expected, but only this variant's
                return {"status": "failed", "seconds": None, "error": f"{type(e).__name__}: {e}"}, staging
            if getattr(kept, "process", None) is None:
                kept.process = _VariantProcess(self.children)
                processes.append(kept.process)
            return run_variant_isolated(job, self.children, kept.process), staging

        pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, workers))
        try:
            futures = {pool.submit(one, vid): vid for vid in todo}
            for future in concurrent.futures.as_completed(futures):
                try:
                    answer, staging = future.result()
                except OSError as e:  # the staging folder could not be made
                    self.fail(e, str(e.filename or self.folder))
                    break
                self.accept(futures[future], answer, staging)
                if self.failure is not None:
                    break
        finally:
            self.children.stop()  # nothing runs any more after a break; none start
            pool.shutdown(wait=True, cancel_futures=True)
            for process in processes:
                process.close()

    def run_dask(self, todo: List[str], workers: int, scheduler: Optional[str]) -> None:
        import importlib

        # python3-distributed has no type information: used through Any.
        dask: Any = importlib.import_module("distributed")
        cluster = None
        if scheduler is None:
            # One thread per worker process: each runs one variant at a time (in its own child).
            cluster = dask.LocalCluster(n_workers=max(1, workers), threads_per_worker=1, processes=True,
                                        dashboard_address=None)
            client = dask.Client(cluster)
        else:
            client = dask.Client(scheduler)
        try:
            # A LocalCluster's workers share this disk and write into OUT's staging folders; remote
            # ones send their files back. A window of jobs at a time: their texts are built late.
            local, queue = scheduler is None, iter(todo)
            futures: Dict[Any, Tuple[str, Optional[Path]]] = {}
            pending = dask.as_completed()

            def submit_next() -> None:
                vid = next(queue, None)
                staging = self.staging(vid) if vid is not None and local else None
                if vid is not None and (staging is not None or not local):
                    future = client.submit(run_variant_on_worker, self.job(vid, staging),
                                           key=f"clayform-variant-{vid}-{os.urandom(4).hex()}", pure=False)
                    futures[future] = (vid, staging)
                    pending.add(future)

            for _ in range(max(4, 2 * sum(client.nthreads().values()))):
                submit_next()
            for future in pending:
                vid, staging = futures.pop(future)
                try:
                    answer = future.result()
                except Exception as e:  # noqa: BLE001 - a lost worker loses only this variant
                    answer = {"status": "crashed", "seconds": None, "error": f"{type(e).__name__}: {e}"}
                self.accept(vid, answer, staging)
                if self.failure is not None or self.children.stopped:
                    client.cancel(list(futures))
                    break
                submit_next()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


def _count(n: int, what: str) -> str:
    return f"{n:,} {what}" + ("" if n == 1 else "s")


def _print_progress(done: int, total: int, row: Dict[str, Any]) -> None:
    seconds = row.get("seconds")
    took = f" {seconds:.2f} s" if isinstance(seconds, (int, float)) else ""
    error = f": {row['error']}" if row.get("error") else ""
    print(f"[{done}/{total}] {row['id']} {row['status']}{took}{error}", file=sys.stderr, flush=True)


def main(argv: Optional[List[str]] = None) -> int:
    """`python -m clayform.sweeps SPEC --out DIR [--executor local|dask] [--workers N]
    [--scheduler tcp://HOST:8786]` (what `clayform sweep` runs). Exit 0: every variant done;
    1: some failed; 2: nothing ran or the sweep stopped (a bad description, a storage error,
    another sweep in the folder), with one line on stderr; 128 + N: stopped by signal N."""
    import argparse

    args = list(sys.argv[1:] if argv is None else argv)
    if args == ["--run-variant"]:  # a variant process (_VariantProcess)
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
    except Interrupted as e:
        print(e.message, file=sys.stderr)
        return 128 + e.signum
    except KeyboardInterrupt:  # before the sweep started: nothing written
        print(f"sweep: {a.spec}: interrupted before any variant ran", file=sys.stderr)
        return 128 + signal.SIGINT
    except (SpecError, StorageError, FolderInUse) as e:
        print(" ".join(str(e).split()), file=sys.stderr)
        return 2
    except OSError as e:
        print(f"sweep: {e.filename or a.out}: {e.strerror or e}", file=sys.stderr)
        return 2
    bad = [r for r in rows if r["status"] not in ("ok", "done")]
    print(f"{len(rows)} variants: {len(rows) - len(bad)} done, {len(bad)} failed; index {Path(a.out) / 'index.csv'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
