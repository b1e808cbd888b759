// Deformation stacks: ordered application (Güdükbay–Özgüç 1990 §3, Fig. 7) and the JSON schema
// "clayform.deformation-stack" version 1 (docs/deform.md). nlohmann-json stays in this file.
//
// Adding a deformation kind: one overload in each set below marked "per kind" (write_fields,
// apply_in_place) and in clay/deform/detail/stack_json.hpp (kind_of, read_fields, the reader the
// recipe shares); the variant drives the rest.
#include <clay/deform/stack.hpp>

#include <clay/deform/detail/stack_json.hpp>
#include <clay/deform/frozen_lattice.hpp>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/fenv.hpp>

#include <nlohmann/json.hpp>

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

using internal::kind_of;

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
void apply_in_place(const ExtendedLattice& d, Points3& p, const DeformOptions& o, std::size_t step,
                    StackReport& report) {
  // deform_points(ExtendedLattice): freeze on the rest shape (Coquillart §3.3), evaluate eq. (1)
  // on the moved control points (§3.4); unresolved points stay, the summary says so.
  FreezeOptions f;
  f.threads = o.threads;
  const FrozenPoints frozen = freeze(d, p, f);
  p = evaluate(d, frozen, o);
  report.freezes.push_back({step, frozen.report});
}
void apply_in_place(const Taper& d, Points3& p, const DeformOptions& o, std::size_t, StackReport&) {
  deform_points(d, p, p, o);
}
void apply_in_place(const Twist& d, Points3& p, const DeformOptions& o, std::size_t, StackReport&) {
  deform_points(d, p, p, o);
}
void apply_in_place(const Bend& d, Points3& p, const DeformOptions& o, std::size_t, StackReport&) {
  deform_points(d, p, p, o);
}

std::string step_label(const DeformationStep& step, std::size_t i) {
  std::string label =
      "steps[" + std::to_string(i) + "] (" + std::string(kind_name(step.deformation));
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

}  // namespace

// ---- the stack --------------------------------------------------------------------------------

std::string_view kind_name(const Deformation& deformation) noexcept {
  return std::visit([](const auto& d) { return kind_of(d); }, deformation);
}

std::vector<std::string> problems(const DeformationStack& stack) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < stack.steps.size(); ++i) {
    const std::string label = step_label(stack.steps[i], i);
    const auto list =
        std::visit([&](const auto& d) { return problems(d, label); }, stack.steps[i].deformation);
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
    if (!f.report.summary.converged()) return false;
  return true;
}

std::string StackReport::brief() const {
  if (freezes.empty()) return "no extended lattice step";
  std::string text;
  for (const Freeze& f : freezes)
    text +=
        (text.empty() ? "steps[" : "; steps[") + std::to_string(f.step) + "]: " + f.report.brief();
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
  report.summary.termination =
      report.converged() ? Termination::Converged : Termination::NotConverged;
  report.summary.message = report.brief();
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
    const internal::FpTrapsHeld traps_held;  // the JSON parser's strtod
    root = Json::parse(json.begin(), json.end());
  } catch (const Json::parse_error& e) {
    throw Error(ErrorCategory::Document,
                "deformation stack JSON is not valid JSON (byte " + std::to_string(e.byte) +
                    "): " + e.what() + "; fix the syntax (NaN and Infinity are not JSON numbers)");
  } catch (const Json::exception& e) {  // e.g. a number beyond the range of a double
    throw Error(ErrorCategory::Document, std::string("deformation stack JSON could not be read: ") +
                                             e.what() +
                                             "; give finite numbers within the range of a double");
  }
  // Every problem with its path (the shared reader), then the values of the steps read.
  internal::JsonReader r;
  DeformationStack stack;
  if (r.object(root, "", {"format", "version", "steps"},
               "the stack {\"format\", \"version\", \"steps\"}")) {
    const Json* format =
        r.member(root, "", "format", true, "\"format\": \"clayform.deformation-stack\"");
    if (format && (!format->is_string() || format->get<std::string>() != format_name))
      r.add("format", "expected \"" + std::string(format_name) + "\", found " +
                          internal::found(*format) + "; this is not a deformation stack file");
    const Json* version = r.member(root, "", "version", true, "\"version\": 1");
    if (version && (!version->is_number_integer() || version->get<long long>() != format_version))
      r.add("version", internal::found(*version) + " is not supported: this build reads version " +
                           std::to_string(format_version) +
                           "; write the file with a matching clayform");
    const Json* steps = r.member(root, "", "steps", true, "the list of steps, [] for none");
    if (steps && !steps->is_array())
      r.add("steps", "expected an array of steps, found " + internal::found(*steps));
    if (steps && steps->is_array()) {
      stack.steps.reserve(steps->size());
      for (std::size_t i = 0; i < steps->size(); ++i) {
        const std::string path = internal::index_path("steps", i);
        if (auto step = internal::read_step(r, (*steps)[i], path)) {
          r.add_all(
              internal::step_label(path, *step),
              std::visit(
                  [&](const auto& d) { return problems(d, internal::step_label(path, *step)); },
                  step->deformation));
          stack.steps.push_back(std::move(*step));
        }
      }
    }
  }
  if (!r.problems.empty()) {
    std::vector<std::string> list;
    for (const auto& p : r.problems) list.push_back(p.path + ": " + p.message);
    throw Error(ErrorCategory::Document,
                "deformation stack JSON: " + internal::join_problems(list));
  }
  return stack;
}

}  // namespace clay::deform
