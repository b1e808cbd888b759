// Surfaces built to meet keep meeting when each is refitted alone (issue #38 step 3):
// deform::shared_boundaries finds the sides two surfaces share and how they meet there, and a
// refit that follows them keeps the join, checked between the two refitted surfaces at points
// the refits never sampled.
#include <catch2/catch.hpp>

#include <clay/deform.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "error_of.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;
namespace surface = clay::surface;

namespace {

// Half a cylinder r 10, h 40 (y >= 0: revolved 180 deg about z from x = 10) and its mirror in
// y = 0: two halves meeting tangentially (G2) along the lines x = +-10, y = 0.
std::pair<surface::BSplineSurface, surface::BSplineSurface> halves() {
  surface::Points3 line(2, 3);
  line << 10, 0, 0, 10, 0, 40;
  const auto half =
      surface::revolve(surface::make_curve(1, {0, 0, 1, 1}, line), {{0, 0, 0}, {0, 0, 1}}, 180)
          .surface;
  return {half, surface::mirrored(half, {0, 0, 0}, {0, 1, 0})};
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b))) * 180 / std::numbers::pi;
}

}  // namespace

TEST_CASE("shared_boundaries finds the sides two surfaces share and how they meet",
          "[refit][shared]") {
  const auto sides = halves();
  const surface::BSplineSurface &a = sides.first, &b = sides.second;
  const auto curves = shared_boundaries(a, {&b}, 1e-6);
  // the two lines (the revolution's first and last profile: u = u0, u = u1), tangent: order 2
  REQUIRE(curves.size() == 2);
  const auto [u0, u1] = a.u.domain();
  for (const MatchedCurve& c : curves) {
    CHECK(c.order == 2);
    const Eigen::Vector3d start = surface::evaluate(c.pcurve, c.t0);
    const Eigen::Vector3d end = surface::evaluate(c.pcurve, c.t1);
    CHECK(start.x() == end.x());  // u fixed along it
    CHECK((start.x() == u0 || start.x() == u1));
  }
  // a sheet standing on one of the lines, square to the half cylinder there: a crease, order 0
  surface::Points3 corners(4, 3);
  corners << 10, 0, 0, 10, 0, 40, 30, 0, 0, 30, 0, 40;
  const surface::BSplineBasis linear = surface::clamped_uniform_basis(1, 2);
  const auto sheet = surface::make_surface(linear, linear, corners);
  const auto crease = shared_boundaries(a, {&sheet}, 1e-6);
  REQUIRE(crease.size() == 1);
  CHECK(crease[0].order == 0);
  // the sheet moved 0.01 mm off: nothing shared at 1e-6 mm, the line at 0.1 mm
  auto moved = sheet;
  moved.points.col(1).array() += 0.01;
  CHECK(shared_boundaries(a, {&moved}, 1e-6).empty());
  CHECK(shared_boundaries(a, {&moved}, 0.1).size() == 1);
  // A copy of a sheet, or a variant with its boundary all round (an inner point raised, as a
  // style step leaves a surface): the same patch, not a neighbour; the sheet beside it still is.
  auto grid = [](double x0) {
    surface::Points3 p(16, 3);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) p.row(i * 4 + j) << x0 + 10 * i, 20.0 * j / 3, 0;
    return surface::make_surface(surface::clamped_uniform_basis(3, 4),
                                 surface::clamped_uniform_basis(3, 4), p);
  };
  const auto left = grid(0), right = grid(30), copy = grid(0);
  auto variant = left;
  variant.points.row(variant.index(1, 2)) += Eigen::RowVector3d(0, 0, 3);
  CHECK(shared_boundaries(left, {&copy}, 1e-6).empty());
  CHECK(shared_boundaries(left, {&variant}, 1e-6).empty());
  const auto beside = shared_boundaries(left, {&copy, &variant, &right}, 1e-6);
  REQUIRE(beside.size() == 1);
  CHECK(surface::evaluate(beside[0].pcurve, beside[0].t0).x() == 1.0);  // the side u = 1 (x = 30)
  // nothing to share with itself or with no neighbour
  CHECK(shared_boundaries(a, {&a}, 1e-6).empty());
  CHECK(shared_boundaries(a, {}, 1e-6).empty());
  const auto [category, message] = error_of([&] { shared_boundaries(a, {&b}, 0); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("tolerance_mm is 0"));
}

TEST_CASE("Mirrored halves refitted with their shared sides keep meeting tangentially",
          "[refit][shared]") {
  // Both halves twisted about a tilted, offset axis and each refitted alone within 0.05 mm: alone
  // their tangent joins open; following shared_boundaries' curves (0.0005 mm, 0.008 deg each)
  // they meet within twice that, measured between the two fits at 201 points per side.
  const auto sides = halves();  // (not bound: lambdas below use them, which clang 14 refuses)
  const surface::BSplineSurface &a = sides.first, &b = sides.second;
  Twist twist;
  twist.frame.origin = {2, 1, 0};
  twist.frame.axis = {0.2, 0.1, 1};
  twist.angle = {0, 0.015};
  RefitOptions alone;
  alone.relative_tolerance = 0;
  alone.tolerance_mm = 0.05;
  auto fitted = [&](const surface::BSplineSurface& s, const surface::BSplineSurface& other,
                    bool matched) {
    RefitOptions o = alone;
    if (matched) {
      o.matched_curves = shared_boundaries(s, {&other}, 1e-6);
      o.matched_gap_mm = 0.0005;
      o.matched_angle_deg = 0.008;
    }
    const RefitResult r = refit_deformed(twist, s, o);
    INFO(r.report.summary.message);
    REQUIRE(r.report.summary.converged());
    return r.surface;
  };
  // The halves meet along a's sides u = u0 and u = u1, each on one of b's (the mirror may
  // reverse u to keep the normals outward: which one, from the source).
  const double u0 = a.u.domain().first, u1 = a.u.domain().second;
  const double v0 = a.v.domain().first, v1 = a.v.domain().second;
  auto partner = [&](double u) {
    const double mid = 0.5 * (v0 + v1);
    return (surface::evaluate(b, u, mid) - surface::evaluate(a, u, mid)).norm() < 1e-9
               ? u
               : u0 + u1 - u;
  };
  auto worst = [&](const surface::BSplineSurface& fa, const surface::BSplineSurface& fb) {
    std::pair<double, double> w{0, 0};
    for (const double u : {u0, u1})
      for (int k = 0; k <= 200; ++k) {
        const double v = v0 + (v1 - v0) * (k + 0.29) / 201.0;
        const auto da = surface::derivatives(fa, u, v, 1);
        const auto db = surface::derivatives(fb, partner(u), v, 1);
        w.first = std::max(w.first, (da.point - db.point).norm());
        w.second = std::max(w.second, angle_deg(da.du.cross(da.dv), db.du.cross(db.dv)));
      }
    return w;
  };
  const auto [gap_alone, angle_alone] = worst(fitted(a, b, false), fitted(b, a, false));
  const auto [gap, angle] = worst(fitted(a, b, true), fitted(b, a, true));
  INFO("alone: " << gap_alone << " mm, " << angle_alone << " deg; matched: " << gap << " mm, "
                 << angle << " deg");
  CHECK(gap <= 2 * 0.0005);
  CHECK(angle <= 2 * 0.008);
  CHECK(angle_alone > 2 * 0.008);  // matching is what keeps the join
}
