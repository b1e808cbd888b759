#pragma once
// A degree-1 B-spline through given points (knots 0, 1, 2, ...): the simplest test curve.
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <vector>

namespace clay::test {

/// Degree-1 curve through the points, knots 0, 0, 1, 2, ..., n-1, n-1 (parameter k at point k).
inline surface::BSplineCurve polyline(const std::vector<Eigen::Vector3d>& points) {
  const int n = static_cast<int>(points.size());
  std::vector<double> knots = {0.0};
  for (int i = 0; i < n; ++i) knots.push_back(i);
  knots.push_back(n - 1);
  surface::Points3 p(n, 3);
  for (int i = 0; i < n; ++i) p.row(i) = points[static_cast<size_t>(i)].transpose();
  return surface::make_curve(1, knots, p);
}

}  // namespace clay::test
