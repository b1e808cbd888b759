#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <cmath>
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
