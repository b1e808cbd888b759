#pragma once
// The recipe checker's walk (internal to clay_recipe): the limits, the path-aware reader with the
// recipe's wording, and RecipeChecker, whose readers are defined by section in recipe_check.cpp
// (the document, composition, exports), recipe_check_curves.cpp (strokes, curves, sketches),
// recipe_check_surfaces.cpp and recipe_check_deformations.cpp. Every reader records a Problem
// with the value's path and returns a fallback, so the walk goes on and everything wrong is
// reported at once (docs/recipe.md).
#include "recipe_model.hpp"

#include <clay/constraints/constraint.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/receiver.hpp>
#include <clay/error.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/sketch/entities.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <clay/deform/detail/stack_json.hpp>
#include <clay/internal/fenv.hpp>
#include <clay/internal/json_reader.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

namespace clay::recipe::check_detail {

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
constexpr std::size_t text_bytes = 64u << 20;  // the recipe text: 64 MiB
constexpr int depth = 64;                      // nesting of arrays and objects (the schema uses 8)
constexpr double magnitude = 1e6;              // |any number|: mm (1 km), degrees, knots, weights
constexpr std::size_t entries = 1000;  // names per section, surfaces per export, skin sections
constexpr std::size_t curve_points = 10000;     // control points of a curve, points of a polyline
constexpr std::size_t stroke_points = 10000;    // drawn points of a stroke
constexpr int stroke_pieces = 100;              // curves of a stroke split at its corners
constexpr std::size_t surface_points = 250000;  // control points of an inline surface (500 x 500)
constexpr std::size_t sketch_items = 1000;      // points, entities, constraints of a sketch
constexpr std::size_t steps = 100;              // steps of a deformation stack
constexpr std::size_t moves = 10000;            // moves of a lattice step or direct manipulation
constexpr double weight_min = 1e-6, weight_max = 1e6;  // rational weights (ratio at most 1e12)
constexpr long lattice_points = 100000;  // control points of a Bézier or B-spline lattice
constexpr int lattice_cells = 64;        // cells of a B-spline lattice per direction
constexpr long chunks = 4096;            // tricubic chunks of an extended lattice
constexpr int prism_sections = 65;       // sections of a prism lattice (64 gaps)
constexpr int cylinder_sectors = 256, cylinder_rings = 64, lattice_layers = 64;
constexpr double twist_turns = 100;           // twist: turns within 1 m of its origin
constexpr double taper_scale = 1e3;           // taper: |r(z)| bound within 1 m of its origin
constexpr double bend_rate = 1;               // bend: rad/mm (radius of curvature >= 1 mm)
constexpr double bend_turns = 10;             // bend: turns over its region
constexpr double sweep_twist_degrees = 3600;  // sweep: 10 turns
constexpr double arc_degrees = 720;           // arc start and end angles
constexpr double min_tolerance = 1e-9;        // smallest refit, sweep and fit tolerance
constexpr int refit_control_points = 40000;   // a refit's net (RefitOptions' default)
}  // namespace limit

// Every number is also within ±limit::magnitude (Checker::number).
constexpr Range any{-limit::magnitude, limit::magnitude, false, false};
constexpr Range positive{0, limit::magnitude, true, false};
constexpr Range non_negative{0, limit::magnitude, false, false};
constexpr Range tolerance_range{limit::min_tolerance, limit::magnitude};

// Keys issue #37 renamed so that a tolerance's name says its unit; validate names the new key.
using Renamed = internal::JsonReader::Renamed;
constexpr Renamed renamed_mm{"tolerance", "tolerance_mm", "in millimetres"};
constexpr Renamed renamed_relative{"tolerance", "relative_tolerance",
                                   "a fraction of the model's size"};
constexpr Renamed renamed_residual{"tolerance", "residual_tolerance",
                                   "mm for distances, radians for angles"};
constexpr Renamed dropped_relative{
    "relative", "",
    "the tolerance's key says its unit: \"relative_tolerance\" (a fraction of the size, what "
    "\"relative\": true meant) or \"tolerance_mm\" (what \"relative\": false meant)"};
// Issue #38: every result has a budget; "editable" (a final copy above its limits) became it.
constexpr Renamed renamed_editable{
    "editable", "budget",
    "the same limits, now on every step: above them a step yields its certified light form"};
// Weights beyond it overflow the homogeneous products (a bottle's neck with weights 1e300 read
// back invalid); within it a weight ratio of 1e12 is still allowed.
constexpr Range weight_range{limit::weight_min, limit::weight_max};
// Knot vectors are count + degree + 1 long.
constexpr std::size_t knot_slack = surface::max_kernel_degree + 1;

inline bool valid_name(std::string_view s) {
  if (s.empty() || s.size() > 64) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

/// The "pieces" of a stroke's JSON when it is a valid count (1 .. limit::stroke_pieces), else 0:
/// the names a stroke defines (declare() and stroke() agree; a bad count is reported by stroke()).
int declared_pieces(const Json& stroke);

/// The walk: the shared path-aware reader (clay/internal/json_reader.hpp) with the recipe's
/// limits and wording, and the recipe's own composite reads.
class Checker : public internal::JsonReader {
 public:
  Checker() {
    magnitude = limit::magnitude;
    refuse_denormal = true;
    magnitude_note = "recipe numbers are limited to ±" + shortest(limit::magnitude) +
                     ": mm, degrees, knots and weights";
    limit_note = "recipe limit";
  }

  using JsonReader::choice;
  /// One of `choices` (the index), or nullopt.
  std::optional<int> choice(const Json& j, const std::string& path,
                            std::initializer_list<std::string_view> choices) {
    return JsonReader::choice(j, path, std::vector<std::string>(choices.begin(), choices.end()));
  }
  /// recipe limits on counts by default.
  std::optional<Points3> points(const Json& j, const std::string& path, std::size_t min,
                                std::size_t max = limit::curve_points) {
    return JsonReader::points(j, path, min, max);
  }
  std::optional<std::vector<double>> numbers(const Json& j, const std::string& path,
                                             std::size_t min,
                                             std::size_t max = limit::surface_points,
                                             Range r = any) {
    return JsonReader::numbers(j, path, min, max, r);
  }
  std::optional<double> number(const Json& j, const std::string& path, Range r = any) {
    return JsonReader::number(j, path, r);
  }
  double number_or(const Json& obj, const std::string& path, std::string_view key, double def,
                   Range r = any) {
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
  std::string wording(std::string message) const override {
    return recipe_wording(std::move(message));
  }
};

/// The reader's problems as the recipe's (a syntax error's line and column are added apart).
inline std::vector<Problem> recipe_problems(const Checker& c) {
  std::vector<Problem> out;
  out.reserve(c.problems.size());
  for (const auto& p : c.problems) out.push_back({p.path, p.message, 0, 0});
  return out;
}

// ---- names and references
// ------------------------------------------------------------------------

/// What has been defined so far, and what the whole document declares (to tell "missing" from
/// "defined later").
struct Names {
  std::vector<std::string> curves;        // strokes, curves and sketch entities, in order
  std::set<std::string> curves_declared;  // everything the document declares as a curve
  std::vector<std::string> surfaces;
  std::set<std::string> surfaces_declared;
  std::vector<std::string> stacks;  // all stacks (may be referenced from anywhere)

  static bool has(const std::vector<std::string>& list, const std::string& name) {
    return std::find(list.begin(), list.end(), name) != list.end();
  }
};

inline std::string listing(const std::vector<std::string>& names) {
  if (names.empty()) return "none is defined";
  if (names.size() <= 12) return "defined: " + join(names);
  return "defined: " + join(std::vector<std::string>(names.begin(), names.begin() + 12)) +
         ", ... (" + std::to_string(names.size()) + " in all)";
}

class RecipeChecker {
 public:
  RecipeChecker(Checker& c, fs::path base) : c_(c), base_(std::move(base)) {}
  RecipeData data;
  /// Set when a deferred sketch is built again at run time: the run's curves by name.
  std::function<const surface::BSplineCurve*(const std::string&)> runtime_curve;

  /// Builds one sketch from its JSON at run time (rebuild_sketch): every curve name is known.
  void rebuild(const std::string& name, const Json& j, const std::string& path);
  /// The curves a rebuild may refer to (all the run's curves).
  void know_curves(std::vector<std::string> names) { names_.curves = std::move(names); }

  void run(const Json& root);

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
      c_.add(std::string(key), std::to_string(j->size()) + " entries; at most " +
                                   std::to_string(limit::entries) +
                                   " are allowed (recipe limit): split the recipe");
      return;
    }
    for (const auto& [name, value] : j->items())
      each(name, value, key_path(std::string(key), name));
  }

  /// First pass: every name the document declares (for "defined later" and the stacks, which
  /// may be referenced before they appear), and malformed or repeated names.
  void declare(const Json& root);

  std::optional<std::string> curve_ref(const Json& j, const std::string& path);
  /// A curve taken from a surface: iso, boundary, project or offset ("surface" may be declared
  /// anywhere; the run builds it first).
  void from_surface(const Json& v, const std::string& p, CurveDef& def);

  std::optional<std::string> surface_ref(const Json& j, const std::string& path);

  std::vector<std::string> curve_refs(const Json& obj, const std::string& path,
                                      std::string_view key, std::size_t min, std::size_t max);

  // ---- composition ------------------------------------------------------------------------

  Composition composition(const Json& j, const std::string& path, Composition c);

  // ---- strokes, curves, sketches --------------------------------------------------------------

  std::optional<sketch::SketchPlane> plane(const Json& j, const std::string& path);

  void stroke(const std::string& name, const Json& j, const std::string& path);

  std::optional<surface::BSplineCurve> inline_curve(const Json& j, const std::string& path);

  void curve(const std::string& name, const Json& j, const std::string& path);

  std::optional<surface::BSplineCurve> polyline_curve(const Points3& pts, const std::string& path);

  /// The three required [x, y, z] members `keys` of the object v at path p (each nullopt when
  /// missing or malformed, reported).
  std::array<std::optional<Eigen::Vector3d>, 3> points3(const Json& v, const std::string& p,
                                                        const std::array<const char*, 3>& keys);
  std::optional<surface::BSplineCurve> arc(const Json& v, const std::string& p);
  std::optional<surface::BSplineCurve> arc_through(const Json& v, const std::string& p);
  std::optional<surface::BSplineCurve> arc_radius(const Json& v, const std::string& p);
  /// The "plane" member {origin, normal} of a mirror at path p (normal made unit).
  std::optional<MirrorPlane> mirror_plane(const Json& v, const std::string& p);

  /// Exactly one of `kinds` is a key of j: true and `kind` set; else the problem is recorded.
  bool one_of(const Json& j, const std::string& path, std::initializer_list<std::string_view> kinds,
              std::string_view what, std::string& kind);

  void sketch(const std::string& name, const Json& j, const std::string& path);

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
    const auto type =
        c_.choice(*t, key_path(path, "type"),
                  {"fixed", "coincident", "point_on", "horizontal", "vertical", "parallel",
                   "perpendicular", "distance", "angle", "radius", "equal_length", "equal_radius",
                   "midpoint", "symmetric", "tangent", "curvature"});
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
      using Id =
          typename std::invoke_result_t<decltype(ref), const Json&, const std::string&>::value_type;
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
      if (!c_.object(v, p, {"entity", "end"},
                     "a curve end {\"entity\": e, \"end\": \"start\"|\"end\"}"))
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
      case 0:
        allowed.push_back("point");
        if (auto p = point("point")) out = cs::fixed(*p);
        break;
      case 1:
        allowed.push_back("points");
        if (auto p = pair_of("points", point_ref)) out = cs::coincident(p->first, p->second);
        break;
      case 2:
        allowed.insert(allowed.end(), {"point", "entity"});
        {
          auto p = point("point");
          auto e = entity("entity");
          if (p && e) out = cs::point_on(*p, *e);
        }
        break;
      case 3:
        allowed.push_back("entity");
        if (auto e = entity("entity")) out = cs::horizontal(*e);
        break;
      case 4:
        allowed.push_back("entity");
        if (auto e = entity("entity")) out = cs::vertical(*e);
        break;
      case 5:
        allowed.push_back("entities");
        if (auto e = pair_of("entities", entity_ref)) out = cs::parallel(e->first, e->second);
        break;
      case 6:
        allowed.push_back("entities");
        if (auto e = pair_of("entities", entity_ref)) out = cs::perpendicular(e->first, e->second);
        break;
      case 7:
        allowed.insert(allowed.end(), {"points", "value"});
        {
          auto p = pair_of("points", point_ref);
          auto v = value(positive);
          if (p && v) out = cs::distance(p->first, p->second, *v);
        }
        break;
      case 8:
        allowed.insert(allowed.end(), {"entities", "value"});
        {
          auto e = pair_of("entities", entity_ref);
          auto v = value(Range{0, 180, true, false});
          if (e && v) out = cs::angle(e->first, e->second, *v);
        }
        break;
      case 9:
        allowed.insert(allowed.end(), {"entity", "value"});
        {
          auto e = entity("entity");
          auto v = value(positive);
          if (e && v) out = cs::radius(*e, *v);
        }
        break;
      case 10:
        allowed.push_back("entities");
        if (auto e = pair_of("entities", entity_ref)) out = cs::equal_length(e->first, e->second);
        break;
      case 11:
        allowed.push_back("entities");
        if (auto e = pair_of("entities", entity_ref)) out = cs::equal_radius(e->first, e->second);
        break;
      case 12:
        allowed.insert(allowed.end(), {"point", "entity"});
        {
          auto p = point("point");
          auto e = entity("entity");
          if (p && e) out = cs::midpoint(*p, *e);
        }
        break;
      case 13:
        allowed.insert(allowed.end(), {"points", "entity"});
        {
          auto p = pair_of("points", point_ref);
          auto e = entity("entity");
          if (p && e) out = cs::symmetric(p->first, p->second, *e);
        }
        break;
      default: {
        allowed.push_back("ends");
        if (auto e = pair_of("ends", end_ref))
          out = *type == 14 ? cs::tangent(e->first, e->second) : cs::curvature(e->first, e->second);
      }
    }
    for (const auto& [key, v] : j.items()) {
      (void)v;
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        c_.add(key_path(path, key),
               "unknown key \"" + key + "\" for a " + t->get<std::string>() +
                   " constraint; its keys are: " +
                   join(std::vector<std::string>(allowed.begin(), allowed.end())));
    }
    return out;
  }

  // ---- surfaces ---------------------------------------------------------------------------

  void surface(const std::string& name, const Json& j, const std::string& path);

  /// In exact mode every enabled step must be one compose_exact handles: twists, bends and
  /// extended lattices are not polynomial maps of the surface's control points (DESIGN.md).
  void exact_composable(const std::string& stack_name, const std::string& path);

  std::optional<surface::BSplineSurface> inline_surface(const Json& j, const std::string& path);

  // ---- deformations -----------------------------------------------------------------------

  std::optional<deform::Frame> lattice_frame(const Json& j, const std::string& path);

  std::optional<std::array<int, 3>> triple(const Json& obj, const std::string& path,
                                           std::string_view key, int lo, int hi,
                                           std::string_view hint);

  /// False (and the problem recorded) when a lattice of counts[0] x counts[1] x counts[2] control
  /// points is above limit::lattice_points; checked before the lattice is built.
  bool lattice_size_ok(std::array<long, 3> counts, const std::string& path);

  /// False (and the problem recorded) when an extended lattice would have more than
  /// limit::chunks tricubic chunks; checked before the lattice is built.
  bool chunks_ok(long chunks, const std::string& path);

  /// Applies "moves" to `points` (rows found by `row_of`, which reports its own problems).
  template <class RowOf>
  bool apply_moves(const Json& moves, const std::string& path, Points3& points, RowOf&& row_of,
                   const std::vector<std::string_view>& index_keys) {
    if (!moves.is_array()) {
      c_.add(path, "expected an array of {\"index\": ..., \"to\" or \"by\": [x, y, z]}, found " +
                       found(moves));
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
  std::optional<Eigen::Index> lattice_row(const Json& m, const std::string& p,
                                          std::array<int, 3> counts);

  /// A Bézier or B-spline lattice from recipe fields (points or moves).
  std::optional<deform::Deformation> lattice(const Json& j, const std::string& path, bool bspline,
                                             std::initializer_list<std::string_view> extra_keys);

  /// "points" (all of them) or "moves" (from the undisplaced points already in `points`).
  bool lattice_points(const Json& j, const std::string& path, Points3& points,
                      std::array<int, 3> counts);

  std::optional<deform::Deformation> extended_from_generator(const Json& j,
                                                             const std::string& path);

  /// Sum |c_k| 1000^k: a bound of |c(z)| for |z| <= 1 m of a polynomial with coefficients c.
  static double bound_within_metre(const std::vector<double>& c);

  /// The recipe's limits on a step the deformation-stack schema read (which checks only that its
  /// numbers are finite): frames and lattice points within ±limit::magnitude, bounded twists,
  /// tapers and bends, and extended lattices of at most limit::chunks chunks.
  bool within_limits(const deform::Deformation& d, const std::string& path);

  /// A stack-schema step, read by the same reader as deform::stack_from_json (one walk, the
  /// problems at their recipe paths), then its values checked by deform's problems().
  std::optional<deform::Deformation> schema_step(const Json& j, const std::string& path);

  void stack(const std::string& name, const Json& j, const std::string& path);

  std::optional<StyleDef> style(const Json& j, const std::string& p);
  /// A lattice step's "keep": distinct names among "volume", "centroid".
  std::vector<std::string> kept_properties(const Json& j, const std::string& path);

  std::optional<DirectDef> direct(const Json& j, const std::string& p);

  // ---- exports ----------------------------------------------------------------------------

  void exporting(const std::string& name, const Json& j, const std::string& path);
  void modelling(const std::string& name, const Json& j, const std::string& path);
  /// The path of an existing STEP or IGES file `j` names, relative to the recipe's folder.
  std::optional<fs::path> exchange_file(const Json& j, const std::string& path);
  /// A "formats" array of "step", "iges", "glb", each once; `fallback` when it has problems.
  std::vector<std::string> formats(const Json& j, const std::string& path);
};

}  // namespace clay::recipe::check_detail
