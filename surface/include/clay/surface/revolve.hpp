#pragma once
/// Surfaces of revolution as exact rational B-spline surfaces (The NURBS Book A8.1): every
/// circle is an exact rational quadratic, not an approximation.
#include <clay/surface/build_report.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

namespace clay::surface {

/// An axis: a point on it and its direction (any length > 0; it is normalized).
struct Axis {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};

/// Revolves `profile` about `axis` by `angle_degrees` in (0, 360], counter-clockwise about the
/// axis direction (right-hand rule). The result's u direction goes around the axis (degree 2,
/// domain [0, 1], one Bézier segment per 90 degrees or less), its v direction is the profile's
/// (same degree, knots and parameters). A full revolution closes exactly (the last row of control
/// points copies the first). Control points on the axis stay there (poles, as on a sphere).
///
/// The report is exact; its max_deviation_mm is the largest difference, over a dense sample,
/// between a surface point's distance to the axis (and height along it) and those of the profile
/// point it comes from. Throws clay::Error: InvalidGeometry for an invalid profile, a profile lying
/// on the axis, a profile that touches or crosses the axis between its ends, or a profile that
/// crosses, touches or doubles back onto itself within 1e-7 × size (find_self_intersection; the
/// surface would intersect itself in each case); InvalidArgument for an axis of zero length or an
/// angle outside (0, 360]. Not detected: a non-planar profile whose meridian (distance to the axis,
/// height along it) crosses itself although the profile does not.
CLAY_SURFACE_API BuiltSurface revolve(const BSplineCurve& profile, const Axis& axis,
                                      double angle_degrees = 360.0);

}  // namespace clay::surface
