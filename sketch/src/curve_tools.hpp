#pragma once
// Internal helpers of the sketch module: Gauss–Legendre rules, measurements. (Curve projection
// is surface::project_normal / closest_point, clay/surface/projection.hpp.)
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Core>

#include <vector>

namespace clay::sketch::detail {

/// Nodes and weights of the n-point Gauss–Legendre rule on [-1, 1] (exact for degree 2n - 1).
struct GaussRule {
  std::vector<double> nodes, weights;
};
GaussRule gauss_legendre(int n);

/// Curvature vector (C' x C'') x C' / |C'|^4 from first and second derivatives.
Eigen::Vector3d curvature_vector(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2);

}  // namespace clay::sketch::detail
