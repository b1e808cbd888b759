#pragma once
/// oversketch — redraw part of a curve: a stroke drawn near a curve replaces the part between the
/// points where its ends project onto the curve, joined to the kept parts with G1 or G2.
///
/// Method: both stroke ends are projected onto the curve (closest point: samples, then Newton).
/// An end within capture_distance cuts the curve there; an end farther away is accepted only when
/// the stroke runs over an end of the curve (passes within capture_distance of the curve's end
/// point), and the stroke then replaces the curve's head or tail (as it does when it ends at the
/// curve's end point). The curve is cut by knot insertion (Boehm) to multiplicity p at the cut
/// parameters, so the kept parts stay the old curve exactly. The new part, of the curve's degree,
/// is fitted as in fit_stroke (fairness, parameter correction, knot refinement) under constrained
/// least squares: at each joint its first control point is the kept part's end point, its second
/// lies on the kept part's tangent line there (G1: P1 = A + alpha T, alpha a free unknown), and
/// for G2 its third is set by the kept part's curvature vector kappa at the cut,
/// C''(0) = beta T + |C'(0)|^2 kappa (beta free; alpha taken from the G1 solution, which makes the
/// condition linear). The three parts are joined into one B-spline with knots of multiplicity p at
/// the joints; a rational curve keeps its weights, the new part getting the joint's weight.
#include <clay/sketch/export.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/stroke.hpp>
#include <clay/summary.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <optional>
#include <string>
#include <vector>

namespace clay::sketch {

/// Geometric continuity of an oversketch joint.
enum class Continuity {
  G1,  ///< common point and tangent direction
  G2,  ///< and common curvature vector
};

/// Settings of oversketch.
struct CLAY_SKETCH_API OversketchOptions {
  Continuity continuity = Continuity::G1;  ///< at both joints
  double capture_distance = 10.0;          ///< mm, > 0: how far a stroke end may be from the curve
  FitOptions fit;  ///< tolerance, fairness, limits, end_samples and drop_duplicates for the new
                   ///< part; its degree is the curve's (fit.degree is not used) and it is not
                   ///< split at corners

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// Continuity measured across one joint of the result (left limit against right limit).
struct Joint {
  double parameter = 0;             ///< on the result curve
  double gap = 0;                   ///< mm, distance between the two sides' points
  double tangent_angle = 0;         ///< radians between the two sides' tangent directions
  double curvature_difference = 0;  ///< |kappa_left - kappa_right| / max(|kappa_left|,
                                    ///< |kappa_right|), curvature vectors (0 when both vanish)
};

/// The redrawn curve and how it was made.
struct CLAY_SKETCH_API OversketchResult {
  surface::BSplineCurve curve;  ///< same domain and degree as the input curve
  double cut_start = 0;         ///< parameter where the replaced part begins (old and new curve)
  double cut_end = 0;           ///< parameter where it ends (a domain end for a new head/tail)
  std::optional<Joint> start_joint;  ///< absent when the stroke replaced the curve's head
  std::optional<Joint> end_joint;    ///< absent when the stroke replaced the curve's tail
  double max_deviation_mm = 0;       ///< stroke points to the new part (foot points)
  double rms_deviation_mm = 0;       ///< root mean square of the same distances
  int control_points = 0;            ///< control points of the new part
  int iterations = 0;                ///< refinement iterations of the new part's fit
  Summary summary;                   ///< the new part's fit; converged when within tolerance

  /// One line: "replaced [0.25, 0.62] with 9 control points, max deviation 0.011 mm (rms 0.004),
  /// joints: gap 3e-16 mm, angle 0.0021 deg at start; gap 0 mm, angle 0.0008 deg at end;
  /// converged".
  std::string brief() const;
};

/// Replaces the part of `curve` that `stroke` redraws (see above). The stroke may be drawn in
/// either direction. Throws clay::Error: InvalidArgument for bad options, for a stroke end farther
/// than capture_distance from the curve (naming the end and the distance) unless the stroke runs
/// over an end of the curve, for a stroke whose ends meet the curve at one point or that runs over
/// both of its ends (covering it all); InvalidGeometry for an invalid curve, a curve of degree 1,
/// or a stroke that problems(stroke) rejects.
CLAY_SKETCH_API OversketchResult oversketch(const surface::BSplineCurve& curve,
                                            const Stroke& stroke,
                                            const OversketchOptions& options = {});

}  // namespace clay::sketch
