#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <random>

#include "random_geometry.hpp"

using namespace clay::surface;
using clay::test::relative_deviation;

TEST_CASE("degree elevation keeps curves unchanged and adds one multiplicity per breakpoint",
          "[elevate]") {
  std::mt19937 rng(41);
  for (int p = 1; p <= 8; ++p) {
    for (int t : {1, 2, 5}) {
      for (bool clamped : {true, false}) {
        const BSplineCurve c = clay::test::random_curve(rng, p, p + 6, true, clamped, p);
        const BSplineCurve e = elevate_degree(c, t);
        CHECK(e.basis.degree == p + t);
        CHECK(problems(e).empty());
        CHECK(relative_deviation(c, e) < 1e-12);
        for (double xi : breakpoints(c.basis)) {
          const auto [a, b] = c.basis.domain();
          const int expect = (xi == a || xi == b) ? p + t + 1 : multiplicity(c.basis, xi) + t;
          CHECK(multiplicity(e.basis, xi) == expect);
        }
      }
    }
  }
}

TEST_CASE("degree elevation of surfaces in u and v", "[elevate]") {
  std::mt19937 rng(42);
  for (int p = 1; p <= 4; ++p) {
    const BSplineSurface s =
        clay::test::random_surface(rng, p, 5 - p, p + 4, 8 - p, true, p % 2 == 1, 2);
    const BSplineSurface eu = elevate_degree_u(s, 2);
    const BSplineSurface ev = elevate_degree_v(s, 1);
    CHECK(eu.u.degree == p + 2);
    CHECK(ev.v.degree == 6 - p);
    CHECK(relative_deviation(s, eu) < 1e-12);
    CHECK(relative_deviation(s, ev) < 1e-12);
    CHECK(relative_deviation(s, clamp(s)) < 1e-12);
    CHECK(is_clamped(clamp(s).u));
    CHECK(is_clamped(clamp(s).v));
  }
  // Elevating a Bézier patch gives the classical count (p + t + 1) and keeps the corners exactly.
  std::mt19937 rng2(43);
  const BSplineSurface bez =
      extract_bezier(clay::test::random_surface(rng2, 3, 3, 4, 4, false)).patch(0, 0);
  const BSplineSurface e = elevate_degree_u(bez, 3);
  CHECK(e.count_u() == 7);
  CHECK(e.points.row(0) == bez.points.row(0));
}

TEST_CASE("degree elevation refuses bad requests", "[elevate][errors]") {
  std::mt19937 rng(44);
  const BSplineCurve c = clay::test::random_curve(rng, 3, 5, false);
  CHECK_THROWS_AS(elevate_degree(c, -1), clay::Error);
  try {
    elevate_degree(c, max_kernel_degree);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidArgument);
    CHECK_THAT(e.what(), Catch::Contains("kernel limit"));
  }
  CHECK(identical(elevate_degree(c, 0), c));
}

TEST_CASE("clamp makes an unclamped curve clamped on the same domain", "[elevate]") {
  std::mt19937 rng(45);
  for (int p = 1; p <= 6; ++p) {
    const BSplineCurve c = clay::test::random_curve(rng, p, p + 4, true, false);
    REQUIRE_FALSE(is_clamped(c.basis));
    const BSplineCurve k = clamp(c);
    CHECK(is_clamped(k.basis));
    CHECK(k.basis.domain() == c.basis.domain());
    CHECK(relative_deviation(c, k) < 1e-12);
    // A clamped curve's end points are its end control points.
    const auto [a, b] = k.basis.domain();
    CHECK((evaluate(c, a) - k.points.row(0).transpose()).norm() < 1e-10);
    CHECK((evaluate(c, b) - k.points.row(k.points.rows() - 1).transpose()).norm() < 1e-10);
    CHECK(identical(clamp(k), k));
  }
}

TEST_CASE("polynomial objects stay polynomial through knot and degree operations",
          "[elevate][knots]") {
  std::mt19937 rng(46);
  for (int p = 1; p <= 6; ++p) {
    const BSplineCurve c = clay::test::random_curve(rng, p, p + 5, false, p % 2 == 0);
    CHECK_FALSE(elevate_degree(c, 3).is_rational());
    CHECK_FALSE(clamp(c).is_rational());
    CHECK_FALSE(insert_knot(c, 0.3).is_rational());
    for (const auto& seg : extract_bezier(c)) CHECK_FALSE(seg.is_rational());
    const BSplineSurface s = clay::test::random_surface(rng, p, 3, p + 4, 6, false, p % 2 == 1);
    CHECK_FALSE(elevate_degree_u(s, 2).is_rational());
    CHECK_FALSE(elevate_degree_v(s, 1).is_rational());
    for (const auto& patch : extract_bezier(s).patches) CHECK_FALSE(patch.is_rational());
    CHECK((elevate_degree_u(s, 2).weights.array() == 1.0).all());
  }
}
