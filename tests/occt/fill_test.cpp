#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/occt/fill.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <Eigen/LU>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "error_of.hpp"
#include "polyline.hpp"
#include "random_geometry.hpp"

using namespace clay::surface;
using Catch::Matchers::WithinAbs;
using clay::test::error_of;
using clay::test::polyline;

namespace {

double curves_size(const std::vector<BSplineCurve>& curves) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& c : curves) {
    lo = lo.cwiseMin(c.points.colwise().minCoeff().transpose());
    hi = hi.cwiseMax(c.points.colwise().maxCoeff().transpose());
  }
  return (hi - lo).norm();
}

/// A random curve of the given degree and count from `from` to `to` (clamped, so the ends are
/// exactly its first and last control points), bulging by up to `bulge` mm.
BSplineCurve curve_between(std::mt19937& rng, int degree, int count, const Eigen::Vector3d& from,
                           const Eigen::Vector3d& to, double bulge, bool rational = false) {
  BSplineCurve c = clay::test::random_curve(rng, degree, count, rational, true, 1, bulge);
  for (int i = 0; i < count; ++i) {
    const double f = double(i) / (count - 1);
    c.points.row(i) += ((1 - f) * from + f * to).transpose();
  }
  c.points.row(0) = from.transpose();
  c.points.row(count - 1) = to.transpose();
  return c;
}

/// Largest pointwise distance between curve c (at normalized parameter f) and the best-matching
/// edge of s (u or v = const, either direction, at the same normalized parameter): an independent
/// check that each boundary curve became an edge of the surface.
double edge_error(const BSplineSurface& s, const BSplineCurve& c) {
  const auto [ua, ub] = s.u.domain();
  const auto [va, vb] = s.v.domain();
  const auto [a, b] = c.basis.domain();
  double best = 1e300;
  for (int edge = 0; edge < 4; ++edge)
    for (bool back : {false, true}) {
      double worst = 0;
      for (double f : linspace(0, 1, 257)) {
        const double g = back ? 1 - f : f;
        const double u = edge == 0 ? ua : edge == 1 ? ub : ua + g * (ub - ua);
        const double v = edge == 2 ? va : edge == 3 ? vb : va + g * (vb - va);
        worst = std::max(
            worst, (evaluate(s, u, v) - evaluate(c, std::clamp(a + f * (b - a), a, b))).norm());
      }
      best = std::min(best, worst);
    }
  return best;
}

/// Four curves of varied degree, count, knots and domains around a warped quad.
std::vector<BSplineCurve> quad_boundary(std::mt19937& rng, bool rational = false) {
  const Eigen::Vector3d p0(0, 0, 0), p1(100, 0, 10), p2(110, 90, -5), p3(-5, 100, 20);
  BSplineCurve c0 = curve_between(rng, 3, 6, p0, p1, 8.0, rational);
  BSplineCurve c1 = curve_between(rng, 2, 4, p1, p2, 8.0, rational);
  BSplineCurve c2 = curve_between(rng, 4, 7, p2, p3, 8.0, rational);
  BSplineCurve c3 = curve_between(rng, 1, 3, p3, p0, 8.0, rational);
  for (double& t : c1.basis.knots) t = 3.0 + 2.0 * t;  // domain [3, 5]
  return {c0, c1, c2, c3};
}

/// Largest distance from samples of c to the surface (closest points): a check that does not
/// depend on the parametrization.
double distance_to(const BSplineSurface& s, const BSplineCurve& c) {
  const auto [a, b] = c.basis.domain();
  double worst = 0;
  for (double t : linspace(a, b, 65))
    worst = std::max(worst, closest_point(s, evaluate(c, t)).distance);
  return worst;
}

/// Fills and checks every curve is an edge: pointwise at the same normalized parameter when the
/// fill keeps the curves' parametrization, else by closest points.
void check_fill(const std::vector<BSplineCurve>& boundary, FillStyle style, bool pointwise = true) {
  FillOptions o;
  o.style = style;
  o.min_span_ratio = 0;  // the construction's own exactness; merging slivers is tested below
  const BuiltSurface built = fill(boundary, o);
  const double size = curves_size(boundary);
  INFO(built.report.brief());
  CHECK(built.report.exact);
  CHECK(built.report.max_deviation_mm <= 1e-9 * size);
  CHECK(problems(built.surface).empty());
  for (const BSplineCurve& c : boundary) {
    if (pointwise)
      CHECK(edge_error(built.surface, c) <= 1e-9 * size);
    else
      CHECK(distance_to(built.surface, c) <= 1e-9 * size);
  }
}

const FillStyle all_styles[] = {FillStyle::Stretch, FillStyle::Coons, FillStyle::Curved};

}  // namespace

TEST_CASE("fill of 4 curves interpolates them exactly in every style", "[fill]") {
  std::mt19937 rng(401);
  const std::vector<BSplineCurve> quad = quad_boundary(rng);
  for (FillStyle style : all_styles) check_fill(quad, style);
}

TEST_CASE("fill of 4 curves in shuffled order and directions", "[fill]") {
  std::mt19937 rng(402);
  const std::vector<BSplineCurve> quad = quad_boundary(rng);
  const std::vector<BSplineCurve> shuffled = {reversed(quad[2]), quad[0], reversed(quad[3]),
                                              quad[1]};
  for (FillStyle style : all_styles) check_fill(shuffled, style);
  const BuiltSurface built = fill(shuffled);
  CHECK_THAT(built.report.method, Catch::Contains("reversed"));
}

TEST_CASE("fill of 4 rational curves is exact", "[fill]") {
  std::mt19937 rng(403);
  // Unequal end weights: the curves are reparametrized (same shape), so only closest points apply.
  for (FillStyle style : all_styles) {
    const std::vector<BSplineCurve> quad = quad_boundary(rng, true);
    check_fill(quad, style, false);
    FillOptions o;
    o.style = style;
    o.min_span_ratio = 0;
    CHECK_THAT(fill(quad, o).report.method, Catch::Contains("reparametrized (Möbius)"));
  }
  // End weights 1 everywhere: no reparametrization, edges equal the curves pointwise.
  for (FillStyle style : all_styles) {
    std::vector<BSplineCurve> quad = quad_boundary(rng, true);
    for (BSplineCurve& c : quad) c.weights[0] = c.weights[c.weights.size() - 1] = 1.0;
    check_fill(quad, style);
  }
}

TEST_CASE("fill of 3 curves collapses one side to the corner", "[fill]") {
  std::mt19937 rng(404);
  const Eigen::Vector3d p0(0, 0, 0), p1(100, 0, 10), p2(40, 90, -5);
  const std::vector<BSplineCurve> tri = {curve_between(rng, 3, 5, p0, p1, 8.0),
                                         reversed(curve_between(rng, 2, 5, p1, p2, 8.0)),
                                         curve_between(rng, 3, 4, p2, p0, 8.0)};
  for (FillStyle style : all_styles) check_fill(tri, style);
}

TEST_CASE("fill of 2 curves: ruled surface (Stretch, Coons) and corner patch (Curved)", "[fill]") {
  std::mt19937 rng(405);
  const BSplineCurve a = curve_between(rng, 3, 6, {0, 0, 0}, {100, 0, 0}, 10.0);
  const BSplineCurve b = curve_between(rng, 2, 5, {0, 80, 20}, {100, 80, 0}, 10.0);
  for (FillStyle style : {FillStyle::Stretch, FillStyle::Coons}) {
    check_fill({a, reversed(b)}, style);
    FillOptions o;
    o.style = style;
    const BuiltSurface ruled = fill({a, reversed(b)}, o);
    CHECK(ruled.surface.v.degree == 1);
    // The ruled surface pairs the ends by distance: S(0, 0) = a start, S(0, 1) = b start.
    CHECK((evaluate(ruled.surface, 0.0, 1.0) - evaluate(b, 0.0)).norm() < 1e-12);
  }
  // Curved: two curves sharing a corner.
  const BSplineCurve c = curve_between(rng, 3, 5, {0, 0, 0}, {10, 90, 30}, 10.0);
  check_fill({a, reversed(c)}, FillStyle::Curved);
}

TEST_CASE("Coons fill of straight sides raises them to degree 3", "[fill]") {
  // Four straight lines (degree 1, 2 control points): OpenCASCADE's Coons needs 4 per side.
  const Eigen::Vector3d p0(0, 0, 0), p1(100, 0, 0), p2(100, 100, 50), p3(0, 100, 0);
  auto line = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    Points3 p(2, 3);
    p << a.transpose(), b.transpose();
    return make_curve(1, {0, 0, 1, 1}, p);
  };
  const std::vector<BSplineCurve> sides = {line(p0, p1), line(p1, p2), line(p2, p3), line(p3, p0)};
  const BuiltSurface built = fill(sides);
  INFO(built.report.brief());
  CHECK_THAT(built.report.method, Catch::Contains("raised from degree 1 to 3"));
  CHECK(built.report.max_deviation_mm < 1e-12 * 200);
  CHECK(built.surface.u.degree == 3);
  CHECK(built.surface.v.degree == 3);
  for (const BSplineCurve& c : sides) CHECK(edge_error(built.surface, c) < 1e-12 * 200);
  // Four coplanar lines: every style stays in their plane.
  const std::vector<BSplineCurve> flat = {line(p0, p1), line(p1, {100, 100, 0}),
                                          line({100, 100, 0}, p3), line(p3, p0)};
  for (FillStyle style : all_styles) {
    FillOptions o;
    o.style = style;
    const BuiltSurface planar = fill(flat, o);
    CHECK(planar.surface.points.col(2).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("fill joins corners within gap_tolerance and reports it", "[fill]") {
  std::mt19937 rng(406);
  std::vector<BSplineCurve> quad = quad_boundary(rng);
  quad[2].points(0, 0) += 2e-5;  // curve #2 starts 2e-5 mm away from curve #1's end
  FillOptions o;
  o.gap_tolerance = 1e-4;
  const BuiltSurface built = fill(quad, o);
  CHECK_THAT(built.report.method, Catch::Contains("corners joined"));
  CHECK(built.report.max_deviation_mm <= 1e-5 + 1e-9);
  CHECK(built.report.max_deviation_mm >= 0.99e-5);
}

TEST_CASE("fill rejects a boundary with a gap, naming the curves and the gap", "[fill][errors]") {
  std::mt19937 rng(407);
  std::vector<BSplineCurve> quad = quad_boundary(rng);
  quad[2].points(0, 0) += 0.25;
  const auto [category, message] = error_of([&] { fill(quad); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(
      message,
      Catch::Contains("curve #1 end and curve #2 start are 0.25 mm apart (tolerance 1e-07 mm)"));
  // Reversed curve: its start becomes the trailing end.
  quad[1] = reversed(quad[1]);
  CHECK_THAT(error_of([&] { fill(quad); }).second,
             Catch::Contains("curve #1 start and curve #2 start are 0.25 mm apart"));
}

TEST_CASE("fill rejects fewer than 2 or more than 4 curves", "[fill][errors]") {
  std::mt19937 rng(408);
  const std::vector<BSplineCurve> quad = quad_boundary(rng);
  const auto [category, message] = error_of([&] { fill({quad[0]}); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Catch::Contains("got 1"));
  std::vector<BSplineCurve> five = quad;
  five.push_back(quad[0]);
  CHECK_THAT(error_of([&] { fill(five); }).second, Catch::Contains("use fill_n_sided"));
}

TEST_CASE("fill rejects a degenerate curve", "[fill][errors]") {
  std::mt19937 rng(409);
  std::vector<BSplineCurve> quad = quad_boundary(rng);
  quad[3].points.rowwise() = quad[3].points.row(0);
  const auto [category, message] = error_of([&] { fill(quad); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("curve #3 is degenerate"));
}

TEST_CASE("fill rejects an invalid curve, naming it", "[fill][errors]") {
  std::mt19937 rng(410);
  std::vector<BSplineCurve> quad = quad_boundary(rng);
  quad[1].basis.knots[3] = -1.0;
  const auto [category, message] = error_of([&] { fill(quad); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("curve #1"));
}

TEST_CASE("fill rejects a boundary curve that crosses itself", "[fill][errors]") {
  std::mt19937 rng(412);
  std::vector<BSplineCurve> quad = quad_boundary(rng);
  // Curve #2 from its start p2 to its end p3 by way of p3 + d and p2 + d: its first and last
  // segments cross at (p2 + p3 + d) / 2, at t = 0.5 and t = 2.5.
  const Eigen::Vector3d p2(110, 90, -5), p3(-5, 100, 20), d(0, -20, 0);
  quad[2] = polyline({p2, p3 + d, p2 + d, p3});
  const auto [category, message] = error_of([&] { fill(quad); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message,
             Catch::Contains(
                 "fill: curve #2 crosses itself at t = 0.5 and t = 2.5 (point (52.5, 85, 7.5)") &&
                 Catch::Contains("must not cross or touch itself"));
  // The same curve reversed and given first: its parameters are still its own.
  std::vector<BSplineCurve> turned = {reversed(quad[2]), quad[0], quad[1], quad[3]};
  CHECK_THAT(error_of([&] { fill(turned); }).second,
             Catch::Contains("curve #0 crosses itself at t = 0.5 and t = 2.5"));
  // Two curves of a ruled fill: each is checked on its own.
  const BSplineCurve zee = polyline({{0, 0, 0}, {100, 30, 0}, {100, 0, 0}, {0, 30, 0}});
  const BSplineCurve far = curve_between(rng, 3, 5, {0, 80, 20}, {100, 80, 0}, 5.0);
  CHECK_THAT(
      error_of([&] {
        fill({far, zee});
      }).second,
      Catch::Contains("fill: curve #1 crosses itself at t = 0.5 and t = 2.5 (point (50, 15, 0)"));
}

TEST_CASE("fill rejects boundary curves that cross each other", "[fill][errors]") {
  // A bow tie: (0,0) -> (100,0) -> (0,100) -> (100,100) -> (0,0); curves #1 and #3 cross at (50,
  // 50).
  auto line = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return polyline({a, b}); };
  const Eigen::Vector3d p0(0, 0, 0), p1(100, 0, 0), p2(0, 100, 0), p3(100, 100, 0);
  const auto [category, message] = error_of([&] {
    fill({line(p0, p1), line(p1, p2), line(p2, p3), line(p3, p0)});
  });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("fill: the boundary crosses itself: curve #1 at t = 0.5 and "
                                      "curve #3 at t = 0.5 meet at point (50, 50, 0)") &&
                          Catch::Contains("must form a simple loop"));
}

TEST_CASE("curved fill of 2 curves needs a shared corner", "[fill][errors]") {
  std::mt19937 rng(411);
  const BSplineCurve a = curve_between(rng, 3, 6, {0, 0, 0}, {100, 0, 0}, 10.0);
  const BSplineCurve b = curve_between(rng, 2, 5, {0, 80, 20}, {100, 80, 0}, 10.0);
  FillOptions o;
  o.style = FillStyle::Curved;
  const auto [category, message] = error_of([&] { fill({a, b}, o); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("share a corner") && Catch::Contains("use Stretch or Coons"));
}

TEST_CASE("fill options are validated", "[fill][errors]") {
  FillOptions o;
  o.gap_tolerance = 0;
  CHECK_THAT(error_of([&] { o.validate(); }).second,
             Catch::Contains("FillOptions::gap_tolerance is 0"));
  o.gap_tolerance = 1e-7;
  o.style = static_cast<FillStyle>(7);
  CHECK_THAT(error_of([&] { o.validate(); }).second, Catch::Contains("FillOptions::style is 7"));
}

// ---- N-sided ----

namespace {

/// A smooth, not quadric dome: z = 30 (1 - (x^2 + y^2) / 100^2) + 2e-5 x^2 y (cubic, so the plate
/// does not reproduce it exactly).
double dome(double x, double y) { return 30.0 * (1.0 - (x * x + y * y) / 1e4) + 2e-5 * x * x * y; }

/// The straight segment a -> b in the xy plane lifted onto the dome: exactly a cubic Bézier (x, y
/// linear and z cubic in t; the z ordinates solve the Bernstein system at t = 0, 1/3, 2/3, 1).
BSplineCurve lifted(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  Eigen::Matrix4d bernstein;
  Eigen::Vector4d z;
  for (int k = 0; k < 4; ++k) {
    const double t = k / 3.0;
    const Eigen::Vector2d q = (1 - t) * a + t * b;
    z[k] = dome(q.x(), q.y());
    bernstein.row(k) << std::pow(1 - t, 3), 3 * t * std::pow(1 - t, 2), 3 * t * t * (1 - t),
        std::pow(t, 3);
  }
  const Eigen::Vector4d ordinates = bernstein.fullPivLu().solve(z);
  Points3 p(4, 3);
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d q = (1 - k / 3.0) * a + (k / 3.0) * b;
    p.row(k) << q.x(), q.y(), ordinates[k];
  }
  return make_curve(3, {0, 0, 0, 0, 1, 1, 1, 1}, p);
}

std::vector<BSplineCurve> pentagon_on_dome() {
  std::vector<Eigen::Vector2d> corners;
  for (int k = 0; k < 5; ++k) {
    const double a = M_PI / 2 + 2 * M_PI * k / 5;
    corners.emplace_back(80 * std::cos(a), 80 * std::sin(a));
  }
  std::vector<BSplineCurve> sides;
  for (int k = 0; k < 5; ++k) sides.push_back(lifted(corners[k], corners[(k + 1) % 5]));
  return sides;
}

}  // namespace

TEST_CASE("n-sided fill of a 5-sided dome with an interior curve reports a measured deviation",
          "[fill][nsided]") {
  std::vector<BSplineCurve> sides = pentagon_on_dome();
  // Shuffle and reverse some: the loop is found regardless.
  std::swap(sides[1], sides[3]);
  sides[2] = reversed(sides[2]);
  const std::vector<BSplineCurve> interior = {lifted({-30, -10}, {30, 15})};
  const NSidedFill result = fill_n_sided(sides, interior);
  std::vector<BSplineCurve> all = sides;
  all.push_back(interior[0]);
  const double size = curves_size(all);
  INFO(result.built.report.brief() << ", size " << size);
  CHECK_FALSE(result.built.report.exact);
  REQUIRE(result.curve_deviations.size() == 6);
  CHECK(result.built.report.max_deviation_mm ==
        *std::max_element(result.curve_deviations.begin(), result.curve_deviations.end()));
  CHECK(result.built.report.max_deviation_mm < 1e-5 * size);  // measured 1.2e-6 mm on 211 mm
  // Independent measurement: closest points of 4x denser samples, each against its reported value.
  for (size_t k = 0; k < all.size(); ++k) {
    double worst = 0;
    for (double t : linspace(0, 1, 257))
      worst = std::max(worst, closest_point(result.built.surface, evaluate(all[k], t)).distance);
    INFO("curve " << k << ": reported " << result.curve_deviations[k] << ", independent " << worst);
    CHECK(worst >= 0.8 * result.curve_deviations[k]);
    CHECK(worst <= 1.25 * result.curve_deviations[k] + 1e-9 * size);
  }
  // The plate passes through the interior curve, so it stays near the dome's top.
  const SurfaceProjection centre = closest_point(result.built.surface, {0, 0, dome(0, 0)});
  CHECK(centre.distance < 0.1);
}

TEST_CASE("n-sided fill rejects an open boundary, naming the gap", "[fill][nsided][errors]") {
  std::vector<BSplineCurve> sides = pentagon_on_dome();
  sides[3].points(3, 2) += 0.5;  // the end of curve #3 lifted by 0.5 mm
  const auto [category, message] = error_of([&] { fill_n_sided(sides); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("curve #3 end and curve #4 start are 0.5 mm apart"));
}

TEST_CASE("n-sided fill rejects fewer than 3 boundary curves and bad options",
          "[fill][nsided][errors]") {
  const std::vector<BSplineCurve> sides = pentagon_on_dome();
  CHECK(error_of([&] {
          fill_n_sided({sides[0], sides[1]});
        }).first == clay::ErrorCategory::InvalidArgument);
  NSidedFillOptions o;
  o.max_degree = 30;
  CHECK_THAT(error_of([&] { fill_n_sided(sides, {}, o); }).second,
             Catch::Contains("NSidedFillOptions::max_degree is 30"));
  o = {};
  o.tolerance_3d = -1;
  CHECK_THAT(error_of([&] { o.validate(); }).second,
             Catch::Contains("NSidedFillOptions::tolerance_3d"));
}

TEST_CASE("n-sided fill rejects a degenerate interior curve", "[fill][nsided][errors]") {
  BSplineCurve point = lifted({0, 0}, {10, 0});
  point.points.rowwise() = point.points.row(0);
  const auto [category, message] = error_of([&] { fill_n_sided(pentagon_on_dome(), {point}); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("interior curve #0 is degenerate"));
}

TEST_CASE("n-sided fill rejects a star-shaped (self-crossing) boundary", "[fill][nsided][errors]") {
  // The pentagon's corners joined every second one: a pentagram, whose sides cross each other (on
  // the dome, so in 3D too). Independently: the first crossing along side #0 in the plane.
  std::vector<Eigen::Vector2d> corners;
  for (int k = 0; k < 5; ++k) {
    const double a = M_PI / 2 + 2 * M_PI * k / 5;
    corners.emplace_back(80 * std::cos(a), 80 * std::sin(a));
  }
  std::vector<BSplineCurve> star;
  for (int k = 0; k < 5; ++k)
    star.push_back(lifted(corners[(2 * k) % 5], corners[(2 * k + 2) % 5]));
  double first = 2, other_t = 0;
  int other = -1;
  const Eigen::Vector2d a0 = corners[0], a1 = corners[2];
  for (int k = 1; k < 5; ++k) {
    const Eigen::Vector2d b0 = corners[(2 * k) % 5], b1 = corners[(2 * k + 2) % 5];
    Eigen::Matrix2d m;
    m << a1 - a0, b0 - b1;
    if (std::abs(m.determinant()) < 1e-9) continue;
    const Eigen::Vector2d x = m.inverse() * (b0 - a0);
    if (x[0] > 1e-9 && x[0] < 1 - 1e-9 && x[1] > 1e-9 && x[1] < 1 - 1e-9 && x[0] < first)
      first = x[0], other = k, other_t = x[1];
  }
  REQUIRE(other > 0);
  char expected[160];
  std::snprintf(expected, sizeof expected, "curve #0 at t = %.4g and curve #%d at t = %.4g meet",
                first, other, other_t);
  const auto [category, message] = error_of([&] { fill_n_sided(star); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("fill_n_sided: the boundary crosses itself") &&
                          Catch::Contains(expected));
}
