"""The studio page says which form it shows (issue #38): the page's reading of a run's step
reports (viewer/src/studio/forms.js, run by Node) against the same figures read here from the
report.json of `clayform run` on the tank example, whose lattice step is a certified light form.
Skipped when `node` is missing."""
import json
import os
import pathlib
import shutil
import subprocess

import pytest

NODE = shutil.which("node")
pytestmark = pytest.mark.skipif(NODE is None, reason="node is not installed (apt-get install nodejs)")

SOURCE = pathlib.Path(os.environ.get("CLAYFORM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
FORMS = SOURCE / "viewer" / "src" / "studio" / "forms.js"
EXAMPLES = pathlib.Path(os.environ.get("CLAYFORM_EXAMPLES", SOURCE / "examples"))


def page_reading(function, argument, tmp_path):
    """forms.js's `function` of `argument`, as the page computes it (run by Node)."""
    script = tmp_path / ("%s.mjs" % function)
    script.write_text(
        "import { %s } from '%s';\n"
        "let text = '';\nfor await (const chunk of process.stdin) text += chunk;\n"
        "process.stdout.write(JSON.stringify(%s(JSON.parse(text))));\n" % (function, FORMS.as_posix(), function))
    done = subprocess.run([NODE, str(script)], input=json.dumps(argument), capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def form_shown(steps, tmp_path):
    return page_reading("formShown", steps, tmp_path)


def run_tank(tmp_path):
    out = tmp_path / "tank"
    subprocess.run([os.environ["CLAYFORM_EXE"], "run", str(EXAMPLES / "recipes" / "tank.json"), "--out", str(out),
                    "--quiet"], check=True, timeout=300)
    return json.loads((out / "report.json").read_text())["steps"]


def test_the_page_says_the_tank_is_a_light_form_within_its_bound(tmp_path):
    steps = run_tank(tmp_path)
    lattice = next(s for s in steps if s["path"] == "surfaces.tank.steps[0]")
    f = lattice["figures"]
    assert f["composition"] == "light"
    expected = ("tank: light form, within %s mm of the exact (exact: degree %d, %d control points)"
                % (format(f["accumulated_bound_mm"], ".2g"), f["exact_degree_u"], f["exact_control_points"]))
    assert form_shown(steps, tmp_path) == expected
    # An exact step, and one after a light one (carrying the bound), read as such.
    exact = {"path": "surfaces.a.steps[0]", "kind": "bezier_lattice", "figures": {"composition": "exact"}}
    carried = {"path": "surfaces.b.steps[1]", "kind": "taper",
               "figures": {"composition": "exact", "accumulated_bound_mm": 0.25}}
    unbounded = {"path": "surfaces.c.steps[0]", "kind": "twist",
                 "figures": {"composition": "refit", "accumulated_bound": "unbounded"}}
    # A drag update's preview (figures as tests/cli/reuse_test.cpp checks the session sends them).
    preview = {"path": "surfaces.d.steps[0]", "kind": "bezier_lattice",
               "figures": {"composition": "light", "preview": True, "accumulated_bound": "unbounded",
                           "certified": False}}
    assert form_shown([exact, carried, unbounded, preview], tmp_path) == (
        "a: exact; b: light form, within 0.25 mm of the exact; "
        "c: refit, distance from the exact unbounded; d: light form (drag preview, certified when let go)")


def test_the_style_panel_warns_of_the_tanks_rings_and_not_of_a_calm_style(tmp_path):
    # The tank's exact style on its first net rings (docs/deform.md § Rings): the run warns, and
    # the page's panel says so with the same count; a calm count and an unmeasured one do not.
    style = next(s for s in run_tank(tmp_path) if s["path"] == "surfaces.styled.steps[0]")
    f = style["figures"]
    waves = f["curvature_waves"]
    assert waves > 4 and style["warning"] and ("rings: the change of mean curvature turns %d times" % waves) in style["message"]
    shown = page_reading("styleSummary", f, tmp_path)
    assert shown["warning"].startswith("rings: the curvature turns %d times" % waves)
    lines = shown["text"].split("\n")
    assert lines[0] == "target curve within %s mm" % format(f["target_curve_distance"], ".2g")
    assert "curvature waves %d (calm: up to 4)" % waves in lines
    calm = dict(f, curvature_waves=4)
    assert page_reading("styleSummary", calm, tmp_path)["warning"] == ""
    unmeasured = dict(f, curvature_waves=-1, target_curve_distance=None)
    shown = page_reading("styleSummary", unmeasured, tmp_path)
    assert shown["warning"] == "" and not any(line.startswith(("curvature waves", "target curve")) for line in shown["text"].split("\n"))
