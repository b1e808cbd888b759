#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/self_intersection.hpp>

#include <Eigen/LU>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include "error_of.hpp"
#include "polyline.hpp"
#include "random_geometry.hpp"

using namespace clay::surface;
using Catch::Matchers::WithinAbs;
using clay::test::error_of;
using clay::test::polyline;

namespace {

/// Homogeneous (w x, w y, w z, w) polynomial of degree `degree` on [a, b] written as a Bézier
/// segment: its Bernstein coefficients, found by collocation at degree + 1 parameters (exact for a
/// polynomial of that degree, up to rounding).
Eigen::MatrixXd bernstein(const std::function<Eigen::Vector4d(double)>& f, int degree, double a,
                          double b) {
  const int n = degree + 1;
  Eigen::MatrixXd m(n, n), rhs(n, 4);
  for (int k = 0; k < n; ++k) {
    const double s = double(k) / degree;
    for (int i = 0; i < n; ++i)
      m(k, i) = std::tgamma(n) / (std::tgamma(i + 1) * std::tgamma(n - i)) * std::pow(s, i) *
                std::pow(1 - s, degree - i);
    rhs.row(k) = f(a + s * (b - a)).transpose();
  }
  return m.fullPivLu().solve(rhs);
}

/// A C0 curve made of Bézier segments of one degree over the breaks (interior knots repeated
/// `degree` times), each the homogeneous polynomial f on its span.
BSplineCurve piecewise(const std::function<Eigen::Vector4d(double)>& f, int degree,
                       const std::vector<double>& breaks) {
  std::vector<double> knots(static_cast<size_t>(degree + 1), breaks.front());
  std::vector<Eigen::Vector4d> rows;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    const Eigen::MatrixXd c = bernstein(f, degree, breaks[k], breaks[k + 1]);
    for (int i = k == 0 ? 0 : 1; i <= degree; ++i) rows.push_back(c.row(i).transpose());
    knots.insert(knots.end(), static_cast<size_t>(k + 2 < breaks.size() ? degree : degree + 1),
                 breaks[k + 1]);
  }
  Points3 p(static_cast<Eigen::Index>(rows.size()), 3);
  Eigen::VectorXd w(p.rows());
  for (size_t i = 0; i < rows.size(); ++i) {
    w[static_cast<Eigen::Index>(i)] = rows[i][3];
    p.row(static_cast<Eigen::Index>(i)) = (rows[i].head<3>() / rows[i][3]).transpose();
  }
  return make_curve(degree, knots, p, w);
}

Eigen::Vector4d polynomial_point(double x, double y, double z) { return {x, y, z, 1.0}; }

/// The nodal cubic (t^2 - 1, t^3 - t, c t) on [-1.5, 1.5]: a loop closing at t = -1 and t = 1
/// when c = 0; lifted by c its strands pass each other at a distance computed below.
BSplineCurve nodal_cubic(double c) {
  return piecewise([c](double t) { return polynomial_point(t * t - 1, t * t * t - t, c * t); }, 3,
                   {-1.5, 1.5});
}

/// Closest approach of the lifted nodal cubic's strands. The objective is symmetric under
/// (s, t) -> (-t, -s), so the minimum lies on s = -t, where |C(-t) - C(t)|^2 = 4 (t^3 - t)^2 +
/// 4 c^2 t^2; its derivative vanishes at 3 t^4 - 4 t^2 + 1 + c^2 = 0.
double nodal_gap(double c, double* t_star = nullptr) {
  const double t = std::sqrt((2.0 + std::sqrt(1.0 - 3.0 * c * c)) / 3.0);
  if (t_star) *t_star = t;
  return 2.0 * t * std::sqrt((t * t - 1) * (t * t - 1) + c * c);
}

/// A hairpin: a straight leg along y = -r, a semicircle of radius r about the origin on the left,
/// and a leg back along y = +r (exact rational quadratic, legs `length` long).
BSplineCurve hairpin(double r, double length) {
  const double w = std::sqrt(0.5);
  Points3 p(9, 3);
  p << length, -r, 0, length / 2, -r, 0, 0, -r, 0, -r, -r, 0, -r, 0, 0, -r, r, 0, 0, r, 0,
      length / 2, r, 0, length, r, 0;
  Eigen::VectorXd wt(9);
  wt << 1, 1, 1, w, 1, w, 1, 1, 1;
  return make_curve(2, {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4}, p, wt);
}

}  // namespace

TEST_CASE("self-intersection: the nodal cubic's loop closes at t = -1 and t = 1",
          "[self_intersection]") {
  const std::optional<CurveSelfIntersection> x = find_self_intersection(nodal_cubic(0.0), 1e-7);
  REQUIRE(x);
  CHECK_THAT(x->t0, WithinAbs(-1.0, 1e-12));
  CHECK_THAT(x->t1, WithinAbs(1.0, 1e-12));
  CHECK(x->distance < 1e-14);
  CHECK(x->point.norm() < 1e-12);
  // Tangents (-2, 2, 0) and (2, 2, 0): a right-angle crossing.
  CHECK_THAT(x->angle_degrees, WithinAbs(90.0, 1e-9));
  // Arc length of the loop, by Simpson's rule on |C'(t)| = sqrt(4 t^2 + (3 t^2 - 1)^2).
  double arc = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    const double a = -1.0 + 2.0 * i / n, b = a + 2.0 / n;
    auto speed = [](double t) { return std::hypot(2 * t, 3 * t * t - 1); };
    arc += (b - a) / 6 * (speed(a) + 4 * speed((a + b) / 2) + speed(b));
  }
  CHECK_THAT(x->arc_length, WithinAbs(arc, 1e-3 * arc));
}

TEST_CASE("self-intersection: a rational figure-8 crosses at its analytic parameters",
          "[self_intersection]") {
  // Lemniscate of Gerono (cos θ, sin θ cos θ) with u = tan(θ/2): homogeneous ((1 - u^4),
  // 2 u (1 - u^2), 0, (1 + u^2)^2), a rational quartic; it passes the origin at θ = ±90°, u = ±1.
  const auto gerono = [](double u) {
    return Eigen::Vector4d(1 - u * u * u * u, 2 * u * (1 - u * u), 0, (1 + u * u) * (1 + u * u));
  };
  const BSplineCurve eight =
      piecewise(gerono, 4, {-2.0, -0.5, 0.5, 2.0});  // weights > 0 on each span
  REQUIRE(eight.is_rational());
  const std::optional<CurveSelfIntersection> x = find_self_intersection(eight, 1e-9);
  REQUIRE(x);
  CHECK_THAT(x->t0, WithinAbs(-1.0, 1e-10));
  CHECK_THAT(x->t1, WithinAbs(1.0, 1e-10));
  CHECK(x->point.norm() < 1e-12);
  // Tangents (-sin θ, cos 2θ) at θ = -90° and 90°: (1, -1) and (-1, -1), at right angles.
  CHECK_THAT(x->angle_degrees, WithinAbs(90.0, 1e-8));
}

TEST_CASE("self-intersection: a 3D curve passing itself just inside or outside the tolerance",
          "[self_intersection]") {
  SECTION("smooth: the lifted nodal cubic") {
    const double c = 1e-4;
    double t_star = 0;
    const double gap = nodal_gap(c, &t_star);  // ~2e-4
    const BSplineCurve curve = nodal_cubic(c);
    const std::optional<CurveSelfIntersection> inside = find_self_intersection(curve, 1.02 * gap);
    REQUIRE(inside);
    CHECK_THAT(inside->distance, WithinAbs(gap, 1e-9 * gap));
    CHECK_THAT(inside->t0, WithinAbs(-t_star, 1e-7));
    CHECK_THAT(inside->t1, WithinAbs(t_star, 1e-7));
    CHECK_FALSE(find_self_intersection(curve, 0.98 * gap));
  }
  SECTION("polyline: a strand along x at z = 0 and one along -y at z = d, crossing over x = 5") {
    const double d = 1e-3;
    const BSplineCurve curve =
        polyline({{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {5, 10, d}, {5, -10, d}});
    const std::optional<CurveSelfIntersection> inside = find_self_intersection(curve, 1.01 * d);
    REQUIRE(inside);
    CHECK_THAT(inside->distance, WithinAbs(d, 1e-12));
    CHECK_THAT(inside->t0, WithinAbs(0.5, 1e-12));  // (5, 0, 0) on the first segment
    CHECK_THAT(inside->t1, WithinAbs(3.5, 1e-12));  // (5, 0, d) halfway down the last one
    CHECK_THAT(inside->angle_degrees, WithinAbs(90.0, 1e-9));
    CHECK_FALSE(find_self_intersection(curve, 0.99 * d));
  }
}

TEST_CASE("self-intersection: a curve running back over itself", "[self_intersection]") {
  SECTION("polyline 0 -> 10 -> 4 along x") {
    const BSplineCurve back = polyline({{0, 0, 0}, {10, 0, 0}, {4, 0, 0}});
    const std::optional<CurveSelfIntersection> x = find_self_intersection(back, 1e-6);
    REQUIRE(x);
    CHECK(x->distance <= 1e-6);
    CHECK_THAT(x->angle_degrees, WithinAbs(180.0, 1e-9));
    // Both points on the overlap x in [4, 10]: t0 = x / 10 on the way out, t1 = 1 + (10 - x) / 6
    // on the way back.
    const double x0 = 10 * x->t0;
    CHECK(x0 >= 4 - 1e-9);
    CHECK(x->t0 < 1.0);
    CHECK(x->t1 > 1.0);
    CHECK_THAT(x->t1, WithinAbs(1 + (10 - x0) / 6, 1e-6));
    CHECK(x->arc_length > 100 * 1e-6);
  }
  SECTION("a hairpin whose legs lie closer than the tolerance") {
    const double tol = 1e-4;
    const std::optional<CurveSelfIntersection> x =
        find_self_intersection(hairpin(0.3 * tol, 10.0), tol);
    REQUIRE(x);
    CHECK_THAT(x->distance, WithinAbs(0.6 * tol, 1e-9));
    CHECK_THAT(x->angle_degrees, WithinAbs(180.0, 1e-6));
    CHECK(x->arc_length >= 100 * tol);
  }
  SECTION("a curve whose end comes back onto its first segment") {
    const BSplineCurve six = polyline({{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {5, 10, 0}, {5, 0, 0}});
    const std::optional<CurveSelfIntersection> x = find_self_intersection(six, 1e-7);
    REQUIRE(x);
    CHECK_THAT(x->t0, WithinAbs(0.5, 1e-12));
    CHECK_THAT(x->t1, WithinAbs(4.0, 0.0));
    CHECK(x->distance < 1e-12);
    CHECK_THAT(x->angle_degrees, WithinAbs(90.0, 1e-9));
  }
}

TEST_CASE("self-intersection: a closed curve meets itself only where it crosses, not at its seam",
          "[self_intersection]") {
  const BSplineCurve circle =
      circular_arc(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                   50.0, 0.0, 2 * std::numbers::pi);
  CHECK_FALSE(find_self_intersection(circle, 1e-5));
  // A closed bow tie: (0,0) -> (10,10) -> (10,0) -> (0,10) -> (0,0) crosses at (5, 5).
  const BSplineCurve bow = polyline({{0, 0, 0}, {10, 10, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 0}});
  const std::optional<CurveSelfIntersection> x = find_self_intersection(bow, 1e-6);
  REQUIRE(x);
  CHECK_THAT(x->t0, WithinAbs(0.5, 1e-12));
  CHECK_THAT(x->t1, WithinAbs(2.5, 1e-12));
  CHECK((x->point - Eigen::Vector3d(5, 5, 0)).norm() < 1e-12);
  // A closed square: four corners, no crossing.
  CHECK_FALSE(find_self_intersection(
      polyline({{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}, {0, 0, 0}}), 1e-6));
}

TEST_CASE("self-intersection: bends, corners and helices are not self-intersections",
          "[self_intersection]") {
  const double tol = 1e-4;
  // A hairpin of radius 50 tolerances: its legs stay 100 tolerances apart.
  CHECK_FALSE(find_self_intersection(hairpin(50 * tol, 10.0), tol));
  // An L corner and a sharp (150 degree) turn.
  CHECK_FALSE(find_self_intersection(polyline({{0, 0, 0}, {10, 0, 0}, {10, 10, 0}}), tol));
  CHECK_FALSE(find_self_intersection(polyline({{0, 0, 0}, {10, 0, 0}, {10 - 8.66, 5, 0}}), tol));
  // A cubic B-spline with its control points on a helix (radius 20, pitch 3, 6 turns).
  const int count = 6 * 12 + 1;
  Points3 p(count, 3);
  for (int i = 0; i < count; ++i) {
    const double a = 2 * std::numbers::pi * i / 12;
    p.row(i) << 20 * std::cos(a), 20 * std::sin(a), 3.0 * i / 12;
  }
  const BSplineCurve helix = make_curve(3, clamped_uniform_basis(3, count).knots, p);
  CHECK_FALSE(find_self_intersection(helix, 1e-5));
  // The pitch squeezed to 1e-3: the turns now lie within a tolerance of 1e-2 of each other.
  for (int i = 0; i < count; ++i) p(i, 2) = 1e-3 * i / 12;
  const std::optional<CurveSelfIntersection> tight =
      find_self_intersection(make_curve(3, clamped_uniform_basis(3, count).knots, p), 1e-2);
  REQUIRE(tight);
  CHECK(tight->distance <= 1e-2);
  CHECK(tight->angle_degrees < 30.0);  // the turns run the same way
}

TEST_CASE(
    "self-intersection: the first crossing of random planar curves matches a brute-force polyline "
    "search",
    "[self_intersection]") {
  std::mt19937 rng(91);
  int crossing = 0, simple = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const bool rational = trial % 3 == 2, clamped = trial % 4 != 1;
    BSplineCurve c = clay::test::random_curve(rng, 3, 6 + trial % 5, rational, clamped, 1, 50.0);
    c.points.col(2).setZero();
    // Brute force: 2000 chords, every pair of non-neighbouring chords intersected in the plane; the
    // first chord that crosses another gives the first crossing.
    const auto [a, b] = c.basis.domain();
    const std::vector<double> ts = linspace(a, b, 2001);
    const Points3 pts = evaluate_many(c, ts);
    std::optional<std::pair<double, double>> first;
    for (size_t i = 0; i + 1 < ts.size() && !first; ++i)
      for (size_t j = i + 2; j + 1 < ts.size(); ++j) {
        const Eigen::Vector2d p0 = pts.row(static_cast<Eigen::Index>(i)).head<2>().transpose();
        const Eigen::Vector2d p1 = pts.row(static_cast<Eigen::Index>(i + 1)).head<2>().transpose();
        const Eigen::Vector2d q0 = pts.row(static_cast<Eigen::Index>(j)).head<2>().transpose();
        const Eigen::Vector2d q1 = pts.row(static_cast<Eigen::Index>(j + 1)).head<2>().transpose();
        Eigen::Matrix2d m;
        m << p1 - p0, q0 - q1;
        if (std::abs(m.determinant()) < 1e-9 * (p1 - p0).norm() * (q1 - q0).norm())
          continue;  // parallel
        const Eigen::Vector2d x = m.inverse() * (q0 - p0);
        const double s = ts[i] + x[0] * (ts[i + 1] - ts[i]), t = ts[j] + x[1] * (ts[j + 1] - ts[j]);
        if (x[0] >= 0 && x[0] < 1 && x[1] >= 0 && x[1] < 1 && (!first || s < first->first))
          first = std::pair{s, t};
      }
    const std::optional<CurveSelfIntersection> found = find_self_intersection(c, 1e-6);
    INFO("trial " << trial);
    REQUIRE(found.has_value() == first.has_value());
    if (!found) {
      ++simple;
      continue;
    }
    ++crossing;
    CHECK_THAT(found->t0, WithinAbs(first->first, 1e-4 * (b - a)));
    CHECK_THAT(found->t1, WithinAbs(first->second, 1e-4 * (b - a)));
    CHECK((evaluate(c, found->t0) - evaluate(c, found->t1)).norm() <= 1e-6);
  }
  CHECK(crossing >= 3);
  CHECK(simple >= 1);
}

TEST_CASE("self-intersection: bad tolerance and invalid curves are refused",
          "[self_intersection][errors]") {
  const BSplineCurve c = nodal_cubic(0.0);
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    const auto [category, message] = error_of([&] { find_self_intersection(c, bad); });
    CHECK(category == clay::ErrorCategory::InvalidArgument);
    CHECK_THAT(message, Catch::Contains("tolerance"));
  }
  BSplineCurve broken = c;
  broken.points(1, 0) = std::nan("");
  CHECK(error_of([&] { find_self_intersection(broken, 1e-7); }).first ==
        clay::ErrorCategory::InvalidGeometry);
}
