#include <clay/sketch/oversketch.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/projection.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "curve_tools.hpp"
#include "fit_engine.hpp"
#include "stroke_fitting.hpp"

namespace clay::sketch {

std::vector<std::string> OversketchOptions::problems() const {
  std::vector<std::string> out;
  if (!(std::isfinite(capture_distance) && capture_distance > 0.0)) {
    std::ostringstream s;
    s << "OversketchOptions::capture_distance = " << capture_distance
      << " must be a positive distance in mm";
    out.push_back(s.str());
  }
  if (continuity != Continuity::G1 && continuity != Continuity::G2)
    out.push_back(
        "OversketchOptions::continuity = " + std::to_string(static_cast<int>(continuity)) +
        " must be Continuity::G1 or Continuity::G2");
  FitOptions f = fit;
  f.degree = 3;  // not used: the curve's degree is
  internal::append(out, f.problems());
  return out;
}

void OversketchOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

namespace {

using surface::BSplineCurve;
using surface::Points3;

/// The curve cut at an interior parameter t into two clamped curves on [t0, t] and [t, t1]
/// (knot insertion to multiplicity p, so both are the old curve exactly).
std::pair<BSplineCurve, BSplineCurve> split_at(const BSplineCurve& c, double t) {
  const int p = c.basis.degree;
  const int have = surface::multiplicity(c.basis, t);
  const BSplineCurve r = have < p ? surface::insert_knot(c, t, p - have) : c;
  const auto& U = r.basis.knots;
  const auto first = static_cast<Eigen::Index>(std::find(U.begin(), U.end(), t) - U.begin());
  // Knots equal to t sit at [first, first + p); C(t) is control point first - 1.
  BSplineCurve left, right;
  left.basis.degree = right.basis.degree = p;
  left.basis.knots.assign(U.begin(), U.begin() + first);
  left.basis.knots.insert(left.basis.knots.end(), static_cast<size_t>(p + 1), t);
  right.basis.knots.assign(static_cast<size_t>(p + 1), t);
  right.basis.knots.insert(right.basis.knots.end(), U.begin() + first + p, U.end());
  left.points = r.points.topRows(first);
  left.weights = r.weights.head(first);
  const Eigen::Index nr = r.points.rows() - first + 1;
  right.points = r.points.bottomRows(nr);
  right.weights = r.weights.tail(nr);
  return {left, right};
}

/// `b` appended to `a` (a ends where b starts, same degree, both clamped): one curve whose knot
/// at the joint has multiplicity p. b's weights are scaled to meet a's at the joint.
BSplineCurve join(const BSplineCurve& a, const BSplineCurve& b) {
  const int p = a.basis.degree;
  BSplineCurve c;
  c.basis.degree = p;
  c.basis.knots.assign(a.basis.knots.begin(), a.basis.knots.end() - 1);
  c.basis.knots.insert(c.basis.knots.end(), b.basis.knots.begin() + p + 1, b.basis.knots.end());
  const Eigen::Index na = a.points.rows(), nb = b.points.rows();
  c.points.resize(na + nb - 1, 3);
  c.points.topRows(na) = a.points;
  c.points.bottomRows(nb - 1) = b.points.bottomRows(nb - 1);
  c.weights.resize(na + nb - 1);
  c.weights.head(na) = a.weights;
  c.weights.tail(nb - 1) = b.weights.tail(nb - 1) * (a.weights[na - 1] / b.weights[0]);
  return c;
}

Joint measure(const BSplineCurve& result, double t) {
  const auto [left, right] = split_at(result, t);
  const auto l = surface::derivatives(left, t, 2);
  const auto r = surface::derivatives(right, t, 2);
  Joint j;
  j.parameter = t;
  j.gap = (l.point - r.point).norm();
  j.tangent_angle = std::atan2(l.d1.cross(r.d1).norm(), l.d1.dot(r.d1));
  const Eigen::Vector3d kl = detail::curvature_vector(l.d1, l.d2);
  const Eigen::Vector3d kr = detail::curvature_vector(r.d1, r.d2);
  const double scale = std::max(kl.norm(), kr.norm());
  j.curvature_difference = scale > 0 ? (kl - kr).norm() / scale : 0.0;
  return j;
}

double polyline_distance(const Points3& poly, const Eigen::Vector3d& q) {
  double best = (poly.row(0).transpose() - q).squaredNorm();
  for (Eigen::Index i = 0; i + 1 < poly.rows(); ++i) {
    const Eigen::Vector3d a = poly.row(i).transpose(), ab = poly.row(i + 1).transpose() - a;
    const double l2 = ab.squaredNorm();
    const double f = l2 > 0 ? std::clamp((q - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
    best = std::min(best, (a + f * ab - q).squaredNorm());
  }
  return std::sqrt(best);
}

std::string distance_text(double d) {
  std::ostringstream s;
  s.precision(4);
  s << d;
  return s.str();
}

}  // namespace

OversketchResult oversketch(const BSplineCurve& curve, const Stroke& stroke,
                            const OversketchOptions& options) {
  options.validate();
  surface::validate(curve, "curve to oversketch");
  const int p = curve.basis.degree;
  if (p < 2)
    throw Error(ErrorCategory::InvalidGeometry,
                "curve to oversketch has degree 1; a tangent-continuous joint needs degree >= 2 "
                "(raise it with elevate_degree)");
  double plane_offset = 0;
  Points3 pts = detail::prepared_points(stroke, options.fit.drop_duplicates, plane_offset);
  if (stroke.plane)  // back to world coordinates, on the plane
    for (Eigen::Index i = 0; i < pts.rows(); ++i)
      pts.row(i) = to_world(*stroke.plane, Eigen::Vector2d(pts(i, 0), pts(i, 1))).transpose();

  // Not a structured binding: lambdas below capture t0 and t1, which Clang 14 refuses for bindings.
  const auto domain = curve.basis.domain();
  const double t0 = domain.first, t1 = domain.second;
  const double at_end_tol = 1e-9 * (t1 - t0);
  const Eigen::Vector3d curve_start = surface::evaluate(curve, t0);
  const Eigen::Vector3d curve_end = surface::evaluate(curve, t1);
  // Where each stroke end meets the curve: a parameter, or past one of the curve's ends (the
  // stroke overlaps that end: it passes within the capture distance of the curve's end point).
  enum class Past { None, Start, End };
  struct End {
    double t = 0, distance = 0;
    Past past = Past::None;
  };
  const double cap = options.capture_distance;
  const bool over_start = polyline_distance(pts, curve_start) <= cap;
  const bool over_end = polyline_distance(pts, curve_end) <= cap;
  auto refuse = [&](const char* which, const End& e) {
    throw Error(
        ErrorCategory::InvalidArgument,
        std::string("oversketch: the stroke's ") + which + " point is " +
            distance_text(e.distance) + " mm from the curve, beyond the capture distance " +
            distance_text(cap) +
            " mm; start and end the stroke on the curve (or draw it over one of the curve's "
            "ends), or raise OversketchOptions::capture_distance");
  };
  auto locate = [&](Eigen::Index row, const char* which) {
    const Eigen::Vector3d q = pts.row(row).transpose();
    End e;
    e.t = surface::closest_point(curve, q).t;
    e.distance = (surface::evaluate(curve, e.t) - q).norm();
    if (e.distance <= cap) {
      if (e.t <= t0 + at_end_tol) e.past = Past::Start;  // the stroke ends at the curve's end
      if (e.t >= t1 - at_end_tol) e.past = Past::End;
    } else {
      // Off the curve: acceptable only where the stroke runs over an end of the curve.
      const double ds = (q - curve_start).norm(), de = (q - curve_end).norm();
      if (over_start && (!over_end || ds <= de))
        e.past = Past::Start;
      else if (over_end)
        e.past = Past::End;
      else
        refuse(which, e);
    }
    if (e.past == Past::Start) e.t = t0;
    if (e.past == Past::End) e.t = t1;
    return e;
  };
  End first_end = locate(0, "first");
  End last_end = locate(pts.rows() - 1, "last");
  if (first_end.past != Past::None && last_end.past != Past::None &&
      first_end.past != last_end.past)
    throw Error(ErrorCategory::InvalidArgument,
                "oversketch: the stroke covers the whole curve (it runs over both of the curve's "
                "ends); fit it with fit_stroke instead");
  // Orient the stroke along the curve's parameter.
  if (first_end.t > last_end.t || (first_end.t == last_end.t && first_end.past == Past::End)) {
    pts = pts.colwise().reverse().eval();
    std::swap(first_end, last_end);
  }
  const bool new_head = first_end.past == Past::Start;
  const bool new_tail = last_end.past == Past::End;
  const double a = first_end.t;
  const double b = last_end.t;
  if (!(b - a > at_end_tol) || (new_head && new_tail))
    throw Error(ErrorCategory::InvalidArgument,
                "oversketch: both ends of the stroke meet the curve at the same point (t = " +
                    distance_text(a) + "); draw along the part of the curve to replace");

  // Kept parts, exact.
  std::optional<BSplineCurve> left, right;
  BSplineCurve middle_src = curve;
  if (!new_head) {
    auto parts = split_at(middle_src, a);
    left = parts.first;
    middle_src = parts.second;
  }
  if (!new_tail) right = split_at(middle_src, b).second;

  // The new part.
  detail::PieceProblem pr = detail::piece_problem(options.fit);
  pr.degree = p;
  pr.max_control_points = std::max(pr.max_control_points, 2 * p + 2);
  pr.data = pts;
  const bool g2 = options.continuity == Continuity::G2;
  auto joint_condition = [&](const BSplineCurve& kept, bool at_start_of_new) {
    detail::EndCondition e;
    const double t = at_start_of_new ? a : b;
    const auto d = surface::derivatives(kept, t, 2);
    e.kind = g2 ? detail::EndKind::Curvature : detail::EndKind::Tangent;
    e.point = kept.points.row(at_start_of_new ? kept.points.rows() - 1 : 0).transpose();
    e.tangent = d.d1.normalized();
    e.curvature = detail::curvature_vector(d.d1, d.d2);
    return e;
  };
  const double end_limit =
      std::min(options.fit.tolerance_mm, 3.0 * detail::noise_level(pts, false));
  if (left) {
    pr.start = joint_condition(*left, true);
  } else {
    pr.start.kind = detail::EndKind::Point;
    pr.start.point = detail::end_anchor(pts, true, options.fit.end_samples, end_limit);
  }
  if (right) {
    pr.end = joint_condition(*right, false);
  } else {
    pr.end.kind = detail::EndKind::Point;
    pr.end.point = detail::end_anchor(pts, false, options.fit.end_samples, end_limit);
  }
  pr.params = detail::anchored_parameters(pr.start.point, pts, pr.end.point);
  const detail::PieceResult fitted = detail::fit_piece(pr);
  OversketchResult out;
  out.cut_start = a;
  out.cut_end = b;
  out.max_deviation_mm = fitted.max_deviation;
  out.rms_deviation_mm = fitted.rms_deviation;
  out.iterations = fitted.iterations;
  out.summary = fitted.summary;
  if (fitted.summary.termination == Termination::Failed) return out;
  out.control_points = static_cast<int>(fitted.curve.points.rows());

  // The new part on [a, b], then the three parts in one curve.
  BSplineCurve middle = fitted.curve;
  for (double& k : middle.basis.knots) k = a + (b - a) * k;
  for (int i = 0; i <= p; ++i) {  // exact ends despite rounding in the map
    middle.basis.knots[static_cast<size_t>(i)] = a;
    middle.basis.knots[middle.basis.knots.size() - 1 - static_cast<size_t>(i)] = b;
  }
  if (left) middle.points.row(0) = left->points.row(left->points.rows() - 1);
  if (right) middle.points.row(middle.points.rows() - 1) = right->points.row(0);
  BSplineCurve result = left ? join(*left, middle) : middle;
  if (right) result = join(result, *right);
  surface::validate(result, "oversketched curve");
  out.curve = result;
  if (left) out.start_joint = measure(result, a);
  if (right) out.end_joint = measure(result, b);
  std::ostringstream m;
  m.precision(3);
  m << out.summary.message;
  for (const auto* j : {&out.start_joint, &out.end_joint})
    if (*j)
      m << "; joint at t = " << (*j)->parameter << ": gap " << (*j)->gap << " mm, tangent angle "
        << (*j)->tangent_angle << " rad, curvature difference " << (*j)->curvature_difference;
  out.summary.message = m.str();
  return out;
}

std::string OversketchResult::brief() const {
  std::ostringstream m;
  m.precision(3);
  auto joint = [&](const std::optional<Joint>& j, const char* where) {
    if (!j) return;
    m << "; gap " << j->gap << " mm, angle " << j->tangent_angle * 180 / std::numbers::pi
      << " deg at " << where;
  };
  m << "replaced [" << cut_start << ", " << cut_end << "] with " << control_points
    << " control points, max deviation " << max_deviation_mm << " mm (rms " << rms_deviation_mm
    << ")";
  joint(start_joint, "start");
  joint(end_joint, "end");
  m << "; " << (summary.converged() ? "converged" : "not converged: " + summary.message);
  return m.str();
}

}  // namespace clay::sketch
