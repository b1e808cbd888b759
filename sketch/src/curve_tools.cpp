#include "curve_tools.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace clay::sketch::detail {

Eigen::Vector3d curvature_vector(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2) {
  const double s2 = d1.squaredNorm();
  return d1.cross(d2).cross(d1) / (s2 * s2);
}

}  // namespace clay::sketch::detail
