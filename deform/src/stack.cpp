// Deformation stacks: ordered application (Güdükbay–Özgüç 1990 §3, Fig. 7) and the JSON schema
// "clayform.deformation-stack" version 1 (docs/deform.md). nlohmann-json stays in this file.
//
// Adding a deformation kind: one overload in each set below marked "per kind" (kind_of,
// write_fields, read_fields, apply_in_place); the variant drives the rest.
#include <clay/deform/stack.hpp>

#include <clay/deform/frozen_lattice.hpp>
#include <clay/error.hpp>

#include <nlohmann/json.hpp>

#include <cfenv>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <sstream>
#include <string>
#include <utility>

namespace clay::deform {

namespace {

using Json = nlohmann::ordered_json;

constexpr std::string_view format_name = "clayform.deformation-stack";
constexpr int format_version = 1;

// ---- per kind: the JSON name ----------------------------------------------------------------

std::string_view kind_of(const BezierLattice&) { return "bezier_lattice"; }
std::string_view kind_of(const BSplineLattice&) { return "bspline_lattice"; }
std::string_view kind_of(const ExtendedLattice&) { return "extended_lattice"; }
std::string_view kind_of(const Taper&) { return "taper"; }
std::string_view kind_of(const Twist&) { return "twist"; }
std::string_view kind_of(const Bend&) { return "bend"; }

// ---- per kind: in-place bulk deformation ----------------------------------------------------
// `step` and `report` serve the kinds that iterate (extended lattices): they add their summary.

void apply_in_place(const BezierLattice& d, Points3& p, const DeformOptions& o, std::size_t,
                    StackReport&) {
  deform_points(FrozenLattice(d), p, p, o);  // frozen once per call
}
void apply_in_place(const BSplineLattice& d, Points3& p, const DeformOptions& o, std::size_t,
                    StackReport&) {
  deform_points(FrozenLattice(d), p, p, o);
}
void apply_in_place(const ExtendedLattice& d, Points3& p, const DeformOptions& o,
                    std::size_t step, StackReport& report) {
  // deform_points(ExtendedLattice): freeze on the rest shape (Coquillart §3.3), evaluate eq. (1)
  // on the moved control points (§3.4); unresolved points stay, the summary says so.
  FreezeOptions f;
  f.threads = o.threads;
  const FrozenPoints frozen = freeze(d, p, f);
  p = evaluate(d, frozen, o);
  report.freezes.push_back({step, frozen.summary});
}
void apply_in_place(const Taper& d, Points3& p, const DeformOptions& o, std::size_t,
                    StackReport&) {
  deform_points(d, p, p, o);
}
void apply_in_place(const Twist& d, Points3& p, const DeformOptions& o, std::size_t,
                    StackReport&) {
  deform_points(d, p, p, o);
}
void apply_in_place(const Bend& d, Points3& p, const DeformOptions& o, std::size_t,
                    StackReport&) {
  deform_points(d, p, p, o);
}

std::string step_label(const DeformationStep& step, std::size_t i) {
  std::string label = "steps[" + std::to_string(i) + "] (" + std::string(kind_name(step.deformation));
  if (!step.name.empty()) label += " '" + step.name + "'";
  return label + ")";
}

// ---- writing ----------------------------------------------------------------------------------

Json vec(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json points_json(const Points3& p) {
  Json a = Json::array();
  for (Eigen::Index r = 0; r < p.rows(); ++r) a.push_back(Json::array({p(r, 0), p(r, 1), p(r, 2)}));
  return a;
}

Json frame_json(const Frame& f) {
  Json j = Json::object();
  j["origin"] = vec(f.origin);
  j["s"] = vec(f.s);
  j["t"] = vec(f.t);
  j["u"] = vec(f.u);
  return j;
}

Json frame_json(const AxisFrame& f) {
  Json j = Json::object();
  j["origin"] = vec(f.origin);
  j["axis"] = vec(f.axis);
  j["reference"] = vec(f.reference);
  return j;
}

// per kind: the fields after "kind", "name", "enabled"
void write_fields(const BezierLattice& d, Json& j) {
  j["frame"] = frame_json(d.frame);
  j["degrees"] = Json::array({d.degrees[0], d.degrees[1], d.degrees[2]});
  j["points"] = points_json(d.points);
}
void write_fields(const BSplineLattice& d, Json& j) {
  j["frame"] = frame_json(d.frame);
  Json bases = Json::array();
  for (const auto& b : d.bases) {
    Json basis = Json::object();
    basis["degree"] = b.degree;
    basis["knots"] = b.knots;
    bases.push_back(std::move(basis));
  }
  j["bases"] = std::move(bases);
  j["points"] = points_json(d.points);
}
void write_fields(const ExtendedLattice& d, Json& j) {
  j["rest"] = points_json(d.rest);
  j["points"] = points_json(d.points);
  Json chunks = Json::array();
  for (const Chunk& c : d.chunks) chunks.push_back(c);  // 64 indices, entry (i * 4 + j) * 4 + k
  j["chunks"] = std::move(chunks);
}
void write_fields(const Taper& d, Json& j) {
  j["frame"] = frame_json(d.frame);
  j["profile"] = d.profile;
}
void write_fields(const Twist& d, Json& j) {
  j["frame"] = frame_json(d.frame);
  j["angle"] = d.angle;
}
void write_fields(const Bend& d, Json& j) {
  j["frame"] = frame_json(d.frame);
  j["y_min"] = d.y_min;
  j["y_max"] = d.y_max;
  j["center"] = d.center;
  j["rate"] = d.rate;
}

// ---- reading: every failure names the JSON path -----------------------------------------------

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error(ErrorCategory::Recipe, "deformation stack JSON: " + path + ": " + what);
}

std::string found(const Json& v) {
  if (v.is_array()) return "an array of " + std::to_string(v.size());
  if (v.is_object()) return "an object";
  if (v.is_string()) return "the string " + v.dump();
  return v.dump();  // null, true, numbers
}

const Json& member(const Json& object, const std::string& path, const char* key,
                   const std::string& expected) {
  const auto it = object.find(key);
  if (it == object.end())
    fail(path, std::string("the key \"") + key + "\" is missing; give " + expected);
  return *it;
}

/// The object's keys must all be in `allowed` (catches misspelt fields).
void check_keys(const Json& object, const std::string& path,
                std::initializer_list<const char*> allowed, std::string_view what) {
  for (const auto& [key, value] : object.items()) {
    bool known = false;
    for (const char* a : allowed) known = known || key == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(path, "unknown key \"" + key + "\" in " + std::string(what) + "; the keys are " + list);
    }
  }
}

void expect_object(const Json& v, const std::string& path, const char* what) {
  if (!v.is_object()) fail(path, std::string("expected ") + what + " (a JSON object), found " + found(v));
}

double number(const Json& v, const std::string& path) {
  if (!v.is_number()) fail(path, "expected a number, found " + found(v) + "; give a finite number");
  const double d = v.get<double>();
  if (!std::isfinite(d))
    fail(path, "the number " + v.dump() + " is not finite (outside the range of a double); give a finite number");
  return d;
}

int integer(const Json& v, const std::string& path) {
  if (!v.is_number_integer())
    fail(path, "expected an integer, found " + found(v) + "; give a whole number such as 3");
  const auto i = v.get<long long>();
  if (i < -1'000'000'000 || i > 1'000'000'000)
    fail(path, "the integer " + v.dump() + " is out of range; give a value between -1e9 and 1e9");
  return static_cast<int>(i);
}

std::vector<double> numbers(const Json& v, const std::string& path) {
  if (!v.is_array()) fail(path, "expected an array of numbers, found " + found(v));
  std::vector<double> out;
  out.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(number(v[i], path + "[" + std::to_string(i) + "]"));
  return out;
}

Eigen::Vector3d vec3(const Json& v, const std::string& path) {
  if (!v.is_array() || v.size() != 3)
    fail(path, "expected 3 numbers, found " + found(v) + "; give [x, y, z]");
  return {number(v[0], path + "[0]"), number(v[1], path + "[1]"), number(v[2], path + "[2]")};
}

Points3 points3(const Json& v, const std::string& path) {
  if (!v.is_array()) fail(path, "expected an array of control points [x, y, z], found " + found(v));
  Points3 p(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t r = 0; r < v.size(); ++r)
    p.row(static_cast<Eigen::Index>(r)) = vec3(v[r], path + "[" + std::to_string(r) + "]").transpose();
  return p;
}

Frame lattice_frame(const Json& v, const std::string& path) {
  expect_object(v, path, "a lattice frame {origin, s, t, u}");
  check_keys(v, path, {"origin", "s", "t", "u"}, "a lattice frame");
  Frame f;
  f.origin = vec3(member(v, path, "origin", "X0 as [x, y, z]"), path + ".origin");
  f.s = vec3(member(v, path, "s", "the edge S as [x, y, z]"), path + ".s");
  f.t = vec3(member(v, path, "t", "the edge T as [x, y, z]"), path + ".t");
  f.u = vec3(member(v, path, "u", "the edge U as [x, y, z]"), path + ".u");
  return f;
}

AxisFrame axis_frame(const Json& v, const std::string& path) {
  expect_object(v, path, "an axis frame {origin, axis, reference}");
  check_keys(v, path, {"origin", "axis", "reference"}, "an axis frame");
  AxisFrame f;
  f.origin = vec3(member(v, path, "origin", "a point of the axis as [x, y, z]"), path + ".origin");
  f.axis = vec3(member(v, path, "axis", "the axis direction as [x, y, z]"), path + ".axis");
  f.reference = vec3(member(v, path, "reference", "the reference direction as [x, y, z]"),
                     path + ".reference");
  return f;
}

// per kind: the fields after "kind", "name", "enabled"
void read_fields(BezierLattice& d, const Json& j, const std::string& path) {
  check_keys(j, path, {"kind", "name", "enabled", "frame", "degrees", "points"}, "a bezier_lattice step");
  d.frame = lattice_frame(member(j, path, "frame", "the lattice frame {origin, s, t, u}"), path + ".frame");
  const Json& deg = member(j, path, "degrees", "the degrees as [l, m, n]");
  if (!deg.is_array() || deg.size() != 3)
    fail(path + ".degrees", "expected 3 integers, found " + found(deg) + "; give [l, m, n]");
  for (std::size_t i = 0; i < 3; ++i) d.degrees[i] = integer(deg[i], path + ".degrees[" + std::to_string(i) + "]");
  d.points = points3(member(j, path, "points", "the control points [[x, y, z], ...]"), path + ".points");
}
void read_fields(BSplineLattice& d, const Json& j, const std::string& path) {
  check_keys(j, path, {"kind", "name", "enabled", "frame", "bases", "points"}, "a bspline_lattice step");
  d.frame = lattice_frame(member(j, path, "frame", "the lattice frame {origin, s, t, u}"), path + ".frame");
  const Json& bases = member(j, path, "bases", "three bases [{degree, knots}, ...] along S, T, U");
  if (!bases.is_array() || bases.size() != 3)
    fail(path + ".bases", "expected 3 bases (along S, T, U), found " + found(bases) +
                              "; give [{\"degree\": p, \"knots\": [...]}, ...]");
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string bp = path + ".bases[" + std::to_string(i) + "]";
    expect_object(bases[i], bp, "a basis {degree, knots}");
    check_keys(bases[i], bp, {"degree", "knots"}, "a basis");
    d.bases[i].degree = integer(member(bases[i], bp, "degree", "the degree p >= 1"), bp + ".degree");
    d.bases[i].knots = numbers(member(bases[i], bp, "knots", "the knot vector"), bp + ".knots");
  }
  d.points = points3(member(j, path, "points", "the control points [[x, y, z], ...]"), path + ".points");
}
void read_fields(ExtendedLattice& d, const Json& j, const std::string& path) {
  check_keys(j, path, {"kind", "name", "enabled", "rest", "points", "chunks"},
             "an extended_lattice step");
  d.rest = points3(member(j, path, "rest", "the rest control points [[x, y, z], ...]"),
                   path + ".rest");
  d.points = points3(member(j, path, "points", "the current control points [[x, y, z], ...]"),
                     path + ".points");
  const Eigen::Index rows = d.rest.rows();
  if (d.points.rows() != rows)
    fail(path + ".points", "found " + std::to_string(d.points.rows()) +
                               " control points but rest has " + std::to_string(rows) +
                               "; give one current position per rest control point");
  const Json& chunks = member(j, path, "chunks", "the chunks, each 64 row indices");
  if (!chunks.is_array())
    fail(path + ".chunks", "expected an array of chunks (64 row indices each), found " + found(chunks));
  d.chunks.resize(chunks.size());
  for (std::size_t c = 0; c < chunks.size(); ++c) {
    const std::string cp = path + ".chunks[" + std::to_string(c) + "]";
    const Json& chunk = chunks[c];
    if (!chunk.is_array() || chunk.size() != static_cast<std::size_t>(chunk_control_points))
      fail(cp, "expected 64 indices (control point (i, j, k) at (i * 4 + j) * 4 + k), found " +
                   found(chunk));
    for (std::size_t e = 0; e < chunk.size(); ++e) {
      const std::string ep = cp + "[" + std::to_string(e) + "]";
      const int index = integer(chunk[e], ep);
      if (index < 0 || index >= rows)
        fail(ep, "index " + std::to_string(index) + " is out of range " +
                     (rows > 0 ? "(0.." + std::to_string(rows - 1) + ")" : "(rest has no rows)") +
                     "; give a row of rest / points");
      d.chunks[c][e] = index;
    }
  }
}
void read_fields(Taper& d, const Json& j, const std::string& path) {
  check_keys(j, path, {"kind", "name", "enabled", "frame", "profile"}, "a taper step");
  d.frame = axis_frame(member(j, path, "frame", "the axis frame {origin, axis, reference}"), path + ".frame");
  d.profile = numbers(member(j, path, "profile", "the coefficients of r(z), e.g. [1, -0.01]"), path + ".profile");
}
void read_fields(Twist& d, const Json& j, const std::string& path) {
  check_keys(j, path, {"kind", "name", "enabled", "frame", "angle"}, "a twist step");
  d.frame = axis_frame(member(j, path, "frame", "the axis frame {origin, axis, reference}"), path + ".frame");
  d.angle = numbers(member(j, path, "angle", "the coefficients of θ(z) in radians, e.g. [0, 0.01]"),
                    path + ".angle");
}
void read_fields(Bend& d, const Json& j, const std::string& path) {
  check_keys(j, path, {"kind", "name", "enabled", "frame", "y_min", "y_max", "center", "rate"}, "a bend step");
  d.frame = axis_frame(member(j, path, "frame", "the axis frame {origin, axis, reference}"), path + ".frame");
  d.y_min = number(member(j, path, "y_min", "the start of the bent region (mm)"), path + ".y_min");
  d.y_max = number(member(j, path, "y_max", "the end of the bent region (mm)"), path + ".y_max");
  d.center = number(member(j, path, "center", "the centre of the bend y0 (mm)"), path + ".center");
  d.rate = number(member(j, path, "rate", "the bending rate k (rad/mm)"), path + ".rate");
}

/// The alternative of Deformation whose kind_of is `kind`, read from j; false when none is.
template <std::size_t I = 0>
bool read_kind(std::string_view kind, const Json& j, const std::string& path, Deformation& out) {
  if constexpr (I < std::variant_size_v<Deformation>) {
    using T = std::variant_alternative_t<I, Deformation>;
    if (kind == kind_of(T{})) {
      T d;
      read_fields(d, j, path);
      out = std::move(d);
      return true;
    }
    return read_kind<I + 1>(kind, j, path, out);
  } else {
    return false;
  }
}

template <std::size_t I = 0>
std::string all_kinds() {
  if constexpr (I < std::variant_size_v<Deformation>) {
    using T = std::variant_alternative_t<I, Deformation>;
    return (I ? ", " : "") + std::string(kind_of(T{})) + all_kinds<I + 1>();
  } else {
    return "";
  }
}

DeformationStep read_step(const Json& j, const std::string& path) {
  expect_object(j, path, "a step {\"kind\": ..., ...}");
  const Json& kind = member(j, path, "kind", "the kind of deformation, one of " + all_kinds());
  if (!kind.is_string())
    fail(path + ".kind", "expected a string, found " + found(kind) + "; give one of " + all_kinds());
  DeformationStep step;
  if (const auto it = j.find("name"); it != j.end()) {
    if (!it->is_string()) fail(path + ".name", "expected a string, found " + found(*it) + "; give a label or \"\"");
    step.name = it->get<std::string>();
  }
  if (const auto it = j.find("enabled"); it != j.end()) {
    if (!it->is_boolean()) fail(path + ".enabled", "expected true or false, found " + found(*it));
    step.enabled = it->get<bool>();
  }
  const auto k = kind.get<std::string>();
  if (!read_kind(k, j, path, step.deformation))
    fail(path + ".kind", "unknown kind \"" + k + "\"; give one of " + all_kinds());
  return step;
}

/// Floating-point traps held (off) for a scope, the caller's environment restored on the way out:
/// strtod reports a literal beyond the range of a double by raising overflow, as C requires, and
/// a host that traps overflow (the Debug tests do) would die of the very number the reader
/// exists to refuse. (A local helper until the internal helper library has one.)
class FpTrapsHeld {
 public:
  FpTrapsHeld() { std::feholdexcept(&saved_); }
  ~FpTrapsHeld() { std::fesetenv(&saved_); }
  FpTrapsHeld(const FpTrapsHeld&) = delete;
  FpTrapsHeld& operator=(const FpTrapsHeld&) = delete;

 private:
  std::fenv_t saved_;
};

}  // namespace

// ---- the stack --------------------------------------------------------------------------------

std::string_view kind_name(const Deformation& deformation) noexcept {
  return std::visit([](const auto& d) { return kind_of(d); }, deformation);
}

std::vector<std::string> problems(const DeformationStack& stack) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < stack.steps.size(); ++i) {
    const std::string label = step_label(stack.steps[i], i);
    const auto list = std::visit([&](const auto& d) { return problems(d, label); },
                                 stack.steps[i].deformation);
    out.insert(out.end(), list.begin(), list.end());
  }
  return out;
}

void validate(const DeformationStack& stack) {
  const auto list = problems(stack);
  if (list.empty()) return;
  std::string text;
  for (std::size_t k = 0; k < list.size(); ++k) text += (k ? "; " : "") + list[k];
  throw Error(ErrorCategory::InvalidGeometry, "deformation stack: " + text);
}

Eigen::Vector3d deform_point(const DeformationStack& stack, const Eigen::Vector3d& x) {
  Eigen::Vector3d p = x;
  for (const auto& step : stack.steps)
    if (step.enabled)
      p = std::visit([&](const auto& d) -> Eigen::Vector3d { return deform_point(d, p); },
                     step.deformation);
  return p;
}

bool StackReport::converged() const noexcept {
  for (const Freeze& f : freezes)
    if (!f.summary.summary.converged()) return false;
  return true;
}

std::string StackReport::brief() const {
  if (freezes.empty()) return "no extended lattice step";
  std::string text;
  for (const Freeze& f : freezes)
    text += (text.empty() ? "steps[" : "; steps[") + std::to_string(f.step) + "]: " + f.summary.brief();
  return text;
}

void deform_points(const DeformationStack& stack, const Points3& points, Points3& out,
                   StackReport& report, const DeformOptions& options) {
  validate(stack);
  options.validate();
  report = StackReport{};
  if (&out != &points) out = points;
  for (std::size_t i = 0; i < stack.steps.size(); ++i)
    if (stack.steps[i].enabled)
      std::visit([&](const auto& d) { apply_in_place(d, out, options, i, report); },
                 stack.steps[i].deformation);
}

void deform_points(const DeformationStack& stack, const Points3& points, Points3& out,
                   const DeformOptions& options) {
  StackReport report;
  deform_points(stack, points, out, report, options);
}

Points3 deform_points(const DeformationStack& stack, const Points3& points,
                      const DeformOptions& options) {
  Points3 out;
  deform_points(stack, points, out, options);
  return out;
}

// ---- JSON ---------------------------------------------------------------------------------------

std::string to_json(const DeformationStack& stack) {
  validate(stack);
  // One step per line (diff-friendly); inside a step the compact form.
  std::string text = "{\n  \"format\": \"" + std::string(format_name) +
                     "\",\n  \"version\": " + std::to_string(format_version) + ",\n  \"steps\": [";
  for (std::size_t i = 0; i < stack.steps.size(); ++i) {
    const auto& step = stack.steps[i];
    Json j = Json::object();
    j["kind"] = std::string(kind_name(step.deformation));
    j["name"] = step.name;
    j["enabled"] = step.enabled;
    std::visit([&](const auto& d) { write_fields(d, j); }, step.deformation);
    std::string line;
    try {
      line = j.dump();
    } catch (const Json::type_error&) {  // the only string that can be bad is the name
      throw Error(ErrorCategory::InvalidArgument,
                  "to_json: steps[" + std::to_string(i) +
                      "].name is not valid UTF-8; give the name as UTF-8 text");
    }
    text += (i ? ",\n    " : "\n    ") + line;
  }
  text += stack.steps.empty() ? "]\n}\n" : "\n  ]\n}\n";
  return text;
}

DeformationStack stack_from_json(std::string_view json) {
  Json root;
  try {
    const FpTrapsHeld traps_held;  // the JSON parser's strtod
    root = Json::parse(json.begin(), json.end());
  } catch (const Json::parse_error& e) {
    throw Error(ErrorCategory::Recipe,
                "deformation stack JSON is not valid JSON (byte " + std::to_string(e.byte) +
                    "): " + e.what() + "; fix the syntax (NaN and Infinity are not JSON numbers)");
  } catch (const Json::exception& e) {  // e.g. a number beyond the range of a double
    throw Error(ErrorCategory::Recipe, std::string("deformation stack JSON could not be read: ") +
                                           e.what() + "; give finite numbers within the range of a double");
  }
  const std::string top = "(top level)";
  expect_object(root, top, "the stack {\"format\", \"version\", \"steps\"}");
  check_keys(root, top, {"format", "version", "steps"}, "a deformation stack");
  const Json& format = member(root, top, "format", "\"format\": \"clayform.deformation-stack\"");
  if (!format.is_string() || format.get<std::string>() != format_name)
    fail("format", "expected \"" + std::string(format_name) + "\", found " + found(format) +
                       "; this is not a deformation stack file");
  const Json& version = member(root, top, "version", "\"version\": 1");
  if (!version.is_number_integer() || version.get<long long>() != format_version)
    fail("version", found(version) + " is not supported: this build reads version " +
                        std::to_string(format_version) + "; write the file with a matching clayform");
  const Json& steps = member(root, top, "steps", "the list of steps, [] for none");
  if (!steps.is_array()) fail("steps", "expected an array of steps, found " + found(steps));
  DeformationStack stack;
  stack.steps.reserve(steps.size());
  for (std::size_t i = 0; i < steps.size(); ++i)
    stack.steps.push_back(read_step(steps[i], "steps[" + std::to_string(i) + "]"));
  const auto list = problems(stack);
  if (!list.empty()) {
    std::string text;
    for (std::size_t k = 0; k < list.size(); ++k) text += (k ? "; " : "") + list[k];
    throw Error(ErrorCategory::Recipe, "deformation stack JSON: " + text);
  }
  return stack;
}

}  // namespace clay::deform
