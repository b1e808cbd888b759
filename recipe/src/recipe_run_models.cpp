// Running a recipe's models (imported, flattened, deformed by a stack; deform_model): see
// recipe_run.hpp.
#include "recipe_run.hpp"

#include "recipe_model.hpp"

#include <clay/brep/mass_properties.hpp>
#include <clay/brep/volume.hpp>
#include <clay/constraints/solve.hpp>
#include <clay/deform/jacobian.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/deform/model_derivatives.hpp>
#include <clay/deform/refit.hpp>
#include <clay/deform/surface_deformation.hpp>
#include <clay/error.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/sketch/entities.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

namespace clay::recipe {
namespace detail {

deform::SurfaceDeformationOptions deformation_options(const Composition& c) {
  deform::SurfaceDeformationOptions o;
  o.compose.check_samples = c.check_samples;
  // Under a budget every fit is a light form: within the budget, knots where the error needs
  // them; without one, a refit keeps the input's breakpoints, up to max_control_points.
  if (c.refit) o.refit = c.budget ? light_fit(c) : fit_keeping_breakpoints(c);
  o.accept_out_of_tolerance = c.accept_out_of_tolerance;
  if (c.budget) {
    deform::Budget b;
    b.max_degree = c.budget->max_degree;
    b.max_control_points = c.budget->max_control_points;
    b.light = light_fit(c);
    o.budget = b;
  }
  return o;
}

deform::RefitOptions fit_keeping_breakpoints(const Composition& c) {
  deform::RefitOptions r;
  r.degree = c.degree;
  r.relative_tolerance = c.relative_tolerance;
  r.tolerance_mm = c.tolerance_mm;
  r.max_control_points = c.max_control_points;
  return r;
}

std::vector<deform::MatchedCurve> shared_sides(
    const surface::BSplineSurface& parent,
    const std::vector<std::pair<std::string, surface::BSplineSurface>>& surfaces,
    const Composition& c) {
  if (!(c.refit || c.budget) || !(c.edge_gap_mm > 0)) return {};
  std::vector<const surface::BSplineSurface*> others;
  for (const auto& [n, s] : surfaces) others.push_back(&s);
  // built to meet: one boundary curve, or a mirror's rounding (1e-9 of the size)
  const Eigen::Vector3d lo = parent.points.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = parent.points.colwise().maxCoeff().transpose();
  return deform::shared_boundaries(parent, others, std::max(1e-9 * (hi - lo).norm(), 1e-12));
}

void follow_shared(deform::RefitOptions& o, const std::vector<deform::MatchedCurve>& shared,
                   const Composition& c) {
  if (shared.empty()) return;
  o.matched_curves = shared;
  o.matched_gap_mm = c.edge_gap_mm;
  o.matched_angle_deg = c.edge_angle_deg;
}

void lattice_figures(const deform::Deformation& d, StepReport& rep) {
  std::optional<deform::JacobianBounds> j;
  if (const auto* b = std::get_if<deform::BezierLattice>(&d)) j = deform::jacobian_bounds(*b);
  if (const auto* b = std::get_if<deform::BSplineLattice>(&d)) j = deform::jacobian_bounds(*b);
  if (!j) return;
  rep.figures.emplace_back("fold_free", j->fold_free);
  rep.figures.emplace_back("volume_ratio_min", j->min);
  rep.figures.emplace_back("volume_ratio_max", j->max);
  if (!j->fold_free) {
    rep.warning = true;
    rep.message +=
        "; the lattice may fold (Jacobian coefficient " + format("%.3g", j->min) + " <= 0)";
  }
}

deform::RefitOptions light_fit(const Composition& c) {
  deform::RefitOptions r = fit_keeping_breakpoints(c);
  r.keep_breakpoints = deform::Budget::light_fit().keep_breakpoints;
  if (c.budget) r.max_control_points = std::min(c.max_control_points, c.budget->max_control_points);
  return r;
}

namespace {
using surface::BSplineSurface;
}  // namespace

/// The recipe's deformation stack named `deformation`, or its only one when the name is empty.
const StackDef& pick_stack(const RecipeData& d, std::string_view deformation) {
  std::string names;
  for (const auto& s : d.stacks) names += (names.empty() ? "" : ", ") + s.name;
  if (deformation.empty()) {
    if (d.stacks.size() != 1)
      throw Error(ErrorCategory::InvalidArgument,
                  "the recipe has " + std::to_string(d.stacks.size()) + " deformation stacks (" +
                      names + "); name one with --deformation");
    return d.stacks.front();
  }
  for (const auto& s : d.stacks)
    if (s.name == deformation) return s;
  throw Error(ErrorCategory::InvalidArgument, "the recipe has no deformation stack '" +
                                                  std::string(deformation) +
                                                  "'; its stacks: " + names);
}

/// Clears `fold_free` when `d` is a lattice whose Jacobian bounds are not positive; then, unless
/// `allow_fold`, refuses it naming `where` and how to allow it (`allow`): a folded lattice wrote a
/// self-intersecting solid reported valid, 155 mm^3 for a 15,708 mm^3 rod (issue #36).
void check_fold(const deform::Deformation& d, const std::string& where, const std::string& allow,
                bool& fold_free, bool allow_fold) {
  std::optional<deform::JacobianBounds> bounds;
  if (const auto* b = std::get_if<deform::BezierLattice>(&d)) bounds = deform::jacobian_bounds(*b);
  if (const auto* b = std::get_if<deform::BSplineLattice>(&d)) bounds = deform::jacobian_bounds(*b);
  if (!bounds || bounds->fold_free) return;
  fold_free = false;
  if (!allow_fold)
    throw Error(ErrorCategory::InvalidGeometry,
                where +
                    ": the lattice may fold space (the smallest Bernstein coefficient of its "
                    "Jacobian is " +
                    format("%.3g", bounds->min) +
                    " <= 0, Sederberg-Parry section 4), so the deformed solid may intersect "
                    "itself; move its points less or use a finer lattice, or allow it with " +
                    allow);
}

/// A stack for a whole model: lattices and regular deformations as they are, direct
/// manipulation solved from moves in space; a style step or a move from a surface point is
/// refused, naming the step. `fold_free` is cleared when a lattice's Jacobian bounds are not
/// positive; then, unless `allow_fold`, the step is refused: a folded lattice wrote a
/// self-intersecting solid reported valid, 155 mm^3 for a 15,708 mm^3 rod (issue #36).
deform::DeformationStack model_stack(const StackDef& def, bool& fold_free, bool allow_fold) {
  deform::DeformationStack stack;
  for (std::size_t i = 0; i < def.steps.size(); ++i) {
    const StepDef& step = def.steps[i];
    const std::string where = def.path + ".steps[" + std::to_string(i) + "] (" + step.kind + ")";
    deform::Deformation lattice = std::visit(
        [&](const auto& k) -> deform::Deformation {
          using T = std::decay_t<decltype(k)>;
          if constexpr (std::is_same_v<T, deform::Deformation>) {
            return k;
          } else if constexpr (std::is_same_v<T, DirectDef>) {
            std::vector<deform::PointMove> moves;
            for (const auto& m : k.moves) {
              if (m.on_surface)
                throw Error(ErrorCategory::InvalidArgument,
                            where +
                                ": a move from a \"surface_point\" needs one surface; to "
                                "deform a model, give the move's \"point\" in space");
              moves.push_back({m.point, m.to});
            }
            deform::Deformation solved;
            bool feasible = true;
            std::string message;
            std::visit(
                [&](const auto& lat) {
                  auto r = deform::manipulate(lat, moves, k.options);
                  feasible = r.report.feasible;
                  message = r.report.summary.message;
                  solved = std::move(r.lattice);
                },
                k.lattice);
            if (!feasible && !k.accept_out_of_tolerance)
              throw Error(ErrorCategory::ToleranceNotMet,
                          where + ": the lattice cannot meet every move (" + message +
                              "); free more control points, use a finer lattice or ask for "
                              "fewer moves");
            return solved;
          } else {
            throw Error(ErrorCategory::InvalidArgument,
                        where +
                            ": a style step shapes one surface by its control points; a "
                            "model deforms through lattices, direct manipulation and "
                            "regular deformations (taper, twist, bend)");
          }
        },
        step.step);
    if (step.enabled)
      check_fold(lattice, where, "\"allow_fold\": true on the model (clayform deform --allow-fold)",
                 fold_free, allow_fold);
    stack.steps.push_back({std::move(lattice), step.name, step.enabled});
  }
  return stack;
}

/// The faces of `flat` the model's "bodies" and "faces" name (every face when both are empty);
/// a name that matches nothing is refused, listing the names the model has.
std::vector<int> chosen_faces(const brep::Model& flat, const ModelDef& def) {
  std::vector<int> out;
  if (def.bodies.empty() && def.faces.empty()) return out;
  std::vector<bool> chosen(flat.faces.size(), false);
  auto known = [](const auto& items) {
    std::vector<std::string> names;
    for (const auto& x : items)
      if (!x.name.empty() && std::find(names.begin(), names.end(), x.name) == names.end())
        names.push_back(x.name);
    std::string text;
    for (const auto& n : names) text += (text.empty() ? "\"" : ", \"") + n + "\"";
    return text.empty() ? std::string("none is named") : text;
  };
  for (std::size_t i = 0; i < def.bodies.size(); ++i) {
    bool found = false;
    for (const brep::Body& body : flat.bodies)
      if (body.name == def.bodies[i]) {
        found = true;
        if (body.kind == brep::BodyKind::Wire)
          throw Error(ErrorCategory::InvalidArgument,
                      "bodies[" + std::to_string(i) + "]: \"" + def.bodies[i] +
                          "\" is a wire body (free curves); a selection chooses faces, and free "
                          "curves move only when the whole model is deformed: leave \"bodies\" "
                          "and \"faces\" out");
        for (const brep::Shell& shell : body.shells)
          for (int f : shell.faces) chosen[static_cast<std::size_t>(f)] = true;
      }
    if (!found)
      throw Error(ErrorCategory::InvalidArgument,
                  "bodies[" + std::to_string(i) + "]: the model has no body named \"" +
                      def.bodies[i] + "\"; its bodies: " + known(flat.bodies));
  }
  for (std::size_t i = 0; i < def.faces.size(); ++i) {
    bool found = false;
    for (std::size_t f = 0; f < flat.faces.size(); ++f)
      if (flat.faces[f].name == def.faces[i]) found = chosen[f] = true;
    if (!found)
      throw Error(ErrorCategory::InvalidArgument,
                  "faces[" + std::to_string(i) + "]: the model has no face named \"" +
                      def.faces[i] + "\"; its named faces: " + known(flat.faces));
  }
  for (std::size_t f = 0; f < chosen.size(); ++f)
    if (chosen[f]) out.push_back(static_cast<int>(f));
  return out;
}

/// One lattice corrected to keep `properties` of `model` (see keep_properties below).
template <class Lattice>
ModelRunResult::Kept keep_step(Lattice& lattice, const brep::Model& model,
                               const std::vector<std::string>& properties,
                               const std::string& where) {
  ModelRunResult::Kept out;
  out.properties = properties;
  bool solid = false;
  for (const brep::Body& b : model.bodies) solid = solid || b.kind == brep::BodyKind::Solid;
  const bool mass = std::find(properties.begin(), properties.end(), "area") == properties.end() ||
                    properties.size() > 1;
  if (!solid && mass)
    throw Error(
        ErrorCategory::InvalidArgument,
        where +
            ": \"keep\" holds a solid's volume or centroid, but the model has no "
            "solid (its bodies are sheets or wires); keep only \"area\", or remove \"keep\"");
  deform::ModelJacobian jacobian;
  try {
    jacobian = deform::model_jacobian(lattice, model);
  } catch (const Error& e) {
    throw Error(e.category(), where +
                                  ": \"keep\" needs the model composed exactly with the "
                                  "lattice: " +
                                  e.message());
  }
  brep::MassProperties before;
  deform::KeptProperties keep;
  try {
    if (mass) before = brep::mass_properties(model);
    for (const std::string& p : properties) {
      if (p == "volume") keep.volume_mm3 = before.volume_mm3;
      if (p == "centroid") keep.centroid_mm = before.centroid_mm;
      if (p == "area") keep.area_mm2 = out.area_before_mm2 = brep::surface_area(model).area_mm2;
    }
  } catch (const Error& e) {
    throw Error(e.category(), where + ": \"keep\" measures the model first: " + e.message());
  }
  // The points the step moved stay where it put them (a drag stays under the cursor); a point
  // within 1e-9 of the frame's size of its rest position (a recipe's "points" rounded on a round
  // trip) is at rest.
  const surface::Points3 rest = deform::undisplaced_points(lattice);
  const double size = lattice.frame.s.norm() + lattice.frame.t.norm() + lattice.frame.u.norm();
  for (Eigen::Index r = 0; r < rest.rows(); ++r)
    if ((lattice.points.row(r) - rest.row(r)).norm() > 1e-9 * size)
      keep.held.push_back(static_cast<int>(r));
  if (keep.held.size() == static_cast<std::size_t>(rest.rows()))
    throw Error(ErrorCategory::InvalidArgument,
                where +
                    ": \"keep\" corrects the points the step leaves at rest, but it moves all " +
                    std::to_string(rest.rows()) +
                    " of them; move fewer points, or use a lattice with more points");
  deform::KeptMove kept;
  try {
    kept = deform::keep_properties(jacobian, lattice.points, keep);
  } catch (const Error& e) {
    throw Error(e.category(), where + ": " + e.message());
  }
  out.volume_before_mm3 = before.volume_mm3;
  out.volume_after_mm3 = kept.properties.volume_mm3;
  if (keep.area_mm2) out.area_after_mm2 = kept.area_mm2;
  out.centroid_shift_mm = (kept.properties.centroid_mm - before.centroid_mm).norm();
  out.iterations = kept.iterations;
  out.largest_correction_mm = (kept.points - lattice.points).rowwise().norm().maxCoeff();
  lattice.points = kept.points;
  return out;
}

/// The lattice steps with "keep" corrected so that the model's kept properties stay as they were
/// before each such step (deform::keep_properties on the model's fixed form; the points the step
/// moved from their rest positions stay, the others take the correction). The model before a
/// step is the stack's earlier steps applied to `flat`. Refused with a face selection (the kept
/// figures are the whole model's) and, naming the step, where the model has no solid or a face
/// crosses the lattice's boundary.
void keep_properties(const StackDef& def, deform::DeformationStack& stack, const brep::Model& flat,
                     const deform::ModelDeformationOptions& options, bool allow_fold,
                     const std::string& allow, ModelRunResult& out) {
  for (std::size_t i = 0; i < def.steps.size(); ++i) {
    const StepDef& step = def.steps[i];
    if (step.keep.empty() || !step.enabled) continue;
    const std::string where = def.path + ".steps[" + std::to_string(i) + "]" +
                              (step.name.empty() ? "" : " '" + step.name + "'");
    if (!options.faces.empty())
      throw Error(ErrorCategory::InvalidArgument,
                  where +
                      ": \"keep\" holds the whole model's figures, but the model deforms "
                      "chosen faces only (\"bodies\"/\"faces\"); deform the whole model, or "
                      "remove \"keep\"");
    deform::DeformationStack before_step;
    before_step.steps.assign(stack.steps.begin(),
                             stack.steps.begin() + static_cast<std::ptrdiff_t>(i));
    bool any_before = false;
    for (const auto& s : before_step.steps) any_before = any_before || s.enabled;
    brep::Model before;
    try {
      before = any_before ? deform::deform_model(before_step, flat, options).model : flat;
    } catch (const Error& e) {
      throw Error(
          e.category(),
          where + ": \"keep\" measures the model after the steps before it: " + e.message());
    }
    ModelRunResult::Kept kept;
    std::visit(
        [&](auto& lattice) {
          using T = std::decay_t<decltype(lattice)>;
          if constexpr (std::is_same_v<T, deform::BezierLattice> ||
                        std::is_same_v<T, deform::BSplineLattice>) {
            kept = keep_step(lattice, before, step.keep, where);
          }
        },
        stack.steps[i].deformation);
    kept.step = where;
    out.kept.push_back(std::move(kept));
    // The correction moved points too: the corrected lattice is checked for folds again.
    check_fold(stack.steps[i].deformation, where + " (corrected to keep its figures)", allow,
               out.fold_free, allow_fold);
  }
}

ModelRunResult run_model(const RecipeData& d, const ModelDef& def, const std::string& profile) {
  const auto t0 = Clock::now();
  ModelRunResult out;
  out.recipe = d.name;
  out.name = def.name;
  out.source = def.file.string();
  out.deformation = def.deformation;
  out.bodies = def.bodies;
  out.faces = def.faces;
  out.formats = def.formats;
  out.schema = def.schema;
  brep::ModelReadOptions read_options;
  read_options.sew = def.sew;
  read_options.read.isolate = true;  // a file that crashes OpenCASCADE fails the run, not clayform
  const brep::Model flat = brep::flattened(brep::read_model(def.file, read_options).model);
  if (def.deformation.empty()) {
    out.model = flat;
    out.report.counts = brep::counts(flat);
    out.report.faces_untouched = out.report.counts.faces;
    out.report.edges_untouched = out.report.counts.edges;
    for (const brep::EdgeGap& g : brep::edge_gaps(flat))
      out.report.max_edge_gap_mm = std::max(out.report.max_edge_gap_mm, g.gap_mm);
    out.report.volume_before_mm3 = out.report.volume_after_mm3 = brep::volume_mm3(flat);
  } else {
    const StackDef& stack_def = pick_stack(d, def.deformation);
    deform::DeformationStack stack = model_stack(stack_def, out.fold_free, def.allow_fold);
    deform::ModelDeformationOptions options;
    options.surface = deformation_options(d.composition);
    // Faces above the composition's budget are light, and every refitted or light face
    // follows its edges (composition "edges"), so its neighbours keep their continuity.
    options.edge_gap_mm = d.composition.edge_gap_mm;
    options.edge_angle_deg = d.composition.edge_angle_deg;
    options.faces = chosen_faces(flat, def);
    const std::string& receiver = profile.empty() ? def.profile : profile;
    if (!receiver.empty()) options.profile = deform::receiver_profile(receiver);
    keep_properties(stack_def, stack, flat, options, def.allow_fold,
                    "\"allow_fold\": true on the model (clayform deform --allow-fold)", out);
    auto r = deform::deform_model(stack, flat, options);
    out.model = std::move(r.model);
    out.report = std::move(r.report);
  }
  out.seconds = seconds_since(t0);
  return out;
}

}  // namespace detail

using namespace detail;

ModelRunResult deform_model(const Recipe& recipe, const brep::Model& model,
                            std::string_view deformation, bool allow_fold,
                            std::string_view profile) {
  if (!recipe.data)
    throw Error(ErrorCategory::InvalidArgument,
                "deform_model: empty recipe; load or parse one first");
  const RecipeData& d = *recipe.data;
  const StackDef& def = pick_stack(d, deformation);
  const auto t0 = Clock::now();
  ModelRunResult result;
  result.recipe = d.name;
  result.deformation = def.name;
  deform::DeformationStack stack = model_stack(def, result.fold_free, allow_fold);
  deform::ModelDeformationOptions options;
  options.surface = deformation_options(d.composition);
  options.edge_gap_mm = d.composition.edge_gap_mm;
  options.edge_angle_deg = d.composition.edge_angle_deg;
  if (!profile.empty()) options.profile = deform::receiver_profile(profile);
  keep_properties(def, stack, brep::flattened(model), options, allow_fold,
                  "--allow-fold (clayform deform) or allow_fold=True (Python)", result);
  try {
    auto r = deform::deform_model(stack, model, options);
    result.model = std::move(r.model);
    result.report = std::move(r.report);
  } catch (const Error& e) {
    throw Error(e.category(), def.path + ": " + recipe_wording(e.message()));
  }
  result.formats = d.exports.empty() ? std::vector<std::string>{"step", "iges", "glb"}
                                     : d.exports.front().formats;
  result.schema = d.exports.empty() ? "AP214" : d.exports.front().schema;
  result.seconds = seconds_since(t0);
  return result;
}

ModelRunResult deform_model(const deform::DeformationStack& stack, const brep::Model& model,
                            bool allow_fold, std::string_view profile,
                            const std::vector<int>& faces, double refit_tolerance_mm) {
  if (!(refit_tolerance_mm >= 0 && std::isfinite(refit_tolerance_mm)))
    throw Error(ErrorCategory::InvalidArgument,
                "deform_model: refit_tolerance_mm " + format("%g", refit_tolerance_mm) +
                    " must be >= 0 and finite (0: faces that cannot be exact are refused)");
  const auto t0 = Clock::now();
  ModelRunResult result;
  for (std::size_t i = 0; i < stack.steps.size(); ++i)
    if (stack.steps[i].enabled)
      check_fold(stack.steps[i].deformation,
                 "deform_model: step " + std::to_string(i) + " (" +
                     std::string(deform::kind_name(stack.steps[i].deformation)) + ")",
                 "allow_fold", result.fold_free, allow_fold);
  Composition defaults;  // a recipe's, where it says nothing
  if (refit_tolerance_mm > 0) {
    defaults.refit = true;
    defaults.tolerance_mm = refit_tolerance_mm;
    defaults.relative_tolerance = 0;
  }
  deform::ModelDeformationOptions options;
  options.surface = deformation_options(defaults);
  options.edge_gap_mm = defaults.edge_gap_mm;
  options.edge_angle_deg = defaults.edge_angle_deg;
  options.faces = faces;
  if (!profile.empty()) options.profile = deform::receiver_profile(profile);
  auto r = deform::deform_model(stack, model, options);
  result.model = std::move(r.model);
  result.report = std::move(r.report);
  result.formats = {"step", "iges", "glb"};
  result.schema = "AP214";
  result.seconds = seconds_since(t0);
  return result;
}

}  // namespace clay::recipe
