#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <numbers>
#include <random>

#include "random_geometry.hpp"

using namespace clay::surface;

namespace {

BSplineSurface good_surface() {
  std::mt19937 rng(3);
  return clay::test::random_surface(rng, 2, 3, 4, 5, true);
}

/// Runs validate() and returns the clay::Error message; fails the test when nothing is thrown.
std::string error_of(const BSplineSurface& s) {
  try {
    validate(s, "test surface");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidGeometry);
    return e.what();
  }
  FAIL("validate(surface) did not throw");
  return {};
}

}  // namespace

TEST_CASE("a valid surface and curve pass validation", "[bspline]") {
  CHECK(problems(good_surface()).empty());
  CHECK_NOTHROW(validate(good_surface()));
  std::mt19937 rng(4);
  CHECK(problems(clay::test::random_curve(rng, 3, 6, true, false)).empty());
  const BSplineCurve line =
      make_curve(1, {0, 0, 1, 1}, (Points3(2, 3) << 0, 0, 0, 1, 2, 3).finished());
  CHECK_FALSE(line.is_rational());
  CHECK(line.weights.size() == 2);
}

TEST_CASE("surface invariant: knots non-decreasing", "[bspline][errors]") {
  BSplineSurface s = good_surface();
  std::swap(s.u.knots[3], s.u.knots[4]);
  s.u.knots[3] = 0.9;
  s.u.knots[4] = 0.1;
  CHECK_THAT(error_of(s), Catch::Contains("test surface u basis") && Catch::Contains("decrease"));
}

TEST_CASE("surface invariant: control point count matches degree and knots", "[bspline][errors]") {
  BSplineSurface s = good_surface();
  s.points.conservativeResize(s.points.rows() - 1, 3);  // one control point short
  s.weights.conservativeResize(s.weights.rows() - 1);
  CHECK_THAT(error_of(s),
             Catch::Contains("has 19 control points") && Catch::Contains("4 x 5 = 20"));
}

TEST_CASE("surface invariant: weights positive", "[bspline][errors]") {
  BSplineSurface s = good_surface();
  s.weights[7] = 0.0;
  CHECK_THAT(error_of(s),
             Catch::Contains("weight of control point (1, 2)") && Catch::Contains("positive"));
  s.weights[7] = -2.0;
  CHECK_THAT(error_of(s), Catch::Contains("-2"));
}

TEST_CASE("surface invariant: weights finite", "[bspline][errors]") {
  BSplineSurface s = good_surface();
  s.weights[2] = std::numeric_limits<double>::infinity();
  CHECK_THAT(error_of(s), Catch::Contains("weight of control point (0, 2)"));
}

TEST_CASE("surface invariant: coordinates finite", "[bspline][errors]") {
  BSplineSurface s = good_surface();
  s.points(19, 1) = std::nan("");
  CHECK_THAT(error_of(s), Catch::Contains("control point (3, 4)") && Catch::Contains("non-finite"));
}

TEST_CASE("surface invariant: weight count", "[bspline][errors]") {
  BSplineSurface s = good_surface();
  s.weights.resize(3);
  CHECK_THAT(error_of(s), Catch::Contains("3 weights for 20"));
}

TEST_CASE("surface invariant: multiplicity at most the degree inside", "[bspline][errors]") {
  BSplineSurface s = good_surface();  // u: degree 2, 4 points: knots 0 0 0 k 1 1 1
  s.u.knots = {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1};
  s.points.conservativeResize(s.points.rows() + 10, 3);
  s.weights.conservativeResize(s.weights.rows() + 10);
  s.points.bottomRows(10).setZero();
  s.weights.tail(10).setOnes();
  REQUIRE(s.u.count() == 6);
  CHECK_THAT(error_of(s), Catch::Contains("knot 0.5 has multiplicity 3"));
}

TEST_CASE("curve invariants raise clay::Error naming the curve", "[bspline][errors]") {
  CHECK_THROWS_AS(make_curve(3, {0, 0, 0, 0, 1, 1, 1, 1}, Points3::Zero(3, 3)), clay::Error);
  try {
    make_curve(2, {0, 0, 0, 1, 1, 1}, Points3::Zero(3, 3), Eigen::Vector3d(1, std::nan(""), 1));
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("weight of control point 1"));
  }
}

TEST_CASE("identical compares bit for bit", "[bspline]") {
  const BSplineSurface a = good_surface();
  BSplineSurface b = a;
  CHECK(identical(a, b));
  b.points(0, 0) = std::nextafter(b.points(0, 0), 1e300);
  CHECK_FALSE(identical(a, b));
  const auto [lo, hi] = control_box(a);
  CHECK((lo.array() <= hi.array()).all());
}

TEST_CASE("reversed runs a curve backwards on the same domain", "[bspline]") {
  std::mt19937 rng(5);
  for (bool clamped : {true, false}) {
    const BSplineCurve c = clay::test::random_curve(rng, 3, 8, true, clamped, 2);
    const BSplineCurve r = reversed(c);
    const auto [a, b] = c.basis.domain();
    CHECK(r.basis.domain() == c.basis.domain());
    for (double t : linspace(a, b, 41))
      CHECK((evaluate(r, a + b - t) - evaluate(c, t)).norm() < 1e-12);
    // Twice reversed: the same control net bit for bit; knots a + b - (a + b - k) up to rounding.
    const BSplineCurve rr = reversed(r);
    CHECK(rr.points == c.points);
    CHECK(rr.weights == c.weights);
    for (size_t k = 0; k < c.basis.knots.size(); ++k)
      CHECK(std::abs(rr.basis.knots[k] - c.basis.knots[k]) <= 4e-16 * (std::abs(a) + std::abs(b)));
  }
}

TEST_CASE("mirrored reflects a curve at every parameter, and twice gives it back", "[bspline]") {
  std::mt19937 rng(8);
  const BSplineCurve c = clay::test::random_curve(rng, 3, 8, true);
  const Eigen::Vector3d origin(1, -2, 3), normal(0.3, -1.1, 0.7);  // any length
  const Eigen::Vector3d n = normal.normalized();
  const BSplineCurve m = mirrored(c, origin, normal);
  const auto [a, b] = c.basis.domain();
  for (double t : linspace(a, b, 41)) {
    const Eigen::Vector3d p = evaluate(c, t);
    const Eigen::Vector3d reflected = p - 2 * (p - origin).dot(n) * n;  // independent
    CHECK((evaluate(m, t) - reflected).norm() <= 1e-12 * (1 + p.norm()));
  }
  CHECK(m.basis.knots == c.basis.knots);
  CHECK(m.weights == c.weights);
  const BSplineCurve back = mirrored(m, origin, normal);
  CHECK((back.points - c.points).cwiseAbs().maxCoeff() <= 1e-12 * c.points.cwiseAbs().maxCoeff());
  CHECK_THROWS_AS(mirrored(c, origin, Eigen::Vector3d::Zero()), clay::Error);
}

TEST_CASE("mirrored reflects a surface with u reversed, so its normal is the mirror image",
          "[bspline]") {
  const BSplineSurface s = good_surface();  // rational
  const Eigen::Vector3d origin(0, 0, 1), n(1, 0, 0);
  const BSplineSurface m = mirrored(s, origin, 2 * n);
  CHECK(problems(m).empty());
  const auto [a, b] = s.u.domain();
  const auto [c, d] = s.v.domain();
  for (double u : linspace(a, b, 9))
    for (double v : linspace(c, d, 9)) {
      const SurfaceDerivatives x = derivatives(s, a + b - u, v, 1);
      const SurfaceDerivatives y = derivatives(m, u, v, 1);
      const Eigen::Vector3d reflected = x.point - 2 * (x.point - origin).dot(n) * n;
      CHECK((y.point - reflected).norm() <= 1e-12 * (1 + x.point.norm()));
      // The normal: the reflection of the original's normal.
      const Eigen::Vector3d nx = x.du.cross(x.dv).normalized(), ny = y.du.cross(y.dv).normalized();
      const Eigen::Vector3d nx_reflected = nx - 2 * nx.dot(n) * n;
      CHECK(ny.dot(nx_reflected) >= 1 - 1e-9);
    }
}

TEST_CASE("arc_through is the circle through its three points, ends exact", "[bspline]") {
  const Eigen::Vector3d p0(10, 0, 5), p1(3, 7, 6), p2(-8, 2, 4);
  const BSplineCurve arc = arc_through(p0, p1, p2);
  // The circumcentre, independently: on the points' plane, equidistant from all three.
  const Eigen::Vector3d w = (p1 - p0).cross(p2 - p0);
  Eigen::Matrix3d m;
  Eigen::Vector3d rhs;
  m.row(0) = 2 * (p1 - p0).transpose();
  m.row(1) = 2 * (p2 - p0).transpose();
  m.row(2) = w.transpose();
  rhs << p1.squaredNorm() - p0.squaredNorm(), p2.squaredNorm() - p0.squaredNorm(), w.dot(p0);
  const Eigen::Vector3d center = m.fullPivLu().solve(rhs);
  const double r = (p0 - center).norm();
  const auto [t0, t1] = arc.basis.domain();
  double nearest_through = 1e300;
  for (double t : linspace(t0, t1, 2001)) {
    const Eigen::Vector3d q = evaluate(arc, t);
    CHECK(std::abs((q - center).norm() - r) <= 1e-12 * r);
    CHECK(std::abs((q - center).dot(w.normalized())) <= 1e-12 * r);
    nearest_through = std::min(nearest_through, (q - p1).norm());
  }
  CHECK(nearest_through <= 1e-2 * r);  // it passes `through` (sampled at 2,001 points)
  CHECK(Eigen::Vector3d(arc.points.row(0).transpose()) == p0);
  CHECK(Eigen::Vector3d(arc.points.row(arc.points.rows() - 1).transpose()) == p2);
  // More than half a turn when `through` lies on the far side: the sweep follows it.
  const BSplineCurve major =
      arc_through(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, -1, 0));
  CHECK(major.points.rows() == 7);  // three 90-degree segments: 270 degrees
  CHECK((evaluate(major, 2.0 / 3) - Eigen::Vector3d(-1, 0, 0)).norm() <= 1e-15);
  CHECK((evaluate(major, 1.0 / 3) - Eigen::Vector3d(0, 1, 0)).norm() <= 1e-15);
  CHECK_THROWS_AS(arc_through(p0, 0.5 * (p0 + p2), p2), clay::Error);  // on one line
  CHECK_THROWS_AS(arc_through(p0, p0, p2), clay::Error);
}
