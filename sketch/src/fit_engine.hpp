#pragma once
// The least-squares engine behind fit_stroke and oversketch (internal): one B-spline piece fitted
// to ordered points with end conditions, fairness, parameter correction and knot refinement.
#include <clay/summary.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <vector>

namespace clay::sketch::detail {

/// What a piece must satisfy at one end (open pieces only).
enum class EndKind {
  Point,      ///< passes through `point`
  Tangent,    ///< passes through `point` leaving along `tangent` (G1)
  Curvature,  ///< as Tangent, with curvature vector `curvature` (G2)
};

/// An end condition; `tangent` is the unit direction of travel (into the piece at the start, out of
/// it at the end), `curvature` the curvature vector (1/mm).
struct EndCondition {
  EndKind kind = EndKind::Point;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d tangent = Eigen::Vector3d::Zero();
  Eigen::Vector3d curvature = Eigen::Vector3d::Zero();
};

/// The problem: ordered points, their starting parameters in [0, 1], and the settings.
struct PieceProblem {
  surface::Points3 data;
  std::vector<double> params;  ///< one per data row; in [0, 1) when periodic
  bool periodic = false;       ///< closed piece: unclamped periodic knots, C^(p-1) everywhere
  int degree = 3;
  EndCondition start, end;      ///< ignored when periodic
  double tolerance_mm = 0.1;    ///< max point-to-curve distance sought
  double fairness = 1e-8;       ///< alpha: lambda = alpha * points on the unit domain
  int fairness_reductions = 6;  ///< times alpha may be divided by 10
  int max_control_points = 100;
  int max_iterations = 200;
};

/// The fitted piece and how it went.
struct PieceResult {
  surface::BSplineCurve curve;  ///< on [0, 1]; clamped (open) or unclamped periodic
  std::vector<double> params;   ///< foot point parameters of the data
  Eigen::VectorXd distances;    ///< data point to foot point (mm)
  double max_deviation = 0;
  double rms_deviation = 0;
  double fairness = 0;  ///< alpha in use at the end
  double noise = 0;     ///< estimated noise of the data per coordinate (mm)
  int iterations = 0;   ///< refinement iterations (each: solve + parameter correction)
  Summary summary;
};

/// Fits one piece (see fit.hpp for the method and its sources).
PieceResult fit_piece(const PieceProblem& problem);

/// Noise per coordinate (mm) estimated from the residuals of a 7-point cubic smoother (median).
double noise_level(const surface::Points3& points, bool closed);

/// The points after three passes of the [1 2 1] / 4 filter (the ends kept when open).
surface::Points3 smoothed(const surface::Points3& points, bool closed);

/// Cumulative chord length parameters of `points` normalized to [0, 1] (open) or to [0, 1) with
/// the closing chord included (closed); the points are lightly smoothed first (three passes of
/// the [1 2 1] / 4 filter) so that noise does not inflate the chords.
std::vector<double> chord_parameters(const surface::Points3& points, bool closed);

}  // namespace clay::sketch::detail
