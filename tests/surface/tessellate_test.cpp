// The grid tessellator and the quadrature area (clay/surface/tessellate.hpp), against closed forms
// (areas of a rectangle, a sphere and a cylinder) and pointwise evaluation.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/tessellate.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

using namespace clay::surface;
using Catch::Matchers::WithinRel;

namespace {

/// The sphere of radius r about the origin, revolved from two rational quarter circles.
BSplineSurface sphere(double r) {
  const double h = std::sqrt(0.5);
  const BSplineCurve meridian =
      make_curve(2, {0, 0, 0, 0.5, 0.5, 1, 1, 1},
                 (Points3(5, 3) << 0, 0, -r, r, 0, -r, r, 0, 0, r, 0, r, 0, 0, r).finished(),
                 (Eigen::VectorXd(5) << 1, h, 1, h, 1).finished());
  return revolve(meridian, Axis{}).surface;
}

}  // namespace

TEST_CASE("surface_area matches closed forms", "[tessellate]") {
  // A bilinear 30 x 20 rectangle, tilted: area 600.
  Points3 p(4, 3);
  p << 0, 0, 0, 0, 20, 0, 30, 0, 30 * 0.0, 30, 20, 0;
  const BSplineSurface flat =
      make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  CHECK_THAT(surface_area(flat, 0), WithinRel(600.0, 1e-13));
  CHECK_THAT(surface_area(sphere(7), 2), WithinRel(4 * std::numbers::pi * 49, 1e-9));
  // A cylinder r = 5, height 12: the side area 2 pi r h.
  const BSplineCurve line =
      make_curve(1, {0, 0, 1, 1}, (Points3(2, 3) << 5, 0, 0, 5, 0, 12).finished());
  CHECK_THAT(surface_area(revolve(line, Axis{}).surface, 1),
             WithinRel(2 * std::numbers::pi * 5 * 12, 1e-9));
  CHECK_THROWS_AS(surface_area(flat, -1), clay::Error);
}

TEST_CASE("tessellate: vertices on the surface, exact normals, the viewer's grid", "[tessellate]") {
  const BSplineSurface s = sphere(10);
  const GridMesh m = tessellate(s);
  // The grid follows the knots: every breakpoint is a grid parameter, 8 per span, 17 at least.
  for (double b : breakpoints(s.u)) CHECK(std::find(m.us.begin(), m.us.end(), b) != m.us.end());
  CHECK(m.rows == static_cast<int>(m.us.size()));
  CHECK(m.rows >= 17);
  CHECK(m.rows <= 161);
  CHECK(tessellation_parameters(clamped_uniform_basis(3, 4)).size() == 17);     // 1 span: 16 + 1
  CHECK(tessellation_parameters(clamped_uniform_basis(3, 500)).size() == 161);  // capped
  CHECK(tessellation_parameters(clamped_uniform_basis(3, 8), 8).size() == 5 * 8 + 1);  // 5 spans
  double worst_point = 0, worst_normal = 0;
  // The side S_u x S_v points to, read at a regular point (the equator): every normal, the poles'
  // too, must point there, and every triangle must wind the same way.
  const SurfaceDerivatives e = derivatives(s, 0.3, 0.5, 1);
  const double side = e.du.cross(e.dv).dot(e.point) > 0 ? 1.0 : -1.0;
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j) {
      const Eigen::Vector3d x = m.positions.row(i * m.cols + j).transpose();
      worst_point =
          std::max(worst_point, (x - evaluate(s, m.us[size_t(i)], m.vs[size_t(j)])).norm());
      // On a sphere about the origin the normal is side x / |x|, also at the poles, where
      // S_u x S_v vanishes and the neighbouring triangles decide.
      const Eigen::Vector3d n = m.normals.row(i * m.cols + j).transpose();
      worst_normal = std::max(worst_normal, (n - side * x.normalized()).norm());
    }
  int against = 0;
  for (int i = 0; i + 1 < m.rows; ++i)
    for (int j = 0; j + 1 < m.cols; ++j)
      for (const auto& t : cell_triangles(m, i, j)) {
        const Eigen::Vector3d a = m.positions.row(t[0]).transpose(),
                              b = m.positions.row(t[1]).transpose(),
                              c = m.positions.row(t[2]).transpose();
        const Eigen::Vector3d n = (b - a).cross(c - a);
        if (n.norm() > 1e-12 && side * n.dot(a + b + c) < 0) ++against;
      }
  CHECK(against == 0);
  CHECK(worst_point <= 1e-12);
  CHECK(worst_normal <= 0.02);
  // The mesh's area approaches the sphere's from below as the grid is refined.
  const double exact = 4 * std::numbers::pi * 100;
  const double coarse = mesh_area(m), fine = mesh_area(tessellate(s, 32, 641));
  CHECK(coarse < exact);
  CHECK(fine < exact);
  CHECK(exact - fine < 0.2 * (exact - coarse));
  const GridMesh met = tessellate_to_area(s, 0.001);
  CHECK(std::abs(mesh_area(met) - exact) <= 0.001 * exact);
  CHECK_THROWS_AS(tessellate_to_area(s, 0.0), clay::Error);
  CHECK_THROWS_AS(tessellation_parameters(s.u, 0), clay::Error);
}

TEST_CASE("tessellate_to_area refines a wavy single patch past the viewer's grid", "[tessellate]") {
  // One Bezier span of degree 15 whose control points zigzag 40 mm up and down across 100 mm:
  // the viewer's 17 samples cut the waves; the area needs a much finer grid in u.
  const int n = 16;
  Points3 p(n * 2, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2; ++j)
      p.row(i * 2 + j) << 100.0 * i / (n - 1), 30.0 * j, (i % 2 ? 40.0 : -40.0);
  std::vector<double> ku(static_cast<size_t>(2 * n), 0.0);
  for (int k = n; k < 2 * n; ++k) ku[static_cast<size_t>(k)] = 1;
  const BSplineSurface s = make_surface(BSplineBasis{n - 1, ku}, clamped_uniform_basis(1, 2), p);
  const double exact = surface_area(s, 5);
  CHECK_THAT(surface_area(s, 2), WithinRel(exact, 1e-4));  // the quadrature tessellate_to_area uses
  const GridMesh coarse = tessellate(s);
  const double coarse_error = std::abs(mesh_area(coarse) - exact) / exact;
  INFO("the viewer's grid (" << coarse.rows << " x " << coarse.cols << ") is off by "
                             << 100 * coarse_error << " %");
  const GridMesh m = tessellate_to_area(s, 0.001);
  CHECK(std::abs(mesh_area(m) - exact) <= 0.001 * exact);
  CHECK(m.rows > coarse.rows);
  // With a cap too small for the waves, the failure names the grid and both areas.
  try {
    (void)tessellate_to_area(s, 1e-6, 17);
    FAIL("no exception");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::ToleranceNotMet);
    CHECK_THAT(e.message(), Catch::Matchers::Contains("17 x 17 samples"));
  }
}
