#pragma once
// Small curve helpers shared by the surface builders (loft.cpp, sweep.cpp, revolve.cpp, the OCCT
// library's fill.cpp) and the self-intersection search. A detail header of the surface module:
// inline, never installed, included only by sources (the include-rule test holds it).
#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/self_intersection.hpp>
#include <clay/surface/skin.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace clay::surface::detail {

/// A number for messages: 3 significant digits ("0.25", "1e-07").
inline std::string short_number(double x) { return internal::with_digits(x, 3); }

/// A parameter or coordinate for messages: 4 significant digits ("0.3125", "-12.5").
inline std::string parameter_text(double x) { return internal::with_digits(x, 4); }

/// "(x, y, z)" with 4 significant digits; coordinates within `zero` of 0 (rounding noise below
/// the tolerance of the result) are written as 0.
inline std::string point_text(const Eigen::Vector3d& p, double zero = 0.0) {
  auto c = [zero](double x) { return parameter_text(std::abs(x) <= zero ? 0.0 : x); };
  return "(" + c(p.x()) + ", " + c(p.y()) + ", " + c(p.z()) + ")";
}

/// What a self-intersection is, in words: "crosses itself at t = 0.31 and t = 0.74 (point (1, 2,
/// 3), tangents 62 degrees apart)", "touches itself at ..." (tangents within 10 degrees) or
/// "doubles back onto itself at ..." (tangents within 10 degrees of opposite), with the distance
/// between the two points when it is not 0 up to rounding.
inline std::string describe(const CurveSelfIntersection& x, double tolerance) {
  const double a = x.angle_degrees;
  std::string text = a <= 10.0    ? "touches itself"
                     : a >= 170.0 ? "doubles back onto itself"
                                  : "crosses itself";
  text += " at t = " + parameter_text(x.t0) + " and t = " + parameter_text(x.t1) + " (point " +
          point_text(x.point, 1e-3 * tolerance);
  if (a > 10.0 && a < 170.0) text += ", tangents " + parameter_text(a) + " degrees apart";
  if (x.distance > 1e-3 * tolerance)
    text +=
        ", " + short_number(x.distance) + " mm apart, tolerance " + short_number(tolerance) + " mm";
  return text + ")";
}

/// Throws clay::Error(InvalidGeometry) "<who> <describe(...)>; <fix>" when `curve` meets itself
/// within `tolerance` (find_self_intersection).
inline void reject_self_intersection(const BSplineCurve& curve, double tolerance,
                                     const std::string& who, const std::string& fix) {
  if (const auto x = find_self_intersection(curve, tolerance))
    throw Error(ErrorCategory::InvalidGeometry, who + " " + describe(*x, tolerance) + "; " + fix);
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

/// The problems of a builder's sliver-merging options (`owner` names the struct): min_span_ratio
/// in [0, 0.5), merge_tolerance (relative to the model size) in (0, 1e-2].
inline void merge_option_problems(const std::string& owner, double min_span_ratio,
                                  double merge_tolerance, std::vector<std::string>& out) {
  if (!(min_span_ratio >= 0.0 && min_span_ratio < 0.5))
    out.push_back(owner + "::min_span_ratio is " + short_number(min_span_ratio) +
                  "; it must be in [0, 0.5) (0 keeps every span)");
  if (!(merge_tolerance > 0.0 && merge_tolerance <= 1e-2))
    out.push_back(owner + "::merge_tolerance is " + short_number(merge_tolerance) +
                  "; it must be in (0, 1e-2]");
}

/// "2 knots moved to merge sliver spans of the knot union (section #1 at 0.50089 -> 0.50057,
/// reparametrized; ...), largest deviation 3.1e-05 mm", or "" when nothing merged. `what` names
/// the curves ("section", or "curve" with `labels` giving each merged curve's name).
inline std::string merge_note(const CompatibleCurves& merged, const std::string& what,
                              const std::vector<std::string>& labels = {}) {
  if (merged.merges.empty()) return "";
  std::string out = std::to_string(merged.merges.size()) +
                    (merged.merges.size() == 1 ? " knot" : " knots") +
                    " moved to merge sliver spans of the knot union (";
  for (size_t i = 0; i < merged.merges.size(); ++i) {
    const KnotMerge& m = merged.merges[i];
    const auto k = static_cast<size_t>(m.curve);
    out += (i ? "; " : "") +
           (k < labels.size() ? labels[k] : what + " #" + std::to_string(m.curve)) + " at " +
           short_number(m.from) + (m.removed ? " removed" : " -> " + short_number(m.to)) +
           (m.reparametrized ? ", reparametrized" : "");
  }
  return out + "), largest deviation " + short_number(merged.max_deviation_mm) + " mm";
}

}  // namespace clay::surface::detail
