#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>

#include <random>
#include <vector>

#include "random_geometry.hpp"

using namespace clay::surface;
using Catch::Matchers::WithinAbs;

TEST_CASE("find_span locates knot spans, domain ends included", "[basis]") {
  BSplineBasis b{2, {0, 0, 0, 1, 2, 2, 3, 3, 3}};  // 6 control points, double knot at 2
  REQUIRE(b.count() == 6);
  CHECK(find_span(b, 0.0) == 2);
  CHECK(find_span(b, 0.5) == 2);
  CHECK(find_span(b, 1.0) == 3);
  CHECK(find_span(b, 2.0) == 5);
  CHECK(find_span(b, 2.5) == 5);
  CHECK(find_span(b, 3.0) == 5);  // the domain end maps to the last non-empty span
  // Past an end by rounding (within 1e-12 of the domain's scale, here 3e-12): the end span, as
  // real files' parameters land (issue #39); farther, refused.
  CHECK(find_span(b, -1e-300) == 2);
  CHECK(find_span(b, -2.9e-12) == 2);
  CHECK(find_span(b, 3.0 + 2.9e-12) == 5);
  CHECK(find_span(b, std::nextafter(3.0, 4.0)) == 5);
  CHECK_THROWS_AS(find_span(b, -3.1e-12), clay::Error);
  CHECK_THROWS_AS(find_span(b, 3.0000001), clay::Error);
  CHECK_THROWS_AS(find_span(b, std::nan("")), clay::Error);
}

TEST_CASE("basis functions: partition of unity, non-negativity, closed form", "[basis]") {
  std::mt19937 rng(7);
  for (int p = 1; p <= 9; ++p) {
    for (bool clamped : {true, false}) {
      const BSplineBasis b = clay::test::random_basis(rng, p, p + 6, clamped, p);
      const auto [a, e] = b.domain();
      for (int k = 0; k <= 50; ++k) {
        const double t = a + (e - a) * k / 50.0;
        std::vector<double> n(static_cast<size_t>(p + 1));
        basis_functions(b, find_span(b, t), t, n);
        double sum = 0;
        for (double x : n) {
          CHECK(x >= -1e-15);
          sum += x;
        }
        CHECK_THAT(sum, WithinAbs(1.0, 1e-14));
      }
    }
  }
  // Bernstein polynomials: clamped single segment of degree 3 on [0, 1].
  BSplineBasis bern{3, {0, 0, 0, 0, 1, 1, 1, 1}};
  const double t = 0.3;
  std::vector<double> n(4);
  basis_functions(bern, find_span(bern, t), t, n);
  CHECK_THAT(n[0], WithinAbs(0.7 * 0.7 * 0.7, 1e-15));
  CHECK_THAT(n[1], WithinAbs(3 * 0.3 * 0.7 * 0.7, 1e-15));
  CHECK_THAT(n[2], WithinAbs(3 * 0.3 * 0.3 * 0.7, 1e-15));
  CHECK_THAT(n[3], WithinAbs(0.3 * 0.3 * 0.3, 1e-15));
}

TEST_CASE("basis derivatives match central differences and vanish above the degree", "[basis]") {
  std::mt19937 rng(11);
  for (int p = 1; p <= 7; ++p) {
    const BSplineBasis b = clay::test::random_basis(rng, p, p + 5, true);
    const auto [a, e] = b.domain();
    for (int k = 1; k < 20; ++k) {
      const double t = a + (e - a) * (k + 0.37) / 20.3;
      const int span = find_span(b, t);
      const double h = 1e-6;
      if (find_span(b, t - h) != span || find_span(b, t + h) != span) continue;  // skip knots
      std::vector<double> d(static_cast<size_t>(3 * (p + 1))), lo(static_cast<size_t>(p + 1)),
          hi(static_cast<size_t>(p + 1)), mid(static_cast<size_t>(p + 1));
      basis_derivatives(b, span, t, 2, d);
      basis_functions(b, span, t - h, lo);
      basis_functions(b, span, t + h, hi);
      basis_functions(b, span, t, mid);
      for (int j = 0; j <= p; ++j) {
        CHECK_THAT(d[static_cast<size_t>(j)], WithinAbs(mid[static_cast<size_t>(j)], 1e-14));
        const double fd1 = (hi[static_cast<size_t>(j)] - lo[static_cast<size_t>(j)]) / (2 * h);
        CHECK_THAT(d[static_cast<size_t>(p + 1 + j)], WithinAbs(fd1, 1e-5 * (1 + std::abs(fd1))));
        const double fd2 = (hi[static_cast<size_t>(j)] - 2 * mid[static_cast<size_t>(j)] +
                            lo[static_cast<size_t>(j)]) /
                           (h * h);
        if (p >= 2)
          CHECK_THAT(d[static_cast<size_t>(2 * (p + 1) + j)],
                     WithinAbs(fd2, 1e-2 * (1 + std::abs(fd2))));
        else
          CHECK(d[static_cast<size_t>(2 * (p + 1) + j)] == 0.0);
      }
    }
  }
}

TEST_CASE("basis validation names each broken invariant", "[basis][errors]") {
  CHECK(problems(BSplineBasis{2, {0, 0, 0, 1, 1, 1}}, "b").empty());
  auto first = [](const BSplineBasis& b) {
    const auto p = problems(b, "test basis");
    return p.empty() ? std::string() : p.front();
  };
  CHECK_THAT(first(BSplineBasis{0, {0, 1}}), Catch::Contains("degree 0"));
  CHECK_THAT(first(BSplineBasis{3, {0, 0, 0, 1, 1, 1}}), Catch::Contains("needs at least 8"));
  CHECK_THAT(first(BSplineBasis{2, {0, 0, 0, 0.7, 0.5, 1, 1, 1}}),
             Catch::Contains("decrease at index 4"));
  CHECK_THAT(first(BSplineBasis{2, {0, 0, 0, std::nan(""), 1, 1, 1}}),
             Catch::Contains("not finite"));
  CHECK_THAT(first(BSplineBasis{2, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1}}),
             Catch::Contains("multiplicity 3"));
  CHECK_THAT(first(BSplineBasis{2, {0, 0, 0, 0, 1, 1, 1}}), Catch::Contains("multiplicity 4"));
  CHECK_THAT(first(BSplineBasis{1, {1, 1, 1, 1}}), Catch::Contains("domain"));
  try {
    validate(BSplineBasis{2, {0, 0, 0, 0.7, 0.5, 1, 1, 1}}, "hood u basis");
    FAIL("validate did not throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidGeometry);
    CHECK_THAT(e.what(),
               Catch::Contains("hood u basis") && Catch::Contains("sort the knot vector"));
  }
}

TEST_CASE("clamped_uniform_basis, breakpoints, multiplicity", "[basis]") {
  const BSplineBasis b = clamped_uniform_basis(3, 7, -1.0, 3.0);
  CHECK(b.knots == std::vector<double>{-1, -1, -1, -1, 0, 1, 2, 3, 3, 3, 3});
  CHECK(is_clamped(b));
  CHECK(multiplicity(b, -1.0) == 4);
  CHECK(breakpoints(b) == std::vector<double>{-1, 0, 1, 2, 3});
  CHECK_THROWS_AS(clamped_uniform_basis(3, 3), clay::Error);
  CHECK_THROWS_AS(clamped_uniform_basis(2, 5, 1.0, 1.0), clay::Error);
}

TEST_CASE("greville_abscissae average degree-many knots and reproduce linear functions",
          "[basis]") {
  const BSplineBasis b{3, {0, 0, 0, 0, 1, 3, 4, 4, 4, 4}};
  const auto xi = greville_abscissae(b);
  REQUIRE(xi.size() == 6);
  CHECK_THAT(xi[0], WithinAbs(0.0, 1e-15));
  CHECK_THAT(xi[1], WithinAbs(1.0 / 3, 1e-15));
  CHECK_THAT(xi[2], WithinAbs(4.0 / 3, 1e-15));
  CHECK_THAT(xi[3], WithinAbs(8.0 / 3, 1e-15));
  CHECK_THAT(xi[4], WithinAbs(11.0 / 3, 1e-15));
  CHECK_THAT(xi[5], WithinAbs(4.0, 1e-15));
  // Linear precision: sum_i N_i(t) xi_i = t at every parameter.
  std::vector<double> N(4);
  for (double t : {0.0, 0.3, 1.0, 2.2, 3.9, 4.0}) {
    const int k = find_span(b, t);
    basis_functions(b, k, t, N);
    double sum = 0;
    for (int r = 0; r <= 3; ++r)
      sum += N[static_cast<size_t>(r)] * xi[static_cast<size_t>(k - 3 + r)];
    CHECK_THAT(sum, WithinAbs(t, 1e-14));
  }
}

TEST_CASE("span_samples follows the knot spans", "[basis]") {
  const BSplineBasis b{2, {0, 0, 0, 1, 1, 3, 3, 3}};  // spans [0, 1], [1, 3]
  CHECK(span_samples(b, 2) == std::vector<double>{0, 0.5, 1, 2, 3});
  CHECK(span_samples(b, 1) == std::vector<double>{0, 1, 3});
  CHECK_THROWS_AS(span_samples(b, 0), clay::Error);
}
