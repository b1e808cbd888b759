"""The type stubs (python/clayform/_clayform.pyi) match the built module (issue #37: they were kept
by hand and never checked). mypy.stubtest compares every class, function, method and attribute of
clayform._clayform with the stub, both ways: what the stub declares and the module lacks, and what
the module has and the stub misses. pybind11's functions carry no introspectable signature, so
their argument lists are checked by mypy --strict on the examples (test_examples.py) and by the
tests that call them, not here. The pure-Python modules (errors, sweeps) are their own stubs."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import clayform

ALLOWLIST = Path(__file__).with_name("stubtest-allowlist.txt")


def stubtest(package_dir: Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(package_dir))
    return subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "clayform._clayform", "--allowlist", str(ALLOWLIST),
         "--mypy-config-file", os.devnull],
        capture_output=True, text=True, cwd=cwd, env=env, timeout=240)


def test_stubs_match_the_module(tmp_path: Path) -> None:
    done = stubtest(Path(clayform.__file__).parents[1], tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr


def test_stubtest_catches_a_stub_that_lies(tmp_path: Path) -> None:
    # A copy of the package whose stub declares a function and a method the module lacks, and
    # misses a function it has: the check must name all three (so a green run above means
    # something).
    package = tmp_path / "pkg"
    shutil.copytree(Path(clayform.__file__).parent, package / "clayform",
                    ignore=shutil.ignore_patterns("__pycache__"))
    stub = package / "clayform" / "_clayform.pyi"
    text = stub.read_text()
    read_step = next(line for line in text.splitlines() if line.startswith("def read_step("))
    assert "\nclass Surface:\n" in text
    text = text.replace(read_step + "\n", "", 1)
    text = text.replace("\nclass Surface:\n", "\nclass Surface:\n    def smooth(self) -> None: ...\n", 1)
    stub.write_text(text + "\ndef smooth_everything(tolerance: float) -> None: ...\n")
    done = stubtest(package, tmp_path)
    assert done.returncode != 0
    assert "clayform._clayform.smooth_everything is not present at runtime" in done.stdout
    assert "clayform._clayform.Surface.smooth is not present at runtime" in done.stdout
    assert "clayform._clayform.read_step is not present in stub" in done.stdout
