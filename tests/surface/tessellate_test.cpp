// The grid tessellator and the quadrature area (clay/surface/tessellate.hpp), against closed forms
// (areas of a rectangle, a sphere and a cylinder) and pointwise evaluation.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/tessellate.hpp>

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
  const BSplineSurface flat = make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  CHECK_THAT(surface_area(flat, 0), WithinRel(600.0, 1e-13));
  CHECK_THAT(surface_area(sphere(7), 2), WithinRel(4 * std::numbers::pi * 49, 1e-9));
  // A cylinder r = 5, height 12: the side area 2 pi r h.
  const BSplineCurve line = make_curve(1, {0, 0, 1, 1}, (Points3(2, 3) << 5, 0, 0, 5, 0, 12).finished());
  CHECK_THAT(surface_area(revolve(line, Axis{}).surface, 1), WithinRel(2 * std::numbers::pi * 5 * 12, 1e-9));
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
  CHECK(tessellation_parameters(clamped_uniform_basis(3, 4)).size() == 17);            // 1 span: 16 + 1
  CHECK(tessellation_parameters(clamped_uniform_basis(3, 500)).size() == 161);          // capped
  CHECK(tessellation_parameters(clamped_uniform_basis(3, 8), 8).size() == 5 * 8 + 1);  // 5 spans
  double worst_point = 0, worst_normal = 0;
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j) {
      const Eigen::Vector3d x = m.positions.row(i * m.cols + j).transpose();
      worst_point = std::max(worst_point, (x - evaluate(s, m.us[size_t(i)], m.vs[size_t(j)])).norm());
      // On a sphere about the origin the outward normal is x / |x|, also at the poles, where
      // S_u x S_v vanishes and the neighbouring triangles decide.
      const Eigen::Vector3d n = m.normals.row(i * m.cols + j).transpose();
      worst_normal = std::max(worst_normal, std::min((n - x.normalized()).norm(), (n + x.normalized()).norm()));
    }
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
