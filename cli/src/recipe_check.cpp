// Recipe checking: JSON text → RecipeData, with every problem collected (docs/recipe.md).
// The JSON is walked once; each reader records a Problem with the value's path and returns a
// fallback so the walk goes on and everything wrong is reported at once.
#include "recipe_model.hpp"

#include <clay/constraints/constraint.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/error.hpp>
#include <clay/sketch/entities.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/exchange.hpp>

#include <clay/internal/deformation_json.hpp>
#include <clay/internal/json_reader.hpp>
#include <clay/internal/fenv.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <regex>
#include <set>
#include <sstream>

namespace clay::recipe {

namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;
using surface::Points3;

constexpr std::string_view format_name = "clayform.recipe";
constexpr int format_version = 1;
constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double degrees_to_radians = std::numbers::pi / 180.0;

using internal::found;
using internal::index_path;
using internal::join;
using internal::key_path;
using internal::Range;
using internal::shortest;

// ---- limits ----------------------------------------------------------------------------------
// Every count, size and magnitude a recipe can ask for has a ceiling (docs/recipe.md, "Limits"),
// so that `validate` refuses in milliseconds what would take minutes or gigabytes to run: a fuzz
// campaign (issue #18) found recipes that did, among them one surface listed 100,000 times in an
// export, a lattice of 200^3 cells, 100,000 prism sections and coordinates of 2^31 mm. Each
// ceiling is far above what styling work needs (a car is 5,000 mm long; the examples stay far
// below every one) and low enough that the largest recipe allowed still runs in seconds.
namespace limit {
constexpr std::size_t text_bytes = 64u << 20;   // the recipe text: 64 MiB
constexpr int depth = 64;                        // nesting of arrays and objects (the schema uses 8)
constexpr double magnitude = 1e6;                // |any number|: mm (1 km), degrees, knots, weights
constexpr std::size_t entries = 1000;            // names per section, surfaces per export, skin sections
constexpr std::size_t curve_points = 10000;      // control points of a curve, points of a polyline
constexpr std::size_t stroke_points = 10000;     // drawn points of a stroke
constexpr std::size_t surface_points = 250000;   // control points of an inline surface (500 x 500)
constexpr std::size_t sketch_items = 1000;       // points, entities, constraints of a sketch
constexpr std::size_t steps = 100;               // steps of a deformation stack
constexpr std::size_t moves = 10000;             // moves of a lattice step or direct manipulation
constexpr double weight_min = 1e-6, weight_max = 1e6;  // rational weights (ratio at most 1e12)
constexpr long lattice_points = 100000;          // control points of a Bézier or B-spline lattice
constexpr int lattice_cells = 64;                // cells of a B-spline lattice per direction
constexpr long chunks = 4096;                    // tricubic chunks of an extended lattice
constexpr int prism_sections = 65;               // sections of a prism lattice (64 gaps)
constexpr int cylinder_sectors = 256, cylinder_rings = 64, lattice_layers = 64;
constexpr double twist_turns = 100;              // twist: turns within 1 m of its origin
constexpr double taper_scale = 1e3;              // taper: |r(z)| bound within 1 m of its origin
constexpr double bend_rate = 1;                  // bend: rad/mm (radius of curvature >= 1 mm)
constexpr double bend_turns = 10;                // bend: turns over its region
constexpr double sweep_twist_degrees = 3600;     // sweep: 10 turns
constexpr double arc_degrees = 720;              // arc start and end angles
constexpr double min_tolerance = 1e-9;           // smallest refit, sweep and fit tolerance
constexpr int refit_control_points = 40000;      // a refit's net (RefitOptions' default)
}  // namespace limit

// Every number is also within ±limit::magnitude (Checker::number).
constexpr Range any{-limit::magnitude, limit::magnitude, false, false};
constexpr Range positive{0, limit::magnitude, true, false};
constexpr Range non_negative{0, limit::magnitude, false, false};
constexpr Range tolerance_range{limit::min_tolerance, limit::magnitude};
// Weights beyond it overflow the homogeneous products (a bottle's neck with weights 1e300 read
// back invalid); within it a weight ratio of 1e12 is still allowed.
constexpr Range weight_range{limit::weight_min, limit::weight_max};
// Knot vectors are count + degree + 1 long.
constexpr std::size_t knot_slack = surface::max_kernel_degree + 1;

bool valid_name(std::string_view s) {
  if (s.empty() || s.size() > 64) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

/// The walk: the shared path-aware reader (clay/internal/json_reader.hpp) with the recipe's
/// limits and wording, and the recipe's own composite reads.
class Checker : public internal::JsonReader {
 public:
  Checker() {
    magnitude = limit::magnitude;
    magnitude_note = "recipe numbers are limited to ±" + shortest(limit::magnitude) + ": mm, degrees, knots and weights";
    limit_note = "recipe limit";
  }

  using JsonReader::choice;
  /// One of `choices` (the index), or nullopt.
  std::optional<int> choice(const Json& j, const std::string& path, std::initializer_list<std::string_view> choices) {
    return JsonReader::choice(j, path, std::vector<std::string>(choices.begin(), choices.end()));
  }
  /// recipe limits on counts by default.
  std::optional<Points3> points(const Json& j, const std::string& path, std::size_t min,
                                std::size_t max = limit::curve_points) {
    return JsonReader::points(j, path, min, max);
  }
  std::optional<std::vector<double>> numbers(const Json& j, const std::string& path, std::size_t min,
                                             std::size_t max = limit::surface_points, Range r = any) {
    return JsonReader::numbers(j, path, min, max, r);
  }
  std::optional<double> number(const Json& j, const std::string& path, Range r = any) {
    return JsonReader::number(j, path, r);
  }
  double number_or(const Json& obj, const std::string& path, std::string_view key, double def, Range r = any) {
    return JsonReader::number_or(obj, path, key, def, r);
  }

  /// Runs `build` and turns a clay::Error into a problem at `path`.
  template <class F>
  bool attempt(const std::string& path, F&& build) {
    try {
      build();
      return true;
    } catch (const Error& e) {
      add(path, e.message());
      return false;
    }
  }
  /// `value` when `list` (its problems(value, path)) is empty; else the problems, and nullopt.
  template <class T>
  std::optional<T> checked(T value, const std::string& path, const std::vector<std::string>& list) {
    if (list.empty()) return value;
    add_all(path, list);
    return std::nullopt;
  }

  /// Reads the required [x, y, z] members of j into their targets; false when any is bad.
  bool vec3_members(const Json& j, const std::string& path,
                    std::initializer_list<std::pair<const char*, Eigen::Vector3d*>> members) {
    bool ok = true;
    for (auto [key, target] : members) {
      const Json* v = member(j, path, key, true, "[x, y, z] (mm)");
      const auto x = v ? vec3(*v, key_path(path, key)) : std::nullopt;
      ok = ok && x.has_value();
      if (x) *target = *x;
    }
    return ok;
  }

 protected:
  std::string wording(std::string message) const override { return recipe_wording(std::move(message)); }
};

/// The reader's problems as the recipe's (a syntax error's line and column are added apart).
std::vector<Problem> recipe_problems(const Checker& c) {
  std::vector<Problem> out;
  out.reserve(c.problems.size());
  for (const auto& p : c.problems) out.push_back({p.path, p.message, 0, 0});
  return out;
}

// ---- names and references ------------------------------------------------------------------------

/// What has been defined so far, and what the whole document declares (to tell "missing" from
/// "defined later").
struct Names {
  std::vector<std::string> curves;            // strokes, curves and sketch entities, in order
  std::set<std::string> curves_declared;      // everything the document declares as a curve
  std::vector<std::string> surfaces;
  std::set<std::string> surfaces_declared;
  std::vector<std::string> stacks;            // all stacks (may be referenced from anywhere)

  static bool has(const std::vector<std::string>& list, const std::string& name) {
    return std::find(list.begin(), list.end(), name) != list.end();
  }
};

std::string listing(const std::vector<std::string>& names) {
  if (names.empty()) return "none is defined";
  if (names.size() <= 12) return "defined: " + join(names);
  return "defined: " + join(std::vector<std::string>(names.begin(), names.begin() + 12)) + ", ... (" +
         std::to_string(names.size()) + " in all)";
}

class RecipeChecker {
 public:
  RecipeChecker(Checker& c, fs::path base) : c_(c), base_(std::move(base)) {}
  RecipeData data;
  /// Set when a deferred sketch is built again at run time: the run's curves by name.
  std::function<const surface::BSplineCurve*(const std::string&)> runtime_curve;

  /// Builds one sketch from its JSON at run time (rebuild_sketch): every curve name is known.
  void rebuild(const std::string& name, const Json& j, const std::string& path) {
    names_.curves_declared.clear();
    sketch(name, j, path);
  }
  /// The curves a rebuild may refer to (all the run's curves).
  void know_curves(std::vector<std::string> names) { names_.curves = std::move(names); }

  void run(const Json& root) {
    if (!c_.object(root, "", {"format", "version", "name", "description", "units", "composition",
                              "strokes", "curves", "sketches", "surfaces", "deformations", "exports"},
                   "a recipe {\"format\": \"clayform.recipe\", \"version\": 1, ...}"))
      return;
    const Json* format = c_.member(root, "", "format", true, "\"format\": \"clayform.recipe\"");
    if (format && (!format->is_string() || format->get<std::string>() != format_name))
      c_.add("format", "expected \"clayform.recipe\", found " + found(*format) +
                           "; this is not a Clayform recipe (a deformation stack file is read by "
                           "deform::stack_from_json)");
    const Json* version = c_.member(root, "", "version", true, "\"version\": 1");
    if (version && (!version->is_number_integer() || version->get<long long>() != format_version))
      c_.add("version", found(*version) + " is not supported: this clayform reads version " +
                            std::to_string(format_version) + "; write the recipe for version 1");
    if (const Json* j = c_.member(root, "", "name", false, ""))
      data.name = c_.string(*j, "name").value_or("");
    if (const Json* j = c_.member(root, "", "description", false, ""))
      data.description = c_.string(*j, "description").value_or("");
    if (const Json* j = c_.member(root, "", "units", false, "")) {
      const auto u = c_.string(*j, "units");
      if (u && *u != "mm")
        c_.add("units", "\"" + *u + "\" is not supported: Clayform models are in millimetres; "
                        "convert the lengths and write \"units\": \"mm\"");
    }
    if (const Json* j = c_.member(root, "", "composition", false, ""))
      data.composition = composition(*j, "composition", Composition{});

    declare(root);
    section(root, "strokes", [&](const std::string& n, const Json& j, const std::string& p) { stroke(n, j, p); });
    section(root, "curves", [&](const std::string& n, const Json& j, const std::string& p) { curve(n, j, p); });
    section(root, "sketches", [&](const std::string& n, const Json& j, const std::string& p) { sketch(n, j, p); });
    section(root, "deformations", [&](const std::string& n, const Json& j, const std::string& p) { stack(n, j, p); });
    section(root, "surfaces", [&](const std::string& n, const Json& j, const std::string& p) { surface(n, j, p); });
    section(root, "exports", [&](const std::string& n, const Json& j, const std::string& p) { exporting(n, j, p); });
  }

 private:
  Checker& c_;
  fs::path base_;
  Names names_;

  template <class F>
  void section(const Json& root, std::string_view key, F&& each) {
    const Json* j = c_.member(root, "", key, false, "");
    if (!j) return;
    if (!j->is_object()) {
      c_.add(std::string(key), "expected an object of NAME: {...} entries, found " + found(*j));
      return;
    }
    if (j->size() > limit::entries) {
      c_.add(std::string(key), std::to_string(j->size()) + " entries; at most " + std::to_string(limit::entries) +
                                   " are allowed (recipe limit): split the recipe");
      return;
    }
    for (const auto& [name, value] : j->items()) each(name, value, key_path(std::string(key), name));
  }

  /// First pass: every name the document declares (for "defined later" and the stacks, which
  /// may be referenced before they appear), and malformed or repeated names.
  void declare(const Json& root) {
    std::map<std::string, std::string> curve_owner;  // name → path of its definition
    auto declare_curve = [&](const std::string& name, const std::string& path) {
      const auto [it, inserted] = curve_owner.emplace(name, path);
      if (!inserted)
        c_.add(path, "the curve name \"" + name + "\" is already used by " + it->second +
                         "; strokes, curves and sketch entities share one namespace: rename one");
      names_.curves_declared.insert(name);
    };
    auto each = [&](std::string_view section_key, auto&& f) {
      const Json* s = c_.member(root, "", section_key, false, "");
      if (!s || !s->is_object() || s->size() > limit::entries) return;  // reported by section()
      for (const auto& [name, value] : s->items()) {
        const std::string path = key_path(std::string(section_key), name);
        if (!valid_name(name))
          c_.add(path, "the name \"" + name + "\" is not allowed; use 1 to 64 of A-Z a-z 0-9 _ -");
        f(name, value, path);
      }
    };
    each("strokes", [&](const std::string& n, const Json&, const std::string& p) { declare_curve(n, p); });
    each("curves", [&](const std::string& n, const Json&, const std::string& p) { declare_curve(n, p); });
    each("sketches", [&](const std::string& n, const Json& v, const std::string& p) {
      if (!v.is_object()) return;
      const auto e = v.find("entities");
      if (e == v.end() || !e->is_object()) return;
      for (const auto& [entity, ev] : e->items()) {
        (void)ev;
        const std::string ep = key_path(key_path(p, "entities"), entity);
        if (!valid_name(entity))
          c_.add(ep, "the name \"" + entity + "\" is not allowed; use 1 to 64 of A-Z a-z 0-9 _ -");
        declare_curve(n + "." + entity, ep);
      }
    });
    each("surfaces", [&](const std::string& n, const Json&, const std::string&) {
      names_.surfaces_declared.insert(n);
    });
    each("deformations", [&](const std::string& n, const Json&, const std::string&) {
      names_.stacks.push_back(n);
    });
    each("exports", [&](const std::string&, const Json&, const std::string&) {});
  }

  std::optional<std::string> curve_ref(const Json& j, const std::string& path) {
    const auto name = c_.string(j, path);
    if (!name) return std::nullopt;
    if (Names::has(names_.curves, *name)) return name;
    if (names_.curves_declared.count(*name))
      c_.add(path, "the curve \"" + *name + "\" is defined later in the recipe; a curve may only use "
                   "curves defined before it (move its definition up)");
    else
      c_.add(path, "no curve named \"" + *name + "\"; " + listing(names_.curves));
    return std::nullopt;
  }

  std::optional<std::string> surface_ref(const Json& j, const std::string& path) {
    const auto name = c_.string(j, path);
    if (!name) return std::nullopt;
    if (Names::has(names_.surfaces, *name)) return name;
    if (names_.surfaces_declared.count(*name))
      c_.add(path, "the surface \"" + *name + "\" is defined later in \"surfaces\" (or is this one); "
                   "surfaces are built in document order: move its definition up");
    else
      c_.add(path, "no surface named \"" + *name + "\"; " + listing(names_.surfaces));
    return std::nullopt;
  }

  std::vector<std::string> curve_refs(const Json& obj, const std::string& path, std::string_view key,
                                      std::size_t min, std::size_t max) {
    const Json* j = c_.member(obj, path, key, true, "an array of curve names");
    if (!j) return {};
    const std::string p = key_path(path, key);
    if (!j->is_array() || j->size() < min || j->size() > max) {
      c_.add(p, "expected an array of " + std::to_string(min) + (max > min ? " to " + std::to_string(max) : "") +
                    " curve names, found " + found(*j));
      return {};
    }
    std::vector<std::string> out;
    for (std::size_t i = 0; i < j->size(); ++i)
      if (const auto n = curve_ref((*j)[i], index_path(p, i))) out.push_back(*n);
    return out.size() == j->size() ? out : std::vector<std::string>{};
  }

  // ---- composition ------------------------------------------------------------------------

  Composition composition(const Json& j, const std::string& path, Composition c) {
    if (!c_.object(j, path, {"mode", "tolerance", "relative", "degree", "check_samples", "max_control_points",
                             "accept_out_of_tolerance"},
                   "a composition {\"mode\": \"exact\"|\"refit\", ...}"))
      return c;
    if (const Json* m = c_.member(j, path, "mode", false, ""))
      if (const auto k = c_.choice(*m, key_path(path, "mode"), {"exact", "refit"})) c.refit = *k == 1;
    c.tolerance = c_.number_or(j, path, "tolerance", c.tolerance, tolerance_range);
    c.relative = c_.boolean_or(j, path, "relative", c.relative);
    c.degree = c_.integer_or(j, path, "degree", c.degree, 1, 25);
    c.check_samples = c_.integer_or(j, path, "check_samples", c.check_samples, 2, 64);
    c.accept_out_of_tolerance = c_.boolean_or(j, path, "accept_out_of_tolerance", c.accept_out_of_tolerance);
    // The refit's cap on its net (RefitOptions::max_control_points, 40,000 at most: the default,
    // which already takes about 20 s to reach), at least the (degree + 1)^2 of one patch.
    c.max_control_points = c_.integer_or(j, path, "max_control_points", c.max_control_points,
                                         (c.degree + 1) * (c.degree + 1), limit::refit_control_points);
    return c;
  }

  // ---- strokes, curves, sketches --------------------------------------------------------------

  std::optional<sketch::SketchPlane> plane(const Json& j, const std::string& path) {
    if (!c_.object(j, path, {"origin", "x_axis", "y_axis"}, "a plane {origin, x_axis, y_axis}"))
      return std::nullopt;
    sketch::SketchPlane pl;
    if (!c_.vec3_members(j, path, {{"origin", &pl.origin}, {"x_axis", &pl.x_axis}, {"y_axis", &pl.y_axis}}))
      return std::nullopt;
    return c_.checked(pl, path, sketch::problems(pl, path));
  }

  void stroke(const std::string& name, const Json& j, const std::string& path) {
    names_.curves.push_back(name);  // defined even when broken: one problem, not a cascade
    if (!c_.object(j, path, {"points", "plane", "tolerance", "degree", "fairness", "closing_ratio", "accept_out_of_tolerance"},
                   "a stroke {points, plane, tolerance, degree, fairness, closing_ratio}"))
      return;
    StrokeDef s{name, path, {}, {}};
    const Json* pts = c_.member(j, path, "points", true, "the drawn points [[x, y, z], ...]");
    const auto p = pts ? c_.points(*pts, key_path(path, "points"), 2, limit::stroke_points) : std::nullopt;
    if (const Json* pl = c_.member(j, path, "plane", false, ""))
      s.stroke.plane = plane(*pl, key_path(path, "plane"));
    s.fit.tolerance = c_.number_or(j, path, "tolerance", s.fit.tolerance, tolerance_range);
    s.fit.degree = c_.integer_or(j, path, "degree", s.fit.degree, 2, 9);
    s.fit.fairness = c_.number_or(j, path, "fairness", s.fit.fairness, non_negative);
    s.fit.closing_ratio = c_.number_or(j, path, "closing_ratio", s.fit.closing_ratio, Range{0, 0.5});
    s.fit.corner_angle = 180.0;  // one curve per stroke in a recipe (docs/recipe.md)
    s.accept_out_of_tolerance = c_.boolean_or(j, path, "accept_out_of_tolerance", false);
    if (!p) return;
    s.stroke.points = *p;
    const auto list = sketch::problems(s.stroke, path);
    if (!list.empty()) return c_.add_all(path, list);
    if (c_.attempt(path, [&] { s.fit.validate(); })) data.strokes.push_back(std::move(s));
  }

  std::optional<surface::BSplineCurve> inline_curve(const Json& j, const std::string& path) {
    if (!c_.object(j, path, {"degree", "knots", "points", "weights"},
                   "a B-spline curve {degree, knots, points, weights}"))
      return std::nullopt;
    const Json* d = c_.member(j, path, "degree", true, "the degree, e.g. 3");
    const Json* k = c_.member(j, path, "knots", true, "the knot vector (count + degree + 1 numbers)");
    const Json* p = c_.member(j, path, "points", true, "the control points [[x, y, z], ...]");
    const auto degree = d ? c_.integer(*d, key_path(path, "degree"), 1, surface::max_kernel_degree) : std::nullopt;
    const auto knots = k ? c_.numbers(*k, key_path(path, "knots"), 2, limit::curve_points + knot_slack) : std::nullopt;
    const auto points = p ? c_.points(*p, key_path(path, "points"), 2) : std::nullopt;
    std::optional<std::vector<double>> weights;
    if (const Json* w = c_.member(j, path, "weights", false, ""))
      if (!(weights = c_.numbers(*w, key_path(path, "weights"), 2, limit::curve_points, weight_range))) return std::nullopt;
    if (!degree || !knots || !points) return std::nullopt;
    surface::BSplineCurve curve;
    curve.basis = {*degree, *knots};
    curve.points = *points;
    curve.weights = weights ? Eigen::Map<const Eigen::VectorXd>(weights->data(), static_cast<Eigen::Index>(weights->size())).eval()
                            : Eigen::VectorXd::Ones(points->rows()).eval();
    return c_.checked(curve, path, surface::problems(curve, path));
  }

  void curve(const std::string& name, const Json& j, const std::string& path) {
    CurveDef def{name, path, "", std::nullopt, ""};
    const bool ok = one_of(j, path, {"bspline", "line", "arc", "polyline", "reversed"}, "a curve", def.kind);
    const std::string p = key_path(path, def.kind);
    if (ok) {
      const Json& v = j.at(def.kind);
      if (def.kind == "bspline") {
        def.curve = inline_curve(v, p);
      } else if (def.kind == "line") {
        if (c_.object(v, p, {"from", "to"}, "a line {from, to}")) {
          const Json* a = c_.member(v, p, "from", true, "[x, y, z]");
          const Json* b = c_.member(v, p, "to", true, "[x, y, z]");
          const auto from = a ? c_.vec3(*a, key_path(p, "from")) : std::nullopt;
          const auto to = b ? c_.vec3(*b, key_path(p, "to")) : std::nullopt;
          if (from && to) {
            Points3 pts(2, 3);
            pts.row(0) = from->transpose();
            pts.row(1) = to->transpose();
            def.curve = polyline_curve(pts, p);
          }
        }
      } else if (def.kind == "polyline") {
        if (c_.object(v, p, {"points"}, "a polyline {points}")) {
          const Json* a = c_.member(v, p, "points", true, "[[x, y, z], ...]");
          if (const auto pts = a ? c_.points(*a, key_path(p, "points"), 2) : std::nullopt)
            def.curve = polyline_curve(*pts, p);
        }
      } else if (def.kind == "arc") {
        def.curve = arc(v, p);
      } else {  // reversed
        if (const auto n = curve_ref(v, p)) def.reversed_of = *n;
      }
    }
    names_.curves.push_back(name);
    if (def.curve || !def.reversed_of.empty()) data.curves.push_back(std::move(def));
  }

  std::optional<surface::BSplineCurve> polyline_curve(const Points3& pts, const std::string& path) {
    const auto n = pts.rows();
    for (Eigen::Index i = 1; i < n; ++i)
      if (pts.row(i) == pts.row(i - 1)) {
        c_.add(path, "points " + std::to_string(i - 1) + " and " + std::to_string(i) +
                         " are the same; a polyline needs distinct consecutive points");
        return std::nullopt;
      }
    surface::BSplineCurve c;
    c.basis.degree = 1;
    c.basis.knots.resize(static_cast<std::size_t>(n) + 2);
    c.basis.knots.front() = 0.0;
    for (Eigen::Index i = 0; i < n; ++i)
      c.basis.knots[static_cast<std::size_t>(i) + 1] = static_cast<double>(i) / static_cast<double>(n - 1);
    c.basis.knots.back() = 1.0;
    c.points = pts;
    c.weights = Eigen::VectorXd::Ones(n);
    return c;
  }

  std::optional<surface::BSplineCurve> arc(const Json& v, const std::string& p) {
    if (!c_.object(v, p, {"center", "x_axis", "y_axis", "radius", "start", "end"},
                   "an arc {center, x_axis, y_axis, radius, start, end}"))
      return std::nullopt;
    std::array<std::optional<Eigen::Vector3d>, 3> vs;
    int k = 0;
    for (const char* key : {"center", "x_axis", "y_axis"}) {
      const Json* m = c_.member(v, p, key, true, "[x, y, z]");
      vs[static_cast<std::size_t>(k++)] = m ? c_.vec3(*m, key_path(p, key)) : std::nullopt;
    }
    const Json* r = c_.member(v, p, "radius", true, "the radius in mm");
    const Json* s = c_.member(v, p, "start", true, "the start angle in degrees");
    const Json* e = c_.member(v, p, "end", true, "the end angle in degrees");
    const auto radius = r ? c_.number(*r, key_path(p, "radius"), positive) : std::nullopt;
    const Range angle{-limit::arc_degrees, limit::arc_degrees};
    const auto start = s ? c_.number(*s, key_path(p, "start"), angle) : std::nullopt;
    const auto end = e ? c_.number(*e, key_path(p, "end"), angle) : std::nullopt;
    if (!vs[0] || !vs[1] || !vs[2] || !radius || !start || !end) return std::nullopt;
    if (!(*end > *start && *end - *start <= 360.0)) {
      c_.add(p, "end − start = " + shortest(*end - *start) + " degrees; give 0 < end − start <= 360");
      return std::nullopt;
    }
    std::optional<surface::BSplineCurve> out;
    c_.attempt(p, [&] {
      out = surface::circular_arc(*vs[0], *vs[1], *vs[2], *radius, *start * degrees_to_radians,
                                  *end * degrees_to_radians);
    });
    return out;
  }

  /// Exactly one of `kinds` is a key of j: true and `kind` set; else the problem is recorded.
  bool one_of(const Json& j, const std::string& path, std::initializer_list<std::string_view> kinds,
              std::string_view what, std::string& kind) {
    std::vector<std::string> names(kinds.begin(), kinds.end());
    if (!j.is_object()) {
      c_.add(path, "expected " + std::string(what) + " as an object with one of " + join(names) +
                       ", found " + found(j));
      return false;
    }
    std::vector<std::string> present;
    for (const auto& [key, value] : j.items()) {
      (void)value;
      if (std::find(names.begin(), names.end(), key) != names.end())
        present.push_back(key);
      else
        c_.add(key_path(path, key), "unknown key \"" + key + "\" in " + std::string(what) +
                                        "; give exactly one of " + join(names));
    }
    if (present.size() != 1) {
      if (present.empty())
        c_.add(path, std::string(what) + " needs exactly one of " + join(names));
      else
        c_.add(path, std::string(what) + " has " + join(present) + "; give exactly one");
      return false;
    }
    kind = present.front();
    return true;
  }

  void sketch(const std::string& name, const Json& j, const std::string& path) {
    SketchDef def{name, path, {}, {}, {}, {}, {}};
    bool deferred = false;
    const auto register_entities = [&] {
      const auto e = j.is_object() ? j.find("entities") : j.end();
      if (j.is_object() && e != j.end() && e->is_object())
        for (const auto& [entity, v] : e->items()) {
          (void)v;
          names_.curves.push_back(name + "." + entity);
        }
    };
    if (!c_.object(j, path, {"plane", "points", "entities", "constraints", "tolerance"},
                   "a sketch {plane, points, entities, constraints, tolerance}")) {
      return;
    }
    const std::size_t before = c_.problems.size();
    sketch::PlaneId plane_id;
    if (const Json* pl = c_.member(j, path, "plane", false, ""))
      if (const auto p = plane(*pl, key_path(path, "plane"))) plane_id = def.sketch.add_plane(*p);
    std::map<std::string, sketch::PointId> points;
    std::map<std::string, sketch::EntityId> entities;
    if (const Json* pts = c_.member(j, path, "points", true, "an object of NAME: position")) {
      const std::string pp = key_path(path, "points");
      if (pts->is_object() && pts->size() > limit::sketch_items) {
        c_.add(pp, std::to_string(pts->size()) + " points; at most " + std::to_string(limit::sketch_items) +
                       " are allowed in a sketch (recipe limit)");
      } else if (pts->is_object()) {
        for (const auto& item : pts->items()) {  // no structured binding: Clang 14 cannot capture one
          const std::string& pname = item.key();
          const Json& pv = item.value();
          const std::string p = key_path(pp, pname);
          if (!plane_id.free()) {
            if (const auto ab = c_.vec2(pv, p))
              c_.attempt(p, [&] { points[pname] = def.sketch.add_point(plane_id, *ab); });
          } else if (const auto x = c_.vec3(pv, p)) {
            c_.attempt(p, [&] { points[pname] = def.sketch.add_point(*x); });
          }
        }
      } else {
        c_.add(pp, "expected an object of NAME: position, found " + found(*pts));
      }
    }
    // Messages of the sketch and the solver name points and entities as the recipe does.
    def.sketch.point_names.resize(def.sketch.points.size());
    for (const auto& [pname, id] : points) def.sketch.point_names[static_cast<std::size_t>(id.index)] = pname;
    auto name_next_entity = [&](const std::string& ename) {
      def.sketch.entity_names.resize(def.sketch.entities.size() + 1);
      def.sketch.entity_names.back() = ename;
    };
    // A point or entity declared in this sketch but not built has its own problem reported at
    // its declaration; references to it stay quiet rather than adding a follow-on "no point".
    // An entity left unbuilt because it refers to such a point or entity is quiet too.
    const std::string points_path = key_path(path, "points"), entities_path = key_path(path, "entities");
    std::set<std::string> unbuilt_by_reference;
    std::string building;  // the entity being built, while entities are read
    auto failed = [&](const Json* section, const std::string& section_path, const std::string& declared) {
      if (!section || !section->is_object() || !section->contains(declared)) return false;
      const std::string at = key_path(section_path, declared);
      const bool quiet =
          (section_path == entities_path && unbuilt_by_reference.count(declared) > 0) ||
          std::any_of(c_.problems.begin(), c_.problems.end(), [&](const internal::JsonProblem& q) {
            return q.path == at || q.path.rfind(at + ".", 0) == 0 || q.path.rfind(at + "[", 0) == 0;
          });
      if (quiet && !building.empty()) unbuilt_by_reference.insert(building);
      return quiet;
    };
    const Json* declared_points = j.contains("points") ? &j.at("points") : nullptr;
    const Json* declared_entities = j.contains("entities") ? &j.at("entities") : nullptr;
    auto point_ref = [&](const Json& v, const std::string& p) -> std::optional<sketch::PointId> {
      const auto n = c_.string(v, p);
      if (!n) return std::nullopt;
      const auto it = points.find(*n);
      if (it != points.end()) return it->second;
      if (failed(declared_points, points_path, *n)) return std::nullopt;
      // "E.start" / "E.end": an end point of a line, arc or B-spline curve entity (a curve's
      // first or last control point: the curve is clamped).
      if (const auto dot = n->rfind('.'); dot != std::string::npos) {
        const std::string e = n->substr(0, dot), end = n->substr(dot + 1);
        const auto ei = entities.find(e);
        if (ei == entities.end() && (end == "start" || end == "end") && failed(declared_entities, entities_path, e))
          return std::nullopt;
        if (ei != entities.end() && (end == "start" || end == "end")) {
          const bool start = end == "start";
          const auto& entity = def.sketch.entities[static_cast<std::size_t>(ei->second.index)];
          if (const auto* l = std::get_if<sketch::Line>(&entity)) return start ? l->start : l->end;
          if (const auto* a = std::get_if<sketch::Arc>(&entity)) return start ? a->start : a->end;
          if (const auto* c = std::get_if<sketch::Curve>(&entity))
            return start ? c->control_points.front() : c->control_points.back();
          c_.add(p, "\"" + e + "\" is a circle, which has no end points; refer to its center point");
          return std::nullopt;
        }
      }
      std::vector<std::string> known;
      for (const auto& [k, id] : points) known.push_back(k);
      c_.add(p, "no point named \"" + *n + "\" in this sketch (an entity's end is \"ENTITY.start\" or "
                "\"ENTITY.end\"); " + listing(known));
      return std::nullopt;
    };
    auto entity_ref = [&](const Json& v, const std::string& p) -> std::optional<sketch::EntityId> {
      const auto n = c_.string(v, p);
      if (!n) return std::nullopt;
      const auto it = entities.find(*n);
      if (it != entities.end()) return it->second;
      if (failed(declared_entities, entities_path, *n)) return std::nullopt;
      std::vector<std::string> known;
      for (const auto& [k, id] : entities) known.push_back(k);
      c_.add(p, "no entity named \"" + *n + "\" in this sketch; " + listing(known));
      return std::nullopt;
    };
    if (const Json* ents = c_.member(j, path, "entities", true, "an object of NAME: {line|circle|arc}")) {
      const std::string ep = key_path(path, "entities");
      if (ents->is_object() && ents->size() > limit::sketch_items) {
        c_.add(ep, std::to_string(ents->size()) + " entities; at most " + std::to_string(limit::sketch_items) +
                       " are allowed in a sketch (recipe limit)");
      } else if (ents->is_object()) {
        for (const auto& item : ents->items()) {  // no structured binding: Clang 14 cannot capture one
          const std::string& ename = item.key();
          const Json& ev = item.value();
          const std::string p = key_path(ep, ename);
          building = ename;
          std::string kind;
          if (!one_of(ev, p, {"line", "circle", "arc", "bspline", "curve"}, "a sketch entity", kind)) continue;
          const Json& v = ev.at(kind);
          const std::string kp = key_path(p, kind);
          if (kind == "bspline" || kind == "curve") {
            // A clamped B-spline whose control points become sketch points (the solver moves
            // them): inline, or a curve of the "curves" section given inline there.
            std::optional<surface::BSplineCurve> curve;
            if (kind == "bspline") {
              curve = inline_curve(v, kp);
            } else if (const auto source = curve_ref(v, kp)) {
              const auto cd = std::find_if(data.curves.begin(), data.curves.end(),
                                           [&](const CurveDef& d) { return d.name == *source; });
              if (runtime_curve) {
                if (const surface::BSplineCurve* c = runtime_curve(*source)) curve = *c;
              } else if (cd != data.curves.end() && cd->curve) {
                curve = cd->curve;
              } else {
                // A stroke's fit or a reversed curve: known when the recipe runs. Checked here
                // with a stand-in (a straight cubic in the plane), built again then.
                surface::Points3 stand_in(4, 3);
                for (int k = 0; k < 4; ++k)
                  stand_in.row(k) = (plane_id.free() ? Eigen::Vector3d(k, 0, 0)
                                                     : sketch::to_world(def.sketch.planes[static_cast<std::size_t>(plane_id.index)],
                                                                        Eigen::Vector2d(k, 0)))
                                        .transpose();
                surface::BSplineCurve c;
                c.basis.degree = 3;
                c.basis.knots.assign({0, 0, 0, 0, 1, 1, 1, 1});
                c.points = stand_in;
                c.weights = Eigen::VectorXd::Ones(4);
                curve = std::move(c);
                deferred = true;
              }
            }
            if (curve) {
              name_next_entity(ename);
              c_.attempt(kp, [&] { entities[ename] = def.sketch.add_curve(*curve, plane_id); });
            }
            continue;
          }
          if (kind == "line") {
            if (!v.is_array() || v.size() != 2) {
              c_.add(kp, "expected [\"P\", \"Q\"] (two point names), found " + found(v));
              continue;
            }
            const auto a = point_ref(v[0], index_path(kp, 0));
            const auto b = point_ref(v[1], index_path(kp, 1));
            if (a && b) {
              name_next_entity(ename);
              c_.attempt(kp, [&] { entities[ename] = def.sketch.add_line(*a, *b); });
            }
          } else if (kind == "circle") {
            if (!c_.object(v, kp, {"center", "radius"}, "a circle {center, radius}")) continue;
            const Json* cj = c_.member(v, kp, "center", true, "a point name");
            const Json* rj = c_.member(v, kp, "radius", true, "the radius in mm");
            const auto center = cj ? point_ref(*cj, key_path(kp, "center")) : std::nullopt;
            const auto r = rj ? c_.number(*rj, key_path(kp, "radius"), positive) : std::nullopt;
            if (plane_id.free()) {
              c_.add(kp, "a circle needs the sketch's plane; give the sketch a \"plane\"");
              continue;
            }
            if (center && r) {
              name_next_entity(ename);
              c_.attempt(kp, [&] { entities[ename] = def.sketch.add_circle(*center, *r, plane_id); });
            }
          } else {
            if (!c_.object(v, kp, {"center", "start", "end"}, "an arc {center, start, end}")) continue;
            std::array<std::optional<sketch::PointId>, 3> ids;
            int k = 0;
            for (const char* key : {"center", "start", "end"}) {
              const Json* m = c_.member(v, kp, key, true, "a point name");
              ids[static_cast<std::size_t>(k++)] = m ? point_ref(*m, key_path(kp, key)) : std::nullopt;
            }
            if (plane_id.free()) {
              c_.add(kp, "an arc needs the sketch's plane; give the sketch a \"plane\"");
              continue;
            }
            if (ids[0] && ids[1] && ids[2]) {
              name_next_entity(ename);
              c_.attempt(kp, [&] { entities[ename] = def.sketch.add_arc(*ids[0], *ids[1], *ids[2], plane_id); });
            }
          }
        }
      } else {
        c_.add(ep, "expected an object of NAME: {line|circle|arc}, found " + found(*ents));
      }
      building.clear();
    }
    if (const Json* cons = c_.member(j, path, "constraints", false, "")) {
      const std::string cp = key_path(path, "constraints");
      if (!cons->is_array()) {
        c_.add(cp, "expected an array of {\"type\": ..., ...}, found " + found(*cons));
      } else if (c_.at_most(*cons, cp, limit::sketch_items, "constraints")) {
        for (std::size_t i = 0; i < cons->size(); ++i)
          if (auto con = constraint((*cons)[i], index_path(cp, i), point_ref, entity_ref)) {
            con->label = index_path(cp, i);  // the solver's messages name it by its path
            def.constraints.push_back(*con);
          }
      }
    }
    def.solve.tolerance = c_.number_or(j, path, "tolerance", def.solve.tolerance, Range{0, 1e-3, true, false});
    register_entities();
    if (c_.problems.size() != before) return;
    for (const auto& [ename, id] : entities) def.entities.emplace_back(name + "." + ename, id);
    // keep the entities in document order (the map sorted them)
    const Json& ents = j.at("entities");
    std::vector<std::pair<std::string, sketch::EntityId>> ordered;
    for (const auto& [ename, ev] : ents.items()) {
      (void)ev;
      ordered.emplace_back(name + "." + ename, entities.at(ename));
    }
    def.entities = std::move(ordered);
    if (deferred) def.deferred_json = j.dump();
    data.sketches.push_back(std::move(def));
  }

  template <class PointRef, class EntityRef>
  std::optional<constraints::Constraint> constraint(const Json& j, const std::string& path,
                                                    PointRef& point_ref, EntityRef& entity_ref) {
    namespace cs = constraints;
    if (!j.is_object()) {
      c_.add(path, "expected a constraint {\"type\": ..., ...}, found " + found(j));
      return std::nullopt;
    }
    const Json* t = c_.member(j, path, "type", true, "the constraint type, e.g. \"coincident\"");
    if (!t) return std::nullopt;
    const auto type = c_.choice(*t, key_path(path, "type"),
                                {"fixed", "coincident", "point_on", "horizontal", "vertical", "parallel",
                                 "perpendicular", "distance", "angle", "radius", "equal_length",
                                 "equal_radius", "midpoint", "symmetric", "tangent", "curvature"});
    if (!type) return std::nullopt;
    auto point = [&](std::string_view key) -> std::optional<sketch::PointId> {
      const Json* m = c_.member(j, path, key, true, "a point name");
      return m ? point_ref(*m, key_path(path, key)) : std::nullopt;
    };
    auto entity = [&](std::string_view key) -> std::optional<sketch::EntityId> {
      const Json* m = c_.member(j, path, key, true, "an entity name");
      return m ? entity_ref(*m, key_path(path, key)) : std::nullopt;
    };
    auto pair_of = [&](std::string_view key, auto&& ref) {
      using Id = typename std::invoke_result_t<decltype(ref), const Json&, const std::string&>::value_type;
      std::optional<std::pair<Id, Id>> out;
      const Json* m = c_.member(j, path, key, true, "two names [\"a\", \"b\"]");
      if (!m) return out;
      const std::string p = key_path(path, key);
      if (!m->is_array() || m->size() != 2) {
        c_.add(p, "expected two names [\"a\", \"b\"], found " + found(*m));
        return out;
      }
      const auto a = ref((*m)[0], index_path(p, 0));
      const auto b = ref((*m)[1], index_path(p, 1));
      if (a && b) out = std::pair<Id, Id>{*a, *b};
      return out;
    };
    auto value = [&](Range r) -> std::optional<double> {
      const Json* m = c_.member(j, path, "value", true, "the value (mm or degrees)");
      return m ? c_.number(*m, key_path(path, "value"), r) : std::nullopt;
    };
    auto end_ref = [&](const Json& v, const std::string& p) -> std::optional<cs::CurveEnd> {
      if (!c_.object(v, p, {"entity", "end"}, "a curve end {\"entity\": e, \"end\": \"start\"|\"end\"}"))
        return std::nullopt;
      const Json* e = c_.member(v, p, "entity", true, "an entity name");
      const Json* w = c_.member(v, p, "end", true, "\"start\" or \"end\"");
      if (!e || !w) return std::nullopt;
      const auto id = entity_ref(*e, key_path(p, "entity"));
      const auto which = c_.choice(*w, key_path(p, "end"), {"start", "end"});
      if (!id.has_value() || !which.has_value()) return std::nullopt;
      cs::CurveEnd end;
      end.curve = id.value();
      end.at_start = which.value() == 0;
      return end;
    };
    std::vector<std::string_view> allowed{"type"};
    std::optional<cs::Constraint> out;
    switch (*type) {
      case 0: allowed.push_back("point"); if (auto p = point("point")) out = cs::fixed(*p); break;
      case 1: allowed.push_back("points"); if (auto p = pair_of("points", point_ref)) out = cs::coincident(p->first, p->second); break;
      case 2: allowed.insert(allowed.end(), {"point", "entity"}); { auto p = point("point"); auto e = entity("entity"); if (p && e) out = cs::point_on(*p, *e); } break;
      case 3: allowed.push_back("entity"); if (auto e = entity("entity")) out = cs::horizontal(*e); break;
      case 4: allowed.push_back("entity"); if (auto e = entity("entity")) out = cs::vertical(*e); break;
      case 5: allowed.push_back("entities"); if (auto e = pair_of("entities", entity_ref)) out = cs::parallel(e->first, e->second); break;
      case 6: allowed.push_back("entities"); if (auto e = pair_of("entities", entity_ref)) out = cs::perpendicular(e->first, e->second); break;
      case 7: allowed.insert(allowed.end(), {"points", "value"}); { auto p = pair_of("points", point_ref); auto v = value(positive); if (p && v) out = cs::distance(p->first, p->second, *v); } break;
      case 8: allowed.insert(allowed.end(), {"entities", "value"}); { auto e = pair_of("entities", entity_ref); auto v = value(Range{0, 180, true, false}); if (e && v) out = cs::angle(e->first, e->second, *v); } break;
      case 9: allowed.insert(allowed.end(), {"entity", "value"}); { auto e = entity("entity"); auto v = value(positive); if (e && v) out = cs::radius(*e, *v); } break;
      case 10: allowed.push_back("entities"); if (auto e = pair_of("entities", entity_ref)) out = cs::equal_length(e->first, e->second); break;
      case 11: allowed.push_back("entities"); if (auto e = pair_of("entities", entity_ref)) out = cs::equal_radius(e->first, e->second); break;
      case 12: allowed.insert(allowed.end(), {"point", "entity"}); { auto p = point("point"); auto e = entity("entity"); if (p && e) out = cs::midpoint(*p, *e); } break;
      case 13: allowed.insert(allowed.end(), {"points", "entity"}); { auto p = pair_of("points", point_ref); auto e = entity("entity"); if (p && e) out = cs::symmetric(p->first, p->second, *e); } break;
      default: {
        allowed.push_back("ends");
        if (auto e = pair_of("ends", end_ref)) out = *type == 14 ? cs::tangent(e->first, e->second) : cs::curvature(e->first, e->second);
      }
    }
    for (const auto& [key, v] : j.items()) {
      (void)v;
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        c_.add(key_path(path, key), "unknown key \"" + key + "\" for a " + t->get<std::string>() +
                                        " constraint; its keys are: " +
                                        join(std::vector<std::string>(allowed.begin(), allowed.end())));
    }
    return out;
  }

  // ---- surfaces ---------------------------------------------------------------------------

  void surface(const std::string& name, const Json& j, const std::string& path) {
    SurfaceDef def{name, path, "", surface::BSplineSurface{}};
    const std::size_t before = c_.problems.size();
    if (one_of(j, path, {"bspline", "fill", "skin", "sweep", "revolve", "superellipsoid", "supertoroid",
                         "import", "deform"},
               "a surface", def.kind)) {
      const Json& v = j.at(def.kind);
      const std::string p = key_path(path, def.kind);
      if (def.kind == "bspline") {
        if (auto s = inline_surface(v, p)) def.build = std::move(*s);
      } else if (def.kind == "fill") {
        FillDef f;
        if (c_.object(v, p, {"curves", "style", "gap_tolerance"}, "a fill {curves, style, gap_tolerance}")) {
          f.curves = curve_refs(v, p, "curves", 2, 4);
          if (const Json* s = c_.member(v, p, "style", false, ""))
            if (const auto k = c_.choice(*s, key_path(p, "style"), {"stretch", "coons", "curved"}))
              f.options.style = static_cast<surface::FillStyle>(*k);
          f.options.gap_tolerance = c_.number_or(v, p, "gap_tolerance", f.options.gap_tolerance, positive);
          c_.attempt(p, [&] { f.options.validate(); });
        }
        def.build = std::move(f);
      } else if (def.kind == "skin") {
        SkinDef s;
        if (c_.object(v, p, {"sections", "degree", "parametrization"}, "a skin {sections, degree, parametrization}")) {
          s.sections = curve_refs(v, p, "sections", 2, limit::entries);
          s.options.degree = c_.integer_or(v, p, "degree", s.options.degree, 1, surface::max_exchange_degree);
          if (const Json* m = c_.member(v, p, "parametrization", false, ""))
            if (const auto k = c_.choice(*m, key_path(p, "parametrization"), {"chord_length", "centripetal", "uniform"}))
              s.options.parametrization = static_cast<surface::LoftParametrization>(*k);
          c_.attempt(p, [&] { s.options.validate(); });
        }
        def.build = std::move(s);
      } else if (def.kind == "sweep") {
        SweepDef s;
        if (c_.object(v, p, {"profile", "path", "twist_degrees", "tolerance"}, "a sweep {profile, path, twist_degrees, tolerance}")) {
          if (const Json* m = c_.member(v, p, "profile", true, "a curve name"))
            s.profile = curve_ref(*m, key_path(p, "profile")).value_or("");
          if (const Json* m = c_.member(v, p, "path", true, "a curve name"))
            s.path = curve_ref(*m, key_path(p, "path")).value_or("");
          s.options.twist_degrees = c_.number_or(v, p, "twist_degrees", s.options.twist_degrees,
                                                 Range{-limit::sweep_twist_degrees, limit::sweep_twist_degrees});
          s.options.tolerance = c_.number_or(v, p, "tolerance", s.options.tolerance, tolerance_range);
          c_.attempt(p, [&] { s.options.validate(); });
        }
        def.build = std::move(s);
      } else if (def.kind == "revolve") {
        RevolveDef r;
        if (c_.object(v, p, {"profile", "axis", "angle"}, "a revolve {profile, axis, angle}")) {
          if (const Json* m = c_.member(v, p, "profile", true, "a curve name"))
            r.profile = curve_ref(*m, key_path(p, "profile")).value_or("");
          if (const Json* a = c_.member(v, p, "axis", true, "{\"point\": [x, y, z], \"direction\": [x, y, z]}")) {
            const std::string ap = key_path(p, "axis");
            if (c_.object(*a, ap, {"point", "direction"}, "an axis {point, direction}")) {
              if (const Json* m = c_.member(*a, ap, "point", true, "[x, y, z]"))
                r.axis.point = c_.vec3(*m, key_path(ap, "point")).value_or(r.axis.point);
              if (const Json* m = c_.member(*a, ap, "direction", true, "[x, y, z]"))
                r.axis.direction = c_.vec3(*m, key_path(ap, "direction")).value_or(r.axis.direction);
              if (r.axis.direction.norm() == 0.0)
                c_.add(key_path(ap, "direction"), "the axis direction is zero; give a non-zero vector");
            }
          }
          r.angle = c_.number_or(v, p, "angle", r.angle, Range{0, 360, true, false});
        }
        def.build = std::move(r);
      } else if (def.kind == "superellipsoid" || def.kind == "supertoroid") {
        const bool toroid = def.kind == "supertoroid";
        std::initializer_list<std::string_view> keys_e{"radii", "e1", "e2", "tolerance", "degree"};
        std::initializer_list<std::string_view> keys_t{"radii", "e1", "e2", "tolerance", "degree", "hole"};
        if (c_.object(v, p, toroid ? keys_t : keys_e, toroid ? "a supertoroid" : "a superellipsoid")) {
          surface::SuperquadricOptions o;
          Eigen::Vector3d radii = Eigen::Vector3d::Ones();
          if (const Json* m = c_.member(v, p, "radii", false, "")) {
            radii = c_.vec3(*m, key_path(p, "radii")).value_or(radii);
            if (!(radii.minCoeff() > 0)) c_.add(key_path(p, "radii"), "every radius must be > 0 (mm)");
          }
          const double e1 = c_.number_or(v, p, "e1", 1.0, Range{0, 10, true, false});
          const double e2 = c_.number_or(v, p, "e2", 1.0, Range{0, 10, true, false});
          o.tolerance = c_.number_or(v, p, "tolerance", o.tolerance, tolerance_range);
          o.degree = c_.integer_or(v, p, "degree", o.degree, 2, 7);
          if (toroid) {
            SupertoroidDef d{{radii, 2.0, e1, e2}, o};
            d.shape.hole = c_.number_or(v, p, "hole", 2.0, Range{1, inf, true, false});
            def.build = d;
          } else {
            def.build = SuperellipsoidDef{{radii, e1, e2}, o};
          }
        }
      } else if (def.kind == "import") {
        ImportDef d;
        if (c_.object(v, p, {"file", "index"}, "an import {file, index}")) {
          if (const Json* f = c_.member(v, p, "file", true, "the path of a .step/.stp/.igs/.iges file"))
            if (const auto s = c_.string(*f, key_path(p, "file"))) {
              d.file = fs::path(*s).is_absolute() ? fs::path(*s) : base_ / *s;
              std::string ext = d.file.extension().string();
              for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
              if (ext != ".step" && ext != ".stp" && ext != ".igs" && ext != ".iges")
                c_.add(key_path(p, "file"), "\"" + *s + "\" is not a STEP or IGES file; give a .step, .stp, .igs or .iges file");
              else if (!fs::is_regular_file(d.file))
                c_.add(key_path(p, "file"), "no file \"" + d.file.string() + "\" (paths are relative to the recipe's folder)");
            }
          d.index = c_.integer_or(v, p, "index", 0, 0, 1000000);
        }
        def.build = d;
      } else {  // deform
        DeformDef d;
        d.composition = data.composition;
        if (c_.object(v, p, {"surface", "deformation", "composition"}, "a deform {surface, deformation, composition}")) {
          if (const Json* m = c_.member(v, p, "surface", true, "the name of an earlier surface"))
            d.surface = surface_ref(*m, key_path(p, "surface")).value_or("");
          if (const Json* m = c_.member(v, p, "deformation", true, "the name of a deformation stack"))
            if (const auto s = c_.string(*m, key_path(p, "deformation"))) {
              if (Names::has(names_.stacks, *s))
                d.deformation = *s;
              else
                c_.add(key_path(p, "deformation"), "no deformation stack named \"" + *s + "\"; " + listing(names_.stacks));
            }
          if (const Json* m = c_.member(v, p, "composition", false, ""))
            d.composition = composition(*m, key_path(p, "composition"), d.composition);
          if (!d.composition.refit) exact_composable(d.deformation, key_path(p, "deformation"));
        }
        def.build = d;
      }
    }
    names_.surfaces.push_back(name);
    if (c_.problems.size() == before) data.surfaces.push_back(std::move(def));
  }

  /// In exact mode every enabled step must be one compose_exact handles: twists, bends and
  /// extended lattices are not polynomial maps of the surface's control points (DESIGN.md).
  void exact_composable(const std::string& stack_name, const std::string& path) {
    for (const auto& stack : data.stacks) {
      if (stack.name != stack_name) continue;
      for (const auto& step : stack.steps) {
        const auto* d = std::get_if<deform::Deformation>(&step.step);
        if (!step.enabled || !d) continue;
        if (std::holds_alternative<deform::Twist>(*d) || std::holds_alternative<deform::Bend>(*d) ||
            std::holds_alternative<deform::ExtendedLattice>(*d))
          c_.add(path, step.path + " is a " + step.kind + ", which cannot be composed exactly (only " +
                           "Bézier and B-spline lattices and tapers can); give this surface or the recipe " +
                           "\"composition\": {\"mode\": \"refit\", \"tolerance\": 1e-4}");
      }
    }
  }

  std::optional<surface::BSplineSurface> inline_surface(const Json& j, const std::string& path) {
    if (!c_.object(j, path, {"degrees", "knots_u", "knots_v", "points", "weights"},
                   "a B-spline surface {degrees, knots_u, knots_v, points, weights}"))
      return std::nullopt;
    const Json* d = c_.member(j, path, "degrees", true, "[p, q]");
    const Json* ku = c_.member(j, path, "knots_u", true, "the u knot vector");
    const Json* kv = c_.member(j, path, "knots_v", true, "the v knot vector");
    const Json* p = c_.member(j, path, "points", true, "count_u x count_v control points, (i, j) at row i * count_v + j");
    std::optional<std::pair<int, int>> degrees;
    if (d) {
      if (!d->is_array() || d->size() != 2) {
        c_.add(key_path(path, "degrees"), "expected [p, q], found " + found(*d));
      } else {
        const auto a = c_.integer((*d)[0], index_path(key_path(path, "degrees"), 0), 1, surface::max_kernel_degree);
        const auto b = c_.integer((*d)[1], index_path(key_path(path, "degrees"), 1), 1, surface::max_kernel_degree);
        if (a && b) degrees = std::pair{*a, *b};
      }
    }
    const auto knots_u = ku ? c_.numbers(*ku, key_path(path, "knots_u"), 2) : std::nullopt;
    const auto knots_v = kv ? c_.numbers(*kv, key_path(path, "knots_v"), 2) : std::nullopt;
    const auto points = p ? c_.points(*p, key_path(path, "points"), 4, limit::surface_points) : std::nullopt;
    std::optional<std::vector<double>> weights;
    if (const Json* w = c_.member(j, path, "weights", false, ""))
      if (!(weights = c_.numbers(*w, key_path(path, "weights"), 4, limit::surface_points, weight_range)))
        return std::nullopt;
    if (!degrees || !knots_u || !knots_v || !points) return std::nullopt;
    surface::BSplineSurface s;
    s.u = {degrees->first, *knots_u};
    s.v = {degrees->second, *knots_v};
    s.points = *points;
    s.weights = weights ? Eigen::Map<const Eigen::VectorXd>(weights->data(), static_cast<Eigen::Index>(weights->size())).eval()
                        : Eigen::VectorXd::Ones(points->rows()).eval();
    return c_.checked(s, path, surface::problems(s, path));
  }

  // ---- deformations -----------------------------------------------------------------------

  std::optional<deform::Frame> lattice_frame(const Json& j, const std::string& path) {
    if (!c_.object(j, path, {"origin", "s", "t", "u"}, "a lattice frame {origin, s, t, u}")) return std::nullopt;
    deform::Frame f;
    if (!c_.vec3_members(j, path, {{"origin", &f.origin}, {"s", &f.s}, {"t", &f.t}, {"u", &f.u}}))
      return std::nullopt;
    return c_.checked(f, path, deform::problems(f, path));
  }

  std::optional<std::array<int, 3>> triple(const Json& obj, const std::string& path, std::string_view key,
                                           int lo, int hi, std::string_view hint) {
    const Json* j = c_.member(obj, path, key, true, hint);
    if (!j) return std::nullopt;
    const std::string p = key_path(path, key);
    if (!j->is_array() || j->size() != 3) {
      c_.add(p, "expected 3 integers " + std::string(hint) + ", found " + found(*j));
      return std::nullopt;
    }
    std::array<int, 3> out{};
    bool ok = true;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto x = c_.integer((*j)[k], index_path(p, k), lo, hi);
      ok = ok && x.has_value();
      out[k] = x.value_or(0);
    }
    return ok ? std::optional(out) : std::nullopt;
  }

  /// False (and the problem recorded) when a lattice of counts[0] x counts[1] x counts[2] control
  /// points is above limit::lattice_points; checked before the lattice is built.
  bool lattice_size_ok(std::array<long, 3> counts, const std::string& path) {
    const long total = counts[0] * counts[1] * counts[2];
    if (total <= limit::lattice_points) return true;
    c_.add(path, "the lattice would have " + std::to_string(counts[0]) + " x " + std::to_string(counts[1]) + " x " +
                     std::to_string(counts[2]) + " = " + std::to_string(total) + " control points; at most " +
                     std::to_string(limit::lattice_points) +
                     " are allowed (recipe limit): use fewer cells or lower degrees");
    return false;
  }

  /// False (and the problem recorded) when an extended lattice would have more than
  /// limit::chunks tricubic chunks; checked before the lattice is built.
  bool chunks_ok(long chunks, const std::string& path) {
    if (chunks <= limit::chunks) return true;
    c_.add(path, "the lattice would have " + std::to_string(chunks) + " chunks; at most " +
                     std::to_string(limit::chunks) +
                     " are allowed (recipe limit): use fewer sectors, rings, sections or layers");
    return false;
  }

  /// Applies "moves" to `points` (rows found by `row_of`, which reports its own problems).
  template <class RowOf>
  bool apply_moves(const Json& moves, const std::string& path, Points3& points, RowOf&& row_of,
                   const std::vector<std::string_view>& index_keys) {
    if (!moves.is_array()) {
      c_.add(path, "expected an array of {\"index\": ..., \"to\" or \"by\": [x, y, z]}, found " + found(moves));
      return false;
    }
    if (!c_.at_most(moves, path, limit::moves, "moves")) return false;
    bool ok = true;
    std::vector<std::string_view> keys = index_keys;
    keys.push_back("to");
    keys.push_back("by");
    for (std::size_t i = 0; i < moves.size(); ++i) {
      const std::string p = index_path(path, i);
      const Json& m = moves[i];
      if (!m.is_object()) {
        c_.add(p, "expected {\"index\": ..., \"to\" or \"by\": [x, y, z]}, found " + found(m));
        ok = false;
        continue;
      }
      for (const auto& [key, v] : m.items()) {
        (void)v;
        if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
          c_.add(key_path(p, key), "unknown key \"" + key + "\" in a move; the keys are: " +
                                       join(std::vector<std::string>(keys.begin(), keys.end())));
          ok = false;
        }
      }
      const auto row = row_of(m, p);
      const bool has_to = m.contains("to"), has_by = m.contains("by");
      if (has_to == has_by) {
        c_.add(p, "give exactly one of \"to\" (new position) and \"by\" (displacement)");
        ok = false;
        continue;
      }
      const auto v = c_.vec3(m.at(has_to ? "to" : "by"), key_path(p, has_to ? "to" : "by"));
      if (!row || !v) {
        ok = false;
        continue;
      }
      if (has_to)
        points.row(*row) = v->transpose();
      else
        points.row(*row) += v->transpose();
    }
    return ok;
  }

  /// An [i, j, k] index in counts, as a row of an s-major lattice.
  std::optional<Eigen::Index> lattice_row(const Json& m, const std::string& p, std::array<int, 3> counts) {
    const Json* idx = c_.member(m, p, "index", true, "[i, j, k]");
    if (!idx) return std::nullopt;
    const std::string ip = key_path(p, "index");
    if (!idx->is_array() || idx->size() != 3) {
      c_.add(ip, "expected [i, j, k], found " + found(*idx));
      return std::nullopt;
    }
    Eigen::Index row = 0;
    bool ok = true;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto x = c_.integer((*idx)[k], index_path(ip, k), 0, counts[k] - 1);
      ok = ok && x.has_value();
      row = row * counts[k] + x.value_or(0);
    }
    return ok ? std::optional(row) : std::nullopt;
  }

  /// A Bézier or B-spline lattice from recipe fields (points or moves).
  std::optional<deform::Deformation> lattice(const Json& j, const std::string& path, bool bspline,
                                             std::initializer_list<std::string_view> extra_keys) {
    std::vector<std::string_view> keys{"kind", "name", "enabled", "frame", "degrees", "points", "moves"};
    if (bspline) keys.insert(keys.end(), {"bases", "cells", "knots"});
    keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
    for (const auto& [key, v] : j.items()) {
      (void)v;
      if (std::find(keys.begin(), keys.end(), key) == keys.end())
        c_.add(key_path(path, key), "unknown key \"" + key + "\" in a " +
                                        std::string(bspline ? "bspline_lattice" : "bezier_lattice") +
                                        " step; the keys are: " + join(std::vector<std::string>(keys.begin(), keys.end())));
    }
    const Json* fj = c_.member(j, path, "frame", true, "{\"origin\", \"s\", \"t\", \"u\"}");
    const auto frame = fj ? lattice_frame(*fj, key_path(path, "frame")) : std::nullopt;
    std::optional<deform::Deformation> out;
    if (!bspline) {
      const auto degrees = triple(j, path, "degrees", 1, surface::max_kernel_degree, "[l, m, n]");
      if (!frame || !degrees) return std::nullopt;
      if (!lattice_size_ok({(*degrees)[0] + 1L, (*degrees)[1] + 1L, (*degrees)[2] + 1L}, key_path(path, "degrees")))
        return std::nullopt;
      deform::BezierLattice lat = deform::make_bezier_lattice(*frame, *degrees);
      if (!lattice_points(j, path, lat.points, lat.counts())) return std::nullopt;
      const auto list = deform::problems(lat, path);
      if (!list.empty()) return c_.add_all(path, list), std::nullopt;
      out = std::move(lat);
    } else {
      std::optional<deform::BSplineLattice> lat;
      const bool has_bases = j.contains("bases");
      if (has_bases == j.contains("cells")) {
        c_.add(path, "give either \"bases\" (three {degree, knots}) or \"cells\" with \"degrees\" and \"knots\"");
        return std::nullopt;
      }
      if (has_bases) {
        const Json& b = j.at("bases");
        const std::string bp = key_path(path, "bases");
        if (!b.is_array() || b.size() != 3) {
          c_.add(bp, "expected 3 bases [{degree, knots}, ...] along s, t, u, found " + found(b));
          return std::nullopt;
        }
        std::array<surface::BSplineBasis, 3> bases;
        bool ok = true;
        for (std::size_t k = 0; k < 3; ++k) {
          const std::string p = index_path(bp, k);
          if (!c_.object(b[k], p, {"degree", "knots"}, "a basis {degree, knots}")) {
            ok = false;
            continue;
          }
          const Json* d = c_.member(b[k], p, "degree", true, "the degree");
          const Json* kn = c_.member(b[k], p, "knots", true, "the knot vector on [0, 1]");
          const auto degree = d ? c_.integer(*d, key_path(p, "degree"), 1, surface::max_kernel_degree) : std::nullopt;
          const auto knots = kn ? c_.numbers(*kn, key_path(p, "knots"), 2, limit::lattice_points) : std::nullopt;
          ok = ok && degree && knots;
          if (degree && knots) bases[k] = {*degree, *knots};
        }
        if (!ok || !frame) return std::nullopt;
        std::array<long, 3> counts{};
        for (std::size_t k = 0; k < 3; ++k)
          counts[k] = std::max(0L, static_cast<long>(bases[k].knots.size()) - bases[k].degree - 1);
        if (!lattice_size_ok(counts, bp)) return std::nullopt;
        if (!c_.attempt(bp, [&] { lat = deform::make_bspline_lattice(*frame, bases); })) return std::nullopt;
      } else {
        const auto cells = triple(j, path, "cells", 1, limit::lattice_cells, "[a, b, c]");
        const auto degrees = triple(j, path, "degrees", 1, surface::max_kernel_degree, "[p, q, r]");
        deform::LatticeKnots knots = deform::LatticeKnots::Clamped;
        if (const Json* k = c_.member(j, path, "knots", false, ""))
          if (const auto c = c_.choice(*k, key_path(path, "knots"), {"clamped", "uniform"}))
            knots = static_cast<deform::LatticeKnots>(*c);
        if (!cells || !degrees || !frame) return std::nullopt;
        if (!lattice_size_ok({(*cells)[0] + static_cast<long>((*degrees)[0]), (*cells)[1] + static_cast<long>((*degrees)[1]),
                              (*cells)[2] + static_cast<long>((*degrees)[2])},
                             path))
          return std::nullopt;
        if (!c_.attempt(path, [&] { lat = deform::make_bspline_lattice(*frame, *degrees, *cells, knots); }))
          return std::nullopt;
      }
      if (!lattice_points(j, path, lat->points, lat->counts())) return std::nullopt;
      const auto list = deform::problems(*lat, path);
      if (!list.empty()) return c_.add_all(path, list), std::nullopt;
      out = std::move(*lat);
    }
    return out;
  }

  /// "points" (all of them) or "moves" (from the undisplaced points already in `points`).
  bool lattice_points(const Json& j, const std::string& path, Points3& points, std::array<int, 3> counts) {
    const bool has_points = j.contains("points"), has_moves = j.contains("moves");
    if (has_points && has_moves) {
      c_.add(path, "give either \"points\" (every control point) or \"moves\" (by index), not both");
      return false;
    }
    if (has_points) {
      const auto p = c_.points(j.at("points"), key_path(path, "points"), 1);
      if (!p) return false;
      if (p->rows() != points.rows()) {
        c_.add(key_path(path, "points"), "found " + std::to_string(p->rows()) + " control points, the lattice has " +
                                             std::to_string(points.rows()) + " (" + std::to_string(counts[0]) + " x " +
                                             std::to_string(counts[1]) + " x " + std::to_string(counts[2]) +
                                             "); give all, s-major, or use \"moves\"");
        return false;
      }
      points = *p;
      return true;
    }
    if (!has_moves) return true;  // undisplaced (an identity step)
    return apply_moves(j.at("moves"), key_path(path, "moves"), points,
                       [&](const Json& m, const std::string& p) { return lattice_row(m, p, counts); },
                       std::vector<std::string_view>{"index"});
  }

  std::optional<deform::Deformation> extended_from_generator(const Json& j, const std::string& path) {
    for (const auto& [key, v] : j.items()) {
      (void)v;
      if (key != "kind" && key != "name" && key != "enabled" && key != "generator" && key != "moves")
        c_.add(key_path(path, key), "unknown key \"" + key + "\" in an extended_lattice step with a generator; "
                                        "the keys are: kind, name, enabled, generator, moves");
    }
    const std::string gp = key_path(path, "generator");
    std::string kind;
    if (!one_of(j.at("generator"), gp, {"cylinder", "prism"}, "a lattice generator", kind)) return std::nullopt;
    const Json& g = j.at("generator").at(kind);
    const std::string p = key_path(gp, kind);
    deform::ExtendedLattice lat;
    std::function<std::optional<Eigen::Index>(const Json&, const std::string&)> row_of;
    std::vector<std::string_view> index_keys{"index"};
    if (kind == "cylinder") {
      if (!c_.object(g, p, {"origin", "axis", "reference", "radius", "inner_radius", "height", "sectors", "rings", "layers"},
                     "a cylinder lattice {origin, axis, reference, radius, inner_radius, height, sectors, rings, layers}"))
        return std::nullopt;
      deform::CylinderSpec spec;
      for (auto [key, target] : {std::pair{"origin", &spec.origin}, std::pair{"axis", &spec.axis},
                                 std::pair{"reference", &spec.reference}})
        if (const Json* m = c_.member(g, p, key, false, ""))
          *target = c_.vec3(*m, key_path(p, key)).value_or(*target);
      spec.radius = c_.number_or(g, p, "radius", spec.radius, positive);
      spec.inner_radius = c_.number_or(g, p, "inner_radius", spec.inner_radius, non_negative);
      spec.height = c_.number_or(g, p, "height", spec.height, positive);
      spec.sectors = c_.integer_or(g, p, "sectors", spec.sectors, 3, limit::cylinder_sectors);
      spec.rings = c_.integer_or(g, p, "rings", spec.rings, 1, limit::cylinder_rings);
      spec.layers = c_.integer_or(g, p, "layers", spec.layers, 1, limit::lattice_layers);
      if (!chunks_ok(static_cast<long>(spec.sectors) * spec.rings * spec.layers, p)) return std::nullopt;
      if (!c_.attempt(p, [&] { lat = deform::make_cylindrical_lattice(spec); })) return std::nullopt;
      row_of = [this, spec](const Json& m, const std::string& mp) -> std::optional<Eigen::Index> {
        const Json* idx = c_.member(m, mp, "index", true, "[radial, angular, axial]");
        if (!idx) return std::nullopt;
        const std::string ip = key_path(mp, "index");
        if (!idx->is_array() || idx->size() != 3) {
          c_.add(ip, "expected [radial, angular, axial], found " + found(*idx));
          return std::nullopt;
        }
        const auto r = c_.integer((*idx)[0], index_path(ip, 0), 0, 3 * spec.rings);
        const auto a = c_.integer((*idx)[1], index_path(ip, 1), -3 * 1024 * 1024, 3 * 1024 * 1024);
        const auto h = c_.integer((*idx)[2], index_path(ip, 2), 0, 3 * spec.layers);
        if (!r || !a || !h) return std::nullopt;
        std::optional<Eigen::Index> row;
        c_.attempt(ip, [&] { row = deform::cylindrical_index(spec, *r, *a, *h); });
        return row;
      };
    } else {
      if (!c_.object(g, p, {"origin", "x_axis", "y_axis", "extrusion", "sections", "layers"},
                     "a prism lattice {origin, x_axis, y_axis, extrusion, sections, layers}"))
        return std::nullopt;
      deform::PrismSpec spec;
      for (auto [key, target] : {std::pair{"origin", &spec.origin}, std::pair{"x_axis", &spec.x_axis},
                                 std::pair{"y_axis", &spec.y_axis}, std::pair{"extrusion", &spec.extrusion}})
        if (const Json* m = c_.member(g, p, key, false, ""))
          *target = c_.vec3(*m, key_path(p, key)).value_or(*target);
      spec.layers = c_.integer_or(g, p, "layers", spec.layers, 1, limit::lattice_layers);
      const Json* s = c_.member(g, p, "sections", true, "two or more sections [[[a, b], ...], ...]");
      if (!s) return std::nullopt;
      const std::string sp = key_path(p, "sections");
      if (!s->is_array() || s->size() < 2) {
        c_.add(sp, "expected two or more sections (arrays of [a, b]), found " + found(*s));
        return std::nullopt;
      }
      // Counted before any section is read: reading 100,000 of them took a minute (issue #18).
      if (!c_.at_most(*s, sp, static_cast<std::size_t>(limit::prism_sections), "sections")) return std::nullopt;
      bool ok = true;
      for (std::size_t a = 0; a < s->size(); ++a) {
        const std::string ap = index_path(sp, a);
        if (!(*s)[a].is_array()) {
          c_.add(ap, "expected an array of [a, b] points, found " + found((*s)[a]));
          ok = false;
          continue;
        }
        if (!c_.at_most((*s)[a], ap, 3 * static_cast<std::size_t>(limit::prism_sections - 1) + 1, "section points")) {
          ok = false;
          continue;
        }
        std::vector<Eigen::Vector2d> section;
        for (std::size_t b = 0; b < (*s)[a].size(); ++b) {
          const auto v = c_.vec2((*s)[a][b], index_path(ap, b));
          ok = ok && v.has_value();
          if (v) section.push_back(*v);
        }
        spec.sections.push_back(std::move(section));
      }
      if (!ok || spec.sections.empty()) return std::nullopt;  // each bad section reported above
      const long segments_first = std::max(0L, static_cast<long>(spec.sections.front().size()) - 1) / 3;
      if (!chunks_ok(static_cast<long>(spec.sections.size() - 1) * segments_first * spec.layers, p))
        return std::nullopt;
      if (!c_.attempt(p, [&] { lat = deform::make_prismatic_lattice(spec); })) return std::nullopt;
      // A control point by its welded row, or by its index [i, j, k] in the lattice before
      // welding (i across the sections, j along them, k along the extrusion), found through the
      // chunk that holds it: chunk (a, b, c) is chunks[(a * segments + b) * layers + c].
      const auto rows = lat.rest.rows();
      const int gaps = static_cast<int>(spec.sections.size()) - 1;
      const int segments = (static_cast<int>(spec.sections.front().size()) - 1) / 3;
      const int layers = spec.layers;
      const auto chunks = lat.chunks;
      row_of = [this, rows, gaps, segments, layers, chunks](const Json& m,
                                                            const std::string& mp) -> std::optional<Eigen::Index> {
        if (m.contains("row") == m.contains("index")) {
          c_.add(mp, "give exactly one of \"row\" (a control-point row) and \"index\" ([i, j, k])");
          return std::nullopt;
        }
        if (m.contains("row")) {
          const auto x = c_.integer(m.at("row"), key_path(mp, "row"), 0, static_cast<int>(rows) - 1);
          return x ? std::optional<Eigen::Index>(*x) : std::nullopt;
        }
        const Json& idx = m.at("index");
        const std::string ip = key_path(mp, "index");
        if (!idx.is_array() || idx.size() != 3) {
          c_.add(ip, "expected [i, j, k], found " + found(idx));
          return std::nullopt;
        }
        const auto i = c_.integer(idx[0], index_path(ip, 0), 0, 3 * gaps);
        const auto jj = c_.integer(idx[1], index_path(ip, 1), 0, 3 * segments);
        const auto k = c_.integer(idx[2], index_path(ip, 2), 0, 3 * layers);
        if (!i || !jj || !k) return std::nullopt;
        const int a = std::min(*i / 3, gaps - 1), b = std::min(*jj / 3, segments - 1), c = std::min(*k / 3, layers - 1);
        const auto& chunk = chunks[static_cast<std::size_t>((a * segments + b) * layers + c)];
        return chunk[static_cast<std::size_t>(((*i - 3 * a) * 4 + (*jj - 3 * b)) * 4 + (*k - 3 * c))];
      };
      index_keys = {std::string_view("row"), std::string_view("index")};
    }
    if (const Json* m = c_.member(j, path, "moves", false, ""))
      if (!apply_moves(*m, key_path(path, "moves"), lat.points, row_of, index_keys)) return std::nullopt;
    const auto list = deform::problems(lat, path);
    if (!list.empty()) return c_.add_all(path, list), std::nullopt;
    return deform::Deformation(std::move(lat));
  }

  /// Sum |c_k| 1000^k: a bound of |c(z)| for |z| <= 1 m of a polynomial with coefficients c.
  static double bound_within_metre(const std::vector<double>& c) {
    double sum = 0, scale = 1;
    for (double x : c) sum += std::abs(x) * scale, scale *= 1000.0;
    return sum;
  }

  /// The recipe's limits on a step the deformation-stack schema read (which checks only that its
  /// numbers are finite): frames and lattice points within ±limit::magnitude, bounded twists,
  /// tapers and bends, and extended lattices of at most limit::chunks chunks.
  bool within_limits(const deform::Deformation& d, const std::string& path) {
    const std::size_t before = c_.problems.size();
    auto frame = [&](const deform::AxisFrame& f) {
      for (auto [key, v] : {std::pair{"origin", &f.origin}, std::pair{"axis", &f.axis}, std::pair{"reference", &f.reference}})
        if (!(v->cwiseAbs().maxCoeff() <= limit::magnitude))
          c_.add(key_path(key_path(path, "frame"), key), "a coordinate is beyond ±" + shortest(limit::magnitude) +
                                                             " mm (recipe limit); give the frame in millimetres within it");
    };
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, deform::Twist>) {
            frame(x.frame);
            const double turns = bound_within_metre(x.angle) / (2 * std::numbers::pi);
            if (!(turns <= limit::twist_turns))
              c_.add(key_path(path, "angle"),
                     "the twist may turn " + shortest(turns * 360) + " degrees within 1 m of its origin (sum of |angle[k]| · 1000^k = " +
                         shortest(turns * 2 * std::numbers::pi) + " rad); at most " + shortest(limit::twist_turns * 360) +
                         " degrees (" + shortest(limit::twist_turns) + " turns) are allowed (recipe limit): the coefficients are radians per mm^k");
          } else if constexpr (std::is_same_v<T, deform::Taper>) {
            frame(x.frame);
            const double scale = bound_within_metre(x.profile);
            if (!(scale <= limit::taper_scale))
              c_.add(key_path(path, "profile"),
                     "the taper may scale by up to " + shortest(scale) + " within 1 m of its origin (sum of |profile[k]| · 1000^k); at most " +
                         shortest(limit::taper_scale) + " is allowed (recipe limit): the coefficients are per mm^k");
          } else if constexpr (std::is_same_v<T, deform::Bend>) {
            frame(x.frame);
            for (auto [key, v] : {std::pair{"y_min", x.y_min}, std::pair{"y_max", x.y_max}, std::pair{"center", x.center}})
              if (!(std::abs(v) <= limit::magnitude))
                c_.add(key_path(path, key), shortest(v) + " mm is beyond ±" + shortest(limit::magnitude) + " mm (recipe limit)");
            const double turns = std::abs(x.rate) * (x.y_max - x.y_min) / (2 * std::numbers::pi);
            if (!(std::abs(x.rate) <= limit::bend_rate))
              c_.add(key_path(path, "rate"), shortest(x.rate) + " rad/mm is beyond ±" + shortest(limit::bend_rate) +
                                                 " rad/mm (recipe limit: a radius of curvature of at least 1 mm)");
            else if (!(turns <= limit::bend_turns))
              c_.add(key_path(path, "rate"), "the bend turns " + shortest(turns * 360) + " degrees over its region (rate · (y_max − y_min)); at most " +
                                                 shortest(limit::bend_turns * 360) + " degrees are allowed (recipe limit)");
          } else if constexpr (std::is_same_v<T, deform::ExtendedLattice>) {
            if (static_cast<long>(x.chunks.size()) > limit::chunks)
              c_.add(key_path(path, "chunks"), std::to_string(x.chunks.size()) + " chunks; at most " +
                                                   std::to_string(limit::chunks) + " are allowed (recipe limit)");
            for (auto [key, m] : {std::pair{"rest", &x.rest}, std::pair{"points", &x.points}})
              if (m->size() > 0 && !(m->cwiseAbs().maxCoeff() <= limit::magnitude))
                c_.add(key_path(path, key), "a coordinate is beyond ±" + shortest(limit::magnitude) + " mm (recipe limit)");
          }
        },
        d);
    return c_.problems.size() == before;
  }

  /// A stack-schema step, read by the same reader as deform::stack_from_json (one walk, the
  /// problems at their recipe paths), then its values checked by deform's problems().
  std::optional<deform::Deformation> schema_step(const Json& j, const std::string& path) {
    auto step = internal::read_step(c_, j, path);
    if (!step) return std::nullopt;
    const std::string label = internal::step_label(path, *step);
    const auto list = std::visit([&](const auto& d) { return problems(d, label); }, step->deformation);
    if (!list.empty()) {
      c_.add_all(label, list);
      return std::nullopt;
    }
    return std::move(step->deformation);
  }

  void stack(const std::string& name, const Json& j, const std::string& path) {
    StackDef def{name, path, {}};
    if (!j.is_array()) {
      c_.add(path, "expected an array of deformation steps, found " + found(j));
      return;
    }
    const std::size_t before = c_.problems.size();
    if (!c_.at_most(j, path, limit::steps, "steps")) return;
    for (std::size_t i = 0; i < j.size(); ++i) {
      const std::string p = index_path(path, i);
      const Json& s = j[i];
      if (!s.is_object()) {
        c_.add(p, "expected a step {\"kind\": ..., ...}, found " + found(s));
        continue;
      }
      StepDef step{p, "", "", true, deform::Deformation{}};
      const Json* k = c_.member(s, p, "kind", true, "the step's kind, e.g. \"bezier_lattice\"");
      if (!k) continue;
      const auto kind = c_.choice(*k, key_path(p, "kind"),
                                  {"bezier_lattice", "bspline_lattice", "extended_lattice", "taper", "twist",
                                   "bend", "style", "direct_manipulation"});
      if (!kind) continue;
      step.kind = k->get<std::string>();
      if (const Json* n = c_.member(s, p, "name", false, "")) step.name = c_.string(*n, key_path(p, "name")).value_or("");
      step.enabled = c_.boolean_or(s, p, "enabled", true);
      bool ok = false;
      if (*kind <= 1) {
        if (auto d = lattice(s, p, *kind == 1, {})) step.step = std::move(*d), ok = true;
      } else if (*kind == 2 && s.contains("generator")) {
        if (auto d = extended_from_generator(s, p)) step.step = std::move(*d), ok = true;
      } else if (*kind <= 5) {
        if (auto d = schema_step(s, p); d && within_limits(*d, p)) step.step = std::move(*d), ok = true;
      } else if (*kind == 6) {
        if (auto d = style(s, p)) step.step = std::move(*d), ok = true;
      } else {
        if (auto d = direct(s, p)) step.step = std::move(*d), ok = true;
      }
      if (ok) def.steps.push_back(std::move(step));
    }
    if (c_.problems.size() == before) data.stacks.push_back(std::move(def));
  }

  std::optional<StyleDef> style(const Json& j, const std::string& p) {
    if (!c_.object(j, p, {"kind", "name", "enabled", "target", "bound", "mode", "lambda", "relaxation", "smoothing",
                          "key_points_per_row", "boundary_rows", "tolerance", "curve_tolerance", "max_refinements",
                          "max_key_point_rounds", "accept_out_of_tolerance"},
                   "a style step"))
      return std::nullopt;
    StyleDef d;
    const std::size_t before = c_.problems.size();
    if (const Json* t = c_.member(j, p, "target", true, "the target curve's name"))
      d.target = curve_ref(*t, key_path(p, "target")).value_or("");
    if (const Json* b = c_.member(j, p, "bound", false, ""))
      d.bound = curve_ref(*b, key_path(p, "bound")).value_or("");
    // A bound curve given inline is known now: an open one is reported here, not at run time
    // (the rule of deform::influence_factors: ends within 1e-7 of the curve's size).
    if (!d.bound.empty()) {
      const auto cd = std::find_if(data.curves.begin(), data.curves.end(),
                                   [&](const CurveDef& x) { return x.name == d.bound; });
      if (cd != data.curves.end() && cd->curve) {
        const surface::Points3& pts = cd->curve->points;
        const double size = (pts.colwise().maxCoeff() - pts.colwise().minCoeff()).norm();
        const auto [t0, t1] = cd->curve->basis.domain();
        const double gap = (surface::evaluate(*cd->curve, t1) - surface::evaluate(*cd->curve, t0)).norm();
        if (gap > 1e-7 * size)
        {
          char apart[32];
          std::snprintf(apart, sizeof apart, "%.4g", gap);
          c_.add(key_path(p, "bound"), "the bound curve \"" + d.bound + "\" is open: its ends are " + apart +
                                           " mm apart; a bound curve must be closed (make its last control point "
                                           "equal its first)");
        }
      }
    }
    auto& o = d.options;
    if (const Json* m = c_.member(j, p, "mode", false, ""))
      if (const auto k = c_.choice(*m, key_path(p, "mode"), {"paper", "exact"}))
        o.mode = *k == 0 ? deform::StyleMode::Paper : deform::StyleMode::Exact;
    o.lambda = c_.number_or(j, p, "lambda", o.lambda, Range{0, 1});
    o.relaxation = c_.boolean_or(j, p, "relaxation", o.relaxation);
    o.smoothing = c_.boolean_or(j, p, "smoothing", o.smoothing);
    o.key_points_per_row = c_.integer_or(j, p, "key_points_per_row", o.key_points_per_row, 1, 64);
    o.boundary_rows = c_.integer_or(j, p, "boundary_rows", o.boundary_rows, 0, 4);
    o.tolerance = c_.number_or(j, p, "tolerance", o.tolerance, positive);
    o.curve_tolerance = c_.number_or(j, p, "curve_tolerance", o.curve_tolerance, positive);
    o.max_refinements = c_.integer_or(j, p, "max_refinements", o.max_refinements, 0, 8);
    o.max_key_point_rounds = c_.integer_or(j, p, "max_key_point_rounds", o.max_key_point_rounds, 0, 16);
    d.accept_out_of_tolerance = c_.boolean_or(j, p, "accept_out_of_tolerance", d.accept_out_of_tolerance);
    c_.attempt(p, [&] { o.validate(); });
    if (c_.problems.size() != before) return std::nullopt;
    return d;
  }

  std::optional<DirectDef> direct(const Json& j, const std::string& p) {
    if (!c_.object(j, p, {"kind", "name", "enabled", "lattice", "moves", "locked", "tied", "tolerance",
                          "accept_out_of_tolerance"},
                   "a direct_manipulation step"))
      return std::nullopt;
    const std::size_t before = c_.problems.size();
    DirectDef d{deform::BezierLattice{}, {}, {}, false};
    d.accept_out_of_tolerance = c_.boolean_or(j, p, "accept_out_of_tolerance", false);
    const Json* lj = c_.member(j, p, "lattice", true, "a bezier_lattice or bspline_lattice object with \"kind\"");
    std::array<int, 3> counts{0, 0, 0};
    if (lj) {
      const std::string lp = key_path(p, "lattice");
      const Json* k = lj->is_object() ? c_.member(*lj, lp, "kind", true, "\"bezier_lattice\" or \"bspline_lattice\"") : nullptr;
      if (!lj->is_object()) c_.add(lp, "expected a lattice object, found " + found(*lj));
      const auto kind = k ? c_.choice(*k, key_path(lp, "kind"), {"bezier_lattice", "bspline_lattice"}) : std::nullopt;
      if (kind) {
        if (auto lat = lattice(*lj, lp, *kind == 1, {})) {
          if (auto* b = std::get_if<deform::BezierLattice>(&*lat)) {
            counts = b->counts();
            d.lattice = *b;
          } else {
            const auto& s = std::get<deform::BSplineLattice>(*lat);
            counts = s.counts();
            d.lattice = s;
          }
        }
      }
    }
    const Json* mj = c_.member(j, p, "moves", true, "[{\"point\": [x,y,z] | \"surface_point\": [u, v], \"to\": [x,y,z]}]");
    if (mj) {
      const std::string mp = key_path(p, "moves");
      if (!mj->is_array() || mj->empty()) {
        c_.add(mp, "expected a non-empty array of moves, found " + found(*mj));
      } else if (c_.at_most(*mj, mp, limit::moves, "moves")) {
        for (std::size_t i = 0; i < mj->size(); ++i) {
          const std::string ip = index_path(mp, i);
          const Json& m = (*mj)[i];
          if (!c_.object(m, ip, {"point", "surface_point", "to"}, "a move {point | surface_point, to}")) continue;
          DirectMove move;
          const bool has_point = m.contains("point"), has_uv = m.contains("surface_point");
          if (has_point == has_uv) {
            c_.add(ip, "give exactly one of \"point\" ([x, y, z]) and \"surface_point\" ([u, v])");
            continue;
          }
          if (has_point) {
            if (const auto v = c_.vec3(m.at("point"), key_path(ip, "point"))) move.point = *v;
          } else if (const auto uv = c_.vec2(m.at("surface_point"), key_path(ip, "surface_point"))) {
            move.on_surface = true;
            move.point = Eigen::Vector3d((*uv)[0], (*uv)[1], 0.0);
          }
          if (const Json* t = c_.member(m, ip, "to", true, "the target [x, y, z]"))
            if (const auto v = c_.vec3(*t, key_path(ip, "to"))) move.to = *v;
          d.moves.push_back(move);
        }
      }
    }
    const Eigen::Index rows = static_cast<Eigen::Index>(counts[0]) * counts[1] * counts[2];
    auto index_row = [&](const Json& v, const std::string& ip) -> std::optional<Eigen::Index> {
      if (!v.is_array() || v.size() != 3) {
        c_.add(ip, "expected [i, j, k], found " + found(v));
        return std::nullopt;
      }
      Eigen::Index row = 0;
      for (std::size_t k = 0; k < 3; ++k) {
        const auto x = c_.integer(v[k], index_path(ip, k), 0, std::max(counts[k] - 1, 0));
        if (!x) return std::nullopt;
        row = row * counts[k] + *x;
      }
      return row;
    };
    if (const Json* lk = c_.member(j, p, "locked", false, "")) {
      const std::string lp = key_path(p, "locked");
      if (!lk->is_array()) {
        c_.add(lp, "expected an array of [i, j, k], found " + found(*lk));
      } else if (rows > 0) {
        d.options.locked.assign(static_cast<std::size_t>(rows), false);
        for (std::size_t i = 0; i < lk->size(); ++i)
          if (const auto r = index_row((*lk)[i], index_path(lp, i))) d.options.locked[static_cast<std::size_t>(*r)] = true;
      }
    }
    if (const Json* tj = c_.member(j, p, "tied", false, "")) {
      const std::string tp = key_path(p, "tied");
      if (!tj->is_array()) {
        c_.add(tp, "expected an array of groups [[i, j, k], ...], found " + found(*tj));
      } else {
        for (std::size_t g = 0; g < tj->size(); ++g) {
          const std::string gp = index_path(tp, g);
          if (!(*tj)[g].is_array() || (*tj)[g].size() < 2) {
            c_.add(gp, "expected a group of at least 2 indices [i, j, k], found " + found((*tj)[g]));
            continue;
          }
          std::vector<Eigen::Index> group;
          for (std::size_t i = 0; i < (*tj)[g].size(); ++i)
            if (const auto r = index_row((*tj)[g][i], index_path(gp, i))) group.push_back(*r);
          d.options.tied.push_back(std::move(group));
        }
      }
    }
    d.options.tolerance = c_.number_or(j, p, "tolerance", d.options.tolerance, positive);
    c_.attempt(p, [&] { d.options.validate(); });
    if (c_.problems.size() != before) return std::nullopt;
    return d;
  }

  // ---- exports ----------------------------------------------------------------------------

  void exporting(const std::string& name, const Json& j, const std::string& path) {
    if (!c_.object(j, path, {"surfaces", "formats", "schema"}, "an export {surfaces, formats, schema}")) return;
    const std::size_t before = c_.problems.size();
    ExportDef def{name, path, {}, {"step", "iges", "glb"}, "AP214"};
    if (const Json* s = c_.member(j, path, "surfaces", true, "an array of surface names")) {
      const std::string sp = key_path(path, "surfaces");
      if (!s->is_array() || s->empty()) {
        c_.add(sp, "expected a non-empty array of surface names, found " + found(*s));
      } else if (c_.at_most(*s, sp, limit::entries, "surface names")) {
        // A surface listed twice would be written as two coincident faces; 100,000 times took a
        // minute and 4 GB (issue #18).
        std::map<std::string, std::size_t> first;
        for (std::size_t i = 0; i < s->size(); ++i) {
          const auto n = surface_ref((*s)[i], index_path(sp, i));
          if (!n) continue;
          if (const auto [it, fresh] = first.emplace(*n, i); !fresh)
            c_.add(index_path(sp, i), "the surface \"" + *n + "\" is already listed at [" + std::to_string(it->second) +
                                          "]; list each surface once");
          else
            def.surfaces.push_back(*n);
        }
      }
    }
    if (const Json* f = c_.member(j, path, "formats", false, "")) {
      const std::string fp = key_path(path, "formats");
      def.formats.clear();
      if (!f->is_array() || f->empty()) {
        c_.add(fp, "expected a non-empty array of \"step\", \"iges\", \"glb\", found " + found(*f));
      } else {
        for (std::size_t i = 0; i < f->size(); ++i)
          if (const auto k = c_.choice((*f)[i], index_path(fp, i), {"step", "iges", "glb"})) {
            const std::string fmt = (*f)[i].get<std::string>();
            if (std::find(def.formats.begin(), def.formats.end(), fmt) != def.formats.end())
              c_.add(index_path(fp, i), "\"" + fmt + "\" is listed twice; list each format once");
            else
              def.formats.push_back(fmt);
          }
      }
    }
    if (const Json* s = c_.member(j, path, "schema", false, ""))
      if (const auto k = c_.choice(*s, key_path(path, "schema"), {"AP214", "AP242"})) def.schema = *k == 0 ? "AP214" : "AP242";
    if (c_.problems.size() == before) data.exports.push_back(std::move(def));
  }
};

// ---- syntax: line and column, duplicate keys ----------------------------------------------------

std::pair<int, int> line_column(std::string_view text, std::size_t byte) {
  // nlohmann's byte is the 1-based position of the last character read: the end of the token
  // that broke the syntax. Report where that token starts (the start of "name" in a missing-comma
  // error), which is where the eye looks.
  std::size_t end = std::min(byte > 0 ? byte - 1 : 0, text.size());
  if (end < text.size() && text[end] == '"' && end > 0) {
    std::size_t k = end;
    while (k > 0 && !(text[k - 1] == '"' && (k < 2 || text[k - 2] != '\\'))) --k;
    if (k > 0) end = k - 1;
  } else {
    auto literal = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+'; };
    while (end > 0 && end < text.size() && literal(text[end]) && literal(text[end - 1])) --end;
  }
  int line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < end; ++i)
    if (text[i] == '\n') ++line, line_start = i + 1;
  return {line, static_cast<int>(end - line_start) + 1};
}

/// Where arrays and objects first nest deeper than limit::depth, found by counting brackets
/// outside strings before any parser sees the text: nlohmann's parser, called on a recipe nested
/// 100,000 levels deep, recursed ~87,000 frames and overflowed the stack (issue #18). The problem
/// names the top-level key it is under (when there is one) and the bracket's line and column.
std::optional<Problem> too_deep(std::string_view text) {
  int depth = 0, line = 1;
  std::size_t line_start = 0, string_start = 0;
  bool in_string = false;
  std::string key, top_key;  // the last string closed at depth 1, and the key it became
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      line_start = i + 1;
    }
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character cannot end the string
      } else if (c == '"') {
        in_string = false;
        if (depth == 1) key = std::string(text.substr(string_start, std::min<std::size_t>(i - string_start, 64)));
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
      string_start = i + 1;
    } else if (c == ':' && depth == 1) {
      top_key = key;
    } else if (c == '[' || c == '{') {
      if (++depth > limit::depth)
        return Problem{top_key.empty() ? "(syntax)" : top_key,
                       "arrays and objects nest deeper than " + std::to_string(limit::depth) +
                           " levels here (recipe limit; a recipe needs at most 8): remove the extra brackets",
                       line, static_cast<int>(i - line_start) + 1};
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return std::nullopt;
}

/// Parses with a callback that reports keys repeated in one object (nlohmann would keep the last
/// silently: a second curve of the same name would replace the first).
Json parse_reporting_duplicates(std::string_view text, Checker& c) {
  struct Level {
    bool array = false;
    long index = -1;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Level> levels;
  auto path = [&] {
    std::string p;
    for (std::size_t i = 0; i + 1 < levels.size(); ++i)
      p = levels[i].array ? index_path(p, static_cast<std::size_t>(levels[i].index)) : key_path(p, levels[i].key);
    return p;
  };
  auto element = [&] {
    if (!levels.empty() && levels.back().array) ++levels.back().index;
  };
  Json::parser_callback_t cb = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start: element(); levels.push_back({false, -1, "", {}}); break;
      case Json::parse_event_t::array_start: element(); levels.push_back({true, -1, "", {}}); break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!levels.empty()) levels.pop_back();
        break;
      case Json::parse_event_t::key: {
        auto& top = levels.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second) {
          levels.push_back({});  // so path() includes top's key
          c.add(path(), "the key \"" + top.key + "\" appears twice in this object; only the last would "
                        "count: remove or rename one");
          levels.pop_back();
        }
        break;
      }
      case Json::parse_event_t::value: element(); break;
    }
    return true;
  };
  const internal::FpTrapsHeld traps_held;  // the JSON parser's strtod
  try {
    return Json::parse(text.begin(), text.end(), cb);
  } catch (const Json::out_of_range& e) {  // a number beyond the double range: name where it is
    element();                             // the number being read is the next element
    levels.push_back({});                  // so path() includes the innermost level
    std::string what = e.what();
    if (const auto k = what.find("] "); k != std::string::npos) what = what.substr(k + 2);
    c.add(path(), what + "; give finite numbers within the range of a double");
    throw;
  }
}

}  // namespace

CheckOutcome check(std::string_view text, const fs::path& base_dir) {
  Checker c;
  CheckOutcome out;
  if (text.size() > limit::text_bytes) {
    out.problems.push_back({"(top level)", "the recipe is " + std::to_string(text.size()) + " bytes; at most " +
                                               std::to_string(limit::text_bytes) + " (64 MiB) are allowed (recipe limit)",
                            0, 0});
    return out;
  }
  if (auto deep = too_deep(text)) {
    out.problems.push_back(std::move(*deep));
    return out;
  }
  Json root;
  try {
    root = parse_reporting_duplicates(text, c);
  } catch (const Json::parse_error& e) {
    const auto [line, column] = line_column(text, e.byte);
    std::string what = e.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error while
    // parsing object - unexpected ..." → keep the part after the position.
    if (const auto k = what.find(": syntax error"); k != std::string::npos) what = what.substr(k + 2);
    else if (const auto k2 = what.find("] "); k2 != std::string::npos) what = what.substr(k2 + 2);
    out.problems.push_back({"(syntax)", what + "; fix the JSON syntax (NaN and Infinity are not JSON numbers)",
                            line, column});
    return out;
  } catch (const Json::exception& e) {  // a number beyond the range of a double
    std::string what = e.what();
    if (const auto k = what.find("] "); k != std::string::npos) what = what.substr(k + 2);
    out.problems = recipe_problems(c);  // where the number is (parse_reporting_duplicates)
    if (out.problems.empty())
      out.problems.push_back({"(syntax)", what + "; give finite numbers within the range of a double", 0, 0});
    return out;
  }
  RecipeChecker rc(c, base_dir);
  rc.run(root);
  out.data = std::move(rc.data);
  out.problems = recipe_problems(c);
  return out;
}

SketchDef rebuild_sketch(const SketchDef& def,
                         const std::function<const surface::BSplineCurve*(const std::string&)>& curve) {
  Checker c;
  RecipeChecker rc(c, {});
  rc.runtime_curve = curve;
  std::vector<std::string> names;  // every name resolves through `curve`; unknown ones are reported
  const Json j = Json::parse(def.deferred_json);
  if (j.contains("entities") && j["entities"].is_object())
    for (const auto& [e, v] : j["entities"].items())
      if (v.is_object() && v.contains("curve") && v["curve"].is_string()) {
        const std::string n = v["curve"].get<std::string>();
        if (curve(n)) names.push_back(n);
      }
  rc.know_curves(std::move(names));
  rc.rebuild(def.name, j, def.path);
  if (!c.problems.empty()) {
    std::string m = "with the run's curves the sketch has " + std::to_string(c.problems.size()) + " problem" +
                    (c.problems.size() == 1 ? "" : "s") + ":";
    for (const auto& p : recipe_problems(c)) m += "\n  " + to_string(p);
    throw Error(ErrorCategory::InvalidGeometry, m);
  }
  return std::move(rc.data.sketches.front());
}

std::string recipe_wording(std::string m) {
  // The library's fixes, as a recipe applies them (or dropped where a recipe cannot).
  static const std::pair<std::string_view, std::string_view> phrases[] = {
      {"Allow a certified refit (SurfaceDeformationOptions::refit) to approximate this step within a tolerance",
       "Allow a certified refit to approximate this step within a tolerance: give the deformation "
       "\"composition\": {\"mode\": \"refit\", \"tolerance\": 1e-4} (relative to the size)"},
      {"set SurfaceDeformationOptions::accept_out_of_tolerance",
       "set \"accept_out_of_tolerance\": true in the \"composition\""},
      {"(RefitOptions::relative = false)", "(\"relative\": false in the \"composition\")"},
      {"remove the repeated point or set FitOptions::drop_duplicates", "remove the repeated point"},
      {" (or build the plane with make_plane)", ""},
      {"; build the plane with make_plane(origin, normal, x direction)",
       "; give a \"y_axis\" perpendicular to the \"x_axis\""},
      {"reverse it or set LoftOptions::auto_orient", "reverse it (a curve {\"reversed\": NAME})"},
      {"loosen SuperquadricOptions::tolerance, raise max_spans, ", "loosen \"tolerance\" "},
      {"not reached at max_sections", "not reached with the most sections allowed"},
      {"raise gap_tolerance", "raise \"gap_tolerance\""},
  };
  // A refit's advice depends on the limit it hit: a recipe can raise max_control_points (up to
  // its 40,000 cap), not the iteration or per-direction limits.
  if (const auto at = m.find("; raise the limits, the tolerance or the degree"); at != std::string::npos) {
    static const std::regex net_limit("control point limit ([0-9]+) reached");
    std::smatch hit;
    const bool raisable = std::regex_search(m, hit, net_limit) && std::stol(hit[1].str()) < limit::refit_control_points;
    m.replace(at, std::string_view("; raise the limits, the tolerance or the degree").size(),
              raisable ? "; raise the composition's \"max_control_points\" (at most 40,000), loosen its "
                         "\"tolerance\" or raise its \"degree\""
                       : "; loosen the composition's \"tolerance\" or raise its \"degree\", or deform less");
  }
  for (const auto& [from, to] : phrases)
    for (std::size_t at = m.find(from); at != std::string::npos; at = m.find(from, at + to.size()))
      m.replace(at, from.size(), to);
  // What is left: a field of a C++ options struct in a validation message ("SweepOptions::
  // twist_degrees is ..."), which for the options a recipe sets is the recipe's own key.
  static const std::regex options_struct("\\b[A-Z][A-Za-z]*Options::");
  m = std::regex_replace(m, options_struct, "");
  // The library's own prefixes: the recipe path in front of the message already names the step
  // (and a recipe runs deform_surface one step at a time, so its "steps[0]" would mislead).
  static const std::regex library_prefix("\\b(deform_surface: steps\\[[0-9]+\\] \\([^)]*\\)(: )?|compose_exact: |refit_deformed: )");
  return std::regex_replace(m, library_prefix, "");
}

std::string to_string(const Problem& problem) {
  std::string s;
  if (problem.line > 0) s = "line " + std::to_string(problem.line) + ", column " + std::to_string(problem.column) + ": ";
  if (problem.path != "(syntax)") s += problem.path + ": ";
  return s + problem.message;
}

std::vector<Problem> check_recipe(std::string_view text, const fs::path& base_dir) {
  return check(text, base_dir).problems;
}

Recipe parse_recipe(std::string_view text, const fs::path& base_dir) {
  CheckOutcome out = check(text, base_dir);
  if (!out.problems.empty()) {
    std::string m = "the recipe has " + std::to_string(out.problems.size()) + " problem" +
                    (out.problems.size() == 1 ? "" : "s") + ":";
    for (const auto& p : out.problems) m += "\n  " + to_string(p);
    throw Error(ErrorCategory::Recipe, m);
  }
  return Recipe{std::make_shared<const RecipeData>(std::move(out.data))};
}

Recipe load_recipe(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(ErrorCategory::Io, "cannot read the recipe \"" + file.string() + "\"; check the path");
  std::ostringstream text;
  text << in.rdbuf();
  CheckOutcome out = check(text.str(), file.parent_path());
  if (!out.problems.empty()) {
    std::string m = file.string() + ": the recipe has " + std::to_string(out.problems.size()) + " problem" +
                    (out.problems.size() == 1 ? "" : "s") + ":";
    for (const auto& p : out.problems) m += "\n  " + to_string(p);
    throw Error(ErrorCategory::Recipe, m);
  }
  if (out.data.name.empty()) out.data.name = file.stem().string();
  return Recipe{std::make_shared<const RecipeData>(std::move(out.data))};
}

const std::string& Recipe::name() const {
  static const std::string empty;
  return data ? data->name : empty;
}

std::vector<std::string> Recipe::deformation_names() const {
  std::vector<std::string> out;
  if (data)
    for (const auto& s : data->stacks) out.push_back(s.name);
  return out;
}

}  // namespace clay::recipe
