// A surface through a deformation stack: exact composition where it exists, certified refit
// where it does not (and is allowed), a report per step.
#include <clay/deform/surface_deformation.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <variant>

#include "certifier.hpp"
#include "compose_size.hpp"
#include "messages.hpp"

namespace clay::deform {

RefitOptions Budget::light_fit() {
  RefitOptions o;
  o.keep_breakpoints = false;
  return o;
}

std::vector<std::string> Budget::problems() const {
  std::vector<std::string> out;
  if (max_degree < 1 || max_degree > 25)
    out.push_back("Budget: max_degree = " + std::to_string(max_degree) +
                  " breaks the rule 1 <= max_degree <= 25; give e.g. 15 (CATIA's order 16)");
  if (max_control_points < 1)
    out.push_back("Budget: max_control_points = " + std::to_string(max_control_points) +
                  " breaks the rule max_control_points >= 1; give e.g. 10000");
  for (const std::string& p : light.problems()) out.push_back("Budget::light: " + p);
  return out;
}

std::vector<std::string> SurfaceDeformationOptions::problems() const {
  std::vector<std::string> out;
  internal::append(out, compose.problems());
  if (refit) internal::append(out, refit->problems());
  if (budget) internal::append(out, budget->problems());
  if (!(input_bound_mm >= 0))
    out.push_back("SurfaceDeformationOptions: input_bound_mm = " + detail::format(input_bound_mm) +
                  " breaks the rule input_bound_mm >= 0 (inf when unknown)");
  return out;
}

void SurfaceDeformationOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string SurfaceDeformationReport::brief() const {
  std::ostringstream out;
  for (const StepOutcome& s : steps) {
    out << "steps[" << s.step << "] " << s.kind;
    if (!s.name.empty()) out << " '" << s.name << "'";
    switch (s.method) {
      case StepOutcome::Method::Skipped:
        out << ": disabled, skipped";
        break;
      case StepOutcome::Method::Exact:
        out << ": exact, " << s.compose.brief();
        break;
      case StepOutcome::Method::Refit:
        out << ": refit, " << s.refit.brief();
        break;
      case StepOutcome::Method::Light:
        out << ": light form of the exact degree " << s.exact_size.degree_u << " x "
            << s.exact_size.degree_v;
        if (s.exact_size.control_points > 0)
          out << ", " << s.exact_size.control_points << " control points";
        out << ", " << s.refit.brief();
        break;
    }
    out << "\n";
  }
  out << "result: degree " << degree_u << " x " << degree_v << ", " << control_points
      << " control points, "
      << (exact       ? "exact"
          : certified ? "certified refit"
                      : "refit (not certified)");
  if (!exact) out << ", within " << detail::format(accumulated_bound_mm, 3) << " mm of the exact";
  return out.str();
}

namespace {

template <class... F>
struct overloaded : F... {
  using F::operator()...;
};
template <class... F>
overloaded(F...) -> overloaded<F...>;

// The exact composition of one step, or why there is none. compose_exact refuses with
// DegreeLimit (above the exchange limit), OutOfDomain (the surface leaves the lattice, where the
// FFD is the identity: not one polynomial) or InvalidArgument (a knot plane crossed other than
// along an iso-parameter line); inputs and options are validated before, so these are the only
// refusals caught here.
struct Attempt {
  std::optional<ComposeResult> result;
  std::string reason;
  ErrorCategory category = ErrorCategory::InvalidArgument;
  std::optional<ExactSize> size;  ///< refused for its size: what it would have been
};

template <class F>
Attempt attempt(F compose) {
  try {
    return {compose(), {}, {}, {}};
  } catch (const detail::ExactSizeError& e) {
    return {std::nullopt, e.what(), e.category(), e.size()};
  } catch (const Error& e) {
    const ErrorCategory c = e.category();
    if (c == ErrorCategory::DegreeLimit || c == ErrorCategory::OutOfDomain ||
        c == ErrorCategory::InvalidArgument)
      return {std::nullopt, e.what(), c, {}};
    throw;
  }
}

Attempt try_exact(const Deformation& d, const surface::BSplineSurface& s, const ComposeOptions& o) {
  return std::visit(
      overloaded{
          [&](const BezierLattice& l) { return attempt([&] { return compose_exact(l, s, o); }); },
          [&](const BSplineLattice& l) { return attempt([&] { return compose_exact(l, s, o); }); },
          [&](const Taper& t) { return attempt([&] { return compose_exact(t, s, o); }); },
          [&](const auto&) {
            return Attempt{std::nullopt,
                           "a " + std::string(kind_name(d)) +
                               " is not polynomial, so no NURBS equals the deformed surface",
                           ErrorCategory::InvalidArgument,
                           {}};
          }},
      d);
}

/// Where a surface crosses the boundary of a lattice: the largest jump |F(x) − x| of the map
/// there, the parameter, and the face (axis, 0 or 1).
struct FaceJump {
  double mm = 0;
  double u = 0, v = 0;
  int axis = 0;
  int face = 0;
};

/// How far outside the unit cube local coordinates are (<= face_tolerance: inside), and along
/// which axis and face.
double outside_by(const Eigen::Vector3d& c, int* axis = nullptr, int* face = nullptr) {
  double worst = -1;
  for (int d = 0; d < 3; ++d)
    for (int f = 0; f < 2; ++f) {
      const double by = f == 0 ? -c[d] : c[d] - 1;
      if (by > worst) {
        worst = by;
        if (axis) *axis = d;
        if (face) *face = f;
      }
    }
  return worst;
}

/// The largest jump of the lattice's map where `s` crosses the lattice's boundary: on a grid of
/// 8 samples per knot span (the refit's own sizing grid), every grid edge with one end inside and
/// one outside is bisected to the crossing (40 halvings), and the map is evaluated at the last
/// point inside. A lower bound of the true largest jump (a crossing between grid lines can be
/// missed). Nothing to measure when every control point is inside (the surface is in their
/// convex hull).
template <class Lattice>
FaceJump face_jump(const Lattice& lattice, const surface::BSplineSurface& s) {
  bool all_inside = true;
  for (Eigen::Index r = 0; r < s.points.rows() && all_inside; ++r)
    all_inside =
        outside_by(local_coordinates(lattice.frame, s.points.row(r).transpose())) <= face_tolerance;
  if (all_inside) return {};
  const std::vector<double> us = surface::span_samples(s.u, 8), vs = surface::span_samples(s.v, 8);
  const Points3 grid = surface::evaluate_grid(s, us, vs);
  const size_t nu = us.size(), nv = vs.size();
  std::vector<char> in(nu * nv);
  for (size_t k = 0; k < in.size(); ++k)
    in[k] =
        outside_by(local_coordinates(
            lattice.frame, grid.row(static_cast<Eigen::Index>(k)).transpose())) <= face_tolerance;
  FaceJump worst;
  auto crossing = [&](double ua, double va, double ub, double vb) {  // a inside, b outside
    double lo = 0, hi = 1;
    for (int it = 0; it < 40; ++it) {
      const double m = 0.5 * (lo + hi);
      const Eigen::Vector3d x = surface::evaluate(s, ua + m * (ub - ua), va + m * (vb - va));
      (outside_by(local_coordinates(lattice.frame, x)) <= face_tolerance ? lo : hi) = m;
    }
    const double u = ua + lo * (ub - ua), v = va + lo * (vb - va);
    const Eigen::Vector3d x = surface::evaluate(s, u, v);
    const double jump = (deform_point(lattice, x) - x).norm();
    if (jump > worst.mm) {
      const Eigen::Vector3d out = local_coordinates(
          lattice.frame, surface::evaluate(s, ua + hi * (ub - ua), va + hi * (vb - va)));
      worst = {jump, u, v, 0, 0};
      outside_by(out, &worst.axis, &worst.face);
    }
  };
  for (size_t i = 0; i < nu; ++i)
    for (size_t j = 0; j < nv; ++j) {
      const size_t k = i * nv + j;
      for (const auto& [di, dj] : {std::pair<size_t, size_t>{1, 0}, {0, 1}}) {
        if (i + di >= nu || j + dj >= nv) continue;
        const size_t n = (i + di) * nv + j + dj;
        if (in[k] == in[n]) continue;
        if (in[k])
          crossing(us[i], vs[j], us[i + di], vs[j + dj]);
        else
          crossing(us[i + di], vs[j + dj], us[i], vs[j]);
      }
    }
  return worst;
}

/// Refuses a lattice step whose map is torn by more than twice the tolerance where the surface
/// leaves the lattice (see deform_surface): no continuous fit could meet the tolerance.
void refuse_torn(const Deformation& d, const surface::BSplineSurface& s, const RefitOptions& o,
                 const std::string& where) {
  std::optional<FaceJump> jump;
  if (const auto* l = std::get_if<BezierLattice>(&d)) jump = face_jump(*l, s);
  if (const auto* l = std::get_if<BSplineLattice>(&d)) jump = face_jump(*l, s);
  if (!jump || jump->mm == 0) return;
  double tolerance = o.tolerance_mm;
  if (o.relative_tolerance >
      0) {  // as refit_deformed: of the deformed surface's size, sampled 8 x 8 per span
    const std::vector<double> su = surface::span_samples(s.u, 8),
                              sv = surface::span_samples(s.v, 8);
    Points3 sample = surface::evaluate_grid(s, su, sv);
    for (Eigen::Index r = 0; r < sample.rows(); ++r)
      sample.row(r) = std::visit(
                          [&](const auto& k) -> Eigen::Vector3d {
                            return deform_point(k, sample.row(r).transpose());
                          },
                          d)
                          .transpose();
    tolerance =
        o.relative_tolerance * (sample.colwise().maxCoeff() - sample.colwise().minCoeff()).norm();
  }
  if (jump->mm / 2 <= tolerance) return;
  constexpr const char* axis_name[3] = {"s", "t", "u"};
  throw Error(
      ErrorCategory::ToleranceNotMet,
      where + ": the deformation is discontinuous where the surface crosses the lattice face " +
          axis_name[jump->axis] + " = " + std::to_string(jump->face) + ": it jumps by " +
          detail::format(jump->mm, 4) + " mm there (at parameter (" + detail::format(jump->u, 6) +
          ", " + detail::format(jump->v, 6) +
          ")), because the FFD is the identity outside the lattice and that face's control points "
          "are "
          "displaced; the deformed surface is torn, and no refit can come closer than half the "
          "jump (" +
          detail::format(jump->mm / 2, 4) + " mm > the tolerance " + detail::format(tolerance, 4) +
          " mm). Enlarge the lattice so that it contains the surface, or keep that face's control "
          "points at rest");
}

/// sup |D'| over the control box of `s` grown by `margin` (mm) on every side: a box that holds
/// every point within `margin` of the surface, and the segments to them (certifier.hpp); inf
/// when the kind has no derivative bounds.
double lipschitz(const Deformation& d, const surface::BSplineSurface& s, double margin) {
  const detail::Certifier c = std::visit([](const auto& k) { return detail::certifier(k); }, d);
  if (!c.info) return std::numeric_limits<double>::infinity();
  const auto [lo, hi] = surface::control_box(s);
  Points3 corners(8, 3);
  for (int k = 0; k < 8; ++k)
    for (int a = 0; a < 3; ++a) corners(k, a) = (k >> a & 1) ? hi[a] + margin : lo[a] - margin;
  return c.info(corners).bounds.first;
}

/// The bound ledger (StepOutcome::accumulated_bound_mm): E = e + L·E_in.
double accumulated(const Deformation& d, const surface::BSplineSurface& input, double e,
                   double in) {
  if (in == 0) return e;
  if (!std::isfinite(in) || !std::isfinite(e)) return std::numeric_limits<double>::infinity();
  return e + lipschitz(d, input, in) * in;
}

}  // namespace

SurfaceDeformationResult deform_surface(const DeformationStack& stack,
                                        const surface::BSplineSurface& surface,
                                        const SurfaceDeformationOptions& options) {
  options.validate();
  surface::validate(surface, "surface to deform");
  validate(stack);
  SurfaceDeformationResult out{surface, {}};
  SurfaceDeformationReport& report = out.report;
  double bound = options.input_bound_mm;  // the ledger: how far from the exact reference
  for (size_t i = 0; i < stack.steps.size(); ++i) {
    const DeformationStep& step = stack.steps[i];
    StepOutcome o;
    o.step = static_cast<int>(i);
    o.kind = std::string(kind_name(step.deformation));
    o.name = step.name;
    if (!step.enabled) {
      o.accumulated_bound_mm = bound;
      report.steps.push_back(std::move(o));
      continue;
    }
    ComposeOptions within = options.compose;
    if (options.budget) {
      within.max_degree = std::min(within.max_degree, options.budget->max_degree);
      within.max_control_points = options.budget->max_control_points;
    }
    Attempt a = try_exact(step.deformation, out.surface, within);
    const surface::BSplineSurface& input = out.surface;
    // A light or refitted step: its certified bound, the ledger, the result.
    auto fitted = [&](StepOutcome::Method method, RefitResult r) {
      o.method = method;
      o.reason = std::move(a.reason);
      o.refit = r.report;
      o.bound_mm = r.report.certified ? r.report.certified_bound_mm
                                      : std::numeric_limits<double>::infinity();
      o.accumulated_bound_mm = accumulated(step.deformation, input, o.bound_mm, bound);
      report.exact = false;
      report.certified = report.certified && r.report.certified;
      out.surface = std::move(r.surface);
    };
    if (a.result) {
      o.method = StepOutcome::Method::Exact;
      o.compose = a.result->report;
      o.accumulated_bound_mm = accumulated(step.deformation, input, 0, bound);
      out.surface = std::move(a.result->surface);
    } else if (a.size && options.budget) {
      const std::string where = "deform_surface: steps[" + std::to_string(i) + "] (" + o.kind +
                                (o.name.empty() ? "" : " '" + o.name + "'") + ")";
      refuse_torn(step.deformation, input, options.budget->light, where);
      RefitResult r = refit_deformed(step.deformation, input, options.budget->light);
      if (!r.report.summary.converged() && !options.accept_out_of_tolerance)
        throw Error(ErrorCategory::ToleranceNotMet,
                    where + ": its exact form (degree " + std::to_string(a.size->degree_u) + " x " +
                        std::to_string(a.size->degree_v) +
                        (a.size->control_points > 0
                             ? ", " + std::to_string(a.size->control_points) + " control points"
                             : std::string()) +
                        ") is above the budget, and its light form misses its tolerance: " +
                        r.report.summary.message +
                        ". Loosen the light form's tolerance, allow it more control points, or "
                        "raise the budget to keep the exact form");
      o.exact_size = *a.size;
      ++report.light_steps;
      fitted(StepOutcome::Method::Light, std::move(r));
    } else {
      const std::string where = "deform_surface: steps[" + std::to_string(i) + "] (" + o.kind +
                                (o.name.empty() ? "" : " '" + o.name + "'") + ")";
      if (!options.refit)
        throw Error(a.category,
                    where + " cannot be composed exactly: " + a.reason +
                        ". Allow a certified refit (SurfaceDeformationOptions::refit) to "
                        "approximate this step within a tolerance");
      refuse_torn(step.deformation, out.surface, *options.refit, where);
      RefitResult r = refit_deformed(step.deformation, out.surface, *options.refit);
      if (!r.report.summary.converged() && !options.accept_out_of_tolerance)
        throw Error(ErrorCategory::ToleranceNotMet,
                    where + " misses its tolerance: the refit's " + r.report.summary.message +
                        ". Nothing is returned; to accept the result anyway set "
                        "SurfaceDeformationOptions::accept_out_of_tolerance");
      fitted(StepOutcome::Method::Refit, std::move(r));
    }
    bound = o.accumulated_bound_mm;
    report.steps.push_back(std::move(o));
  }
  report.accumulated_bound_mm = bound;
  report.degree_u = out.surface.u.degree;
  report.degree_v = out.surface.v.degree;
  report.control_points = static_cast<long>(out.surface.points.rows());
  bool within = true;  // every refit within its tolerance (else it was accepted out of tolerance)
  for (const StepOutcome& o : report.steps)
    within = within &&
             ((o.method != StepOutcome::Method::Refit && o.method != StepOutcome::Method::Light) ||
              o.refit.summary.converged());
  report.summary.termination = within ? Termination::Converged : Termination::NotConverged;
  report.summary.message = report.brief();
  return out;
}

SurfaceDeformationResult deform_surface(const Deformation& deformation,
                                        const surface::BSplineSurface& surface,
                                        const SurfaceDeformationOptions& options) {
  DeformationStack stack;
  stack.steps.push_back({deformation, {}, true});
  return deform_surface(stack, surface, options);
}

}  // namespace clay::deform
