// A surface through a deformation stack (issue #7 items 5 and 6): exact steps stay exact, other
// steps are refitted with a certified bound when allowed and refused with the reason when not.
// Every result is checked against the pointwise deformation of the original (deform_point of the
// stack) at random parameters.
#include <catch2/catch.hpp>

#include <clay/deform/surface_deformation.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "error_of.hpp"
#include "shapes.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;
using namespace clay::test;
namespace surface = clay::surface;

namespace {

/// A bicubic dome, 100 x 100 mm, inside box_frame().
surface::BSplineSurface dome() {
  const auto b = surface::clamped_uniform_basis(3, 6);
  const auto xi = surface::greville_abscissae(b);
  surface::Points3 p(36, 3);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const double x = 100 * xi[static_cast<size_t>(i)], y = 100 * xi[static_cast<size_t>(j)];
      p.row(i * 6 + j) << x, y, 20 * std::sin(0.03 * x) * std::sin(0.03 * y);
    }
  return surface::make_surface(b, b, p);
}

Twist spin() {
  Twist t;
  t.frame.origin = {50, 50, 0};
  t.angle = {0.0, 0.004};  // 0.004 rad per mm of height
  return t;
}

/// Largest |result(u, v) - deform_point(stack, S(u, v))| at n random parameters.
double worst_against_pointwise(const DeformationStack& stack,
                               const surface::BSplineSurface& original,
                               const surface::BSplineSurface& result, int n) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0;
  for (int k = 0; k < n; ++k) {
    const double u = unit(rng), v = unit(rng);
    const Eigen::Vector3d want = deform_point(stack, surface::evaluate(original, u, v));
    worst = std::max(worst, (surface::evaluate(result, u, v) - want).norm());
  }
  return worst;
}

}  // namespace

TEST_CASE("deform_surface: a stack of exact steps stays an exact NURBS", "[surface_deformation]") {
  const surface::BSplineSurface s = dome();
  DeformationStack stack;
  stack.steps.push_back({bulge(), "bulge", true});
  stack.steps.push_back({flare(), "flare", true});
  stack.steps.push_back({spin(), "off", false});  // disabled: skipped
  const SurfaceDeformationResult r = deform_surface(stack, s);
  INFO(r.report.brief());
  REQUIRE(r.report.steps.size() == 3);
  CHECK(r.report.exact);
  CHECK(r.report.summary.converged());
  CHECK(r.report.summary.message == r.report.brief());
  CHECK(r.report.steps[0].method == StepOutcome::Method::Exact);
  CHECK(r.report.steps[1].method == StepOutcome::Method::Exact);
  CHECK(r.report.steps[2].method == StepOutcome::Method::Skipped);
  // The dome is axis-aligned in the lattice: s is linear in u only, t in v only, u bicubic, so
  // the bulge gives degree 2 + 0 + 3 = 5 and the linear taper 5 + 5 = 10 in each direction.
  CHECK(r.surface.u.degree == 10);
  CHECK(r.surface.v.degree == 10);
  const double size = box_frame().s.norm();
  CHECK(worst_against_pointwise(stack, s, r.surface, 2000) <= 1e-12 * size);
  CHECK(r.report.degree_u == r.surface.u.degree);
  CHECK(r.report.control_points == r.surface.points.rows());
}

TEST_CASE("deform_surface: a twist is refitted with a certified bound that holds",
          "[surface_deformation]") {
  const surface::BSplineSurface s = dome();
  DeformationStack stack;
  stack.steps.push_back({bulge(), "bulge", true});
  stack.steps.push_back({spin(), "spin", true});
  SurfaceDeformationOptions options;
  options.refit = RefitOptions{};
  options.refit->relative_tolerance = 1e-4;
  const SurfaceDeformationResult r = deform_surface(stack, s, options);
  INFO(r.report.brief());
  CHECK_FALSE(r.report.exact);
  CHECK(r.report.steps[0].method == StepOutcome::Method::Exact);
  REQUIRE(r.report.steps[1].method == StepOutcome::Method::Refit);
  CHECK_THAT(r.report.steps[1].reason, Contains("not polynomial"));
  const RefitReport& fit = r.report.steps[1].refit;
  REQUIRE(fit.certified);
  CHECK(fit.certified_bound_mm <= fit.tolerance_mm);
  // The exact first step contributes rounding only: the bound of the refit holds for the stack.
  CHECK(worst_against_pointwise(stack, s, r.surface, 2000) <= fit.certified_bound_mm + 1e-9);
  // Without a refit the twist is refused, naming the step and the way out.
  auto [category, message] = error_of([&] { deform_surface(stack, s); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("steps[1] (twist 'spin')"));
  CHECK_THAT(message, Contains("refit"));
}

TEST_CASE(
    "deform_surface: above the degree limit, a refit when allowed, the DegreeLimit error otherwise",
    "[surface_deformation]") {
  const surface::BSplineSurface s = dome();
  // A frame turned against the dome: every local coordinate is bicubic, so the exact result
  // would have degree 3 x 3 + 3 x 3 + 3 x 3 = 27 > 25 in each direction.
  const Eigen::Vector3d a(std::cos(0.35), std::sin(0.35), 0.1),
      b(-std::sin(0.35), std::cos(0.35), 0.1);
  Frame turned;
  turned.s = 170 * a;
  turned.t = 170 * b;
  turned.u = 90 * a.cross(b).normalized();
  turned.origin = Eigen::Vector3d(50, 50, 0) - 0.5 * (turned.s + turned.t + turned.u);
  BezierLattice heavy = make_bezier_lattice(turned, {3, 3, 3});
  heavy.points.row(heavy.index(1, 2, 3)) += Eigen::RowVector3d(0, 0, 8);
  const Deformation d = heavy;
  auto [category, message] = error_of([&] { deform_surface(d, s); });
  CHECK(category == ErrorCategory::DegreeLimit);
  CHECK_THAT(message, Contains("steps[0]"));
  SurfaceDeformationOptions options;
  options.refit = RefitOptions{};
  const SurfaceDeformationResult r = deform_surface(d, s, options);
  INFO(r.report.brief());
  REQUIRE(r.report.steps[0].method == StepOutcome::Method::Refit);
  CHECK_THAT(r.report.steps[0].reason, Contains("degree"));
  CHECK(r.surface.u.degree == 3);
  DeformationStack one;
  one.steps.push_back({heavy, {}, true});
  CHECK(worst_against_pointwise(one, s, r.surface, 1000) <=
        r.report.steps[0].refit.certified_bound_mm + 1e-9);
}

TEST_CASE("deform_surface: bad input", "[surface_deformation][errors]") {
  const surface::BSplineSurface s = dome();
  DeformationStack bad;
  BezierLattice broken = bulge();
  broken.points(0, 0) = std::nan("");
  bad.steps.push_back({broken, "broken", true});
  CHECK(error_of([&] { deform_surface(bad, s); }).first == ErrorCategory::InvalidGeometry);
  SurfaceDeformationOptions options;
  options.compose.check_samples = -1;
  CHECK(error_of([&] { deform_surface(Deformation{bulge()}, s, options); }).first ==
        ErrorCategory::InvalidArgument);
  options = {};
  options.refit = RefitOptions{};
  options.refit->degree = 0;
  CHECK(error_of([&] { deform_surface(Deformation{bulge()}, s, options); }).first ==
        ErrorCategory::InvalidArgument);
  surface::BSplineSurface nan_surface = s;
  nan_surface.points(3, 1) = std::nan("");
  CHECK(error_of([&] { deform_surface(Deformation{bulge()}, nan_surface); }).first ==
        ErrorCategory::InvalidGeometry);
}

// Issue #18: a refit that misses its tolerance is a failure, not a warning.
TEST_CASE(
    "deform_surface: a lattice torn where the surface leaves it is refused at once, naming the "
    "jump",
    "[surface_deformation][errors]") {
  const surface::BSplineSurface s = dome();  // x, y in [0, 100]
  // The lattice covers x in [-10, 60] only: the dome crosses its face s = 1 along x = 60, and
  // every control point is displaced, that face's too.
  Frame half = box_frame();
  half.s = {70, 0, 0};
  BezierLattice torn = make_bezier_lattice(half, {2, 2, 1});
  for (Eigen::Index r = 0; r < torn.points.rows(); ++r)
    torn.points.row(r) += Eigen::RowVector3d(0, 0, 6 + r % 3);
  const Deformation d = torn;
  // The independent figure: at the crossing x = 60 the face s = 1 is moved by P(1, t, u) − X,
  // here straight up by 6..8 mm, while the surface outside stays put.
  const Eigen::Vector3d on_face = surface::evaluate(s, 0.6, 0.5);
  const double jump = (deform_point(torn, on_face) - on_face).norm();
  REQUIRE(jump > 5);
  SurfaceDeformationOptions options;
  options.refit = RefitOptions{};
  options.refit->relative_tolerance = 1e-4;
  const auto [category, message] = error_of([&] { deform_surface(d, s, options); });
  CHECK(category == ErrorCategory::ToleranceNotMet);
  CHECK_THAT(message, Contains("steps[0]") && Contains("discontinuous") &&
                          Contains("lattice face s = 1") &&
                          Contains("no refit can come closer than half the jump") &&
                          Contains("Enlarge the lattice"));
  // The figure in the message is the map's jump, measured where the surface crosses the face.
  const auto at = message.find("jumps by ");
  REQUIRE(at != std::string::npos);
  const double said = std::stod(message.substr(at + 9));
  CHECK(said <= 8 * (1 + 1e-3));  // printed to 4 digits
  CHECK(said >= jump * (1 - 1e-3));
  // A tolerance above half the jump is not refused up front (the refit's own bound decides).
  options.refit->relative_tolerance = 0;
  options.refit->tolerance_mm = 10;
  options.refit->max_iterations = 2;
  options.accept_out_of_tolerance = true;
  CHECK_NOTHROW(deform_surface(d, s, options));
}

TEST_CASE("deform_surface: a refit that cannot meet a too tight tolerance within its limits fails",
          "[surface_deformation][errors]") {
  const surface::BSplineSurface s = dome();
  DeformationStack stack;
  stack.steps.push_back({spin(), "spin", true});
  SurfaceDeformationOptions options;
  options.refit = RefitOptions{};
  options.refit->relative_tolerance =
      1e-11;  // relative: 1.4e-9 mm, far below what 2 rounds can reach
  options.refit->max_iterations = 2;
  const auto [category, message] = error_of([&] { deform_surface(stack, s, options); });
  CHECK(category == ErrorCategory::ToleranceNotMet);
  CHECK_THAT(message, Contains("steps[0] (twist 'spin') misses its tolerance") &&
                          Contains("iteration limit 2 reached") &&
                          Contains("accept_out_of_tolerance"));
  // With the opt-in the result comes back, with its figures.
  options.accept_out_of_tolerance = true;
  const SurfaceDeformationResult r = deform_surface(stack, s, options);
  const RefitReport& fit = r.report.steps[0].refit;
  CHECK_FALSE(fit.summary.converged());
  CHECK(fit.certified_bound_mm > fit.tolerance_mm);
  // The bound is honest: the pointwise deformation is within it.
  CHECK(worst_against_pointwise(stack, s, r.surface, 1000) <= fit.certified_bound_mm);
}
