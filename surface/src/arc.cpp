#include <clay/surface/arc.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <string>

namespace clay::surface {

BSplineCurve circular_arc(const Eigen::Vector3d& center, const Eigen::Vector3d& x_axis,
                          const Eigen::Vector3d& y_axis, double radius, double start, double end) {
  const double two_pi = 2.0 * std::numbers::pi;
  const double sweep = end - start;
  auto bad = [](const std::string& what) {
    throw Error(ErrorCategory::InvalidArgument, "circular_arc: " + what);
  };
  if (!internal::all_finite(center) || !internal::all_finite(x_axis) ||
      !internal::all_finite(y_axis) || !std::isfinite(radius) || !std::isfinite(start) ||
      !std::isfinite(end))
    bad("non-finite input; give finite center, axes, radius and angles");
  if (!(radius >= 0.0)) bad("radius " + std::to_string(radius) + " is negative; give radius >= 0");
  if (!(sweep > 0.0) || sweep > two_pi * (1.0 + 1e-14))
    bad("sweep end - start = " + std::to_string(sweep) + " rad is outside (0, 2 pi]");
  if (std::abs(x_axis.norm() - 1.0) > 1e-12 || std::abs(y_axis.norm() - 1.0) > 1e-12 ||
      std::abs(x_axis.dot(y_axis)) > 1e-12)
    bad("x_axis and y_axis must be orthonormal");
  const bool full = std::abs(sweep - two_pi) <= 1e-12;
  // Segments of at most 90 degrees (A7.1).
  const int arcs = sweep <= 0.5 * std::numbers::pi + 1e-15   ? 1
                   : sweep <= std::numbers::pi + 1e-15       ? 2
                   : sweep <= 1.5 * std::numbers::pi + 1e-15 ? 3
                                                             : 4;
  const double step = sweep / arcs;
  const double w1 = std::cos(0.5 * step);
  const int n = 2 * arcs + 1;
  BSplineCurve c;
  c.basis.degree = 2;
  c.basis.knots.assign(3, 0.0);
  for (int i = 1; i < arcs; ++i) {
    const double k = static_cast<double>(i) / arcs;
    c.basis.knots.push_back(k);
    c.basis.knots.push_back(k);
  }
  c.basis.knots.insert(c.basis.knots.end(), 3, 1.0);
  c.points.resize(n, 3);
  c.weights.resize(n);
  auto on_circle = [&](double a, double r) -> Eigen::Vector3d {
    return center + r * (std::cos(a) * x_axis + std::sin(a) * y_axis);
  };
  c.points.row(0) = on_circle(start, radius).transpose();
  c.weights[0] = 1.0;
  for (int i = 1; i <= arcs; ++i) {
    const double a = start + i * step;
    // The middle control point is where the end tangents meet: at radius r / cos(step / 2).
    c.points.row(2 * i - 1) = on_circle(a - 0.5 * step, radius / w1).transpose();
    c.weights[2 * i - 1] = w1;
    c.points.row(2 * i) = on_circle(a, radius).transpose();
    c.weights[2 * i] = 1.0;
  }
  if (full) c.points.row(n - 1) = c.points.row(0);
  return c;
}

BSplineCurve arc_through(const Eigen::Vector3d& start, const Eigen::Vector3d& through,
                         const Eigen::Vector3d& end) {
  if (!internal::all_finite(start) || !internal::all_finite(through) || !internal::all_finite(end))
    throw Error(ErrorCategory::InvalidArgument,
                "arc_through: a point is not finite; give three finite points");
  // Circumcentre of the triangle (start, through, end): with u = through - start, v = end - start
  // and w = u x v, c = start + (|u|^2 (v x w) + |v|^2 (w x u)) / (2 |w|^2).
  const Eigen::Vector3d u = through - start, v = end - start, w = u.cross(v);
  if (!(w.norm() > 1e-12 * u.norm() * v.norm()))
    throw Error(ErrorCategory::InvalidArgument,
                "arc_through: the three points are on one line (or two are the same); an arc "
                "needs its middle point off the line from start to end");
  const Eigen::Vector3d center =
      start + (u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u)) / (2 * w.squaredNorm());
  const double radius = (start - center).norm();
  // Counter-clockwise about w runs start -> through -> end.
  const Eigen::Vector3d x = (start - center) / radius;
  const Eigen::Vector3d y = w.normalized().cross(x);
  double sweep = std::atan2((end - center).dot(y), (end - center).dot(x));
  if (sweep <= 0) sweep += 2 * std::numbers::pi;
  BSplineCurve c = circular_arc(center, x, y, radius, 0.0, sweep);
  c.points.row(0) = start.transpose();
  c.points.row(c.points.rows() - 1) = end.transpose();
  return c;
}

}  // namespace clay::surface
