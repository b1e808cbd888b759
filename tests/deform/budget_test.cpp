// Every result has a budget (issue #38): compose_exact predicts its net before composing and
// refuses above ComposeOptions::max_control_points; deform_surface under a Budget makes such a
// step its certified light form, and stacks the bounds. Sizes are checked against the exact
// compositions themselves; bounds against the exact result and the pointwise map, sampled.
#include <catch2/catch.hpp>

#include <clay/deform/surface_deformation.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <cmath>
#include <random>
#include <regex>
#include <string>

#include "error_of.hpp"
#include "shapes.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;
using namespace clay::test;
namespace surface = clay::surface;

namespace {

/// A bicubic dome, 100 x 100 mm, inside box_frame(): on uniform knots, or (rough) with a
/// double knot at 0.5 and a triple one at 0.75 in u, a double one at 0.4 in v, and control points
/// perturbed off the dome, so it is exactly as smooth as its knots say (C1, C0, C1 there).
surface::BSplineSurface dome(bool rough = false) {
  const auto b = surface::clamped_uniform_basis(3, 6);
  surface::BSplineBasis bu = b, bv = b;
  if (rough) {
    bu.knots = {0, 0, 0, 0, 0.25, 0.5, 0.5, 0.75, 0.75, 0.75, 1, 1, 1, 1};
    bv.knots = {0, 0, 0, 0, 0.2, 0.4, 0.4, 0.7, 1, 1, 1, 1};
  }
  const auto xu = surface::greville_abscissae(bu), xv = surface::greville_abscissae(bv);
  const int nu = bu.count(), nv = bv.count();
  surface::Points3 p(nu * nv, 3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> off(-0.5, 0.5);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double x = 100 * xu[static_cast<size_t>(i)], y = 100 * xv[static_cast<size_t>(j)];
      p.row(i * nv + j) << x, y,
          20 * std::sin(0.03 * x) * std::sin(0.03 * y) + 0.01 * x + (rough ? off(rng) : 0.0);
    }
  return surface::make_surface(bu, bv, p);
}

/// The control points compose_exact refuses with: "up to N control points" in its message.
long refused_at(const Deformation& d, const surface::BSplineSurface& s, long limit) {
  ComposeOptions o;
  o.max_control_points = limit;
  const auto [category, message] = error_of([&] {
    std::visit(
        [&](const auto& k) {
          if constexpr (std::is_same_v<std::decay_t<decltype(k)>, BezierLattice> ||
                        std::is_same_v<std::decay_t<decltype(k)>, BSplineLattice> ||
                        std::is_same_v<std::decay_t<decltype(k)>, Taper>)
            compose_exact(k, s, o);
        },
        d);
  });
  INFO(message);
  CHECK(category == ErrorCategory::DegreeLimit);
  std::smatch m;
  REQUIRE(std::regex_search(message, m, std::regex("up to ([0-9]+) control points")));
  return std::stol(m[1]);
}

}  // namespace

TEST_CASE("compose_exact: the net predicted before composing is the one composed", "[budget]") {
  // A dome with knots of multiplicity 1 (C2), 2 (C1) and 3 (C0), exactly that smooth: the
  // composition keeps each continuity, so its net is known from the patches' degrees and the
  // knots alone.
  const surface::BSplineSurface s = dome(true);
  BSplineLattice spline = make_bspline_lattice(box_frame(), {2, 2, 1}, {3, 3, 1});
  spline.points.row(spline.index(2, 2, 1)) += Eigen::RowVector3d(2, 1, 9);
  for (const Deformation& d : {Deformation(bulge()), Deformation(flare()), Deformation(spline)}) {
    INFO(kind_name(d));
    const long composed = std::visit(
        [&](const auto& k) -> long {
          if constexpr (std::is_same_v<std::decay_t<decltype(k)>, BezierLattice> ||
                        std::is_same_v<std::decay_t<decltype(k)>, BSplineLattice> ||
                        std::is_same_v<std::decay_t<decltype(k)>, Taper>)
            return compose_exact(k, s).report.control_points;
          return 0;
        },
        d);
    REQUIRE(composed > 0);
    CHECK(refused_at(d, s, composed - 1) == composed);
    // At exactly its size the composition goes through.
    ComposeOptions o;
    o.max_control_points = composed;
    CHECK_NOTHROW(std::visit(
        [&](const auto& k) {
          if constexpr (std::is_same_v<std::decay_t<decltype(k)>, BezierLattice> ||
                        std::is_same_v<std::decay_t<decltype(k)>, BSplineLattice> ||
                        std::is_same_v<std::decay_t<decltype(k)>, Taper>)
            compose_exact(k, s, o);
        },
        d));
  }
  ComposeOptions bad;
  bad.max_control_points = -1;
  CHECK_THAT(bad.problems().front(), Contains("max_control_points = -1"));
}

TEST_CASE("deform_surface: above the budget a step is its certified light form",
          "[budget][surface_deformation]") {
  const surface::BSplineSurface s = dome();
  DeformationStack stack;
  stack.steps.push_back({bulge(), "bulge", true});
  stack.steps.push_back({flare(), "flare", true});
  const SurfaceDeformationResult exact = deform_surface(stack, s);  // no budget: exact
  REQUIRE(exact.report.exact);
  REQUIRE(exact.surface.u.degree == 10);

  SurfaceDeformationOptions options;
  options.budget = Budget{};
  options.budget->max_degree = 9;  // the flare's exact degree 10 is above it
  const SurfaceDeformationResult r = deform_surface(stack, s, options);
  INFO(r.report.brief());
  REQUIRE(r.report.steps.size() == 2);
  CHECK(r.report.steps[0].method == StepOutcome::Method::Exact);
  const StepOutcome& light = r.report.steps[1];
  REQUIRE(light.method == StepOutcome::Method::Light);
  CHECK(light.exact_size.degree_u == 10);
  CHECK(light.exact_size.degree_v == 10);
  CHECK_THAT(light.reason, Contains("above the limit 9"));
  CHECK(r.report.light_steps == 1);
  CHECK_FALSE(r.report.exact);
  CHECK(r.report.certified);
  CHECK(r.surface.u.degree == 3);
  CHECK(r.surface.v.degree == 3);
  REQUIRE(light.refit.certified);
  CHECK(light.bound_mm == light.refit.certified_bound_mm);
  CHECK(light.bound_mm <= light.refit.tolerance_mm);
  // The first step was exact, so the ledger is this bound, and it holds against the exact result.
  CHECK(light.accumulated_bound_mm == light.bound_mm);
  CHECK(r.report.accumulated_bound_mm == light.bound_mm);
  const double gap = grid_gap(r.surface, exact.surface);
  INFO("light form against the exact result: " << gap << " mm");
  CHECK(gap <= light.bound_mm);
  CHECK(gap > 0);
  CHECK_THAT(r.report.brief(), Contains("light form of the exact degree 10 x 10"));
}

TEST_CASE("deform_surface: bounds stack through later steps, E = e + L E_in",
          "[budget][surface_deformation]") {
  const surface::BSplineSurface s = dome();
  DeformationStack stack;
  stack.steps.push_back({bulge(), "bulge", true});
  stack.steps.push_back({flare(), "flare", true});
  SurfaceDeformationOptions options;
  options.budget = Budget{};
  options.budget->max_control_points = 100;  // the bulge's exact 12 x 12 net is above it
  options.budget->light.relative_tolerance = 1e-3;
  const SurfaceDeformationResult r = deform_surface(stack, s, options);
  INFO(r.report.brief());
  const StepOutcome& first = r.report.steps[0];
  REQUIRE(first.method == StepOutcome::Method::Light);
  CHECK(first.exact_size.control_points == 144);
  const StepOutcome& second = r.report.steps[1];
  // The flare of the light bicubic: exact or light, its bound carries the first one's, stretched
  // by the flare's Lipschitz bound (r(z) >= 1 where the dome is, so at least the first bound).
  CHECK(second.accumulated_bound_mm >= second.bound_mm + first.accumulated_bound_mm);
  CHECK(std::isfinite(second.accumulated_bound_mm));
  // Against the pointwise map of the original (the exact reference), at random parameters.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0;
  for (int k = 0; k < 3000; ++k) {
    const double u = unit(rng), v = unit(rng);
    worst = std::max(worst, (surface::evaluate(r.surface, u, v) -
                             deform_point(stack, surface::evaluate(s, u, v)))
                                .norm());
  }
  INFO("against the pointwise map: " << worst << " mm, ledger " << r.report.accumulated_bound_mm);
  CHECK(worst <= r.report.accumulated_bound_mm);
  CHECK(worst > first.bound_mm / 100);

  // An input already off its reference: an exact step carries that bound, times its Lipschitz.
  SurfaceDeformationOptions carried;
  carried.input_bound_mm = 0.5;
  const SurfaceDeformationResult c = deform_surface(Deformation(flare()), s, carried);
  CHECK(c.report.steps[0].method == StepOutcome::Method::Exact);
  CHECK(c.report.accumulated_bound_mm >= 0.5);
  // |D'| of the flare near the dome is below 1.3 (r <= 1.09, r' x <= 0.25): its bound is a
  // bound, not that value, but not far from it.
  CHECK(c.report.accumulated_bound_mm <= 0.5 * 2);
  // Unknown (inf) stays unknown.
  carried.input_bound_mm = std::numeric_limits<double>::infinity();
  CHECK(std::isinf(deform_surface(Deformation(flare()), s, carried).report.accumulated_bound_mm));
}

TEST_CASE("deform_surface: a light form that misses its tolerance, and bad budgets, are refused",
          "[budget][surface_deformation][errors]") {
  const surface::BSplineSurface s = dome();
  SurfaceDeformationOptions options;
  options.budget = Budget{};
  options.budget->max_degree = 4;
  options.budget->light.relative_tolerance = 1e-12;
  options.budget->light.max_control_points = 16;
  const auto [category, message] =
      error_of([&] { deform_surface(Deformation(bulge()), s, options); });
  CHECK(category == ErrorCategory::ToleranceNotMet);
  CHECK_THAT(message, Contains("steps[0] (bezier_lattice)") &&
                          Contains("its exact form (degree 5 x 5") &&
                          Contains("its light form misses its tolerance"));
  options.accept_out_of_tolerance = true;  // kept, with its figures
  const SurfaceDeformationResult kept = deform_surface(Deformation(bulge()), s, options);
  CHECK_FALSE(kept.report.summary.converged());

  SurfaceDeformationOptions bad;
  bad.budget = Budget{};
  bad.budget->max_degree = 0;
  bad.budget->max_control_points = 0;
  bad.input_bound_mm = -1;
  const auto problems = bad.problems();
  REQUIRE(problems.size() == 3);
  CHECK_THAT(problems[0], Contains("Budget: max_degree = 0"));
  CHECK_THAT(problems[1], Contains("Budget: max_control_points = 0"));
  CHECK_THAT(problems[2], Contains("input_bound_mm = -1"));
  const auto [bad_category, bad_message] =
      error_of([&] { deform_surface(Deformation(bulge()), s, bad); });
  CHECK(bad_category == ErrorCategory::InvalidArgument);
  CHECK(Budget::light_fit().keep_breakpoints == false);
}
