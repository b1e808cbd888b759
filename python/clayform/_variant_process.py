"""One variant of a sweep, run (clayform.sweeps; docs/sweeps.md § How variants run): in this process
(run_variant_here: the recipe run, its files written, its thumbnail and index figures), or in a
variant process kept for many variants (_VariantProcess: a job a line on its stdin, its answer a
line back, one RunCache across them), which dies with the sweep. run_variant_isolated runs one
there (or in a process of its own); run_variant_on_worker is what a Dask worker runs."""
from __future__ import annotations

import base64
import contextlib
import errno
import io
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, Set, Tuple

#: The errno values of a storage error: the disk is full, the folder is read-only or not
#: writable, the quota is used up, or a file is larger than allowed. Any variant would meet it.
STORAGE_ERRNOS = frozenset({errno.ENOSPC, errno.EROFS, errno.EACCES, errno.EDQUOT, errno.EFBIG})
#: A variant's process: `python3 -m clayform.sweeps --run-variant`, started through this line so
#: that it is tied to the sweep's life (PR_SET_PDEATHSIG) before it spends time importing.
_BOOT = ("import os, sys\n"
         "if sys.platform.startswith('linux'):\n"
         "    try:\n        import ctypes; ctypes.CDLL(None).prctl(1, 9, 0, 0, 0)\n"
         "    except Exception:\n        pass\n"
         "if str(os.getppid()) != os.environ.get('CLAYFORM_SWEEP_PARENT'):\n    os._exit(3)\n"
         "from clayform.sweeps import main\nsys.exit(main(['--run-variant']))\n")


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


def _palette(k: int) -> Tuple[float, float, float]:
    """The renderer's base colour of object k (golden-angle hue steps from blue; render.cpp)."""
    h = math.fmod(0.58 + 0.381966 * k, 1.0) * 6.0
    s, v = 0.45, 0.92
    f = h - math.floor(h)
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    return [(v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q)][int(h) % 6]


def mesh_png(meshes: List[Tuple[Any, Any]], width: int = 320, height: int = 240) -> bytes:
    """A shaded picture (PNG bytes) of triangle meshes [(points (n, 3), triangles (m, 3))] side by
    side, seen as render_png sees surfaces (orthographic, from -x, -y, +z; two-sided Lambert),
    painted far to near. Draws models (their trimmed meshes), which render_png does not take."""
    import numpy as np
    from PIL import Image, ImageDraw  # python3-pil

    eye = np.array([-1.0, -1.2, 0.9]) / np.linalg.norm([-1.0, -1.2, 0.9])
    right = np.cross([0.0, 0.0, 1.0], eye)
    right /= np.linalg.norm(right)
    up = np.cross(eye, right)
    light = eye + 0.5 * up - 0.5 * right
    light /= np.linalg.norm(light)
    xs, ys, depths, fills, shift = [], [], [], [], 0.0
    for k, (points, triangles) in enumerate(meshes):
        corners = np.asarray(points, dtype=float)[np.asarray(triangles, dtype=np.int64)]  # (m, 3, 3)
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        normals /= np.maximum(np.linalg.norm(normals, axis=1), 1e-300)[:, None]
        normals *= np.where(normals @ eye < 0, -1.0, 1.0)[:, None]
        shade = np.clip(0.15 + 0.6 * np.maximum(normals @ light, 0.0) + 0.25 * (normals @ eye), 0.0, 1.0)
        x = corners @ right
        xs.append(x - x.min() + shift)  # each model to the right of the one before
        shift += (x.max() - x.min()) * 1.1
        ys.append(corners @ up)
        depths.append((corners @ eye).mean(axis=1))
        fills.append(np.rint(255 * np.outer(shade, _palette(k))).astype(int))
    x, y, depth, fill = (np.concatenate(a) for a in (xs, ys, depths, fills))
    w, h = 2 * width, 2 * height  # drawn at twice the size, then reduced: smooth edges
    span = max((x.max() - x.min()) / (0.9 * w), (y.max() - y.min()) / (0.9 * h), 1e-300)
    px = (x - (x.max() + x.min()) / 2) / span + w / 2
    py = h / 2 - (y - (y.max() + y.min()) / 2) / span
    picture = Image.new("RGB", (w, h), "white")
    draw = ImageDraw.Draw(picture)
    for k in np.argsort(depth):  # far first
        draw.polygon([(px[k, c], py[k, c]) for c in range(3)], fill=(int(fill[k, 0]), int(fill[k, 1]), int(fill[k, 2])))
    buffer = io.BytesIO()
    picture.resize((width, height), Image.LANCZOS).save(buffer, format="PNG")
    return buffer.getvalue()


def _thumbnail(recipe: Any, result: Any, out_dir: str) -> Optional[bytes]:
    """The variant's picture: its final surfaces (render_png), or, for a recipe with models and
    no surfaces, its deformed models read back from the files it wrote; None when it has neither."""
    from . import read_model, render_png

    finals = [result.surfaces[name] for name in recipe.final_surfaces]
    if finals:
        return bytes(render_png(finals, width=320, height=240))
    meshes = []
    for model in result.report.get("models", []):
        files = [f for f in model.get("files", []) if f.lower().endswith((".step", ".stp", ".igs", ".iges"))]
        if files:
            points, triangles, _ = read_model(str(Path(out_dir, files[0])))[0].tessellate()
            if len(triangles):
                meshes.append((points, triangles))
    return mesh_png(meshes) if meshes else None


def _storage_cause(error: BaseException, folder: str) -> Optional[OSError]:
    """The storage error behind a failed write, if storage is the cause. The kernel's writers
    report errors as text: a test write (1 MiB, synced) into the folder tells."""
    if isinstance(error, OSError) and error.errno in STORAGE_ERRNOS:
        return error
    place = Path(folder)
    while not place.is_dir() and place != place.parent:
        place = place.parent
    fd, name = -1, ""
    try:
        fd, name = tempfile.mkstemp(prefix=".probe-", dir=place)
        for _ in range(16):
            os.write(fd, bytes(1 << 16))
        os.fsync(fd)
    except OSError as e:
        return e if e.errno in STORAGE_ERRNOS else None
    finally:
        if fd >= 0:
            os.close(fd)
            os.unlink(name)
    return None


def run_variant_here(text: str, base_dir: str, out_dir: str, cache: Any = None) -> Dict[str, Any]:
    """Runs one variant in this process, writing its outputs and a thumbnail into out_dir; with
    cache (a clayform.RunCache), the steps it holds unchanged are taken from it ("steps_reused"
    counts them). A storage error while writing is status "storage" (errno, path); other errors
    raise."""
    from . import Recipe  # the extension, imported where the variant runs

    start = time.perf_counter()
    recipe = Recipe.parse(text, base_dir)
    result = recipe.run(cache=cache)
    reused = sum(1 for step in result.steps if step["reused"])
    try:
        result.write(out_dir)
        picture = _thumbnail(recipe, result, out_dir)
        if picture is not None:
            Path(out_dir, "thumbnail.png").write_bytes(picture)
    except Exception as e:  # noqa: BLE001 - a storage error stops the sweep, anything else fails the variant
        cause = _storage_cause(e, out_dir)
        if cause is None:
            raise
        return {"status": "storage", "errno": cause.errno, "path": cause.filename or out_dir,
                "error": cause.strerror or str(cause)}
    return {"status": "ok", "seconds": time.perf_counter() - start, "steps_reused": reused, **_figures(result.report)}


class _Children:
    """The variant processes of a sweep and their staging folders: processes start only until
    stop(), which kills the running ones (from a signal handler too: the lock is reentrant)."""

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self.running: Set["subprocess.Popen[str]"] = set()
        self.stagings: Set[Path] = set()
        self.stopped = False
        self.signum: Optional[int] = None

    def start(self, argv: List[str], env: Dict[str, str], stderr: Any) -> Optional["subprocess.Popen[str]"]:
        with self.lock:
            if self.stopped:
                return None
            child = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=stderr,
                                     text=True, env=env)
            self.running.add(child)
            return child

    def stop(self, signum: Optional[int] = None) -> None:
        with self.lock:
            self.stopped, self.signum = True, self.signum or signum
            for child in self.running:
                with contextlib.suppress(OSError):
                    child.kill()


class _VariantProcess:
    """A variant process kept for many variants, one at a time: a job a line on its stdin, its
    answer a line back. It holds one RunCache, so the steps the variants share are taken from the
    variant before instead of computed again; it starts on the first job and again after a
    variant killed it. Its stderr goes to a file (kept short: emptied at each job) whose last line
    says why a process died."""

    def __init__(self, children: _Children) -> None:
        self.children = children
        self.child: Optional["subprocess.Popen[str]"] = None
        self.errors: Optional[io.BufferedRandom] = None

    def _start(self) -> bool:
        env = dict(os.environ)
        env["CLAYFORM_SWEEP_PARENT"] = str(os.getpid())
        # appended to (O_APPEND), so the process writes at its end after the file is emptied
        fd, name = tempfile.mkstemp(prefix="clayform-variant-", suffix=".err")
        os.close(fd)
        try:
            self.errors = open(os.open(name, os.O_RDWR | os.O_APPEND), "a+b")
        finally:
            os.unlink(name)
        self.child = self.children.start([sys.executable, "-c", _BOOT], env, self.errors)
        return self.child is not None

    def _forget(self) -> None:
        if self.child is not None:
            with self.children.lock:
                self.children.running.discard(self.child)
        if self.errors is not None:
            self.errors.close()
        self.child, self.errors = None, None

    def _last_error(self, fallback: str) -> str:
        assert self.errors is not None
        self.errors.seek(0)
        tail = self.errors.read().decode(errors="replace").strip().splitlines()[-1:]
        return tail[0] if tail else fallback

    def run(self, job: Dict[str, Any]) -> Dict[str, Any]:
        """The job's answer ({"status": ...}); "crashed" when the process died on it (the next job
        starts a new one), "stopped" when the sweep stopped before it could start one."""
        if self.child is None or self.child.poll() is not None:
            self._forget()
            if not self._start():
                return {"status": "stopped", "seconds": None, "error": "the sweep stopped before it ran"}
        assert self.child is not None and self.child.stdin is not None and self.child.stdout is not None
        assert self.errors is not None
        self.errors.truncate(0)
        try:
            self.child.stdin.write(json.dumps(job) + "\n")
            self.child.stdin.flush()
            line = self.child.stdout.readline()
        except OSError:  # the process is gone (a broken pipe)
            line = ""
        if not line:
            code = self.child.wait()
            error = (f"the variant's process died ({signal.Signals(-code).name})" if code < 0
                     else self._last_error(f"exit code {code}"))
            self._forget()
            return {"status": "crashed", "seconds": None, "error": error}
        try:
            return dict(json.loads(line))
        except (json.JSONDecodeError, TypeError, ValueError):
            self.close()
            return {"status": "crashed", "seconds": None, "error": f"the variant's process answered {line[:80]!r}"}

    def close(self) -> None:
        """Ends the process (its stdin closed: it exits; killed if it does not within 10 s)."""
        if self.child is not None:
            with contextlib.suppress(OSError):
                if self.child.stdin is not None:
                    self.child.stdin.close()
            try:
                self.child.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.child.kill()
                self.child.wait()
        self._forget()


def run_variant_isolated(job: Dict[str, Any], children: Optional[_Children] = None,
                         process: Optional[_VariantProcess] = None) -> Dict[str, Any]:
    """Runs one variant in a variant process (`process`, kept for the next ones; without it, one
    started for this variant alone) and returns its figures. With job["stage"] (a folder path on
    a disk this machine shares with the sweep) the process writes its files there; without, into
    a temporary folder whose files come back as base64, so that it works the same on a Dask
    worker elsewhere. A variant that raises is "failed" with its message; one that kills its
    process is "crashed" with the signal; one that meets a storage error is "storage"."""
    start = time.perf_counter()
    tmp = None if job.get("stage") else tempfile.mkdtemp(prefix="clayform-variant-")
    out = job["stage"] if tmp is None else os.path.join(tmp, "variant")
    own = process is None
    runner = process or _VariantProcess(children or _Children())
    try:
        answer = runner.run({"text": job["text"], "base_dir": job["base_dir"], "out": out,
                             "abort": bool(job.get("abort"))})
        answer["seconds"] = time.perf_counter() - start if answer["status"] != "stopped" else None
        if answer["status"] == "ok" and tmp is not None:
            files: Dict[str, str] = {}
            for path in Path(out).rglob("*"):
                if path.is_file():
                    files[str(path.relative_to(out))] = base64.b64encode(path.read_bytes()).decode()
            answer["files"] = files
        return answer
    finally:
        if own:
            runner.close()
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)


#: On a Dask worker: each of its threads' kept variant process (run_variant_on_worker).
_worker = threading.local()
_worker_children = _Children()


def run_variant_on_worker(job: Dict[str, Any]) -> Dict[str, Any]:
    """run_variant_isolated in the variant process this Dask worker thread keeps (started on its
    first variant, tied to the worker's life), so the worker's variants share their steps."""
    process = getattr(_worker, "process", None)
    if process is None:
        process = _worker.process = _VariantProcess(_worker_children)
    return run_variant_isolated(job, process=process)


def _watch_parent() -> None:
    """A variant's process ends when the sweep that started it does, SIGKILL included: _BOOT
    arms PR_SET_PDEATHSIG on Linux; this watch on the parent's id covers the other systems."""
    expected = os.environ.get("CLAYFORM_SWEEP_PARENT")

    def watch() -> None:
        while str(os.getppid()) == expected:
            time.sleep(0.5)
        os._exit(3)

    if expected:
        threading.Thread(target=watch, daemon=True).start()


def _child_main() -> int:
    """`python -m clayform.sweeps --run-variant`: variants, one job a line on stdin and one JSON
    answer a line on stdout each, until stdin ends; one RunCache across them."""
    _watch_parent()
    # The answers get the process's stdout to themselves: anything a library prints goes to stderr.
    answers = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    from . import RunCache

    cache = RunCache()
    for line in sys.stdin:
        job = json.loads(line)
        if job.get("abort"):
            os.abort()  # fault injection for the tests: a variant that kills its process
        try:
            answer = run_variant_here(job["text"], job["base_dir"], job["out"], cache)
        except Exception as e:  # noqa: BLE001 - every failure is the variant's result
            answer = {"status": "failed", "error": f"{type(e).__name__}: {e}"}
        answers.write(json.dumps(answer) + "\n")
        answers.flush()
    return 0
