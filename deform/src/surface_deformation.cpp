// A surface through a deformation stack: exact composition where it exists, certified refit
// where it does not (and is allowed), a report per step.
#include <clay/deform/surface_deformation.hpp>

#include <clay/error.hpp>

#include <sstream>
#include <variant>

namespace clay::deform {

void SurfaceDeformationOptions::validate() const {
  compose.validate();
  if (refit) refit->validate();
}

std::string SurfaceDeformationReport::brief() const {
  std::ostringstream out;
  for (const StepOutcome& s : steps) {
    out << "steps[" << s.step << "] " << s.kind;
    if (!s.name.empty()) out << " '" << s.name << "'";
    switch (s.method) {
      case StepOutcome::Method::skipped: out << ": disabled, skipped"; break;
      case StepOutcome::Method::exact: out << ": exact, " << s.compose.brief(); break;
      case StepOutcome::Method::refit: out << ": refit, " << s.refit.brief(); break;
    }
    out << "\n";
  }
  out << "result: degree " << degree_u << " x " << degree_v << ", " << control_points
      << " control points, " << (exact ? "exact" : certified ? "certified refit" : "refit (not certified)");
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
};

template <class F>
Attempt attempt(F compose) {
  try {
    return {compose(), {}, {}};
  } catch (const Error& e) {
    const ErrorCategory c = e.category();
    if (c == ErrorCategory::DegreeLimit || c == ErrorCategory::OutOfDomain || c == ErrorCategory::InvalidArgument)
      return {std::nullopt, e.what(), c};
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
                           ErrorCategory::InvalidArgument};
          }},
      d);
}

RefitResult refit_step(const Deformation& d, const surface::BSplineSurface& s, const RefitOptions& o) {
  return std::visit([&](const auto& deformation) { return refit_deformed(s, deformation, o); }, d);
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
  for (size_t i = 0; i < stack.steps.size(); ++i) {
    const DeformationStep& step = stack.steps[i];
    StepOutcome o;
    o.step = static_cast<int>(i);
    o.kind = std::string(kind_name(step.deformation));
    o.name = step.name;
    if (!step.enabled) {
      report.steps.push_back(std::move(o));
      continue;
    }
    Attempt a = try_exact(step.deformation, out.surface, options.compose);
    if (a.result) {
      o.method = StepOutcome::Method::exact;
      o.compose = a.result->report;
      out.surface = std::move(a.result->surface);
    } else {
      const std::string where = "deform_surface: steps[" + std::to_string(i) + "] (" + o.kind +
                                (o.name.empty() ? "" : " '" + o.name + "'") + ")";
      if (!options.refit)
        throw Error(a.category, where + " cannot be composed exactly: " + a.reason +
                                    ". Allow a certified refit (SurfaceDeformationOptions::refit) to "
                                    "approximate this step within a tolerance");
      RefitResult r = refit_step(step.deformation, out.surface, *options.refit);
      o.method = StepOutcome::Method::refit;
      o.reason = std::move(a.reason);
      o.refit = r.report;
      report.exact = false;
      report.certified = report.certified && r.report.certified;
      out.surface = std::move(r.surface);
    }
    report.steps.push_back(std::move(o));
  }
  report.degree_u = out.surface.u.degree;
  report.degree_v = out.surface.v.degree;
  report.control_points = static_cast<long>(out.surface.points.rows());
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
