"""How the faces of a STEP model meet along their edges, measured by FreeCAD (OpenCASCADE's
evaluators, not Clayform's): an independent sampler for issue #38 ("exact and light").

Run by FreeCAD's command line (or Debian's python3, which finds FreeCAD's Part module itself):

    freecadcmd tests/freecad/edge_continuity.py MODEL.step [KEY=VALUE ...]
    python3    tests/freecad/edge_continuity.py MODEL.step [KEY=VALUE ...]

Arguments are positional words after the script's own path, never dashed options: freecadcmd
parses dashed words itself ("unrecognised option") and opens every other word as a document once
the script returns, so this script always ends with sys.exit (its exit code is freecadcmd's).
When the script's path is not in sys.argv (freecadcmd -c "exec(...)"), the words are read from
the environment variable EDGE_CONTINUITY_ARGS (split as a shell would). Keys:

    json=FILE          write the table as JSON there (default: none; a summary goes to stdout)
    samples=50         points per edge, both ends included, uniform in the edge's parameter
    reference=SRC      the undeformed source (.step, or a .json this script wrote for it): its
                       edges are classified G1 / G2 by its own figures, the model is checked
                       against the limits below and the exit code says whether it passed
    classify_deg=1e-3  a source edge whose normals agree within this is G1 ...
    classify_rel=1e-3  ... and G2 when its relative curvature jump is also below this
    g1_deg=0.016       limit on the angle of every G1 edge of the source (class A fillets)
    g2_rel=0.01        limit on the relative curvature jump of every G2 edge of the source
    gap_mm=0           limit on every edge's face-to-face gap (0: not checked, only reported)
    table=1            print the per-edge table (0: only the summary)

Exit codes: 0 measured (and, with a reference, every limit held); 1 a limit failed; 2 bad
arguments or a file that could not be read.

Definitions (per edge used by two faces, or by one face twice along a seam):
  * t runs over `samples` points of the edge's parameter range, both ends included. Each side is
    evaluated on its face's own surface at the face's own pcurve at t (BRep_Tool::CurveOnSurface;
    for a seam the pcurves of the edge's two orientations), as BRepCheck does: nothing projected.
  * gap_mm: the largest |S_a(uv_a(t)) - S_b(uv_b(t))|; edge_gap_mm: the largest distance of either
    side's point from the edge's 3D curve C(t).
  * angle_deg: the largest angle between the two faces' outward normals, n = S_u x S_v turned for
    a face whose Orientation is Reversed, as atan2(|n_a x n_b|, n_a . n_b) (accurate near 0).
  * curvature across: on each side the normal curvature k = II(w) / I(w) of the face's surface in
    the direction w = n x T of its tangent plane perpendicular to the edge (T the edge's tangent
    made tangent to that face), with respect to the face's outward normal (do Carmo 3-2),
    from OpenCASCADE's exact derivatives S_u, S_v, S_uu, S_uv, S_vv (Geom_Surface::DN).
    curvature_jump (1/mm) the largest |k_a - k_b|; relative_curvature_jump the largest
    |k_a - k_b| / max(|k_a|, |k_b|, 1 / size), size the diagonal of the model's bounding box: a
    jump between two nearly flat faces is measured against a radius the size of the model, not
    against 0 (a plane meeting a plane at a G2 edge has k_a = k_b = 0 and relative jump 0).
    local_relative_curvature_jump: the same against max(|k_a|, |k_b|, 1e-6 / mm) (Clayform's own
    floor): relative to the faces' own curvature however flat they are; reported, not checked.
  * a sample where either face's S_u x S_v vanishes (a pole, a collapsed corner) is skipped and
    counted (`skipped`).
Shape facts: BRepCheck validity (Shape.isValid), the counts of faces, edges, shared edges,
seams (an edge twice on one face), free edges (on one face once: an open border), degenerated
edges, non-manifold edges (on three or more faces), and the volume.
"""

import json
import math
import os
import shlex
import sys
import importlib
import time
import traceback

SCRIPT = "edge_continuity.py"
LOCAL_FLOOR = 1e-6  # 1/mm: Clayform's own ContinuityOptions::curvature_floor


def _import_part():
    # freecadcmd has FreeCAD and Part on its path; python3 finds them in FreeCAD's lib folder.
    try:
        importlib.import_module("Part")
    except ImportError:
        for lib in (os.environ.get("FREECAD_LIB", ""), "/usr/lib/freecad-python3/lib",
                    "/usr/lib/freecad/lib"):
            if lib and os.path.isdir(lib) and lib not in sys.path:
                sys.path.append(lib)
        importlib.import_module("FreeCAD")
    return importlib.import_module("Part")


def parse_args(argv):
    """The words after this script's path in argv, else EDGE_CONTINUITY_ARGS."""
    words = None
    for i, a in enumerate(argv):
        if os.path.basename(a) == SCRIPT:
            words = argv[i + 1:]
            break
    if words is None or not words:
        env = os.environ.get("EDGE_CONTINUITY_ARGS", "")
        if env:
            words = shlex.split(env)
    if not words:
        raise ValueError("usage: freecadcmd edge_continuity.py MODEL.step [json=OUT.json] "
                         "[samples=50] [reference=SOURCE.step] [g1_deg=0.016] [g2_rel=0.01] ...")
    opts = {"model": None, "json": None, "samples": 50, "reference": None,
            "classify_deg": 1e-3, "classify_rel": 1e-3, "g1_deg": 0.016, "g2_rel": 0.01,
            "gap_mm": 0.0, "table": 1}
    for w in words:
        if "=" in w:
            k, v = w.split("=", 1)
            if k not in opts or k == "model":
                raise ValueError("unknown argument %r (keys: %s)" %
                                 (w, ", ".join(sorted(k for k in opts if k != "model"))))
            if k in ("json", "reference"):
                opts[k] = v
            elif k in ("samples", "table"):
                opts[k] = int(v)
            else:
                opts[k] = float(v)
        elif opts["model"] is None:
            opts["model"] = w
        else:
            raise ValueError("two models given: %r and %r" % (opts["model"], w))
    if opts["model"] is None:
        raise ValueError("no model given")
    if opts["samples"] < 2:
        raise ValueError("samples=%d: give at least 2" % opts["samples"])
    return opts


# --- small vector helpers on tuples (FreeCAD's Vector is slow to build; numpy is not needed) ---

def _v(p):
    return (p.x, p.y, p.z)


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _norm(a):
    return math.sqrt(_dot(a, a))


def _scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


class Side:
    """One face along one edge: its surface, orientation and pcurve (with its range)."""

    def __init__(self, face, pcurve, p0, p1):
        self.surface = face.Surface
        self.sign = -1.0 if face.Orientation == "Reversed" else 1.0
        self.pcurve, self.p0, self.p1 = pcurve, p0, p1

    def at(self, t, e0, e1, tangent3d):
        """(point, outward unit normal, normal curvature across the edge) at edge parameter t,
        or None where S_u x S_v vanishes."""
        # the pcurve at the same t (its range mapped onto the edge's when they differ)
        s = t if (self.p0 == e0 and self.p1 == e1) else \
            self.p0 + (t - e0) * (self.p1 - self.p0) / (e1 - e0)
        uv = self.pcurve.value(s)
        u, v = uv.x, uv.y
        S = self.surface
        p = _v(S.value(u, v))
        su, sv = _v(S.getDN(u, v, 1, 0)), _v(S.getDN(u, v, 0, 1))
        n = _cross(su, sv)
        ln = _norm(n)
        if ln <= 1e-12 * max(_dot(su, su), _dot(sv, sv), 1e-300):
            return None
        n = _scale(n, self.sign / ln)
        suu, suv, svv = (_v(S.getDN(u, v, 2, 0)), _v(S.getDN(u, v, 1, 1)),
                         _v(S.getDN(u, v, 0, 2)))
        # T made tangent to this face, w = n x T across the edge, w = a S_u + b S_v
        T = _sub(tangent3d, _scale(n, _dot(tangent3d, n)))
        lt = _norm(T)
        if lt == 0:
            return None
        w = _cross(n, _scale(T, 1 / lt))
        E, F, G = _dot(su, su), _dot(su, sv), _dot(sv, sv)
        det = E * G - F * F
        wu, wv = _dot(w, su), _dot(w, sv)
        a = (G * wu - F * wv) / det
        b = (E * wv - F * wu) / det
        L, M, N = _dot(suu, n), _dot(suv, n), _dot(svv, n)
        first = E * a * a + 2 * F * a * b + G * b * b
        k = (L * a * a + 2 * M * a * b + N * b * b) / first
        return p, n, k


def measure(Part, path, samples):
    t_start = time.time()
    shape = Part.Shape()
    shape.read(path)
    if shape.isNull() or not shape.Faces:
        raise IOError("%s: no faces read" % path)
    faces = shape.Faces
    edges = shape.Edges
    bb = shape.BoundBox
    size = math.sqrt(bb.XLength ** 2 + bb.YLength ** 2 + bb.ZLength ** 2)
    floor = 1.0 / size
    # which faces use each edge (TopoDS HashCode ignores orientation; isSame confirms)
    by_hash = {}
    for i, e in enumerate(edges):
        by_hash.setdefault(e.hashCode(), []).append(i)
    users = [[] for _ in edges]
    for fi, f in enumerate(faces):
        for fe in f.Edges:
            for i in by_hash.get(fe.hashCode(), ()):
                if edges[i].isSame(fe) and fi not in users[i]:
                    users[i].append(fi)
    counts = {"shared": 0, "seams": 0, "free": 0, "degenerated": 0, "non_manifold": 0,
              "unused": 0}
    table = []
    free_list = []
    for i, e in enumerate(edges):
        if e.Degenerated:
            counts["degenerated"] += 1
            continue
        fs = users[i]
        if len(fs) == 0:
            counts["unused"] += 1
            continue
        if len(fs) > 2:
            counts["non_manifold"] += 1
            continue
        if len(fs) == 1:
            f = faces[fs[0]]
            if not e.isSeam(f):
                counts["free"] += 1
                free_list.append(i)
                continue
            counts["seams"] += 1
            sides = []
            for oriented in (e, e.reversed()):
                c, p0, p1 = f.curveOnSurface(oriented)
                sides.append(Side(f, c, p0, p1))
            pair = [fs[0], fs[0]]
        else:
            counts["shared"] += 1
            sides = []
            for fi in fs:
                got = faces[fi].curveOnSurface(e)
                if got is None:
                    raise RuntimeError("edge %d has no pcurve on face %d" % (i, fi))
                c, p0, p1 = got
                sides.append(Side(faces[fi], c, p0, p1))
            pair = list(fs)
        e0, e1 = e.FirstParameter, e.LastParameter
        mid = e.valueAt(0.5 * (e.FirstParameter + e.LastParameter))
        row = {"edge": i, "faces": pair, "seam": pair[0] == pair[1], "length_mm": e.Length,
               "middle": [mid.x, mid.y, mid.z],
               "gap_mm": 0.0, "edge_gap_mm": 0.0, "angle_deg": 0.0, "curvature_jump": 0.0,
               "relative_curvature_jump": 0.0, "local_relative_curvature_jump": 0.0,
               "k_at_worst": [0.0, 0.0], "t_angle": e0,
               "t_curvature": e0, "skipped": 0}
        for j in range(samples):
            t = e0 + (e1 - e0) * j / (samples - 1)
            c = _v(e.valueAt(t))
            d = _v(e.derivative1At(t))
            ld = _norm(d)
            if ld == 0:
                row["skipped"] += 1
                continue
            tan = _scale(d, 1 / ld)
            a = sides[0].at(t, e0, e1, tan)
            b = sides[1].at(t, e0, e1, tan)
            if a is None or b is None:
                row["skipped"] += 1
                continue
            (pa, na, ka), (pb, nb, kb) = a, b
            row["gap_mm"] = max(row["gap_mm"], _norm(_sub(pa, pb)))
            row["edge_gap_mm"] = max(row["edge_gap_mm"], _norm(_sub(pa, c)), _norm(_sub(pb, c)))
            ang = math.degrees(math.atan2(_norm(_cross(na, nb)), _dot(na, nb)))
            if ang > row["angle_deg"]:
                row["angle_deg"], row["t_angle"] = ang, t
            jump = abs(ka - kb)
            rel = jump / max(abs(ka), abs(kb), floor)
            row["curvature_jump"] = max(row["curvature_jump"], jump)
            row["local_relative_curvature_jump"] = max(
                row["local_relative_curvature_jump"], jump / max(abs(ka), abs(kb), LOCAL_FLOOR))
            if rel >= row["relative_curvature_jump"]:
                row["relative_curvature_jump"] = rel
                row["k_at_worst"], row["t_curvature"] = [ka, kb], t
        table.append(row)
    valid = bool(shape.isValid())
    try:
        volume = shape.Volume
    except Exception:  # an open shell
        volume = None
    return {
        "file": os.path.abspath(path), "valid": valid, "solids": len(shape.Solids),
        "faces": len(faces), "edges": len(edges), "shared_edges": counts["shared"],
        "seam_edges": counts["seams"], "free_edges": counts["free"], "free_edge_list": free_list,
        "degenerated_edges": counts["degenerated"], "non_manifold_edges": counts["non_manifold"],
        "volume_mm3": volume, "size_mm": size, "curvature_floor_per_mm": floor,
        "samples": samples,
        "max_gap_mm": max([r["gap_mm"] for r in table] or [0]),
        "max_edge_gap_mm": max([r["edge_gap_mm"] for r in table] or [0]),
        "max_angle_deg": max([r["angle_deg"] for r in table] or [0]),
        "max_relative_curvature_jump": max([r["relative_curvature_jump"] for r in table] or [0]),
        "seconds": time.time() - t_start, "table": table}


def classify(source, classify_deg, classify_rel):
    """Per source edge: 'G2', 'G1' or '' (a crease), from the source's own figures."""
    out = {}
    for r in source["table"]:
        if r["angle_deg"] < classify_deg:
            out[r["edge"]] = "G2" if r["relative_curvature_jump"] < classify_rel else "G1"
        else:
            out[r["edge"]] = ""
    return out


def match_edges(source, model):
    """source edge index -> model edge index. Faces keep their order through Clayform (checked:
    the same count), edges need not (a face's loops may be written in another order): an edge
    is matched by its two faces, and among several edges between the same two faces (or seams of
    one face) by the nearest middle point, each model edge used once."""
    by_pair = {}
    for r in model["table"]:
        by_pair.setdefault(tuple(sorted(r["faces"])), []).append(r)
    out = {}
    for s in source["table"]:
        cands = [r for r in by_pair.get(tuple(sorted(s["faces"])), [])
                 if r["edge"] not in out.values()]
        if not cands:
            continue
        best = min(cands, key=lambda r: sum((a - b) ** 2 for a, b in zip(r["middle"], s["middle"])))
        out[s["edge"]] = best["edge"]
    return out


def compare(source, model, opts):
    """Checks `model` against the limits on the edges `source` classifies (match_edges pairs
    them)."""
    failures = []
    if not model["valid"]:
        failures.append("BRepCheck: the model is not valid")
    new_free = model["free_edges"] - source["free_edges"]
    if new_free > 0:
        failures.append("%d new free edges (%d, the source %d)" %
                        (new_free, model["free_edges"], source["free_edges"]))
    src_rows = {r["edge"]: r for r in source["table"]}
    rows = {r["edge"]: r for r in model["table"]}
    kinds = classify(source, opts["classify_deg"], opts["classify_rel"])
    if (source["faces"], source["edges"]) != (model["faces"], model["edges"]):
        failures.append("topology changed: %d faces, %d edges (the source %d, %d)" %
                        (model["faces"], model["edges"], source["faces"], source["edges"]))
    summary = {"g1_edges": 0, "g2_edges": 0, "worst_g1_angle_deg": 0.0, "worst_g1_edge": None,
               "worst_g2_angle_deg": 0.0, "worst_g2_relative_curvature_jump": 0.0,
               "worst_g2_edge": None, "worst_g2_local_relative_curvature_jump": 0.0,
               "worst_g2_curvature_jump": 0.0, "worst_gap_mm": model["max_gap_mm"],
               "g1_over": 0, "g2_over": 0}
    matched = match_edges(source, model) if source["faces"] == model["faces"] else {}
    for e, kind in sorted(kinds.items()):
        s = src_rows[e]
        r = rows.get(matched.get(e))
        if r is None:
            failures.append("source edge %d: no edge between faces %s in the model" %
                            (e, s["faces"]))
            continue
        r["class"] = kind
        r["source_edge"] = e
        r["source"] = {"angle_deg": s["angle_deg"],
                       "relative_curvature_jump": s["relative_curvature_jump"],
                       "gap_mm": s["gap_mm"]}
        if opts["gap_mm"] > 0 and r["gap_mm"] > opts["gap_mm"]:
            failures.append("edge %d (faces %s): gap %.3g mm > %g" %
                            (r["edge"], r["faces"], r["gap_mm"], opts["gap_mm"]))
        if kind:
            summary["g1_edges"] += 1
            if r["angle_deg"] >= summary["worst_g1_angle_deg"]:
                summary["worst_g1_angle_deg"], summary["worst_g1_edge"] = r["angle_deg"], r["edge"]
            if r["angle_deg"] > opts["g1_deg"]:
                summary["g1_over"] += 1
                failures.append("%s edge %d (faces %s): %.4g deg > %g" %
                                (kind, r["edge"], r["faces"], r["angle_deg"], opts["g1_deg"]))
        if kind == "G2":
            summary["g2_edges"] += 1
            summary["worst_g2_angle_deg"] = max(summary["worst_g2_angle_deg"], r["angle_deg"])
            summary["worst_g2_curvature_jump"] = max(summary["worst_g2_curvature_jump"],
                                                     r["curvature_jump"])
            summary["worst_g2_local_relative_curvature_jump"] = max(
                summary["worst_g2_local_relative_curvature_jump"],
                r["local_relative_curvature_jump"])
            if r["relative_curvature_jump"] >= summary["worst_g2_relative_curvature_jump"]:
                summary["worst_g2_relative_curvature_jump"] = r["relative_curvature_jump"]
                summary["worst_g2_edge"] = r["edge"]
            if r["relative_curvature_jump"] > opts["g2_rel"]:
                summary["g2_over"] += 1
                failures.append("G2 edge %d (faces %s): curvature jump %.3g > %g "
                                "(k %.4g vs %.4g /mm)" %
                                (r["edge"], r["faces"], r["relative_curvature_jump"],
                                 opts["g2_rel"],
                                 r["k_at_worst"][0], r["k_at_worst"][1]))
    summary["new_free_edges"] = new_free
    summary["limits"] = {k: opts[k] for k in ("classify_deg", "classify_rel", "g1_deg", "g2_rel",
                                              "gap_mm")}
    summary["failures"] = failures
    summary["passed"] = not failures
    return summary


def print_table(res, show_rows):
    print("%s: %s, %d solid(s), %d faces, %d edges: %d shared, %d seams, %d free, %d degenerated,"
          " %d non-manifold; volume %s mm3; %.2f s" %
          (res["file"], "valid" if res["valid"] else "NOT VALID", res["solids"], res["faces"],
           res["edges"], res["shared_edges"], res["seam_edges"], res["free_edges"],
           res["degenerated_edges"], res["non_manifold_edges"],
           "%.6g" % res["volume_mm3"] if res["volume_mm3"] is not None else "-", res["seconds"]))
    print("  max gap %.3g mm, max angle %.4g deg, max relative curvature jump %.3g "
          "(floor 1/%.4g mm)" % (res["max_gap_mm"], res["max_angle_deg"],
                                 res["max_relative_curvature_jump"], res["size_mm"]))
    if not show_rows:
        return
    print("  edge  src  faces   class  gap_mm     angle_deg    k_jump/mm   rel_jump    "
          "src_angle  src_rel")
    for r in res["table"]:
        src = r.get("source", {})
        print("  %4d  %3s  %-7s %-5s  %.3e  %.5e  %.3e  %.3e  %s  %s" %
              (r["edge"], r.get("source_edge", "-"), "%d,%d" % tuple(r["faces"]),
               r.get("class", "?") or "-", r["gap_mm"],
               r["angle_deg"], r["curvature_jump"], r["relative_curvature_jump"],
               "%.3e" % src["angle_deg"] if src else "    -    ",
               "%.3e" % src["relative_curvature_jump"] if src else "    -    "))


def main():
    try:
        opts = parse_args(sys.argv)
        Part = _import_part()
    except Exception as e:  # noqa: BLE001
        print("edge_continuity: %s" % e, file=sys.stderr)
        return 2
    try:
        res = measure(Part, opts["model"], opts["samples"])
        out = {"model": res}
        code = 0
        if opts["reference"]:
            ref = opts["reference"]
            if ref.endswith(".json"):
                with open(ref) as f:
                    source = json.load(f)
                source = source.get("model", source)
            else:
                source = measure(Part, ref, opts["samples"])
            out["source"] = {k: v for k, v in source.items() if k != "table"}
            out["source"]["table"] = source["table"]
            check = compare(source, res, opts)
            out["check"] = check
            code = 0 if check["passed"] else 1
        else:
            for r in res["table"]:
                r["class"] = "G2" if (r["angle_deg"] < opts["classify_deg"] and
                                      r["relative_curvature_jump"] < opts["classify_rel"]) \
                    else ("G1" if r["angle_deg"] < opts["classify_deg"] else "")
        print_table(res, opts["table"])
        if opts["reference"]:
            c = out["check"]
            print("  against %s: %d G1 edges (incl. G2), worst %.4g deg (edge %s); %d G2 edges, "
                  "worst relative curvature jump %.3g (edge %s); %d new free edges: %s" %
                  (opts["reference"], c["g1_edges"], c["worst_g1_angle_deg"], c["worst_g1_edge"],
                   c["g2_edges"], c["worst_g2_relative_curvature_jump"], c["worst_g2_edge"],
                   c["new_free_edges"], "PASSED" if c["passed"] else "FAILED"))
            for f in c["failures"]:
                print("    " + f)
        if opts["json"]:
            with open(opts["json"], "w") as f:
                json.dump(out, f, indent=1)
        sys.stdout.flush()
        return code
    except Exception:  # noqa: BLE001
        traceback.print_exc()
        return 2


# freecadcmd runs a script as a module named after its file, not as __main__
if __name__ == "__main__" or os.path.basename(sys.argv[0] if sys.argv else "") == SCRIPT:
    sys.exit(main())
