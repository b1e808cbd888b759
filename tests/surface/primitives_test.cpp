#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/primitives.hpp>

#include <array>
#include <cmath>
#include <numbers>

using namespace clay::surface;

namespace {

constexpr double pi = std::numbers::pi;

double spow(double x, double e) { return std::copysign(std::pow(std::abs(x), e), x); }

/// The documented parameter map of an approximated direction (primitives.hpp): s in [k, k+1]
/// covers angle segment k through x^m / (x^m + (1-x)^m), m = max(1, 1/e). Returned as cos and
/// sin, computed from the nearer segment end so that tiny offsets keep their digits.
std::array<double, 2> cos_sin_of(double s, const std::vector<double>& breaks, double e) {
  const double m = std::max(1.0, 1.0 / e);
  const int k = std::min(static_cast<int>(s), static_cast<int>(breaks.size()) - 2);
  const double x = s - k, a = std::pow(x, m), b = std::pow(1 - x, m);
  const double lo = breaks[static_cast<size_t>(k)], hi = breaks[static_cast<size_t>(k + 1)];
  const double base = a <= b ? lo : hi,
               offset = a <= b ? (hi - lo) * a / (a + b) : -(hi - lo) * b / (a + b);
  const bool quarter = std::abs(base / (pi / 2) - std::round(base / (pi / 2))) < 1e-12;
  const double cb = quarter ? std::round(std::cos(base)) : std::cos(base);
  const double sb = quarter ? std::round(std::sin(base)) : std::sin(base);
  return {cb * std::cos(offset) - sb * std::sin(offset),
          sb * std::cos(offset) + cb * std::sin(offset)};
}

const std::vector<double> around = {-pi, -pi / 2, 0, pi / 2, pi};

/// max over a grid of the domain of |F(S(u, v))|.
template <class F>
double worst_over(const BSplineSurface& s, F f, int n = 61) {
  double worst = 0;
  const auto [ua, ub] = s.u.domain();
  const auto [va, vb] = s.v.domain();
  for (double u : linspace(ua, ub, n))
    for (double v : linspace(va, vb, n)) worst = std::max(worst, std::abs(f(evaluate(s, u, v))));
  return worst;
}

}  // namespace

TEST_CASE("superellipsoid with exponents (1, 1) is an exact sphere", "[primitives]") {
  Superellipsoid shape;
  shape.radii = Eigen::Vector3d::Constant(40.0);
  const BuiltSurface built = superellipsoid(shape);
  CHECK(built.report.exact);
  CHECK(built.surface.is_rational());
  CHECK(worst_over(built.surface, [](const Eigen::Vector3d& p) { return p.norm() - 40.0; }) <
        1e-12 * 40.0);
  CHECK(built.report.max_deviation_mm < 1e-12 * 40.0);
  // Poles: the whole u = end rows collapse to (0, 0, +-40).
  CHECK((evaluate(built.surface, built.surface.u.domain().second, 0.3) - Eigen::Vector3d(0, 0, 40))
            .norm() < 1e-13);
}

TEST_CASE("ellipsoid, torus and hyperboloids are exact quadrics for exponents (1, 1)",
          "[primitives]") {
  Superellipsoid ell;
  ell.radii = {30, 20, 10};
  const BSplineSurface e = superellipsoid(ell).surface;
  CHECK(worst_over(e, [](const Eigen::Vector3d& p) {
          return std::pow(p.x() / 30, 2) + std::pow(p.y() / 20, 2) + std::pow(p.z() / 10, 2) - 1.0;
        }) < 1e-13);

  Supertoroid tor;
  tor.radii = Eigen::Vector3d::Constant(10.0);
  tor.hole = 3.0;  // major radius 30, minor 10
  const BuiltSurface t = supertoroid(tor);
  CHECK(t.report.exact);
  CHECK(worst_over(t.surface, [](const Eigen::Vector3d& p) {
          return std::hypot(std::hypot(p.x(), p.y()) - 30.0, p.z()) - 10.0;
        }) < 1e-12 * 40.0);

  Superhyperboloid hyp;
  hyp.radii = {5, 6, 7};
  hyp.eta_limit = 1.2;
  hyp.omega_limit = 1.1;
  const BuiltSurface one = superhyperboloid_one_sheet(hyp);
  CHECK(one.report.exact);
  CHECK(worst_over(one.surface, [](const Eigen::Vector3d& p) {
          return std::pow(p.x() / 5, 2) + std::pow(p.y() / 6, 2) - std::pow(p.z() / 7, 2) - 1.0;
        }) < 1e-12);
  // The cut is at eta = +-1.2: z = 7 tan(1.2) at the ends.
  CHECK(std::abs(evaluate(one.surface, one.surface.u.domain().second, 0.0).z() -
                 7 * std::tan(1.2)) < 1e-12);
  const auto two = superhyperboloid_two_sheets(hyp);
  REQUIRE(two.size() == 2);
  for (int k = 0; k < 2; ++k) {
    CHECK(two[static_cast<size_t>(k)].report.exact);
    CHECK(worst_over(two[static_cast<size_t>(k)].surface, [k](const Eigen::Vector3d& p) {
            const double quadric =
                std::pow(p.x() / 5, 2) - std::pow(p.y() / 6, 2) - std::pow(p.z() / 7, 2) - 1.0;
            return (k == 0 ? p.x() > 0 : p.x() < 0) ? quadric : 1.0;
          }) < 1e-12);
  }
}

TEST_CASE("approximated superquadrics meet the tolerance against the analytic form",
          "[primitives]") {
  SuperquadricOptions options;
  options.tolerance_mm = 1e-3;
  struct Case {
    double e1, e2;
  };
  for (const Case c : {Case{0.5, 2.5}, Case{3.0, 0.3}, Case{1.7, 1.3}, Case{0.1, 0.15}}) {
    INFO("exponents " << c.e1 << ", " << c.e2);
    Superellipsoid shape;
    shape.radii = {50, 40, 30};
    shape.e1 = c.e1;
    shape.e2 = c.e2;
    const BuiltSurface built = superellipsoid(shape, options);
    CHECK_FALSE(built.report.exact);
    CHECK(built.report.max_deviation_mm <= options.tolerance_mm);
    // Independent: Barr's formula at the same (eta, omega), on a grid other than the builder's.
    REQUIRE(built.surface.u.domain().second == 2.0);  // two north-south segments
    REQUIRE(built.surface.v.domain().second == 4.0);  // four quarter turns
    double worst = 0;
    for (double su : linspace(0, 2, 97))
      for (double sv : linspace(0, 4, 131)) {
        const auto eta = cos_sin_of(su, {-pi / 2, 0, pi / 2}, c.e1),
                   omega = cos_sin_of(sv, around, c.e2);
        const Eigen::Vector3d x(50 * spow(eta[0], c.e1) * spow(omega[0], c.e2),
                                40 * spow(eta[0], c.e1) * spow(omega[1], c.e2),
                                30 * spow(eta[1], c.e1));
        worst = std::max(worst, (evaluate(built.surface, su, sv) - x).norm());
      }
    CHECK(worst <= options.tolerance_mm);

    Supertoroid tor;
    tor.radii = {10, 10, 10};
    tor.hole = 2.5;
    tor.e1 = c.e1;
    tor.e2 = c.e2;
    const BuiltSurface t = supertoroid(tor, options);
    CHECK(t.report.max_deviation_mm <= options.tolerance_mm);
    worst = 0;
    for (double su : linspace(0, 4, 97))
      for (double sv : linspace(0, 4, 97)) {
        const auto eta = cos_sin_of(su, around, c.e1), omega = cos_sin_of(sv, around, c.e2);
        const double ring = 2.5 + spow(eta[0], c.e1);
        const Eigen::Vector3d x(10 * ring * spow(omega[0], c.e2), 10 * ring * spow(omega[1], c.e2),
                                10 * spow(eta[1], c.e1));
        worst = std::max(worst, (evaluate(t.surface, su, sv) - x).norm());
      }
    CHECK(worst <= options.tolerance_mm);
  }
  // Hyperboloid of one sheet, approximated in both directions.
  Superhyperboloid hyp;
  hyp.radii = {5, 5, 5};
  hyp.e1 = 0.7;
  hyp.e2 = 1.8;
  const BuiltSurface h = superhyperboloid_one_sheet(hyp, options);
  double worst = 0;
  for (double su : linspace(0, 2, 61))
    for (double sv : linspace(0, 4, 91)) {
      const auto eta = cos_sin_of(su, {-1.0, 0.0, 1.0}, 0.7), omega = cos_sin_of(sv, around, 1.8);
      const double sec = 1 / eta[0], tan = eta[1] / eta[0];
      const Eigen::Vector3d x(5 * spow(sec, 0.7) * spow(omega[0], 1.8),
                              5 * spow(sec, 0.7) * spow(omega[1], 1.8), 5 * spow(tan, 0.7));
      worst = std::max(worst, (evaluate(h.surface, su, sv) - x).norm());
    }
  CHECK(worst <= options.tolerance_mm);
  CHECK(h.report.max_deviation_mm <= options.tolerance_mm);
}

TEST_CASE("spherical product of two curves is their exact product", "[primitives]") {
  const BSplineCurve m =
      make_curve(2, {0, 0, 0, 1, 1, 1}, (Points3(3, 3) << 1, -1, 0, 2, 0, 0, 1, 1, 0).finished(),
                 Eigen::Vector3d(1, 0.5, 1));
  const BSplineCurve h =
      make_curve(1, {0, 0, 1, 1}, (Points3(2, 3) << 1, 0, 0, 0, 3, 0).finished());
  const BSplineSurface s = spherical_product(m, h);
  for (double a : linspace(0, 1, 9))
    for (double b : linspace(0, 1, 9)) {
      const Eigen::Vector3d pm = evaluate(m, a), ph = evaluate(h, b);
      CHECK((evaluate(s, a, b) - Eigen::Vector3d(pm.x() * ph.x(), pm.x() * ph.y(), pm.y())).norm() <
            1e-14);
    }
}

TEST_CASE("superquadric builders refuse bad shapes and options", "[primitives][errors]") {
  Superellipsoid bad;
  bad.e1 = 0.0;
  CHECK_THROWS_WITH(superellipsoid(bad), Catch::Contains("e1 = 0"));
  bad.e1 = 1.0;
  bad.radii = {1, -2, 1};
  CHECK_THROWS_WITH(superellipsoid(bad), Catch::Contains("radii"));
  Supertoroid tor;
  tor.hole = 0.5;
  CHECK_THROWS_WITH(supertoroid(tor), Catch::Contains("hole"));
  Superhyperboloid hyp;
  hyp.eta_limit = pi / 2;
  CHECK_THROWS_WITH(superhyperboloid_one_sheet(hyp), Catch::Contains("eta_limit"));
  hyp.eta_limit = 1.0;
  hyp.omega_limit = -1.0;
  CHECK_THROWS_WITH(superhyperboloid_two_sheets(hyp), Catch::Contains("omega_limit"));
  SuperquadricOptions o;
  o.degree = 9;
  CHECK_THROWS_WITH(superellipsoid(Superellipsoid{}, o), Catch::Contains("degree"));
  o = SuperquadricOptions{};
  o.tolerance_mm = 1e-14;
  o.max_spans = 16;
  Superellipsoid hard;
  hard.e1 = 0.3;
  hard.e2 = 0.3;
  CHECK_THROWS_WITH(superellipsoid(hard, o), Catch::Contains("could not reach"));
}
