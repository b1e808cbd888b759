#pragma once
// Internal helpers of the sketch module: measurements. (Gauss–Legendre rules are
// clay/internal/math.hpp.) (Curve projection
// is surface::project_normal / closest_point, clay/surface/projection.hpp.)
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Core>

#include <vector>

namespace clay::sketch::detail {

/// Curvature vector (C' x C'') x C' / |C'|^4 from first and second derivatives.
Eigen::Vector3d curvature_vector(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2);

}  // namespace clay::sketch::detail
