#pragma once
/// SketchPlane — an orthonormal frame in which planar sketch geometry lives.
///
/// A point (a, b) of the plane is origin + a x_axis + b y_axis in the world (millimetres).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string_view>

namespace clay::sketch {

/// A plane with an orthonormal frame: origin, unit x_axis, unit y_axis (normal = x × y).
struct SketchPlane {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();

  /// The unit normal x_axis × y_axis.
  Eigen::Vector3d normal() const { return x_axis.cross(y_axis); }
  /// Plane coordinates (a, b) of the orthogonal projection of a world point.
  Eigen::Vector2d to_plane(const Eigen::Vector3d& point) const {
    const Eigen::Vector3d d = point - origin;
    return {d.dot(x_axis), d.dot(y_axis)};
  }
  /// The world point at plane coordinates (a, b).
  Eigen::Vector3d to_world(const Eigen::Vector2d& ab) const {
    return origin + ab.x() * x_axis + ab.y() * y_axis;
  }
  /// Signed distance of a world point from the plane (along normal()).
  double distance(const Eigen::Vector3d& point) const { return (point - origin).dot(normal()); }
};

/// The plane through `origin` with unit normal along `normal`; its x axis is `x_direction` made
/// orthogonal to the normal (Gram–Schmidt), or, when that is zero (the default), the world axis
/// least aligned with the normal made orthogonal. Throws clay::Error(InvalidGeometry) for a
/// non-finite input, a zero normal, or an x direction parallel to the normal.
SketchPlane make_plane(const Eigen::Vector3d& origin, const Eigen::Vector3d& normal,
                       const Eigen::Vector3d& x_direction = Eigen::Vector3d::Zero());

/// Throws clay::Error(InvalidGeometry) naming `name` when the plane is not finite or its axes are
/// not unit and orthogonal within 1e-12.
void validate(const SketchPlane& plane, std::string_view name = "plane");

}  // namespace clay::sketch
