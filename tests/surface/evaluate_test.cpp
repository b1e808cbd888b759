#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "random_geometry.hpp"

using namespace clay::surface;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

/// Quarter circles of radius r as a degree-2 rational curve: every point at distance r exactly.
BSplineCurve full_circle(double r) {
  const double w = std::sqrt(0.5);
  Points3 p(9, 3);
  p << r, 0, 0, r, r, 0, 0, r, 0, -r, r, 0, -r, 0, 0, -r, -r, 0, 0, -r, 0, r, -r, 0, r, 0, 0;
  Eigen::VectorXd wt(9);
  wt << 1, w, 1, w, 1, w, 1, w, 1;
  return make_curve(2, {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1}, p, wt);
}

}  // namespace

TEST_CASE("rational circle: exact radius, tangent orthogonal, curvature 1/r", "[evaluate]") {
  const double r = 37.5;
  const BSplineCurve c = full_circle(r);
  for (int k = 0; k <= 400; ++k) {
    const double t = k / 400.0;
    const CurveDerivatives d = derivatives(c, t);
    CHECK_THAT(d.point.norm(), WithinRel(r, 1e-15));
    CHECK_THAT(d.point.dot(d.d1), WithinAbs(0.0, 1e-12 * r * d.d1.norm()));
    const double kappa = d.d1.cross(d.d2).norm() / std::pow(d.d1.norm(), 3);
    CHECK_THAT(kappa, WithinRel(1.0 / r, 1e-12));
  }
}

TEST_CASE("surface derivatives match central differences on random rational surfaces",
          "[evaluate]") {
  std::mt19937 rng(21);
  for (int p = 1; p <= 5; ++p) {
    const BSplineSurface s =
        clay::test::random_surface(rng, p, 6 - p, p + 4, 9 - p, true, p % 2 == 0);
    const auto [ua, ub] = s.u.domain();
    const auto [va, vb] = s.v.domain();
    for (int k = 0; k < 25; ++k) {
      const double u = ua + (ub - ua) * (0.05 + 0.9 * ((k * 7) % 25) / 25.0);
      const double v = va + (vb - va) * (0.05 + 0.9 * ((k * 11) % 25) / 25.0);
      const double hu = 1e-5 * (ub - ua), hv = 1e-5 * (vb - va);
      if (find_span(s.u, u - hu) != find_span(s.u, u + hu) ||
          find_span(s.v, v - hv) != find_span(s.v, v + hv))
        continue;
      const SurfaceDerivatives d = derivatives(s, u, v);
      const SurfaceDerivatives pu = derivatives(s, u + hu, v, 1), mu = derivatives(s, u - hu, v, 1);
      const SurfaceDerivatives pv = derivatives(s, u, v + hv, 1), mv = derivatives(s, u, v - hv, 1);
      const double scale = 1.0 + d.du.norm() + d.dv.norm();
      CHECK(((pu.point - mu.point) / (2 * hu) - d.du).norm() < 1e-4 * scale);
      CHECK(((pv.point - mv.point) / (2 * hv) - d.dv).norm() < 1e-4 * scale);
      const double scale2 = 1.0 + d.duu.norm() + d.dvv.norm() + d.duv.norm();
      CHECK(((pu.du - mu.du) / (2 * hu) - d.duu).norm() < 1e-4 * scale2);
      CHECK(((pv.dv - mv.dv) / (2 * hv) - d.dvv).norm() < 1e-4 * scale2);
      CHECK(((pv.du - mv.du) / (2 * hv) - d.duv).norm() < 1e-4 * scale2);
      CHECK(((pu.dv - mu.dv) / (2 * hu) - d.duv).norm() < 1e-4 * scale2);
      CHECK((evaluate(s, u, v) - d.point).norm() == 0.0);
    }
  }
}

TEST_CASE("bilinear patch evaluates to its closed form", "[evaluate]") {
  Points3 p(4, 3);
  p << 0, 0, 0, 0, 10, 1, 20, 0, 2, 20, 10, 7;  // (i, j) = i * 2 + j
  const BSplineSurface s =
      make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  for (double u : {0.0, 0.25, 0.5, 1.0})
    for (double v : {0.0, 0.3, 1.0}) {
      const Eigen::Vector3d expect =
          (1 - u) * (1 - v) * p.row(0).transpose() + (1 - u) * v * p.row(1).transpose() +
          u * (1 - v) * p.row(2).transpose() + u * v * p.row(3).transpose();
      CHECK((evaluate(s, u, v) - expect).norm() < 1e-14);
      const SurfaceDerivatives d = derivatives(s, u, v);
      const Eigen::Vector3d duv =
          p.row(0).transpose() - p.row(1).transpose() - p.row(2).transpose() + p.row(3).transpose();
      CHECK((d.duv - duv).norm() < 1e-13);
      CHECK(d.duu.norm() == 0.0);
    }
  const Eigen::Vector3d n = unit_normal(s, 0.0, 0.0);
  CHECK_THAT(n.dot(Eigen::Vector3d(20, 0, 2).normalized()), WithinAbs(0.0, 1e-15));
  CHECK_THAT(n.norm(), WithinAbs(1.0, 1e-15));
}

TEST_CASE("grid evaluation equals pointwise evaluation", "[evaluate]") {
  std::mt19937 rng(5);
  for (bool rational : {false, true}) {
    const BSplineSurface s = clay::test::random_surface(rng, 3, 2, 9, 7, rational, false, 2);
    const auto [ua, ub] = s.u.domain();
    const auto [va, vb] = s.v.domain();
    const auto us = linspace(ua, ub, 31);
    const auto vs = linspace(va, vb, 17);
    const Points3 g = evaluate_grid(s, us, vs);
    REQUIRE(g.rows() == 31 * 17);
    double worst = 0;
    for (size_t i = 0; i < us.size(); ++i)
      for (size_t j = 0; j < vs.size(); ++j)
        worst = std::max(worst, (g.row(static_cast<Eigen::Index>(i * vs.size() + j)).transpose() -
                                 evaluate(s, us[i], vs[j]))
                                    .norm());
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("evaluation errors: parameter outside the domain, bad order, degenerate normal",
          "[evaluate][errors]") {
  std::mt19937 rng(9);
  const BSplineSurface s = clay::test::random_surface(rng, 2, 2, 4, 4, true);
  try {
    evaluate(s, 1.5, 0.0);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::OutOfDomain);
    CHECK_THAT(e.what(), Catch::Contains("1.5") && Catch::Contains("domain [0, 1]"));
  }
  CHECK_THROWS_AS(derivatives(s, 0.5, 0.5, 3), clay::Error);
  CHECK_THROWS_AS(linspace(0, 1, 1), clay::Error);
  // A surface collapsed to a point along u = 0 has no normal there.
  Points3 p(4, 3);
  p << 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0;
  const BSplineSurface tri =
      make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  CHECK_THROWS_AS(unit_normal(tri, 0.0, 0.5), clay::Error);
  BSplineSurface broken = s;
  broken.weights.resize(2);
  CHECK_THROWS_AS(evaluate(broken, 0.5, 0.5), clay::Error);
  broken = s;
  broken.points(0, 0) = std::nan("");
  CHECK_THROWS_AS(evaluate_grid(broken, linspace(0, 1, 3), linspace(-1, 2, 3)), clay::Error);
}

TEST_CASE("evaluate_many equals pointwise evaluation of a curve", "[evaluate]") {
  std::mt19937 rng(12);
  const BSplineCurve c = clay::test::random_curve(rng, 4, 9, true, false);
  const auto [a, b] = c.basis.domain();
  const auto ts = linspace(a, b, 33);
  const Points3 pts = evaluate_many(c, ts);
  REQUIRE(pts.rows() == 33);
  for (size_t k = 0; k < ts.size(); ++k)
    CHECK((pts.row(static_cast<Eigen::Index>(k)).transpose() - evaluate(c, ts[k])).norm() == 0.0);
  CHECK_THROWS_AS(evaluate_many(c, std::vector<double>{a, b + 1.0}), clay::Error);
}

TEST_CASE("derivatives_grid equals pointwise derivatives on random rational surfaces",
          "[evaluate]") {
  std::mt19937 rng(808);
  for (bool rational : {false, true}) {
    const BSplineSurface s = clay::test::random_surface(rng, 3, 2, 7, 6, rational);
    const auto [u0, u1] = s.u.domain();
    const auto [v0, v1] = s.v.domain();
    const std::vector<double> us = linspace(u0, u1, 23), vs = linspace(v0, v1, 19);
    const std::vector<SurfaceDerivatives> grid = derivatives_grid(s, us, vs);
    REQUIRE(grid.size() == us.size() * vs.size());
    double worst = 0, scale = 0;
    for (size_t i = 0; i < us.size(); ++i)
      for (size_t j = 0; j < vs.size(); ++j) {
        const SurfaceDerivatives a = grid[i * vs.size() + j], b = derivatives(s, us[i], vs[j], 2);
        for (const auto& [x, y] : {std::pair{a.point, b.point},
                                   {a.du, b.du},
                                   {a.dv, b.dv},
                                   {a.duu, b.duu},
                                   {a.duv, b.duv},
                                   {a.dvv, b.dvv}}) {
          worst = std::max(worst, (x - y).norm());
          scale = std::max(scale, y.norm());
        }
      }
    CHECK(worst <= 1e-12 * scale);
  }
}
