// Deformation of whole B-rep models (see clay/deform/model_deformation.hpp).
#include <clay/cancel.hpp>
#include <clay/deform/model_deformation.hpp>

#include <clay/deform/jacobian.hpp>

#include "model_pieces.hpp"

#include <clay/brep/volume.hpp>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace clay::deform {
namespace {

using internal::shortest;
using namespace detail;

/// Calls on_lattice(lattice) for each enabled Bézier or B-spline lattice step of `stack` and
/// on_other() for each other enabled step, in order.
template <class OnLattice, class OnOther>
void for_each_enabled_step(const DeformationStack& stack, OnLattice&& on_lattice,
                           OnOther&& on_other) {
  for (const DeformationStep& step : stack.steps) {
    if (!step.enabled) continue;
    std::visit(
        [&](const auto& d) {
          using T = std::decay_t<decltype(d)>;
          if constexpr (std::is_same_v<T, BezierLattice> || std::is_same_v<T, BSplineLattice>)
            on_lattice(d);
          else
            on_other();
        },
        step.deformation);
  }
}

/// Per enabled step, what makes it leave a face alone: a lattice whose points are all undisplaced
/// (worked out once per step, not per face), or a face outside the lattice's box.
struct Leaves {
  std::vector<const Frame*> frames;  // one per enabled step; null: the step moves everything
  std::vector<bool> identity;        // the step's lattice is undisplaced

  explicit Leaves(const DeformationStack& stack) {
    for_each_enabled_step(
        stack,
        [&](const auto& lattice) {
          frames.push_back(&lattice.frame);
          identity.push_back(lattice.points == undisplaced_points(lattice));
        },
        [&] {
          frames.push_back(nullptr);
          identity.push_back(false);
        });
  }

  /// True when every enabled step leaves `points` (and their convex hull) where they are.
  bool alone(const surface::Points3& points) const {
    for (std::size_t k = 0; k < frames.size(); ++k)
      if (!identity[k] && (frames[k] == nullptr || !outside(*frames[k], points))) return false;
    return true;
  }
};

struct Outcome {
  enum class Way { Untouched, Exact, Refit } way = Way::Untouched;
  double bound = 0;      // certified bound of a refit (mm)
  double deviation = 0;  // largest deviation of an exact result from the pointwise map (mm)
};

/// True when `s` is within the profile's degree and net caps: it conforms, or breaks only the
/// minimum degree (raised exactly, nothing refitted).
bool within_caps(const surface::BSplineSurface& s, const ReceiverProfile& profile) {
  return std::max(s.u.degree, s.v.degree) <= profile.max_degree &&
         (profile.max_count_per_direction == 0 ||
          std::max(s.u.count(), s.v.count()) <= profile.max_count_per_direction);
}

/// `s` raised exactly to the profile's minimum degree, when only that is what it breaks
/// (fit_to_profile's exact branch; nothing is refitted here).
void elevate_to(surface::BSplineSurface& s, const ReceiverProfile& profile) {
  if (std::min(s.u.degree, s.v.degree) < profile.min_degree)
    s = fit_to_profile(s, profile, RefitOptions{}).surface;
}

/// One surface through the stack, with the degree cap and the receiver profile: its result and
/// what happened. A face that is not exact, or that the profile would not take, is refitted
/// whole from `s` with its edges matched (`edges`, when given). No stack: `s` kept (a face the
/// stack leaves alone), refitted only when the profile would not take it.
Outcome deform_one(const DeformationStack* stack, surface::BSplineSurface& s,
                   const ModelDeformationOptions& options, const std::string& name,
                   const std::vector<MatchedCurve>& edges = {}) {
  Outcome out;
  SurfaceDeformationResult r;
  if (stack == nullptr) {
    r.surface = s;
    r.report.exact = r.report.certified = true;
    r.report.degree_u = s.u.degree, r.report.degree_v = s.v.degree;
  } else {
    try {
      r = deform_surface(*stack, s, options.surface);
    } catch (const Error& e) {
      throw Error(e.category(), name + ": " + e.message());
    }
  }
  const ReceiverProfile* profile = options.profile ? &*options.profile : nullptr;
  const int cap = profile ? std::min(options.max_degree, profile->max_degree) : options.max_degree;
  const bool too_high = std::max(r.report.degree_u, r.report.degree_v) > cap;
  const bool off_profile = profile && !within_caps(r.surface, *profile);
  if ((too_high || off_profile) && profile && profile->fit_degree == 0)
    throw Error(
        ErrorCategory::DegreeLimit,
        name + " cannot be written exactly: " + conformance_problems(r.surface, *profile).front() +
            " (the STEP/IGES writers' limit); choose a profile that refits it (e.g. "
            "\"opencascade\") or lower the degree of the steps that deform it");
  // (An uncertified refit, an extended lattice's, is kept as deform_surface made it.)
  if (too_high || off_profile || (!r.report.exact && r.report.certified && !edges.empty())) {
    // the composition's refit settings, else (an exact composition above its budget) the
    // budget's light fit
    const RefitOptions* base = options.surface.refit    ? &*options.surface.refit
                               : options.surface.budget ? &options.surface.budget->light
                                                        : nullptr;
    if (base == nullptr)
      throw Error(ErrorCategory::DegreeLimit,
                  name + ": the exact result has degree " +
                      std::to_string(std::max(r.report.degree_u, r.report.degree_v)) +
                      (profile ? " (" + std::to_string(r.surface.u.count()) + " x " +
                                     std::to_string(r.surface.v.count()) +
                                     " control points), not what the " +
                                     std::string(profile->name) + " profile takes"
                               : ", above max_degree " + std::to_string(options.max_degree)) +
                      "; allow a refit (a refit tolerance) or raise max_degree");
    RefitOptions refit = *base;
    refit.degree = std::min(refit.degree, cap);
    if (profile) {
      // As fit_to_profile: the profile's degree, from the rough breakpoints only; a capped net
      // (class A) adaptive from a uniform start, the worst spans split first up to the cap.
      refit.degree = profile->fit_degree;
      refit.keep_breakpoints = false;
      if (profile->max_count_per_direction > 0) {
        refit.initial_count = std::min(profile->fit_degree + 3, profile->max_count_per_direction);
        refit.max_count_per_direction = profile->max_count_per_direction;
      }
    }
    // One fit of the whole stack from the original, following the exact result along the
    // face's edges (step by step, each step's fit would wander from them).
    refit.matched_curves = edges;
    refit.matched_gap_mm = options.edge_gap_mm;
    refit.matched_angle_deg = options.edge_angle_deg;
    RefitResult fit;
    try {
      fit = stack ? refit_deformed(*stack, s, refit) : refit_surface(s, refit);
    } catch (const Error& e) {
      throw Error(e.category(), name + ": " + e.message());
    }
    if (!fit.report.certified || !(fit.report.certified_bound_mm <= fit.report.tolerance_mm) ||
        !fit.report.summary.converged() || (profile && !within_caps(fit.surface, *profile)))
      throw Error(ErrorCategory::ToleranceNotMet,
                  name + ": the refit" +
                      (profile    ? " for the " + std::string(profile->name) + " profile"
                       : too_high ? " below max_degree " + std::to_string(options.max_degree)
                                  : "") +
                      " failed: " + fit.report.summary.message +
                      (edges.empty() ? ""
                                     : "; or relax edge_gap_mm and edge_angle_deg (a recipe's "
                                       "composition \"edges\")") +
                      (profile ? ", or choose a profile with a larger net" : ""));
    s = std::move(fit.surface);
    if (profile) elevate_to(s, *profile);
    out.way = Outcome::Way::Refit;
    out.bound = fit.report.certified_bound_mm;
    return out;
  }
  s = std::move(r.surface);
  if (profile) elevate_to(s, *profile);
  out.way = r.report.exact ? Outcome::Way::Exact : Outcome::Way::Refit;
  for (const StepOutcome& step : r.report.steps) {
    if (step.method == StepOutcome::Method::Exact)
      out.deviation =
          std::max(out.deviation, step.compose.max_relative_deviation * step.compose.size);
    // A light form's bound too: an edge of degree 9 under a trilinear lattice is exact at
    // degree 27, above the budget, and its light form was 2.1e-4 mm off with the edge's tolerance
    // left at 1e-5 (ANSA's trimmed faces, torn).
    if (step.method == StepOutcome::Method::Refit || step.method == StepOutcome::Method::Light)
      out.bound += step.refit.certified ? step.refit.certified_bound_mm
                                        : std::numeric_limits<double>::infinity();
  }
  return out;
}

/// What a refit keeps along each edge (MatchedCurve::order), from the source's own figures: the
/// curvature where it is G2 (relative jump <= 5 %), the normal where it is tangent (<= 1 deg: an
/// exporter's tangent edge is rarely tangent to 1e-3 deg), else the position (sharp, or used by
/// one face only).
std::vector<int> edge_orders(const brep::Model& m, const brep::ContinuityReport& before) {
  std::vector<int> out(m.edges.size(), 0);
  for (const brep::EdgeContinuity& e : before.edges)
    out[static_cast<std::size_t>(e.edge)] =
        e.angle_deg <= 1 ? (e.relative_curvature_jump <= 0.05 ? 2 : 1) : 0;
  return out;
}

/// The face's edges as curves on its surface, for a refit that follows them (none when
/// ModelDeformationOptions turns that off), each with its edge's order (edge_orders). Each
/// pcurve's part on its edge, [t0, t1] clamped to the pcurve's own domain; poles are left out.
std::vector<MatchedCurve> matched_edges(const brep::Model& m, const brep::Face& face,
                                        const std::vector<int>& orders,
                                        const ModelDeformationOptions& options) {
  std::vector<MatchedCurve> out;
  if (options.edge_gap_mm == 0) return out;
  for (const brep::Loop& loop : face.loops)
    for (const brep::Coedge& co : loop.coedges) {
      const brep::Edge& edge = m.edges[static_cast<std::size_t>(co.edge)];
      if (edge.degenerate) continue;
      const auto [a, b] = co.pcurve.basis.domain();
      const double t0 = std::max(edge.t0, a), t1 = std::min(edge.t1, b);
      if (t0 < t1) out.push_back({co.pcurve, t0, t1, orders[static_cast<std::size_t>(co.edge)]});
    }
  return out;
}

}  // namespace

std::vector<std::string> ModelDeformationOptions::problems() const {
  std::vector<std::string> out = surface.problems();
  if (max_degree < 1 || max_degree > 25)
    out.push_back("max_degree is " + std::to_string(max_degree) + "; it must be in [1, 25]");
  if (!((edge_gap_mm > 0 && std::isfinite(edge_gap_mm) && edge_angle_deg > 0 &&
         edge_angle_deg < 90) ||
        (edge_gap_mm == 0 && edge_angle_deg == 0)))
    out.push_back("edge_gap_mm is " + internal::shortest(edge_gap_mm) + " and edge_angle_deg " +
                  internal::shortest(edge_angle_deg) +
                  "; give both (a gap > 0 mm, an angle in (0, 90) deg; class A: 0.0005 and 0.008 "
                  "per face) or both 0 (faces fitted alone)");
  return out;
}

void ModelDeformationOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string ModelDeformationReport::brief() const {
  char text[400];
  std::snprintf(text, sizeof text,
                "%d faces: %d exact, %d refit, %d untouched; %d edges: %d exact, %d refit, %d "
                "untouched; certified bound %.2g mm; edge gap %.2g mm",
                counts.faces, faces_exact, faces_refit, faces_untouched, counts.edges, edges_exact,
                edges_refit, edges_untouched, max_certified_bound_mm, max_edge_gap_mm);
  std::string line = text;
  if (volume_before_mm3 != 0 || volume_after_mm3 != 0) {  // solids only
    std::snprintf(text, sizeof text, "; volume %.10g -> %.10g mm^3", volume_before_mm3,
                  volume_after_mm3);
    line += text;
  }
  if (volume_ratio_bounded && (volume_before_mm3 != 0 || volume_after_mm3 != 0)) {
    std::snprintf(text, sizeof text, " (ratio %.6g, Jacobian bounds [%.6g, %.6g])",
                  volume_before_mm3 != 0 ? volume_after_mm3 / volume_before_mm3 : 0.0,
                  volume_ratio_min, volume_ratio_max);
    line += text;
  }
  if (solids_reversed > 0)
    line += "; " + std::to_string(solids_reversed) + " solids reversed (mirroring stack)";
  if (faces_restricted > 0)
    line += "; " + std::to_string(faces_restricted) +
            " faces composed on the part of their surface their trims use";
  return line;
}

ModelDeformationResult deform_model(const DeformationStack& stack, const brep::Model& input,
                                    const ModelDeformationOptions& options) {
  options.validate();
  validate(stack);
  brep::validate(input);
  ModelDeformationResult result;
  brep::Model& m = result.model;
  m = brep::flattened(input);
  if (m.faces.empty() && brep::counts(m).wire_edges == 0)
    throw Error(ErrorCategory::InvalidArgument,
                "deform_model: the model has no face and no wire edge; nothing to deform (read "
                "a file with faces or curves)");
  ModelDeformationReport& report = result.report;
  report.continuity_before = brep::edge_continuity(m);
  const std::vector<int> orders = edge_orders(m, report.continuity_before);
  if (options.profile) report.profile = std::string(options.profile->name);
  const std::vector<double> before = brep::body_volumes_mm3(m);
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    if (m.bodies[b].kind == brep::BodyKind::Solid) report.volume_before_mm3 += before[b];
  const double size = size_of(m);

  // Faces.
  std::vector<Outcome> faces(m.faces.size());
  std::vector<double> edge_face_bound(m.edges.size(), 0.0);
  std::vector<bool> edge_touched(m.edges.size(), false);
  const Leaves leaves(stack);
  std::vector<bool> chosen(m.faces.size(), options.faces.empty());
  for (int f : options.faces) {
    if (f < 0 || static_cast<std::size_t>(f) >= m.faces.size())
      throw Error(ErrorCategory::InvalidArgument,
                  "deform_model: ModelDeformationOptions::faces names face " + std::to_string(f) +
                      ", but the model has " + std::to_string(m.faces.size()) +
                      " faces (flattened); give indices in [0, " + std::to_string(m.faces.size()) +
                      ")");
    chosen[static_cast<std::size_t>(f)] = true;
  }
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    throw_if_cancelled("a model's deformation");
    brep::Face& face = m.faces[f];
    if (!chosen[f] || leaves.alone(face.surface.points)) {
      // Kept, unless a profile would not take it: an analytic face is written as such; a NURBS
      // one below the profile's degree is raised exactly; one beyond it is refitted below.
      const ReceiverProfile* profile = options.profile ? &*options.profile : nullptr;
      const bool conforms =
          !profile || face.elementary || conformance_problems(face.surface, *profile).empty();
      if (conforms || within_caps(face.surface, *profile)) {
        if (!conforms) {
          elevate_to(face.surface, *profile);
          ++report.faces_elevated;
        }
        ++report.faces_untouched;
      } else {
        // Refitted in place, following its edges, which stay where they are.
        faces[f] = deform_one(nullptr, face.surface, options, face_name(m, f),
                              matched_edges(m, face, orders, options));
        face.elementary.reset();
        ++report.faces_refit;
        report.max_certified_bound_mm = std::max(report.max_certified_bound_mm, faces[f].bound);
        for (const brep::Loop& loop : face.loops)
          for (const brep::Coedge& co : loop.coedges) {
            const auto e = static_cast<std::size_t>(co.edge);
            edge_face_bound[e] = std::max(edge_face_bound[e], faces[f].bound);
          }
      }
      continue;
    }
    try {
      faces[f] = deform_one(&stack, face.surface, options, face_name(m, f),
                            matched_edges(m, face, orders, options));
    } catch (const Error& e) {
      // A trimmed face inside the lattice on a carrier that leaves it (a large plane or
      // B-spline): composed on the part of the carrier its trims use (issue #39 item 7).
      const auto box = e.category() == ErrorCategory::OutOfDomain ? trims_box(face) : std::nullopt;
      if (!box) throw;
      face.surface = surface::restricted(face.surface, (*box)[0], (*box)[1], (*box)[2], (*box)[3]);
      faces[f] = deform_one(&stack, face.surface, options, face_name(m, f),
                            matched_edges(m, face, orders, options));
      ++report.faces_restricted;
    }
    face.elementary.reset();  // no longer a plane, cylinder, ...: only untouched faces keep it
    (faces[f].way == Outcome::Way::Exact ? report.faces_exact : report.faces_refit) += 1;
    report.max_certified_bound_mm = std::max(report.max_certified_bound_mm, faces[f].bound);
    report.max_deviation_mm = std::max(report.max_deviation_mm, faces[f].deviation);
    for (const brep::Loop& loop : face.loops)
      for (const brep::Coedge& co : loop.coedges) {
        const auto e = static_cast<std::size_t>(co.edge);
        edge_touched[e] = true;
        edge_face_bound[e] = std::max(edge_face_bound[e], faces[f].bound);
      }
  }
  // A wire body's free edges move with the whole model (a selection of faces keeps them).
  if (options.faces.empty())
    for (const brep::Body& body : m.bodies)
      for (int e : body.edges)
        if (!leaves.alone(m.edges[static_cast<std::size_t>(e)].curve.points))
          edge_touched[static_cast<std::size_t>(e)] = true;
  // An edge a deformed face shares with a kept one must stay where it is (within its tolerance).
  if (!options.faces.empty()) {
    std::vector<int> kept_user(m.edges.size(), -1), deformed_user(m.edges.size(), -1);
    for (std::size_t f = 0; f < m.faces.size(); ++f)
      for (const brep::Loop& loop : m.faces[f].loops)
        for (const brep::Coedge& co : loop.coedges)
          (faces[f].way == Outcome::Way::Untouched
               ? kept_user
               : deformed_user)[static_cast<std::size_t>(co.edge)] = static_cast<int>(f);
    for (std::size_t e = 0; e < m.edges.size(); ++e) {
      if (kept_user[e] < 0 || deformed_user[e] < 0 || m.edges[e].degenerate) continue;
      const brep::Edge& edge = m.edges[e];
      double moved = 0;
      for (int k = 0; k <= 32; ++k) {
        const double t = edge.t0 + (edge.t1 - edge.t0) * k / 32;
        const Eigen::Vector3d p = surface::evaluate(edge.curve, t);
        moved = std::max(moved, (deform_point(stack, p) - p).norm());
      }
      if (moved > edge.tolerance_mm)
        throw Error(ErrorCategory::InvalidArgument,
                    "deform_model: " + face_name(m, static_cast<std::size_t>(deformed_user[e])) +
                        " is deformed but " + face_name(m, static_cast<std::size_t>(kept_user[e])) +
                        " is not, and the stack moves their shared edge " + std::to_string(e) +
                        " by " + internal::shortest(moved) +
                        " mm: choose both faces, or keep the deformation off that edge");
    }
  }
  // Edges: F∘C on the same t, when a deformed face uses them; refitted within edge_gap_mm when
  // the faces follow their edges that closely.
  ModelDeformationOptions edge_options = options;
  // An edge's curve is no net a receiver edits: only the profile's degree cap applies to it.
  if (options.profile) {
    edge_options.max_degree = std::min(options.max_degree, options.profile->max_degree);
    edge_options.profile.reset();
  }
  // (The budget's light fit too: an exact composition's edge above the budget is light.)
  auto within_edge_gap = [&](RefitOptions& refit) {
    refit.tolerance_mm = refit.tolerance_mm > 0 ? std::min(refit.tolerance_mm, options.edge_gap_mm)
                                                : options.edge_gap_mm;
    refit.relative_tolerance = 0;
  };
  if (options.edge_gap_mm > 0) {
    if (edge_options.surface.refit) within_edge_gap(*edge_options.surface.refit);
    if (edge_options.surface.budget) within_edge_gap(edge_options.surface.budget->light);
  }
  std::vector<double> edge_bound(m.edges.size(), 0.0);
  for (std::size_t e = 0; e < m.edges.size(); ++e) {
    brep::Edge& edge = m.edges[e];
    if (!edge_touched[e] || edge.degenerate) {
      if (edge_touched[e]) {
        ++report.edges_exact;  // a pole: nothing to map but its vertex
      } else {
        ++report.edges_untouched;
        // a kept edge of a face refitted for the profile: that face's bound widens it
        edge.tolerance_mm += edge_face_bound[e];
        for (int v : {edge.start, edge.end})
          m.vertices[static_cast<std::size_t>(v)].tolerance_mm =
              std::max(m.vertices[static_cast<std::size_t>(v)].tolerance_mm, edge.tolerance_mm);
      }
      continue;
    }
    surface::BSplineSurface strip = ruled(edge.curve);
    const Outcome o = deform_one(&stack, strip, edge_options, "edge " + std::to_string(e));
    edge.curve = row_zero(strip);
    (o.way == Outcome::Way::Exact ? report.edges_exact : report.edges_refit) += 1;
    report.max_certified_bound_mm = std::max(report.max_certified_bound_mm, o.bound);
    report.max_deviation_mm = std::max(report.max_deviation_mm, o.deviation);
    edge_bound[e] = o.bound;
    // A refit's bound, the face's and the edge's own, widens the edge's tolerance.
    edge.tolerance_mm += o.bound + edge_face_bound[e];
  }
  // Vertices: the pointwise map, where a deformed edge ends.
  std::vector<bool> vertex_touched(m.vertices.size(), false);
  std::vector<double> vertex_widen(m.vertices.size(), 0.0);
  for (std::size_t e = 0; e < m.edges.size(); ++e) {
    if (!edge_touched[e]) continue;
    for (int v : {m.edges[e].start, m.edges[e].end}) {
      vertex_touched[static_cast<std::size_t>(v)] = true;
      vertex_widen[static_cast<std::size_t>(v)] =
          std::max(vertex_widen[static_cast<std::size_t>(v)], edge_bound[e] + edge_face_bound[e]);
    }
  }
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    if (vertex_touched[v]) {
      m.vertices[v].point = deform_point(stack, m.vertices[v].point);
      m.vertices[v].tolerance_mm += vertex_widen[v];
    }
  report.max_edge_gap_mm =
      std::max(report.max_edge_gap_mm, widen_stretched_tolerances(m, vertex_touched, size));
  report.counts = brep::counts(m);
  const auto broken = brep::problems(m);
  if (!broken.empty()) {
    std::string text = "deform_model: the deformed model breaks " + std::to_string(broken.size()) +
                       " invariant" + (broken.size() == 1 ? "" : "s") +
                       " (a torn model is not returned):";
    for (std::size_t k = 0; k < std::min<std::size_t>(broken.size(), 8); ++k)
      text += "\n  " + broken[k];
    throw Error(ErrorCategory::ToleranceNotMet, text);
  }
  // A mirroring map turns solids inside out: reverse their faces, which negates their volume
  // (and breaks no invariant: a shell's orientation stays consistent).
  const std::vector<double> after = brep::body_volumes_mm3(m);
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    if (m.bodies[b].kind != brep::BodyKind::Solid) continue;
    if (after[b] < 0) {
      for (const brep::Shell& shell : m.bodies[b].shells)
        for (int f : shell.faces)
          m.faces[static_cast<std::size_t>(f)].reversed =
              !m.faces[static_cast<std::size_t>(f)].reversed;
      ++report.solids_reversed;
    }
    report.volume_after_mm3 += std::abs(after[b]);
  }
  // The Jacobian's volume bounds (lattices only: a twist or bend has no coefficient bounds).
  report.volume_ratio_bounded = options.faces.empty();
  for_each_enabled_step(
      stack,
      [&](const auto& lattice) {
        const JacobianBounds b = jacobian_bounds(lattice);
        report.volume_ratio_bounded = report.volume_ratio_bounded && b.fold_free;
        report.volume_ratio_min *= std::min(b.min, 1.0);
        report.volume_ratio_max *= std::max(b.max, 1.0);
      },
      [&] { report.volume_ratio_bounded = false; });
  if (!report.volume_ratio_bounded) report.volume_ratio_min = report.volume_ratio_max = 1;
  report.continuity_after = brep::edge_continuity(m);
  report.summary.termination = Termination::Converged;
  report.summary.final_residual = report.max_edge_gap_mm;
  report.summary.message = report.brief();
  return result;
}

Frame frame_around(const brep::Model& model, double margin, const std::vector<int>& faces) {
  if (!(margin > 0 && margin <= 10))
    throw Error(ErrorCategory::InvalidArgument,
                "frame_around: margin " + shortest(margin) +
                    " must lie in (0, 10] (a fraction of the box's extent on each side; 0.05 "
                    "by default): the control points must lie strictly inside the lattice");
  const brep::Box box = brep::control_box(model, faces);
  const Eigen::Vector3d extent = box.hi - box.lo;
  // An axis thinner than a tenth of the diagonal grows as if it were that thick: a flat panel
  // still gets a lattice with volume to move its points in.
  const double thinnest = 0.1 * extent.norm();
  Eigen::Vector3d pad;
  for (int k = 0; k < 3; ++k) pad[k] = margin * std::max(extent[k], thinnest);
  if (!(pad.minCoeff() > 0))  // a single point: a 1 mm cube around it
    pad = Eigen::Vector3d::Constant(0.5);
  Frame frame;
  frame.origin = box.lo - pad;
  const Eigen::Vector3d size = extent + 2 * pad;
  frame.s = Eigen::Vector3d(size.x(), 0, 0);
  frame.t = Eigen::Vector3d(0, size.y(), 0);
  frame.u = Eigen::Vector3d(0, 0, size.z());
  return frame;
}

}  // namespace clay::deform
