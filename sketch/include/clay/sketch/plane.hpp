#pragma once
/// SketchPlane — a plane to sketch in: an origin and two orthonormal axes (millimetres).
///
/// Points in the plane have coordinates (x, y) along the axes; the normal is x_axis × y_axis, so
/// (x_axis, y_axis, normal) is right-handed. Strokes, sketch entities and the constraint solver
/// share this one type.
#include <clay/sketch/export.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross() in normal()

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace clay::sketch {

/// Largest |length - 1| of an axis and |x_axis · y_axis| that validate() accepts.
inline constexpr double plane_axis_tolerance = 1e-9;

/// An origin and two orthonormal axes. Value type: copy, compare, store freely.
struct SketchPlane {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   ///< mm
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();  ///< unit
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();  ///< unit, orthogonal to x_axis

  /// x_axis × y_axis (unit when the plane is valid).
  Eigen::Vector3d normal() const { return x_axis.cross(y_axis); }

  /// True when origin and axes are equal bit for bit.
  bool operator==(const SketchPlane& other) const = default;
};

/// Every invariant the plane breaks, in words, each naming `name`: non-finite origin or axes, an
/// axis whose length differs from 1 by more than plane_axis_tolerance, axes whose dot product
/// exceeds it. Empty when valid.
CLAY_SKETCH_API std::vector<std::string> problems(const SketchPlane& plane,
                                                  std::string_view name = "sketch plane");

/// Throws clay::Error(InvalidGeometry) listing problems(plane, name) when there are any.
CLAY_SKETCH_API void validate(const SketchPlane& plane, std::string_view name = "sketch plane");

/// The plane through `origin` with unit normal `normal` / |normal|. The x axis is `x_direction`
/// made orthogonal to the normal (Gram–Schmidt) and unit; without one, the world axis least
/// aligned with the normal is used, so the choice is deterministic. The y axis is normal × x.
/// Throws clay::Error(InvalidArgument) for a non-finite input, a normal of zero length, or an
/// x_direction of zero length or parallel to the normal (within 1e-9 rad).
CLAY_SKETCH_API SketchPlane
make_plane(const Eigen::Vector3d& origin, const Eigen::Vector3d& normal,
           const std::optional<Eigen::Vector3d>& x_direction = std::nullopt);

/// Coordinates (x, y) of the orthogonal projection of `point` onto the plane.
CLAY_SKETCH_API Eigen::Vector2d to_plane(const SketchPlane& plane, const Eigen::Vector3d& point);

/// The world point origin + x x_axis + y y_axis.
CLAY_SKETCH_API Eigen::Vector3d to_world(const SketchPlane& plane,
                                         const Eigen::Vector2d& coordinates);

/// Signed distance of `point` from the plane along the normal (mm).
CLAY_SKETCH_API double signed_distance(const SketchPlane& plane, const Eigen::Vector3d& point);

}  // namespace clay::sketch
