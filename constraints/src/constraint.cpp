#include <clay/constraints/constraint.hpp>

#include <cstdio>

namespace clay::constraints {
namespace {

Constraint make(ConstraintKind kind, std::vector<PointId> points, std::vector<EntityId> entities,
                double value = 0) {
  Constraint c;
  c.kind = kind;
  c.points = std::move(points);
  c.entities = std::move(entities);
  c.value = value;
  return c;
}

std::string num(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", x);
  return buffer;
}

}  // namespace

Constraint fixed(PointId point) { return make(ConstraintKind::Fixed, {point}, {}); }
Constraint coincident(PointId a, PointId b) { return make(ConstraintKind::Coincident, {a, b}, {}); }
Constraint point_on(PointId point, EntityId curve) {
  return make(ConstraintKind::PointOnCurve, {point}, {curve});
}
Constraint horizontal(EntityId line) { return make(ConstraintKind::Horizontal, {}, {line}); }
Constraint vertical(EntityId line) { return make(ConstraintKind::Vertical, {}, {line}); }
Constraint parallel(EntityId a, EntityId b) { return make(ConstraintKind::Parallel, {}, {a, b}); }
Constraint perpendicular(EntityId a, EntityId b) {
  return make(ConstraintKind::Perpendicular, {}, {a, b});
}
Constraint distance(PointId a, PointId b, double d) {
  return make(ConstraintKind::Distance, {a, b}, {}, d);
}
Constraint distance(PointId point, EntityId line, double d) {
  return make(ConstraintKind::PointLineDistance, {point}, {line}, d);
}
Constraint angle(EntityId a, EntityId b, double degrees) {
  return make(ConstraintKind::Angle, {}, {a, b}, degrees);
}
Constraint radius(EntityId circle_or_arc, double r) {
  return make(ConstraintKind::Radius, {}, {circle_or_arc}, r);
}
Constraint equal_length(EntityId a, EntityId b) { return make(ConstraintKind::EqualLength, {}, {a, b}); }
Constraint equal_radius(EntityId a, EntityId b) { return make(ConstraintKind::EqualRadius, {}, {a, b}); }
Constraint midpoint(PointId point, EntityId line) {
  return make(ConstraintKind::Midpoint, {point}, {line});
}
Constraint symmetric(PointId a, PointId b, EntityId line) {
  return make(ConstraintKind::Symmetric, {a, b}, {line});
}
Constraint tangent(CurveEnd a, CurveEnd b) {
  Constraint c = make(ConstraintKind::Tangent, {}, {});
  c.ends = {a, b};
  return c;
}
Constraint curvature(CurveEnd a, CurveEnd b) {
  Constraint c = make(ConstraintKind::Curvature, {}, {});
  c.ends = {a, b};
  return c;
}
Constraint end_tangent(CurveEnd end, const Eigen::Vector3d& direction) {
  Constraint c = make(ConstraintKind::EndTangent, {}, {});
  c.ends = {end};
  c.direction = direction;
  return c;
}

std::string describe(const Constraint& c, const sketch::Sketch& sketch) {
  auto p = [&](size_t i) {
    return i < c.points.size() ? sketch::describe(sketch, c.points[i]) : std::string("?");
  };
  auto e = [&](size_t i) {
    return i < c.entities.size() ? sketch::describe(sketch, c.entities[i]) : std::string("?");
  };
  auto end = [&](size_t i) {
    if (i >= c.ends.size()) return std::string("?");
    return std::string(c.ends[i].at_start ? "start of " : "end of ") + sketch::describe(sketch, c.ends[i].curve);
  };
  std::string text;
  switch (c.kind) {
    case ConstraintKind::Fixed: text = "fixed " + p(0); break;
    case ConstraintKind::Coincident: text = "coincident " + p(0) + " and " + p(1); break;
    case ConstraintKind::PointOnCurve: text = p(0) + " on " + e(0); break;
    case ConstraintKind::Horizontal: text = "horizontal " + e(0); break;
    case ConstraintKind::Vertical: text = "vertical " + e(0); break;
    case ConstraintKind::Parallel: text = "parallel " + e(0) + " and " + e(1); break;
    case ConstraintKind::Perpendicular: text = "perpendicular " + e(0) + " and " + e(1); break;
    case ConstraintKind::Distance:
      text = "distance " + num(c.value) + " mm between " + p(0) + " and " + p(1);
      break;
    case ConstraintKind::PointLineDistance:
      text = "distance " + num(c.value) + " mm from " + p(0) + " to " + e(0);
      break;
    case ConstraintKind::Angle: text = "angle " + num(c.value) + " degrees from " + e(0) + " to " + e(1); break;
    case ConstraintKind::Radius: text = "radius " + num(c.value) + " mm of " + e(0); break;
    case ConstraintKind::EqualLength: text = "equal length " + e(0) + " and " + e(1); break;
    case ConstraintKind::EqualRadius: text = "equal radius " + e(0) + " and " + e(1); break;
    case ConstraintKind::Midpoint: text = p(0) + " at the midpoint of " + e(0); break;
    case ConstraintKind::Symmetric: text = p(0) + " and " + p(1) + " symmetric about " + e(0); break;
    case ConstraintKind::Tangent: text = "G1 joint " + end(0) + " to " + end(1); break;
    case ConstraintKind::Curvature: text = "G2 joint " + end(0) + " to " + end(1); break;
    case ConstraintKind::EndTangent: text = "tangent at " + end(0) + " along a given direction"; break;
  }
  return text;
}

std::string constraint_name(const Constraint& c, int index) {
  return c.label.empty() ? "constraint #" + std::to_string(index) : c.label;
}

}  // namespace clay::constraints
