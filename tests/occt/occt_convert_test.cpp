// The OpenCASCADE adapter (surface/src/occt/convert.*), through the OCCT-free reference interface:
// bit-exact round trips, index order checked against an independent evaluation, and the
// degree limit.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_surface.hpp>

#include "occt_reference.hpp"

#include <random_geometry.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace clay;
using namespace clay::surface;
using Catch::Matchers::WithinAbs;

namespace {

/// Point and derivatives up to order 2 in homogeneous form from basis.cpp (The NURBS Book A2.3)
/// and the quotient rule: an evaluation that shares no code with OCCT or with evaluate.cpp.
struct Reference {
  Eigen::Vector3d s, su, sv, suu, suv, svv;
};

Reference evaluate_by_basis(const BSplineSurface& surface, double u, double v) {
  const int p = surface.u.degree, q = surface.v.degree;
  const int ku = find_span(surface.u, u), kv = find_span(surface.v, v);
  std::vector<double> du(static_cast<size_t>(3 * (p + 1))), dv(static_cast<size_t>(3 * (q + 1)));
  basis_derivatives(surface.u, ku, u, 2, du);
  basis_derivatives(surface.v, kv, v, 2, dv);
  // a[r][s] = sum d^r N_i d^s N_j w P, and w[r][s] the same for the weights.
  Eigen::Vector3d a[3][3];
  double w[3][3] = {};
  for (auto& row : a)
    for (auto& x : row) x.setZero();
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= q; ++j) {
      const Eigen::Index r = surface.index(ku - p + i, kv - q + j);
      const double wij = surface.weights[r];
      const Eigen::Vector3d pw = wij * surface.points.row(r).transpose();
      for (int m = 0; m < 3; ++m)
        for (int n = 0; m + n < 3; ++n) {
          const double b =
              du[static_cast<size_t>(m * (p + 1) + i)] * dv[static_cast<size_t>(n * (q + 1) + j)];
          a[m][n] += b * pw;
          w[m][n] += b * wij;
        }
    }
  Reference out;
  out.s = a[0][0] / w[0][0];
  out.su = (a[1][0] - w[1][0] * out.s) / w[0][0];
  out.sv = (a[0][1] - w[0][1] * out.s) / w[0][0];
  out.suu = (a[2][0] - 2 * w[1][0] * out.su - w[2][0] * out.s) / w[0][0];
  out.svv = (a[0][2] - 2 * w[0][1] * out.sv - w[0][2] * out.s) / w[0][0];
  out.suv = (a[1][1] - w[1][0] * out.sv - w[0][1] * out.su - w[1][1] * out.s) / w[0][0];
  return out;
}

void require_close(const Eigen::Vector3d& got, const Eigen::Vector3d& want, double scale) {
  for (int c = 0; c < 3; ++c) REQUIRE_THAT(got[c], WithinAbs(want[c], 1e-10 * scale));
}

}  // namespace

TEST_CASE("OCCT round trip of random curves is bit-identical", "[occt][convert]") {
  std::mt19937 rng(20240611);
  int checked = 0;
  for (int degree = 1; degree <= 25; ++degree)
    for (bool rational : {false, true})
      for (bool clamped : {true, false}) {
        const int count = degree + 1 + static_cast<int>(rng() % 6);
        const BSplineCurve curve =
            test::random_curve(rng, degree, count, rational, clamped, std::max(1, degree));
        INFO("degree " << degree << (rational ? " rational" : " polynomial")
                       << (clamped ? " clamped" : " unclamped"));
        REQUIRE(problems(curve).empty());
        const BSplineCurve back = occt_reference::round_trip(curve);
        REQUIRE(identical(back, curve));
        ++checked;
      }
  REQUIRE(checked == 100);
}

TEST_CASE("OCCT round trip keeps equal non-unit curve weights", "[occt][convert]") {
  std::mt19937 rng(7);
  BSplineCurve curve = test::random_curve(rng, 3, 6, false);
  curve.weights.setConstant(2.5);  // rational in form only
  REQUIRE(identical(occt_reference::round_trip(curve), curve));
}

TEST_CASE("OCCT round trip of random surfaces is bit-identical", "[occt][convert]") {
  std::mt19937 rng(31337);
  int checked = 0, with_multiple_knots = 0;
  for (int degree_u = 1; degree_u <= 25; ++degree_u)
    for (bool rational : {false, true})
      for (bool clamped : {true, false}) {
        const int degree_v = 1 + (degree_u * 7 + (rational ? 3 : 0)) % 25;
        const int count_u = degree_u + 1 + static_cast<int>(rng() % 5);
        const int count_v = degree_v + 1 + static_cast<int>(rng() % 5);
        const BSplineSurface surface =
            test::random_surface(rng, degree_u, degree_v, count_u, count_v, rational, clamped,
                                 std::max(1, std::min(degree_u, degree_v)));
        INFO("degree (" << degree_u << ", " << degree_v << ")"
                        << (rational ? " rational" : " polynomial")
                        << (clamped ? " clamped" : " unclamped"));
        REQUIRE(problems(surface).empty());
        for (const auto* basis : {&surface.u, &surface.v})
          for (double t : breakpoints(*basis))
            if (multiplicity(*basis, t) > 1 && t != basis->domain().first &&
                t != basis->domain().second) {
              ++with_multiple_knots;
              break;
            }
        REQUIRE(identical(occt_reference::round_trip(surface), surface));
        ++checked;
      }
  REQUIRE(checked == 100);
  REQUIRE(with_multiple_knots > 10);  // interior multiplicities > 1 were exercised
}

TEST_CASE("OCCT evaluates the converted surface as our control net says", "[occt][convert]") {
  // A transposed net or misplaced weights would still round-trip; evaluation catches them.
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 8; ++k) {
    const int degree_u = 1 + k % 4, degree_v = 2 + (k * 3) % 5;
    const BSplineSurface surface = test::random_surface(rng, degree_u, degree_v, degree_u + 3,
                                                        degree_v + 2, k % 2 == 1, k % 3 != 0, 2);
    const auto [u0, u1] = surface.u.domain();
    const auto [v0, v1] = surface.v.domain();
    for (int sample = 0; sample < 20; ++sample) {
      const double u = u0 + (u1 - u0) * unit(rng), v = v0 + (v1 - v0) * unit(rng);
      INFO("surface " << k << " at (" << u << ", " << v << ")");
      const Reference want = evaluate_by_basis(surface, u, v);
      const SurfaceDerivatives got = occt_reference::surface_d2(surface, u, v);
      require_close(got.point, want.s, 1e2);
      require_close(got.du, want.su, 1e4);
      require_close(got.dv, want.sv, 1e4);
      require_close(got.duu, want.suu, 1e6);
      require_close(got.duv, want.suv, 1e6);
      require_close(got.dvv, want.svv, 1e6);
    }
    // The grid evaluator holds one OCCT surface and lays rows out as evaluate_grid does.
    const std::vector<double> us = {u0, 0.5 * (u0 + u1), u1};
    const std::vector<double> vs = {v0, v0 + 0.25 * (v1 - v0), v1};
    const occt_reference::GridEvaluator grid(surface);
    const Points3 points = grid.evaluate_grid(us, vs);
    REQUIRE(points.rows() == 9);
    for (size_t i = 0; i < us.size(); ++i)
      for (size_t j = 0; j < vs.size(); ++j)
        require_close(points.row(static_cast<Eigen::Index>(i * vs.size() + j)).transpose(),
                      evaluate_by_basis(surface, us[i], vs[j]).s, 1e2);
  }
}

TEST_CASE("OCCT curve derivatives match the basis functions", "[occt][convert]") {
  std::mt19937 rng(5);
  const BSplineCurve curve = test::random_curve(rng, 4, 9, false, true, 2);
  // A polynomial curve is a surface of degree 1 in v with two equal rows; reuse the surface code.
  BSplineSurface strip;
  strip.u = curve.basis;
  strip.v = clamped_uniform_basis(1, 2);
  strip.points.resize(2 * curve.points.rows(), 3);
  for (Eigen::Index i = 0; i < curve.points.rows(); ++i)
    strip.points.row(2 * i) = strip.points.row(2 * i + 1) = curve.points.row(i);
  strip.weights = Eigen::VectorXd::Ones(strip.points.rows());
  for (double t : {0.0, 0.13, 0.5, 0.77, 1.0}) {
    const Reference want = evaluate_by_basis(strip, t, 0.5);
    const CurveDerivatives got = occt_reference::curve_d2(curve, t);
    require_close(got.point, want.s, 1e2);
    require_close(got.d1, want.su, 1e4);
    require_close(got.d2, want.suu, 1e6);
  }
}

TEST_CASE("OCCT conversion refuses degree 26 and invalid data", "[occt][convert][errors]") {
  std::mt19937 rng(1);
  const BSplineSurface high = test::random_surface(rng, 26, 3, 27, 4, false);
  REQUIRE(problems(high).empty());  // valid for the kernel (degree <= 63) ...
  try {
    (void)occt_reference::round_trip(high);  // ... but above OCCT's 25
    FAIL("no exception for degree 26");
  } catch (const Error& e) {
    REQUIRE(e.category() == ErrorCategory::DegreeLimit);
    REQUIRE_THAT(e.message(), Catch::Matchers::Contains("26") && Catch::Matchers::Contains("25"));
  }
  const BSplineSurface high_v = test::random_surface(rng, 2, 26, 3, 27, true);
  REQUIRE_THROWS_MATCHES(occt_reference::round_trip(high_v), Error,
                         Catch::Matchers::Predicate<Error>([](const Error& e) {
                           return e.category() == ErrorCategory::DegreeLimit;
                         }));
  const BSplineCurve high_curve = test::random_curve(rng, 26, 30, false);
  REQUIRE_THROWS_MATCHES(occt_reference::round_trip(high_curve), Error,
                         Catch::Matchers::Predicate<Error>([](const Error& e) {
                           return e.category() == ErrorCategory::DegreeLimit;
                         }));
  BSplineSurface nan = test::random_surface(rng, 3, 3, 4, 4, false);
  nan.points(5, 1) = std::numeric_limits<double>::quiet_NaN();
  REQUIRE_THROWS_MATCHES(occt_reference::round_trip(nan), Error,
                         Catch::Matchers::Predicate<Error>([](const Error& e) {
                           return e.category() == ErrorCategory::InvalidGeometry;
                         }));
}
