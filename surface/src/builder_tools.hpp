#pragma once
// Small curve helpers shared by the surface builders (skin.cpp, occt/fill.cpp); internal.
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/degree_elevation.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace clay::surface::detail {

/// A number for messages: 3 significant digits ("0.25", "1e-07").
inline std::string short_number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", x);
  return buffer;
}

/// Diagonal of the box around every control point of `curves` (the model size of a builder).
inline double model_size(const std::vector<const BSplineCurve*>& curves) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const BSplineCurve* c : curves) {
    lo = lo.cwiseMin(c->points.colwise().minCoeff().transpose());
    hi = hi.cwiseMax(c->points.colwise().maxCoeff().transpose());
  }
  return (hi - lo).norm();
}

/// Length of the control polygon (an upper bound of the curve's length; 0 for a point).
inline double polygon_length(const BSplineCurve& c) {
  double length = 0;
  for (Eigen::Index i = 1; i < c.points.rows(); ++i)
    length += (c.points.row(i) - c.points.row(i - 1)).norm();
  return length;
}

/// The clamped curve reparametrized linearly to [0, 1] (same shape; knots already on [0, 1] are
/// kept bit for bit).
inline BSplineCurve normalized(const BSplineCurve& curve) {
  BSplineCurve c = clamp(curve);  // the curve itself, bit for bit, when already clamped
  const auto [a, b] = c.basis.domain();
  if (a == 0.0 && b == 1.0) return c;
  for (double& t : c.basis.knots) t = (t - a) / (b - a);  // (b - a) / (b - a) is exactly 1
  return c;
}

}  // namespace clay::surface::detail
