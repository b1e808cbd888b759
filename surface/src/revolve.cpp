#include <clay/surface/revolve.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/tolerance.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include <clay/surface/detail/builder_tools.hpp>

namespace clay::surface {
namespace {

std::string number(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

/// Throws when the profile lies on the axis, or touches or crosses it between its ends.
void check_profile_against_axis(const BSplineCurve& profile, const Eigen::Vector3d& origin,
                                const Eigen::Vector3d& a, double size) {
  const double touch = tolerance::exact_relative * size;
  const auto radial = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    const Eigen::Vector3d d = p - origin;
    return d - d.dot(a) * a;
  };
  double largest = 0;
  for (Eigen::Index j = 0; j < profile.points.rows(); ++j)
    largest = std::max(largest, radial(profile.points.row(j).transpose()).norm());
  if (largest <= touch)
    throw Error(ErrorCategory::InvalidGeometry,
                "revolve: the profile lies on the axis (all control points within " +
                    number(touch) + " mm of it); revolving it gives no surface");
  const auto ts = span_samples(profile.basis, 32);
  const Points3 pts = evaluate_many(profile, ts);
  Eigen::Vector3d previous = radial(pts.row(0).transpose());
  for (size_t k = 1; k < ts.size(); ++k) {
    const Eigen::Vector3d r = radial(pts.row(static_cast<Eigen::Index>(k)).transpose());
    const bool interior = k + 1 < ts.size();
    if (interior && r.norm() <= touch)
      throw Error(ErrorCategory::InvalidGeometry,
                  "revolve: the profile touches the axis at t = " + number(ts[k]) + " (distance " +
                      number(r.norm()) +
                      " mm); the revolved surface would pinch there. Only the profile's ends may "
                      "lie on the axis");
    if (r.dot(previous) < 0.0)
      throw Error(ErrorCategory::InvalidGeometry,
                  "revolve: the profile crosses the axis between t = " + number(ts[k - 1]) +
                      " and t = " + number(ts[k]) +
                      "; the revolved surface would intersect itself. Keep the profile on one "
                      "side of the axis");
    previous = r;
  }
}

}  // namespace

BuiltSurface revolve(const BSplineCurve& profile, const Axis& axis, double angle_degrees) {
  validate(profile, "revolve profile");
  if (!internal::all_finite(axis.point) || !internal::all_finite(axis.direction))
    throw Error(ErrorCategory::InvalidArgument, "revolve: the axis has a non-finite coordinate");
  const double length = axis.direction.norm();
  if (!(length > 1e-12))
    throw Error(ErrorCategory::InvalidArgument, "revolve: the axis direction has length " +
                                                    number(length) +
                                                    "; give a non-zero direction vector");
  if (!(std::isfinite(angle_degrees) && angle_degrees > 0.0 && angle_degrees <= 360.0))
    throw Error(ErrorCategory::InvalidArgument,
                "revolve: angle " + number(angle_degrees) + " degrees is outside (0, 360]");
  const Eigen::Vector3d a = axis.direction / length;
  const Eigen::Vector3d lo = profile.points.colwise().minCoeff(),
                        hi = profile.points.colwise().maxCoeff();
  const double size = (hi - lo).norm() + (0.5 * (hi + lo) - axis.point).norm();
  check_profile_against_axis(profile, axis.point, a, size);
  detail::reject_self_intersection(profile, tolerance::exact_relative * size,
                                   "revolve: the profile",
                                   "the revolved surface would intersect itself: give a profile "
                                   "that does not cross or touch itself");

  const double sweep =
      angle_degrees == 360.0 ? 2.0 * std::numbers::pi : angle_degrees * std::numbers::pi / 180.0;
  const int nv = profile.basis.count();
  BSplineSurface s;
  s.v = profile.basis;
  for (int j = 0; j < nv; ++j) {
    const Eigen::Vector3d p = profile.points.row(j).transpose();
    const Eigen::Vector3d o = axis.point + (p - axis.point).dot(a) * a;
    Eigen::Vector3d x = p - o;
    const double r = x.norm();
    BSplineCurve arc;
    if (r == 0.0) {
      // On the axis: the "circle" is the point itself (any frame will do).
      x = a.unitOrthogonal();
      arc = circular_arc(p, x, a.cross(x), 0.0, 0.0, sweep);
    } else {
      x /= r;
      arc = circular_arc(o, x, a.cross(x), r, 0.0, sweep);
    }
    if (j == 0) {
      s.u = arc.basis;
      s.points.resize(static_cast<Eigen::Index>(s.u.count()) * nv, 3);
      s.weights.resize(s.points.rows());
    }
    for (int i = 0; i < s.u.count(); ++i) {
      s.points.row(s.index(i, j)) = arc.points.row(i);
      s.weights[s.index(i, j)] = arc.weights[i] * profile.weights[j];
    }
    // The u = 0 iso-curve is the profile itself, bit for bit (and so is u = 1 for a full turn).
    s.points.row(s.index(0, j)) = profile.points.row(j);
    if (angle_degrees == 360.0) s.points.row(s.index(s.u.count() - 1, j)) = profile.points.row(j);
  }

  // Check: every surface point keeps its profile point's height along and distance to the axis.
  BuiltSurface out{s, describe(s, "revolve")};
  const auto us = span_samples(s.u, 16);
  const auto vs = span_samples(s.v, 16);
  const Points3 grid = evaluate_grid(s, us, vs);
  const Points3 prof = evaluate_many(profile, vs);
  double worst = 0;
  for (size_t jv = 0; jv < vs.size(); ++jv) {
    const Eigen::Vector3d c = prof.row(static_cast<Eigen::Index>(jv)).transpose() - axis.point;
    const double hc = c.dot(a), rc = (c - hc * a).norm();
    for (size_t iu = 0; iu < us.size(); ++iu) {
      const Eigen::Vector3d q =
          grid.row(static_cast<Eigen::Index>(iu * vs.size() + jv)).transpose() - axis.point;
      const double hq = q.dot(a), rq = (q - hq * a).norm();
      worst = std::max({worst, std::abs(hq - hc), std::abs(rq - rc)});
    }
  }
  out.report.exact = true;
  out.report.max_deviation_mm = worst;
  out.report.samples = static_cast<int>(us.size() * vs.size());
  return out;
}

}  // namespace clay::surface
