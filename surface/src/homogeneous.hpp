#pragma once
// Homogeneous control nets (internal): rows (w x, w y, w z, w), so that rational algorithms are the
// polynomial ones applied in 4D.
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

namespace clay::surface::detail {

using Homogeneous = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;

inline Homogeneous to_homogeneous(const Points3& points, const Eigen::VectorXd& weights) {
  Homogeneous h(points.rows(), 4);
  h.leftCols<3>() = points.array().colwise() * weights.array();
  h.col(3) = weights;
  return h;
}

/// Splits homogeneous rows back into points and weights. Weights exactly 1 stay exactly 1, so a
/// polynomial net stays bit-identical through a round trip.
inline void from_homogeneous(const Homogeneous& h, Points3& points, Eigen::VectorXd& weights) {
  weights = h.col(3);
  points.resize(h.rows(), 3);
  for (Eigen::Index r = 0; r < h.rows(); ++r) {
    const double w = weights[r];
    if (w == 1.0)
      points.row(r) = h.row(r).head<3>();
    else
      points.row(r) = h.row(r).head<3>() / w;
  }
}

}  // namespace clay::surface::detail
