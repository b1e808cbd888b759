#pragma once
/// fit_stroke — a drawn stroke turned into clamped B-spline curves within a tolerance.
///
/// The method (docs/sketch.md has the details and the reasons for the defaults):
/// - chord-length parameters of the lightly smoothed stroke (The NURBS Book eq. 9.5);
/// - linear least squares with a fairness term: minimize
///     sum_k |C(t_k) - Q_k|^2 + fairness * N * int_0^1 |C''(t)|^2 dt
///   where the bending integral is exact (Gauss–Legendre on each knot span of the basis functions'
///   second derivatives) and the weight scales with the N points, so the trade-off depends neither
///   on the sampling density nor (the domain being [0, 1]) on the stroke's size;
/// - parameter correction: every t_k moved to its foot point on the current curve by Newton's
///   method on (C(t) - Q_k) . C'(t) = 0 (Hoschek 1988, "intrinsic parametrization");
/// - knot refinement (Piegl & Tiller, The NURBS Book §9.4.1): a knot is added in the span where the
///   error is largest, at the median parameter of its points, until the tolerance holds; when no
///   span can be split the fairness weight is divided by 10 (at most fairness_reductions times);
/// - noise: the stroke's noise sigma is estimated from the residuals of a 7-point cubic
///   Savitzky–Golay smoother (median). When sigma > tolerance / 8 the stroke is noisy: errors are
///   residuals averaged over 9 neighbouring points (noise averages out, a misfit does not), and the
///   fit is done when no averaged error exceeds max(tolerance / 2, 1.5 sigma) — single points may
///   then lie beyond the tolerance, by the noise alone; they are counted in the summary, not
///   chased with knots (which would put the noise into the curve);
/// - ends are interpolated: the curve passes exactly through an anchor at each end, the stroke's
///   end point smoothed by a cubic least-squares fit of its last end_samples points against their
///   index (a Savitzky–Golay end estimate; at most a quarter of the points, quadratic below 24,
///   none below 12), moved at most 3 sigma (and the tolerance) from the drawn point — so a clean
///   stroke keeps its end points;
/// - corners: the turning angle between the chords reaching corner_window (arc length) behind
///   and ahead of each point of the smoothed stroke; local maxima above corner_angle split it.
///   Each corner is placed where the lines fitted to its two legs meet, and the curves on both
///   sides share it as their end point, bit for bit (G0);
/// - closed strokes (end within closing_ratio x length of the start, no corner) are fitted with an
///   unclamped periodic knot vector (control points wrap around), so the fit is C^(degree-1)
///   across the seam; the result is then clamped on the same domain and its last control point set
///   to its first: it closes exactly and is C^(degree-1) at the seam to rounding. A closed stroke
///   with corners gives a closed chain of open curves.
#include <clay/sketch/export.hpp>
#include <clay/sketch/stroke.hpp>
#include <clay/summary.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace clay::sketch {

/// Settings of fit_stroke (and of the new piece in oversketch).
struct CLAY_SKETCH_API FitOptions {
  double tolerance_mm = 0.1;     ///< largest distance from a stroke point to its curve
                                 ///< (averaged over 9 neighbours for a noisy stroke); > 0
  int degree = 3;                ///< degree of the curves, in [2, 9]
  double fairness = 1e-8;        ///< weight of the bending energy (see above), >= 0; its fourth
                                 ///< root is about the smoothing length / stroke length
  int fairness_reductions = 6;   ///< times the fairness may be divided by 10 to meet the tolerance
  int max_control_points = 100;  ///< per curve, >= 2 * degree
  int max_iterations = 200;      ///< refinement iterations per curve, >= 1
  double corner_angle = 50.0;    ///< degrees in (0, 180]: turning angle that makes a corner
                                 ///< (180 never splits)
  double corner_window = 0.0;    ///< mm, arc length each side over which turning is measured;
                                 ///< 0 (default) means the larger of 10 x tolerance and 3 x
                                 ///< the stroke's median point spacing; >= 0
  double closing_ratio = 0.03;   ///< a stroke whose end is within closing_ratio x its length of
                                 ///< its start is closed; in [0, 0.5], 0 never closes
  int end_samples = 60;          ///< samples in the end-point estimate, >= 1 (1: the drawn point)
  bool drop_duplicates = false;  ///< drop repeated consecutive points instead of refusing them

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// One fitted curve and its report.
struct FittedCurve {
  surface::BSplineCurve curve;   ///< clamped, polynomial, domain [0, 1]
  bool closed = false;           ///< smooth closed curve: last control point == first, seam C^(p-1)
  Eigen::Index first_point = 0;  ///< first stroke point fitted by this curve
  Eigen::Index last_point = 0;   ///< last stroke point fitted (inclusive; wraps past the stroke's
                                 ///< end for the last curve of a closed stroke with corners)
  double max_deviation_mm = 0;   ///< largest distance from its stroke points to the curve,
                                 ///< measured at each point's foot point (Newton projection)
  double rms_deviation_mm = 0;   ///< root mean square of the same distances
  int control_points = 0;        ///< curve.points.rows()
  int iterations = 0;            ///< refinement iterations
  double fairness = 0;           ///< fairness weight in use at the end (after reductions)
  double noise = 0;              ///< mm, estimated noise of its stroke points per coordinate
  Summary summary;               ///< converged when max_deviation_mm <= tolerance
};

/// The curves fitted to one stroke, in drawing order; consecutive curves share their joint point
/// exactly (corners).
struct CLAY_SKETCH_API StrokeFit {
  std::vector<FittedCurve> curves;    ///< in drawing order
  std::vector<Eigen::Index> corners;  ///< stroke index of each corner (the last point before it)
  bool closed = false;                ///< the chain closes (one closed curve, or corners all round)
  double max_deviation_mm = 0;        ///< largest of the curves' max_deviation_mm
  double plane_offset = 0;            ///< mm, largest distance of a stroke point from its plane
  Summary summary;                    ///< converged when every curve converged

  /// One line: "2 curves (open), 1 corner, 11 control points, max deviation 0.012 mm, plane
  /// offset 0 mm; converged".
  std::string brief() const;
};

/// Fits `stroke` with clamped B-spline curves of options.degree within options.tolerance_mm (see
/// the method above). With a plane, the stroke is projected onto it first and every curve lies in
/// it (its control points are computed in plane coordinates and mapped with to_world). Not meeting
/// the tolerance within the limits is reported in the summaries, not thrown.
/// Throws clay::Error: InvalidArgument for bad options, InvalidGeometry for a stroke that
/// problems(stroke) rejects (fewer than 2 points, NaN or infinite coordinate, repeated consecutive
/// point unless drop_duplicates, zero length, invalid plane).
CLAY_SKETCH_API StrokeFit fit_stroke(const Stroke& stroke, const FitOptions& options = {});

}  // namespace clay::sketch
