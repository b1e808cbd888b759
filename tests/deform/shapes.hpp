#pragma once
// Shapes the surface-deformation tests share: a lattice frame round a 100 x 100 mm dome, a bulge
// lattice and a flaring taper in it, and the largest gap between two surfaces on a grid.
#include <clay/deform/lattice.hpp>
#include <clay/deform/regular.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>

namespace clay::test {

inline deform::Frame box_frame() {
  deform::Frame f;
  f.origin = {-10, -10, -20};
  f.s = {120, 0, 0};
  f.t = {0, 120, 0};
  f.u = {0, 0, 60};
  return f;
}

/// A (2, 2, 1) Bézier lattice in box_frame() with its middle top point raised.
inline deform::BezierLattice bulge() {
  deform::BezierLattice l = deform::make_bezier_lattice(box_frame(), {2, 2, 1});
  l.points.row(l.index(1, 1, 1)) += Eigen::RowVector3d(3, -2, 15);
  return l;
}

/// A linear taper about the dome's middle, r(z) = 1 + 0.004 z.
inline deform::Taper flare() {
  deform::Taper t;
  t.frame.origin = {50, 50, 0};
  t.profile = {1.0, 0.004};
  return t;
}

/// Largest |a(u, v) - b(u, v)| on an (n + 1) x (n + 1) grid of the unit square.
inline double grid_gap(const surface::BSplineSurface& a, const surface::BSplineSurface& b,
                       int n = 60) {
  double worst = 0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      worst = std::max(worst, (surface::evaluate(a, double(i) / n, double(j) / n) -
                               surface::evaluate(b, double(i) / n, double(j) / n))
                                  .norm());
  return worst;
}

}  // namespace clay::test
