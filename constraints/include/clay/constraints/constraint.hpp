#pragma once
/// Geometric constraints on sketch entities (clay/sketch/entities.hpp).
///
/// A Constraint is plain data made by the factory functions below; a list of them and a Sketch
/// go to solve() (clay/constraints/solve.hpp). Lengths are millimetres, angles degrees.
/// Constraints marked "planar" need their entities in one sketch plane and act in it.
#include <clay/constraints/export.hpp>
#include <clay/sketch/entities.hpp>

#include <Eigen/Core>

#include <string>
#include <variant>
#include <vector>

namespace clay::constraints {

using sketch::EntityId;
using sketch::PlaneId;
using sketch::PointId;

/// One end of a line, arc or B-spline curve entity.
struct CurveEnd {
  EntityId curve;
  bool at_start = false;  ///< true: the start (t = domain start), false: the end
};
/// The start of a curve entity.
inline CurveEnd start_of(EntityId curve) { return {curve, true}; }
/// The end of a curve entity.
inline CurveEnd end_of(EntityId curve) { return {curve, false}; }

/// What a constraint requires.
enum class ConstraintKind {
  Fixed,              ///< point stays where it is
  Coincident,         ///< two points at the same place
  PointOnCurve,       ///< point on a line (the infinite line), circle, arc (its circle) or curve
  Horizontal,         ///< planar: line along its plane's x axis
  Vertical,           ///< planar: line along its plane's y axis
  Parallel,           ///< planar: two lines parallel (keeping their sense)
  Perpendicular,      ///< planar: two lines at 90 degrees (keeping their turn)
  Distance,           ///< point–point distance = value (> 0)
  PointLineDistance,  ///< planar: point–line distance = value, on the side it starts on
  Angle,              ///< planar: angle from line a to line b = value degrees, turn sense kept
  Radius,             ///< circle or arc radius = value (> 0)
  EqualLength,        ///< two lines of equal length
  EqualRadius,        ///< two circles/arcs of equal radius
  Midpoint,           ///< point at the midpoint of a line
  Symmetric,          ///< planar: two points mirror images about a line
  Tangent,            ///< G1 joint: ends coincide, tangents parallel with the same sense
  Curvature,          ///< G2 joint: G1 and equal curvature vectors
  EndTangent,         ///< a curve end's tangent along a given direction (same sense)
};

// ---- one value type per kind (the alternatives of Requirement, in ConstraintKind's order) ----

/// The point stays where it is.
struct Fixed {
  PointId point;
};
/// Two points at the same place.
struct Coincident {
  PointId a, b;
};
/// A point on a curve entity (a line counts as its infinite line, an arc as its circle).
struct PointOnCurve {
  PointId point;
  EntityId curve;
};
/// Planar: a line along its plane's x axis.
struct Horizontal {
  EntityId line;
};
/// Planar: a line along its plane's y axis.
struct Vertical {
  EntityId line;
};
/// Planar: two lines parallel, keeping their sense.
struct Parallel {
  EntityId a, b;
};
/// Planar: two lines at 90 degrees, keeping their turn.
struct Perpendicular {
  EntityId a, b;
};
/// Two points `mm` apart (> 0).
struct Distance {
  PointId a, b;
  double mm = 0;
};
/// Planar: a point `mm` from the (infinite) line, on the side it starts on.
struct PointLineDistance {
  PointId point;
  EntityId line;
  double mm = 0;
};
/// Planar: the angle turning line a into line b is `degrees`, in (0, 180], turn sense kept.
struct Angle {
  EntityId a, b;
  double degrees = 0;
};
/// A circle's or arc's radius is `mm` (> 0).
struct Radius {
  EntityId circle_or_arc;
  double mm = 0;
};
/// Two lines of equal length.
struct EqualLength {
  EntityId a, b;
};
/// Two circles/arcs of equal radius.
struct EqualRadius {
  EntityId a, b;
};
/// A point at the midpoint of a line.
struct Midpoint {
  PointId point;
  EntityId line;
};
/// Planar: a and b mirror images about a line.
struct Symmetric {
  PointId a, b;
  EntityId line;
};
/// G1 joint: ends coincide, tangents parallel with the same sense.
struct Tangent {
  CurveEnd a, b;
};
/// G2 joint: G1 and equal curvature vectors.
struct Curvature {
  CurveEnd a, b;
};
/// A curve end's tangent along `direction` (world, nonzero, same sense).
struct EndTangent {
  CurveEnd end;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

/// What a constraint requires: one typed alternative per kind (ConstraintKind is its index), so
/// a constraint cannot hold the wrong number of points or a value it has no use for.
using Requirement =
    std::variant<Fixed, Coincident, PointOnCurve, Horizontal, Vertical, Parallel, Perpendicular,
                 Distance, PointLineDistance, Angle, Radius, EqualLength, EqualRadius, Midpoint,
                 Symmetric, Tangent, Curvature, EndTangent>;

/// A constraint: what it requires and an optional label for reports. Make it with the functions
/// below or from a Requirement directly (Constraint{Distance{a, b, 10}}).
struct Constraint {
  Requirement requirement;
  std::string label;  ///< names the constraint in messages when set (constraint_name)

  /// The kind, as an enum (the requirement's alternative).
  ConstraintKind kind() const noexcept { return static_cast<ConstraintKind>(requirement.index()); }
};

/// The point stays at its current position.
CLAY_CONSTRAINTS_API Constraint fixed(PointId point);
/// The two points coincide.
CLAY_CONSTRAINTS_API Constraint coincident(PointId a, PointId b);
/// The point lies on the curve entity (a line counts as its infinite line, an arc as its circle).
CLAY_CONSTRAINTS_API Constraint point_on(PointId point, EntityId curve);
/// Planar: the line is parallel to its plane's x axis.
CLAY_CONSTRAINTS_API Constraint horizontal(EntityId line);
/// Planar: the line is parallel to its plane's y axis.
CLAY_CONSTRAINTS_API Constraint vertical(EntityId line);
/// Planar: the lines are parallel, pointing the same way they point at the start.
CLAY_CONSTRAINTS_API Constraint parallel(EntityId a, EntityId b);
/// Planar: the lines are perpendicular.
CLAY_CONSTRAINTS_API Constraint perpendicular(EntityId a, EntityId b);
/// The points are `distance` mm apart (> 0; use coincident for 0).
CLAY_CONSTRAINTS_API Constraint distance(PointId a, PointId b, double distance);
/// Planar: the point is `distance` mm from the (infinite) line, on the side where it starts.
CLAY_CONSTRAINTS_API Constraint distance(PointId point, EntityId line, double distance);
/// Planar: the angle turning line a's direction into line b's is `degrees` in (0, 180], turning
/// the way it turns at the start.
CLAY_CONSTRAINTS_API Constraint angle(EntityId a, EntityId b, double degrees);
/// The circle's or arc's radius is `radius` mm (> 0).
CLAY_CONSTRAINTS_API Constraint radius(EntityId circle_or_arc, double radius);
/// The two lines have equal length.
CLAY_CONSTRAINTS_API Constraint equal_length(EntityId a, EntityId b);
/// The two circles/arcs have equal radius.
CLAY_CONSTRAINTS_API Constraint equal_radius(EntityId a, EntityId b);
/// The point is the midpoint of the line.
CLAY_CONSTRAINTS_API Constraint midpoint(PointId point, EntityId line);
/// Planar: a and b are mirror images about the (infinite) line.
CLAY_CONSTRAINTS_API Constraint symmetric(PointId a, PointId b, EntityId line);
/// G1 joint between two curve ends (lines, arcs, B-spline curves): the end points coincide and
/// the curve a continues into curve b with a parallel tangent of the same sense.
CLAY_CONSTRAINTS_API Constraint tangent(CurveEnd a, CurveEnd b);
/// G2 joint: tangent(a, b) and equal curvature vectors at the joint.
CLAY_CONSTRAINTS_API Constraint curvature(CurveEnd a, CurveEnd b);
/// The tangent at a curve end, pointing out of the curve's end (or into it at its start, i.e.
/// along increasing parameter) is along `direction` (world, nonzero).
CLAY_CONSTRAINTS_API Constraint end_tangent(CurveEnd end, const Eigen::Vector3d& direction);

/// The constraint in words, naming its points and entities as the sketch calls them (their
/// names when the sketch has them): "angle 60 degrees from line #1 to line #2".
CLAY_CONSTRAINTS_API std::string describe(const Constraint& constraint,
                                          const sketch::Sketch& sketch);
/// How messages name the constraint at `index` of a list: its label when set (a recipe labels
/// each with its path, "sketches.s.constraints[3]"), else "constraint #3".
CLAY_CONSTRAINTS_API std::string constraint_name(const Constraint& constraint, int index);

}  // namespace clay::constraints
