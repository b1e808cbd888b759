#!/usr/bin/python3
"""Rewrites recipes written before issue #37 so that every tolerance's key says its unit.

    scripts/upgrade_recipe.py RECIPE.json [...]        rewrite in place (a .bak copy is kept)
    scripts/upgrade_recipe.py --check RECIPE.json [...] list what would change, change nothing

The bare "tolerance" became "tolerance_mm" in strokes, projections, offsets and superquadrics,
"relative_tolerance" in sweeps, rebuilds, style and direct_manipulation steps and compositions
("tolerance_mm" in a composition whose "relative" was false; "relative" is dropped), and
"residual_tolerance" in sketches (docs/recipe.md "Conventions"). Only those keys change: the
rest of the text, its layout and its numbers are kept byte for byte.
"""
from __future__ import annotations

import json
import re
import shutil
import sys
from pathlib import Path
from typing import Any, List, Optional, Tuple

MM, RELATIVE, RESIDUAL = "tolerance_mm", "relative_tolerance", "residual_tolerance"


def _new_name(path: Tuple[Any, ...], parent: dict) -> Optional[str]:
    """The new key of a "tolerance" found in `parent` at `path` (None: not one the rename made)."""
    if path and path[-1] == "composition":
        return MM if parent.get("relative") is False else RELATIVE
    if len(path) == 2 and path[0] == "strokes":
        return MM
    if len(path) == 3 and path[0] == "curves" and path[2] in ("project", "offset"):
        return MM
    if len(path) == 2 and path[0] == "sketches":
        return RESIDUAL
    if len(path) == 3 and path[0] == "surfaces":
        return {"sweep": RELATIVE, "rebuild": RELATIVE, "superellipsoid": MM, "supertoroid": MM}.get(path[2])
    if len(path) == 3 and path[0] == "deformations" and parent.get("kind") in ("style", "direct_manipulation"):
        return RELATIVE
    return None


def _walk(node: Any, path: Tuple[Any, ...], out: List[Tuple[str, Optional[str]]]) -> None:
    """Every key of the document in text order: (key, its new name or None to keep it)."""
    if isinstance(node, list):
        for i, x in enumerate(node):
            _walk(x, path + (i,), out)
    elif isinstance(node, dict):
        for key, value in node.items():
            if key == "tolerance":
                out.append((key, _new_name(path, node)))
            elif key == "relative" and path and path[-1] == "composition":
                out.append((key, ""))  # dropped
            else:
                out.append((key, None))
            _walk(value, path + (key,), out)


_KEY = re.compile(r'"((?:[^"\\]|\\.)*)"\s*:')
_STRING = re.compile(r'"(?:[^"\\]|\\.)*"')


def upgrade(text: str) -> Tuple[str, List[str]]:
    """The upgraded text and what changed, one line per key."""
    keys: List[Tuple[str, Optional[str]]] = []
    _walk(json.loads(text), (), keys)
    out, changes, at, k = [], [], 0, 0
    for m in _STRING.finditer(text):
        if not _KEY.match(text, m.start()):
            continue  # a string value, not a key
        key, new = keys[k]
        k += 1
        if new is None:
            continue
        if new == "":  # drop `"relative": false,` (or the `, "relative": true` before a brace)
            end = re.compile(r'"relative"\s*:\s*(true|false)\s*,?\s*').match(text, m.start()).end()
            out.append(text[at:m.start()])
            at = end
            changes.append('"relative" dropped')
        else:
            out.append(text[at:m.start()] + '"' + new + '"')
            at = m.end()
            changes.append(f'"tolerance" -> "{new}"')
    if k != len(keys):
        raise ValueError("a key repeated in one object (JSON keeps the last): fix that first")
    out.append(text[at:])
    result = "".join(out)
    result = re.sub(r",(\s*})", r"\1", result) if any("dropped" in c for c in changes) else result
    json.loads(result)  # still one valid document
    return result, changes


def main(argv: List[str]) -> int:
    check = "--check" in argv
    files = [a for a in argv if a != "--check"]
    status = 0
    if not files:
        print(__doc__, file=sys.stderr)
        return 2
    for name in files:
        path = Path(name)
        try:
            text, changes = upgrade(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as e:  # json.JSONDecodeError is a ValueError
            print(f"{name}: left unchanged: {e}", file=sys.stderr)
            status = 1
            continue
        print(f"{name}: {len(changes)} key(s) {'to change' if check else 'changed'}" + "".join(f"\n  {c}" for c in changes))
        if changes and not check:
            shutil.copyfile(path, path.with_suffix(path.suffix + ".bak"))
            path.write_text(text, encoding="utf-8")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
