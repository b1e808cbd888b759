#pragma once
// The surface the style and studio benchmarks drag on: a car hood about 1200 x 800 mm, a 16 x 16
// bicubic net on clamped uniform knots, crowned 80 mm and tilted 0.05.
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_surface.hpp>

namespace clay::bench {

inline surface::BSplineSurface hood() {
  const int n = 16;
  auto b = surface::clamped_uniform_basis(3, n);
  const auto xi = surface::greville_abscissae(b);
  surface::Points3 p(n * n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = -600 + 1200 * xi[static_cast<size_t>(i)],
                   y = -400 + 800 * xi[static_cast<size_t>(j)];
      p.row(i * n + j) << x, y,
          80 * (1 - (x / 700) * (x / 700)) * (1 - (y / 500) * (y / 500)) + 0.05 * x;
    }
  return surface::make_surface(b, b, p);
}

}  // namespace clay::bench
