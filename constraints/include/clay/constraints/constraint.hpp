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

/// A constraint: its kind, the points, entities and ends it refers to, a value when it has one
/// (mm or degrees) and an optional label for reports. Make it with the functions below.
struct Constraint {
  ConstraintKind kind = ConstraintKind::Fixed;
  std::vector<PointId> points;
  std::vector<EntityId> entities;
  std::vector<CurveEnd> ends;
  double value = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< EndTangent only (world)
  std::string label;  ///< names the constraint in messages when set (constraint_name)
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
