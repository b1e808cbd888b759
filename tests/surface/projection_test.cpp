#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <random>
#include <thread>
#include <vector>

#include "random_geometry.hpp"

using namespace clay::surface;
using Catch::Matchers::WithinAbs;

namespace {

/// A quarter cylinder of radius r and height h about the z axis: exact rational quadratic in u.
BSplineSurface quarter_cylinder(double r, double h) {
  const double w = std::sqrt(0.5);
  Points3 p(6, 3);  // (i, j) = i * 2 + j, j along z
  p << r, 0, 0, r, 0, h, r, r, 0, r, r, h, 0, r, 0, 0, r, h;
  Eigen::VectorXd wt(6);
  wt << 1, 1, w, w, 1, 1;
  return make_surface(BSplineBasis{2, {0, 0, 0, 1, 1, 1}}, clamped_uniform_basis(1, 2), p, wt);
}

}  // namespace

TEST_CASE("closest point on an exact cylinder: distance |rho - r| and the radial foot",
          "[projection]") {
  const double r = 50.0, h = 80.0;
  const BSplineSurface s = quarter_cylinder(r, h);
  std::mt19937 rng(51);
  std::uniform_real_distribution<double> angle(0.05, 1.52), rho(5.0, 120.0), z(1.0, 79.0);
  for (int k = 0; k < 100; ++k) {
    const double a = angle(rng), q = rho(rng), zz = z(rng);
    const Eigen::Vector3d p(q * std::cos(a), q * std::sin(a), zz);
    const SurfaceProjection proj = closest_point(s, p);
    REQUIRE(proj.summary.converged());
    CHECK_THAT(proj.distance, WithinAbs(std::abs(q - r), 1e-9));
    const Eigen::Vector3d foot(r * std::cos(a), r * std::sin(a), zz);
    CHECK((proj.point - foot).norm() < 1e-9);
    CHECK_FALSE(proj.on_boundary);
  }
}

TEST_CASE("closest point beyond the domain edge lands on the edge", "[projection]") {
  const BSplineSurface s = quarter_cylinder(50.0, 80.0);
  const SurfaceProjection above = closest_point(s, Eigen::Vector3d(30.0, 30.0, 120.0));
  CHECK(above.on_boundary);
  CHECK_THAT(above.v, WithinAbs(1.0, 0.0));
  CHECK_THAT(above.distance, WithinAbs(std::hypot(40.0, 50.0 - std::hypot(30.0, 30.0)), 1e-9));
}

TEST_CASE("normal projection recovers the foot point of offset points on random surfaces",
          "[projection]") {
  std::mt19937 rng(52);
  for (int p = 2; p <= 4; ++p) {
    // Mild surfaces (small z relief over a regular xy grid) so that the offset foot point is
    // unique.
    BSplineSurface s = clay::test::random_surface(rng, p, p, p + 3, p + 3, true, true, 1, 10.0);
    for (int i = 0; i < s.count_u(); ++i)
      for (int j = 0; j < s.count_v(); ++j) {
        s.points(s.index(i, j), 0) = 100.0 * i;
        s.points(s.index(i, j), 1) = 100.0 * j;
      }
    const auto [ua, ub] = s.u.domain();
    const auto [va, vb] = s.v.domain();
    for (int k = 1; k < 10; ++k) {
      const double u = ua + (ub - ua) * k / 10.0, v = va + (vb - va) * (10 - k) / 10.0;
      const Eigen::Vector3d foot = evaluate(s, u, v);
      const Eigen::Vector3d p_off = foot + 3.0 * unit_normal(s, u, v);
      const SurfaceProjection proj =
          project_normal(s, p_off, std::min(ub, u + 0.03 * (ub - ua)), v);
      REQUIRE(proj.summary.converged());
      CHECK_THAT(proj.distance, WithinAbs(3.0, 1e-9));
      CHECK((proj.point - foot).norm() < 1e-8);
      // Independent check of the foot condition: S - P orthogonal to both tangents.
      const SurfaceDerivatives d = derivatives(s, proj.u, proj.v, 1);
      const Eigen::Vector3d rr = proj.point - p_off;
      CHECK(std::abs(d.du.dot(rr)) < 1e-9 * d.du.norm() * rr.norm());
      CHECK(std::abs(d.dv.dot(rr)) < 1e-9 * d.dv.norm() * rr.norm());
      const SurfaceProjection global = closest_point(s, p_off);
      CHECK(global.distance <= proj.distance + 1e-9);
    }
  }
}

TEST_CASE("projection refuses bad input", "[projection][errors]") {
  const BSplineSurface s = quarter_cylinder(10.0, 10.0);
  CHECK_THROWS_AS(closest_point(s, Eigen::Vector3d(std::nan(""), 0, 0)), clay::Error);
  try {
    project_normal(s, Eigen::Vector3d(1, 2, 3), 2.0, 0.5);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::OutOfDomain);
  }
  ProjectionOptions bad;
  bad.samples_per_span = 0;
  try {
    closest_point(s, Eigen::Vector3d(1, 2, 3), bad);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("samples_per_span"));
  }
}

TEST_CASE("closest point near a collapsed edge (a triangular patch)", "[projection]") {
  // Bicubic patch whose row i = 0 collapses to the apex (0, 0, 0): S_v vanishes along u = 0.
  Points3 p(16, 3);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double r = 30.0 * i, a = 0.5 * j;  // a fan from the apex
      p.row(i * 4 + j) << r * std::cos(a), r * std::sin(a), 0.0;
    }
  const BSplineSurface s =
      make_surface(clamped_uniform_basis(3, 4), clamped_uniform_basis(3, 4), p);
  // Points of the surface near and at the apex project onto themselves.
  for (double u : {0.0, 1e-6, 0.01, 0.2})
    for (double v : {0.0, 0.4, 1.0}) {
      const Eigen::Vector3d x =
          evaluate(s, u, v) + Eigen::Vector3d(0, 0, 2.0);  // 2 mm above the plane
      const SurfaceProjection proj = closest_point(s, x);
      INFO("u " << u << ", v " << v << ": " << proj.summary.brief());
      CHECK(proj.summary.termination != clay::Termination::Failed);
      CHECK_THAT(proj.distance, WithinAbs(2.0, 1e-9));
    }
}

TEST_CASE("SurfaceProjector: the cylinder's closed-form distance, and the free functions' results",
          "[projection]") {
  const double r = 50.0, h = 80.0;
  const BSplineSurface s = quarter_cylinder(r, h);
  const SurfaceProjector projector(s);
  std::mt19937 rng(52);
  std::uniform_real_distribution<double> angle(0.05, 1.52), rho(5.0, 120.0), z(1.0, 79.0);
  for (int k = 0; k < 50; ++k) {
    const double a = angle(rng), q = rho(rng), zz = z(rng);
    const Eigen::Vector3d p(q * std::cos(a), q * std::sin(a), zz);
    const SurfaceProjection c = projector.closest_point(p);
    REQUIRE(c.summary.converged());
    CHECK_THAT(c.distance, WithinAbs(std::abs(q - r), 1e-9));
    CHECK_THAT(c.point.z(), WithinAbs(zz, 1e-9));
    const SurfaceProjection free = closest_point(s, p);
    CHECK(free.u == c.u);
    CHECK(free.v == c.v);
    const SurfaceProjection n = projector.project_normal(p, 0.5, 0.5);
    const SurfaceProjection free_n = project_normal(s, p, 0.5, 0.5);
    CHECK(n.u == free_n.u);
    CHECK(n.v == free_n.v);
    CHECK(n.distance == free_n.distance);
  }
  CHECK_THROWS_AS(SurfaceProjector(BSplineSurface{}), clay::Error);
  CHECK_THROWS_AS(projector.project_normal(Eigen::Vector3d(0, 0, std::nan("")), 0.5, 0.5),
                  clay::Error);
  CHECK_THROWS_AS(projector.project_normal(Eigen::Vector3d::Zero(), 2.0, 0.5), clay::Error);
  ProjectionOptions bad;
  bad.starts = 0;
  CHECK_THROWS_AS(SurfaceProjector(s, bad), clay::Error);
}

TEST_CASE("SurfaceProjector: the start grid is evaluated once, shared by copies and threads",
          "[projection]") {
  // The grid is built on the first closest_point; threads racing for it, on the projector and on
  // a copy made before it existed, get the cylinder's closed-form distance and the same
  // parameters.
  const double r = 50.0, h = 80.0;
  const BSplineSurface s = quarter_cylinder(r, h);
  std::vector<Eigen::Vector3d> points;
  std::vector<double> distance;
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> angle(0.05, 1.52), rho(5.0, 120.0), z(1.0, 79.0);
  for (int k = 0; k < 200; ++k) {
    const double a = angle(rng), q = rho(rng);
    points.emplace_back(q * std::cos(a), q * std::sin(a), z(rng));
    distance.push_back(std::abs(q - r));
  }
  for (int round = 0; round < 20; ++round) {
    const SurfaceProjector projector(s);
    const SurfaceProjector copy = projector;  // before any grid exists
    std::vector<SurfaceProjection> a(points.size()), b(points.size());
    std::thread other([&] {
      for (size_t k = 0; k < points.size(); ++k) b[k] = copy.closest_point(points[k]);
    });
    for (size_t k = 0; k < points.size(); ++k) a[k] = projector.closest_point(points[k]);
    other.join();
    for (size_t k = 0; k < points.size(); ++k) {
      CHECK_THAT(a[k].distance, WithinAbs(distance[k], 1e-9));
      CHECK(a[k].u == b[k].u);
      CHECK(a[k].v == b[k].v);
    }
  }
  // A moved-from projector says so instead of reading a grid it no longer has.
  SurfaceProjector from(s);
  const SurfaceProjector to = std::move(from);
  CHECK_THAT(to.closest_point(points[0]).distance, WithinAbs(distance[0], 1e-9));
  CHECK_THROWS_AS(from.closest_point(points[0]), clay::Error);  // NOLINT(bugprone-use-after-move)
}

TEST_CASE("curve projection: closed forms on a circle and a segment", "[projection]") {
  // A full circle of radius 5 about (1, 2, 0) in the xy plane, as rational quadratic arcs.
  const Eigen::Vector3d c(1, 2, 0);
  const BSplineCurve circle = circular_arc(c, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 5,
                                           0, 2 * std::numbers::pi);
  for (double angle : {0.3, 1.9, 3.0, 4.4, 6.1}) {
    const Eigen::Vector3d q =
        c + 8 * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0) + Eigen::Vector3d(0, 0, 3);
    const CurveProjection p = closest_point(circle, q);
    // The closest point of a circle: the foot in the direction of q's projection on its plane.
    const Eigen::Vector3d foot = c + 5 * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0);
    CHECK((p.point - foot).norm() < 1e-12);
    CHECK(std::abs(p.distance - std::hypot(3.0, 3.0)) < 1e-12);
    CHECK((evaluate(circle, p.t) - p.point).norm() == 0);
  }
  // A segment: inside, the perpendicular foot; beyond an end, the end (no silent overshoot).
  const BSplineCurve segment =
      make_curve(1, {0, 0, 1, 1}, (Points3(2, 3) << 0, 0, 0, 10, 0, 0).finished());
  CHECK(std::abs(closest_point(segment, Eigen::Vector3d(4, 3, 0)).t - 0.4) < 1e-14);
  CHECK(closest_point(segment, Eigen::Vector3d(14, 3, 0)).t == 1.0);
  CHECK(project_normal(segment, Eigen::Vector3d(-4, 3, 0), 0.5).t == 0.0);
  // Periodic: Newton from near the seam wraps round it instead of stopping at the domain's end.
  const auto [t0, t1] = circle.basis.domain();
  const Eigen::Vector3d near_seam = c + 6 * Eigen::Vector3d(std::cos(-0.2), std::sin(-0.2), 0);
  const CurveProjection wrapped = project_normal(circle, near_seam, t0 + 0.01 * (t1 - t0), true);
  CHECK((wrapped.point - (c + 5 * Eigen::Vector3d(std::cos(-0.2), std::sin(-0.2), 0))).norm() <
        1e-12);
  CHECK_THROWS_AS(closest_point(segment, Eigen::Vector3d(std::nan(""), 0, 0)), clay::Error);
  CHECK_THROWS_AS(closest_point(segment, Eigen::Vector3d(1, 0, 0), 0), clay::Error);
}
