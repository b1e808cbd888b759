#pragma once
// Internal helpers of the sketch module: curve projection, Gauss–Legendre rules, measurements.
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

/// Foot point parameter of q on the curve by Newton's method on (C - q) · C' = 0 from t0, with a
/// backtracking line search. Open curves keep t in the domain (a foot on the end is the end);
/// `periodic` curves wrap t around the domain. The distance never increases from t0's.
double project_from(const surface::BSplineCurve& curve, const Eigen::Vector3d& q, double t0,
                    bool periodic);

/// Global closest point parameter: Newton from the best of `per_span` samples per knot span
/// (and the domain ends).
double closest_parameter(const surface::BSplineCurve& curve, const Eigen::Vector3d& q,
                         int per_span = 8);

/// Curvature vector (C' x C'') x C' / |C'|^4 from first and second derivatives.
Eigen::Vector3d curvature_vector(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2);

}  // namespace clay::sketch::detail
