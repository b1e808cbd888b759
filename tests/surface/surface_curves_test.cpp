// Curves from a surface (issue #21 item 5): exact iso-curves against pointwise evaluation, and
// projections and normal offsets against the closed form on a cylinder.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/surface_curves.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "error_of.hpp"
#include "random_geometry.hpp"

using namespace clay::surface;
using clay::test::error_of;

namespace {

/// A cylinder of radius 100 about the z axis, z in [0, 200]: exact rational (revolve).
BSplineSurface cylinder() {
  Points3 p(2, 3);
  p << 100, 0, 0, 100, 0, 200;
  return revolve(make_curve(1, {0, 0, 1, 1}, p), Axis{}).surface;
}

/// A wavy curve outside the cylinder, going half way round and up.
BSplineCurve wavy() {
  Points3 p(6, 3);
  for (int i = 0; i < 6; ++i) {
    const double a = 0.5 * i, r = 130 + 15 * std::sin(1.7 * i);
    p.row(i) << r * std::cos(a), r * std::sin(a), 20 + 30 * i;
  }
  return make_curve(3, {0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1}, p);
}

}  // namespace

TEST_CASE("iso-curves are the surface's points at every parameter", "[surface_curves]") {
  std::mt19937 rng(2111);
  for (bool rational : {false, true}) {
    const BSplineSurface s = clay::test::random_surface(rng, 3, 2, 7, 5, rational);
    const auto [ua, ub] = s.u.domain();
    const auto [va, vb] = s.v.domain();
    for (double u : {ua, ua + 0.37 * (ub - ua), ub}) {
      const BSplineCurve c = iso_curve_u(s, u);
      CHECK(c.is_rational() == rational);
      double worst = 0;
      for (double v : linspace(va, vb, 101))
        worst = std::max(worst, (evaluate(c, v) - evaluate(s, u, v)).norm());
      CHECK(worst < 1e-12 * 400);
    }
    for (double v : {va, va + 0.61 * (vb - va), vb}) {
      const BSplineCurve c = iso_curve_v(s, v);
      double worst = 0;
      for (double u : linspace(ua, ub, 101))
        worst = std::max(worst, (evaluate(c, u) - evaluate(s, u, v)).norm());
      CHECK(worst < 1e-12 * 400);
    }
    const double beyond = ub + 1;  // a structured binding cannot be captured (Clang 14)
    CHECK(error_of([&] { iso_curve_u(s, beyond); }).first == clay::ErrorCategory::OutOfDomain);
  }
}

TEST_CASE("a curve projected onto a cylinder follows the radial closed form", "[surface_curves]") {
  const BSplineSurface s = cylinder();
  const BSplineCurve c = wavy();
  CurveFitOptions o;
  o.tolerance_mm = 1e-3;
  const FittedCurve fit = project_curve(c, s, o);
  INFO(fit.curve.basis.count() << " control points, deviation " << fit.max_deviation_mm);
  CHECK(fit.max_deviation_mm <= 1e-3);
  double worst = 0;
  for (double t : linspace(0, 1, 2001)) {
    const Eigen::Vector3d q = evaluate(c, t);
    // Closest point on the cylinder: radially in, height kept.
    const Eigen::Vector3d foot(100 * q.x() / q.head<2>().norm(), 100 * q.y() / q.head<2>().norm(),
                               q.z());
    worst = std::max(worst, (evaluate(fit.curve, t) - foot).norm());
  }
  CHECK(worst <= 1e-3);
}

TEST_CASE("a curve offset along the normal of a cylinder", "[surface_curves]") {
  const BSplineSurface s = cylinder();
  // An iso-curve round the cylinder at height 80, offset by 12 mm: a circle of radius 100 +- 12.
  const BSplineCurve ring = iso_curve_v(s, 0.4);
  CurveFitOptions o;
  o.tolerance_mm = 1e-4;
  const FittedCurve out = offset_along_normal(ring, s, 12.0, o);
  CHECK(out.max_deviation_mm <= 1e-4);
  // The side follows S_u x S_v; find it from the surface, then check the radius everywhere.
  const Eigen::Vector3d n = unit_normal(s, 0.1, 0.4);
  const Eigen::Vector3d p = evaluate(s, 0.1, 0.4);
  const double side = n.dot(Eigen::Vector3d(p.x(), p.y(), 0).normalized()) > 0 ? 1.0 : -1.0;
  double worst = 0;
  for (double t : linspace(0, 1, 1001)) {
    const Eigen::Vector3d q = evaluate(out.curve, t);
    worst = std::max(worst, std::abs(q.head<2>().norm() - (100 + side * 12.0)));
    worst = std::max(worst, std::abs(q.z() - 80.0));
  }
  CHECK(worst <= 1e-4);
}

TEST_CASE("curves from a surface refuse bad input", "[surface_curves]") {
  const BSplineSurface s = cylinder();
  CurveFitOptions bad;
  bad.tolerance_mm = -1;
  CHECK_THAT(error_of([&] { project_curve(wavy(), s, bad); }).second,
             Catch::Contains("CurveFitOptions::tolerance_mm"));
  CHECK(error_of([&] { offset_along_normal(wavy(), s, NAN); }).first ==
        clay::ErrorCategory::InvalidArgument);
  // A tolerance no fit of 8 control points reaches: the message names the limit and the fix.
  CurveFitOptions tight;
  tight.tolerance_mm = 1e-12;
  tight.max_control_points = 8;
  const auto [category, message] = error_of([&] { project_curve(wavy(), s, tight); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("max_control_points") && Catch::Contains("tolerance"));
}
