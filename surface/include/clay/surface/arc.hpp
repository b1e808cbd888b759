#pragma once
/// Exact circular arcs as rational quadratic B-spline curves (The NURBS Book A7.1).
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

namespace clay::surface {

/// The arc C(t) = center + radius (cos a x_axis + sin a y_axis), a from `start` to `end` (radians,
/// 0 < end - start <= 2 pi), as a rational quadratic curve on [0, 1] with one Bézier segment per
/// 90 degrees or less (weights 1 and cos(half segment angle)). A full circle closes exactly: its
/// last control point is a bit-for-bit copy of its first. `x_axis` and `y_axis` must be
/// orthonormal; radius >= 0 (0 gives a curve collapsed to `center`). Throws
/// clay::Error(InvalidArgument) naming the bad value.
CLAY_SURFACE_API BSplineCurve circular_arc(const Eigen::Vector3d& center,
                                           const Eigen::Vector3d& x_axis,
                                           const Eigen::Vector3d& y_axis, double radius,
                                           double start, double end);

/// The arc from `start` through `through` to `end`: the circle through the three points (its
/// circumcentre, in their plane), run from start to end the way that passes `through`, exact as
/// circular_arc gives it, with its end control points exactly `start` and `end` (so curves
/// snapped to them meet bit for bit). Throws clay::Error(InvalidArgument) naming the points when
/// they are not finite, or lie on one line (two of them the same included).
CLAY_SURFACE_API BSplineCurve arc_through(const Eigen::Vector3d& start,
                                          const Eigen::Vector3d& through,
                                          const Eigen::Vector3d& end);

}  // namespace clay::surface
