#pragma once
/// Sketch entities: points, line segments, circles, arcs and B-spline curves, in sketch planes or
/// free in 3D — the geometry a constraint system (clay/constraints) solves on.
///
/// A Sketch is plain data: planes, points and entities in vectors, referred to by 0-based ids.
/// Entities share points (a line's end is a point, a B-spline's control points are points), so a
/// constraint on a point moves every entity built on it. A point either lies in a sketch plane
/// (two unknowns: its plane coordinates) or is free in 3D (three unknowns).
#include <clay/sketch/export.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <string>
#include <variant>
#include <vector>

namespace clay::sketch {

/// Index of a plane in Sketch::planes; -1 (the default) means "no plane: free in 3D".
struct PlaneId {
  int index = -1;
  bool free() const noexcept { return index < 0; }
  bool operator==(const PlaneId&) const = default;
};
/// Index of a point in Sketch::points.
struct PointId {
  int index = -1;
  bool operator==(const PointId&) const = default;
};
/// Index of an entity in Sketch::entities.
struct EntityId {
  int index = -1;
  bool operator==(const EntityId&) const = default;
};

/// A point: world position (mm) and the plane it lies in (free in 3D when plane.free()).
struct SketchPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  PlaneId plane;
};

/// A line segment from start to end.
struct Line {
  PointId start, end;
};
/// A full circle in a plane: center (a point of that plane) and radius (mm, > 0; an unknown).
struct Circle {
  PointId center;
  double radius = 1;
  PlaneId plane;
};
/// A circular arc in a plane, counterclockwise about the plane normal from start to end around
/// center; its radius is |start − center|, and the solver keeps |end − center| equal to it.
struct Arc {
  PointId center, start, end;
  PlaneId plane;
};
/// A clamped B-spline curve whose control points are sketch points (in one plane: a planar curve;
/// free points: a free 3D curve). Degree, knots and weights are fixed; the control points move.
struct Curve {
  int degree = 3;
  std::vector<double> knots;
  Eigen::VectorXd weights;  ///< one per control point, > 0 (all 1: polynomial)
  std::vector<PointId> control_points;
};

/// Any sketch entity.
using Entity = std::variant<Line, Circle, Arc, Curve>;

/// Planes, points and entities. Add with the member functions (they check references and
/// reject degenerate geometry); read the geometry back with the free functions below.
struct CLAY_SKETCH_API Sketch {
  std::vector<SketchPlane> planes;
  std::vector<SketchPoint> points;
  std::vector<Entity> entities;
  /// Optional names for messages (a recipe gives its own): point_names[k] names point k and
  /// entity_names[k] entity k; a missing or empty name reads "point #k", "line #k".
  std::vector<std::string> point_names;
  std::vector<std::string> entity_names;

  /// Adds a plane (validated).
  PlaneId add_plane(const SketchPlane& plane);
  /// Adds a free 3D point. Throws clay::Error(InvalidGeometry) for a non-finite position.
  PointId add_point(const Eigen::Vector3d& position);
  /// Adds a point of `plane` at plane coordinates (a, b).
  PointId add_point(PlaneId plane, const Eigen::Vector2d& ab);
  /// Adds a segment between two existing points (distinct ids, distinct positions).
  EntityId add_line(PointId start, PointId end);
  /// Adds a circle in `plane` around `center` (a point of that plane), radius > 0.
  EntityId add_circle(PointId center, double radius, PlaneId plane);
  /// Adds an arc in `plane`; start and end must be at the same distance (> 0) from center within
  /// 1e-9 relative, and distinct.
  EntityId add_arc(PointId center, PointId start, PointId end, PlaneId plane);
  /// Adds a clamped B-spline curve, creating one point per control point: in `plane` (the control
  /// points must lie in it within 1e-9 of the curve's size) or free in 3D. Throws
  /// clay::Error(InvalidGeometry) for an invalid or unclamped curve (clamp it first) or one whose
  /// control polygon has zero length.
  EntityId add_curve(const surface::BSplineCurve& curve, PlaneId plane = {});
};

/// The world position of a point. Throws clay::Error(InvalidArgument) for a missing id.
CLAY_SKETCH_API Eigen::Vector3d position(const Sketch& sketch, PointId point);
/// The B-spline curve of any entity: a Curve as itself, a Line as degree 1, a Circle or an Arc as
/// an exact rational quadratic (surface::circular_arc). Throws clay::Error(InvalidArgument) for a
/// missing id.
CLAY_SKETCH_API surface::BSplineCurve curve_of(const Sketch& sketch, EntityId entity);
/// A short name for messages: "line \"luff\"" when entity_names names it, else "line #3",
/// "arc #0", "curve #2".
CLAY_SKETCH_API std::string describe(const Sketch& sketch, EntityId entity);
/// The same for a point: "point \"tip\"" or "point #7".
CLAY_SKETCH_API std::string describe(const Sketch& sketch, PointId point);
/// Two numbers for a message that says they differ: each with the fewest significant digits
/// (at least 3) that tell them apart, "1200.004 and 1200.01".
CLAY_SKETCH_API std::string distinct_numbers(double a, double b);

/// Every problem of the sketch in words (dangling ids, points off their plane by more than 1e-9
/// of the model size, zero-length lines, non-positive radii, unequal arc radii, invalid curves).
CLAY_SKETCH_API std::vector<std::string> problems(const Sketch& sketch);
/// Throws clay::Error(InvalidGeometry) listing problems(sketch) when there are any.
CLAY_SKETCH_API void validate(const Sketch& sketch);

}  // namespace clay::sketch
