"""scripts/upgrade_recipe.py: recipes written before issue #37 get the tolerance keys that say
their unit, and nothing else of their text changes."""
from __future__ import annotations

import importlib.util
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("CLAYFORM_SOURCE_DIR", Path(__file__).parents[2]))
EXE = os.environ.get("CLAYFORM_EXE", "clayform")
EXAMPLES = SOURCE / "examples" / "recipes"
OLD_KEYS = SOURCE / "tests" / "cli" / "recipes" / "broken" / "27-renamed-tolerance-keys.json"


def _upgrade_module():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("upgrade_recipe", SOURCE / "scripts" / "upgrade_recipe.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.json")))
def test_an_example_written_the_old_way_comes_back_byte_for_byte(name: str) -> None:
    # The old form of each example, made by hand: every new tolerance key back to "tolerance"
    # (no example has a composition in mm, which needed "relative": false).
    new = (EXAMPLES / name).read_text(encoding="utf-8")
    old = re.sub(r'"(tolerance_mm|relative_tolerance|residual_tolerance)"(\s*:)', r'"tolerance"\2', new)
    upgraded, changes = _upgrade_module().upgrade(old)
    assert upgraded == new
    assert len(changes) == len(re.findall(r'"(tolerance_mm|relative_tolerance|residual_tolerance)"\s*:', new))


def test_every_old_key_gets_the_name_its_place_gives_it(tmp_path: Path) -> None:
    recipe = tmp_path / "old.json"
    recipe.write_text(OLD_KEYS.read_text(encoding="utf-8"), encoding="utf-8")
    before = json.loads(recipe.read_text(encoding="utf-8"))
    done = subprocess.run([sys.executable, str(SOURCE / "scripts" / "upgrade_recipe.py"), str(recipe)],
                          capture_output=True, text=True, check=True)
    assert "5 key(s) changed" in done.stdout
    after = json.loads(recipe.read_text(encoding="utf-8"))
    assert (tmp_path / "old.json.bak").read_text(encoding="utf-8") == OLD_KEYS.read_text(encoding="utf-8")
    # The expected document, built from the old one key by key.
    want = json.loads(json.dumps(before))
    want["composition"] = {"mode": "refit", "tolerance_mm": 0.05}
    want["strokes"]["luff"]["tolerance_mm"] = want["strokes"]["luff"].pop("tolerance")
    want["sketches"]["foot"]["residual_tolerance"] = want["sketches"]["foot"].pop("tolerance")
    want["surfaces"]["tube"]["sweep"]["relative_tolerance"] = want["surfaces"]["tube"]["sweep"].pop("tolerance")
    assert after == want
    # The kernel's checker, independent of the script, no longer finds a renamed key.
    checked = subprocess.run([EXE, "validate", str(recipe)], capture_output=True, text=True)
    assert "renamed" not in checked.stdout + checked.stderr
    assert "no longer a key" not in checked.stdout + checked.stderr


def test_a_file_that_is_not_json_is_left_alone(tmp_path: Path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text('{"strokes": {"a": {"tolerance": 1,}}}', encoding="utf-8")
    done = subprocess.run([sys.executable, str(SOURCE / "scripts" / "upgrade_recipe.py"), str(bad)],
                          capture_output=True, text=True)
    assert done.returncode == 1 and "left unchanged" in done.stderr
    assert bad.read_text(encoding="utf-8") == '{"strokes": {"a": {"tolerance": 1,}}}'
