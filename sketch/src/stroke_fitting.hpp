#pragma once
// Stroke preparation shared by fit_stroke and oversketch (internal).
#include <clay/sketch/fit.hpp>

#include "fit_engine.hpp"

#include <Eigen/Core>

#include <vector>

namespace clay::sketch::detail {

/// Validated working points (plane coordinates when the stroke has a plane), repeated points
/// dropped on request; `plane_offset` gets the largest distance of a point from the plane.
Points3 prepared_points(const Stroke& stroke, bool drop_duplicates, double& plane_offset);

/// The curve's end point for the first (`at_start`) or last point of `pts`: a quadratic fit of
/// up to `samples` end points against their index, evaluated at the end, moved at most `limit`
/// from the drawn point.
Eigen::Vector3d end_anchor(const Points3& pts, bool at_start, int samples, double limit);

/// A corner: the stroke splits after point `split`; both curves end at `anchor`.
struct Corner {
  Eigen::Index split = 0;
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
};

/// Corners of the stroke (sorted by split index), see fit.hpp.
std::vector<Corner> find_corners(const Points3& pts, bool closed, double angle_degrees,
                                 double window);

/// Chord-length parameters of `pts` inside the polyline a, pts..., b (a at 0 and b at 1).
std::vector<double> anchored_parameters(const Eigen::Vector3d& a, const Points3& pts,
                                        const Eigen::Vector3d& b);

/// A piece problem carrying the options' tolerance, degree, fairness and limits.
PieceProblem piece_problem(const FitOptions& options);

}  // namespace clay::sketch::detail
