#include <clay/constraints/constraint.hpp>
#include <clay/internal/format.hpp>

#include <variant>

#include "equations.hpp"

#include <cstdio>

namespace clay::constraints {
namespace {

std::string num(double x) { return internal::with_digits(x, 6); }

}  // namespace

Constraint fixed(PointId point) { return {Fixed{point}, {}}; }
Constraint coincident(PointId a, PointId b) { return {Coincident{a, b}, {}}; }
Constraint point_on(PointId point, EntityId curve) { return {PointOnCurve{point, curve}, {}}; }
Constraint horizontal(EntityId line) { return {Horizontal{line}, {}}; }
Constraint vertical(EntityId line) { return {Vertical{line}, {}}; }
Constraint parallel(EntityId a, EntityId b) { return {Parallel{a, b}, {}}; }
Constraint perpendicular(EntityId a, EntityId b) { return {Perpendicular{a, b}, {}}; }
Constraint distance(PointId a, PointId b, double d) { return {Distance{a, b, d}, {}}; }
Constraint distance(PointId point, EntityId line, double d) {
  return {PointLineDistance{point, line, d}, {}};
}
Constraint angle(EntityId a, EntityId b, double degrees) { return {Angle{a, b, degrees}, {}}; }
Constraint radius(EntityId circle_or_arc, double r) { return {Radius{circle_or_arc, r}, {}}; }
Constraint equal_length(EntityId a, EntityId b) { return {EqualLength{a, b}, {}}; }
Constraint equal_radius(EntityId a, EntityId b) { return {EqualRadius{a, b}, {}}; }
Constraint midpoint(PointId point, EntityId line) { return {Midpoint{point, line}, {}}; }
Constraint symmetric(PointId a, PointId b, EntityId line) { return {Symmetric{a, b, line}, {}}; }
Constraint tangent(CurveEnd a, CurveEnd b) { return {Tangent{a, b}, {}}; }
Constraint curvature(CurveEnd a, CurveEnd b) { return {Curvature{a, b}, {}}; }
Constraint end_tangent(CurveEnd end, const Eigen::Vector3d& direction) {
  return {EndTangent{end, direction}, {}};
}

namespace detail {

Lowered lower(const Constraint& constraint) {
  Lowered l;
  l.kind = constraint.kind();
  l.label = constraint.label;
  // One overload per alternative: the struct's fields in declaration order.
  struct Flatten {
    Lowered& l;
    void operator()(const Fixed& c) const { l.points = {c.point}; }
    void operator()(const Coincident& c) const { l.points = {c.a, c.b}; }
    void operator()(const PointOnCurve& c) const { l.points = {c.point}, l.entities = {c.curve}; }
    void operator()(const Horizontal& c) const { l.entities = {c.line}; }
    void operator()(const Vertical& c) const { l.entities = {c.line}; }
    void operator()(const Parallel& c) const { l.entities = {c.a, c.b}; }
    void operator()(const Perpendicular& c) const { l.entities = {c.a, c.b}; }
    void operator()(const Distance& c) const { l.points = {c.a, c.b}, l.value = c.mm; }
    void operator()(const PointLineDistance& c) const {
      l.points = {c.point}, l.entities = {c.line}, l.value = c.mm;
    }
    void operator()(const Angle& c) const { l.entities = {c.a, c.b}, l.value = c.degrees; }
    void operator()(const Radius& c) const { l.entities = {c.circle_or_arc}, l.value = c.mm; }
    void operator()(const EqualLength& c) const { l.entities = {c.a, c.b}; }
    void operator()(const EqualRadius& c) const { l.entities = {c.a, c.b}; }
    void operator()(const Midpoint& c) const { l.points = {c.point}, l.entities = {c.line}; }
    void operator()(const Symmetric& c) const { l.points = {c.a, c.b}, l.entities = {c.line}; }
    void operator()(const Tangent& c) const { l.ends = {c.a, c.b}; }
    void operator()(const Curvature& c) const { l.ends = {c.a, c.b}; }
    void operator()(const EndTangent& c) const { l.ends = {c.end}, l.direction = c.direction; }
  };
  std::visit(Flatten{l}, constraint.requirement);
  return l;
}

}  // namespace detail

std::string describe(const Constraint& constraint, const sketch::Sketch& sketch) {
  const detail::Lowered c = detail::lower(constraint);
  auto p = [&](size_t i) {
    return i < c.points.size() ? sketch::describe(sketch, c.points[i]) : std::string("?");
  };
  auto e = [&](size_t i) {
    return i < c.entities.size() ? sketch::describe(sketch, c.entities[i]) : std::string("?");
  };
  auto end = [&](size_t i) {
    if (i >= c.ends.size()) return std::string("?");
    return std::string(c.ends[i].at_start ? "start of " : "end of ") +
           sketch::describe(sketch, c.ends[i].curve);
  };
  std::string text;
  switch (c.kind) {
    case ConstraintKind::Fixed:
      text = "fixed " + p(0);
      break;
    case ConstraintKind::Coincident:
      text = "coincident " + p(0) + " and " + p(1);
      break;
    case ConstraintKind::PointOnCurve:
      text = p(0) + " on " + e(0);
      break;
    case ConstraintKind::Horizontal:
      text = "horizontal " + e(0);
      break;
    case ConstraintKind::Vertical:
      text = "vertical " + e(0);
      break;
    case ConstraintKind::Parallel:
      text = "parallel " + e(0) + " and " + e(1);
      break;
    case ConstraintKind::Perpendicular:
      text = "perpendicular " + e(0) + " and " + e(1);
      break;
    case ConstraintKind::Distance:
      text = "distance " + num(c.value) + " mm between " + p(0) + " and " + p(1);
      break;
    case ConstraintKind::PointLineDistance:
      text = "distance " + num(c.value) + " mm from " + p(0) + " to " + e(0);
      break;
    case ConstraintKind::Angle:
      text = "angle " + num(c.value) + " degrees from " + e(0) + " to " + e(1);
      break;
    case ConstraintKind::Radius:
      text = "radius " + num(c.value) + " mm of " + e(0);
      break;
    case ConstraintKind::EqualLength:
      text = "equal length " + e(0) + " and " + e(1);
      break;
    case ConstraintKind::EqualRadius:
      text = "equal radius " + e(0) + " and " + e(1);
      break;
    case ConstraintKind::Midpoint:
      text = p(0) + " at the midpoint of " + e(0);
      break;
    case ConstraintKind::Symmetric:
      text = p(0) + " and " + p(1) + " symmetric about " + e(0);
      break;
    case ConstraintKind::Tangent:
      text = "G1 joint " + end(0) + " to " + end(1);
      break;
    case ConstraintKind::Curvature:
      text = "G2 joint " + end(0) + " to " + end(1);
      break;
    case ConstraintKind::EndTangent:
      text = "tangent at " + end(0) + " along a given direction";
      break;
  }
  return text;
}

std::string constraint_name(const Constraint& c, int index) {
  return c.label.empty() ? "constraint #" + std::to_string(index) : c.label;
}

}  // namespace clay::constraints
