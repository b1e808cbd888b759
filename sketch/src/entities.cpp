#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/sketch/entities.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/basis.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace clay::sketch {
namespace {

std::string num(double x) { return internal::with_digits(x, 3); }

/// The name of a point for messages: its recipe name when the sketch has one.
std::string point_name(const Sketch& s, int index) {
  if (index >= 0 && index < static_cast<int>(s.point_names.size()) &&
      !s.point_names[static_cast<size_t>(index)].empty())
    return "point \"" + s.point_names[static_cast<size_t>(index)] + "\"";
  return "point #" + std::to_string(index);
}

/// "kind \"name\"" or "kind #index".
std::string named(const Sketch& s, const char* kind, size_t index) {
  if (index < s.entity_names.size() && !s.entity_names[index].empty())
    return std::string(kind) + " \"" + s.entity_names[index] + "\"";
  return std::string(kind) + " #" + std::to_string(index);
}

[[noreturn]] void fail(ErrorCategory category, const std::string& message) {
  throw Error(category, message);
}

bool finite(const Eigen::Vector3d& v) { return internal::all_finite(v); }

double model_size(const Sketch& sketch) {
  if (sketch.points.empty()) return 1.0;
  Eigen::Vector3d lo = sketch.points.front().position, hi = lo;
  for (const SketchPoint& p : sketch.points) {
    lo = lo.cwiseMin(p.position);
    hi = hi.cwiseMax(p.position);
  }
  return std::max(1.0, (hi - lo).norm());
}

}  // namespace

PlaneId Sketch::add_plane(const SketchPlane& plane) {
  validate(plane, "plane #" + std::to_string(planes.size()));
  planes.push_back(plane);
  return {static_cast<int>(planes.size()) - 1};
}

PointId Sketch::add_point(const Eigen::Vector3d& p) {
  if (!finite(p))
    fail(ErrorCategory::InvalidGeometry,
         "add_point: " + point_name(*this, static_cast<int>(points.size())) +
             " has a non-finite coordinate");
  points.push_back({p, {}});
  return {static_cast<int>(points.size()) - 1};
}

PointId Sketch::add_point(PlaneId plane, const Eigen::Vector2d& ab) {
  if (plane.index < 0 || plane.index >= static_cast<int>(planes.size()))
    fail(ErrorCategory::InvalidArgument, "add_point: plane #" + std::to_string(plane.index) +
                                             " does not exist (the sketch has " +
                                             std::to_string(planes.size()) + " planes)");
  if (!internal::all_finite(ab))
    fail(ErrorCategory::InvalidGeometry,
         "add_point: " + point_name(*this, static_cast<int>(points.size())) +
             " has a non-finite coordinate");
  points.push_back({to_world(planes[static_cast<size_t>(plane.index)], ab), plane});
  return {static_cast<int>(points.size()) - 1};
}

namespace {

void check_point(const Sketch& s, PointId p, const std::string& who) {
  if (p.index < 0 || p.index >= static_cast<int>(s.points.size()))
    fail(ErrorCategory::InvalidArgument, who + ": " + point_name(s, p.index) +
                                             " does not exist (the sketch has " +
                                             std::to_string(s.points.size()) + " points)");
}

void check_plane(const Sketch& s, PlaneId plane, const std::string& who) {
  if (plane.index < 0 || plane.index >= static_cast<int>(s.planes.size()))
    fail(ErrorCategory::InvalidArgument,
         who + ": plane #" + std::to_string(plane.index) + " does not exist (the sketch has " +
             std::to_string(s.planes.size()) + " planes); circles and arcs need a plane");
}

void check_in_plane(const Sketch& s, PointId p, PlaneId plane, const std::string& who) {
  if (!(s.points[static_cast<size_t>(p.index)].plane == plane))
    fail(ErrorCategory::InvalidGeometry,
         who + ": " + point_name(s, p.index) + " is not a point of plane #" +
             std::to_string(plane.index) + "; create it with add_point(plane, ab)");
}

EntityId push(Sketch& s, Entity e) {
  s.entities.push_back(std::move(e));
  return {static_cast<int>(s.entities.size()) - 1};
}

std::string entity_name(const Sketch& s, size_t index) {
  const char* kind = std::visit(
      [](const auto& e) -> const char* {
        using T = std::decay_t<decltype(e)>;
        if constexpr (std::is_same_v<T, Line>)
          return "line";
        else if constexpr (std::is_same_v<T, Circle>)
          return "circle";
        else if constexpr (std::is_same_v<T, Arc>)
          return "arc";
        else
          return "curve";
      },
      s.entities[index]);
  return named(s, kind, index);
}

}  // namespace

EntityId Sketch::add_line(PointId start, PointId end) {
  const std::string who = "add_line (" + named(*this, "line", entities.size()) + ")";
  check_point(*this, start, who);
  check_point(*this, end, who);
  const double length = (position(*this, end) - position(*this, start)).norm();
  if (start == end || !(length > 1e-12 * model_size(*this)))
    fail(ErrorCategory::InvalidGeometry, who + ": zero length (" + point_name(*this, start.index) +
                                             " and " + point_name(*this, end.index) +
                                             " coincide); give two distinct points");
  return push(*this, Line{start, end});
}

EntityId Sketch::add_circle(PointId center, double radius, PlaneId plane) {
  const std::string who = "add_circle (" + named(*this, "circle", entities.size()) + ")";
  check_point(*this, center, who);
  check_plane(*this, plane, who);
  check_in_plane(*this, center, plane, who);
  if (!(radius > 0) || !std::isfinite(radius))
    fail(ErrorCategory::InvalidGeometry,
         who + ": radius " + num(radius) + " must be positive and finite");
  return push(*this, Circle{center, radius, plane});
}

EntityId Sketch::add_arc(PointId center, PointId start, PointId end, PlaneId plane) {
  const std::string who = "add_arc (" + named(*this, "arc", entities.size()) + ")";
  for (PointId p : {center, start, end}) {
    check_point(*this, p, who);
  }
  check_plane(*this, plane, who);
  for (PointId p : {center, start, end}) check_in_plane(*this, p, plane, who);
  const Eigen::Vector3d c = position(*this, center);
  const double r0 = (position(*this, start) - c).norm(), r1 = (position(*this, end) - c).norm();
  if (!(r0 > 1e-12 * model_size(*this)))
    fail(ErrorCategory::InvalidGeometry, who + ": zero radius (start point on the center)");
  if (std::abs(r1 - r0) > 1e-9 * r0)
    fail(ErrorCategory::InvalidGeometry,
         who + ": start and end are at different distances from the center (" +
             distinct_numbers(r0, r1) + " mm); place the end on the circle through the start");
  if (start == end || (position(*this, end) - position(*this, start)).norm() <= 1e-12 * r0)
    fail(ErrorCategory::InvalidGeometry,
         who + ": start and end coincide (a zero-length arc); use a circle for a full turn");
  return push(*this, Arc{center, start, end, plane});
}

EntityId Sketch::add_curve(const surface::BSplineCurve& curve, PlaneId plane) {
  const std::string who = "add_curve (" + named(*this, "curve", entities.size()) + ")";
  surface::validate(curve, who);
  if (!surface::is_clamped(curve.basis))
    fail(ErrorCategory::InvalidGeometry,
         who +
             ": the curve is not clamped, so its ends are not control points; clamp it "
             "(surface::clamp) first");
  double length = 0;
  Eigen::Vector3d lo = curve.points.row(0).transpose(), hi = lo;
  for (Eigen::Index i = 1; i < curve.points.rows(); ++i) {
    length += (curve.points.row(i) - curve.points.row(i - 1)).norm();
    lo = lo.cwiseMin(curve.points.row(i).transpose());
    hi = hi.cwiseMax(curve.points.row(i).transpose());
  }
  const double size = std::max(1.0, (hi - lo).norm());
  if (!(length > 1e-12 * size))
    fail(ErrorCategory::InvalidGeometry, who + ": zero length (all control points coincide)");
  if (!plane.free()) {
    check_plane(*this, plane, who);
    const SketchPlane& pl = planes[static_cast<size_t>(plane.index)];
    for (Eigen::Index i = 0; i < curve.points.rows(); ++i) {
      const double d = std::abs(signed_distance(pl, curve.points.row(i).transpose()));
      if (d > 1e-9 * size)
        fail(ErrorCategory::InvalidGeometry,
             who + ": control point " + std::to_string(i) + " is " + num(d) + " mm off plane #" +
                 std::to_string(plane.index) + "; project the curve into the plane first");
    }
  }
  Curve c;
  c.degree = curve.basis.degree;
  c.knots = curve.basis.knots;
  c.weights = curve.weights;
  for (Eigen::Index i = 0; i < curve.points.rows(); ++i) {
    const Eigen::Vector3d p = curve.points.row(i).transpose();
    c.control_points.push_back(
        plane.free() ? add_point(p)
                     : add_point(plane, to_plane(planes[static_cast<size_t>(plane.index)], p)));
  }
  return push(*this, std::move(c));
}

Eigen::Vector3d position(const Sketch& sketch, PointId point) {
  check_point(sketch, point, "position");
  return sketch.points[static_cast<size_t>(point.index)].position;
}

std::string describe(const Sketch& sketch, PointId point) {
  return point_name(sketch, point.index);
}

std::string distinct_numbers(double a, double b) {
  char x[40], y[40];
  for (int digits = 3; digits <= 17; ++digits) {
    std::snprintf(x, sizeof x, "%.*g", digits, a);
    std::snprintf(y, sizeof y, "%.*g", digits, b);
    if (std::string(x) != y) break;
  }
  return std::string(x) + " and " + y;
}

std::string describe(const Sketch& sketch, EntityId entity) {
  if (entity.index < 0 || entity.index >= static_cast<int>(sketch.entities.size()))
    return "entity #" + std::to_string(entity.index) + " (missing)";
  return entity_name(sketch, static_cast<size_t>(entity.index));
}

surface::BSplineCurve curve_of(const Sketch& sketch, EntityId entity) {
  if (entity.index < 0 || entity.index >= static_cast<int>(sketch.entities.size()))
    fail(ErrorCategory::InvalidArgument, "curve_of: entity #" + std::to_string(entity.index) +
                                             " does not exist (the sketch has " +
                                             std::to_string(sketch.entities.size()) + " entities)");
  const Entity& e = sketch.entities[static_cast<size_t>(entity.index)];
  if (const Line* line = std::get_if<Line>(&e)) {
    surface::Points3 p(2, 3);
    p.row(0) = position(sketch, line->start).transpose();
    p.row(1) = position(sketch, line->end).transpose();
    return surface::make_curve(1, {0, 0, 1, 1}, p);
  }
  if (const Curve* c = std::get_if<Curve>(&e)) {
    surface::Points3 p(static_cast<Eigen::Index>(c->control_points.size()), 3);
    for (size_t i = 0; i < c->control_points.size(); ++i)
      p.row(static_cast<Eigen::Index>(i)) = position(sketch, c->control_points[i]).transpose();
    return surface::make_curve(c->degree, c->knots, p, c->weights);
  }
  if (const Circle* c = std::get_if<Circle>(&e)) {
    const SketchPlane& pl = sketch.planes[static_cast<size_t>(c->plane.index)];
    return surface::circular_arc(position(sketch, c->center), pl.x_axis, pl.y_axis, c->radius, 0,
                                 2 * std::numbers::pi);
  }
  const Arc& a = std::get<Arc>(e);
  const SketchPlane& pl = sketch.planes[static_cast<size_t>(a.plane.index)];
  const Eigen::Vector2d c = to_plane(pl, position(sketch, a.center));
  const Eigen::Vector2d s = to_plane(pl, position(sketch, a.start)) - c;
  const Eigen::Vector2d t = to_plane(pl, position(sketch, a.end)) - c;
  const double start = std::atan2(s.y(), s.x());
  double end = std::atan2(t.y(), t.x());
  while (end <= start) end += 2 * std::numbers::pi;
  return surface::circular_arc(position(sketch, a.center), pl.x_axis, pl.y_axis, s.norm(), start,
                               end);
}

std::vector<std::string> problems(const Sketch& sketch) {
  std::vector<std::string> out;
  const double size = model_size(sketch);
  const int np = static_cast<int>(sketch.points.size());
  const int nplanes = static_cast<int>(sketch.planes.size());
  auto bad_point = [&](PointId p) { return p.index < 0 || p.index >= np; };
  for (int k = 0; k < nplanes; ++k) {
    try {
      validate(sketch.planes[static_cast<size_t>(k)], "plane #" + std::to_string(k));
    } catch (const Error& e) {
      out.push_back(e.message());
    }
  }
  for (int i = 0; i < np; ++i) {
    const SketchPoint& p = sketch.points[static_cast<size_t>(i)];
    if (!finite(p.position)) out.push_back(point_name(sketch, i) + " has a non-finite coordinate");
    if (p.plane.index >= nplanes)
      out.push_back(point_name(sketch, i) + " refers to plane #" + std::to_string(p.plane.index) +
                    ", which does not exist");
    else if (!p.plane.free()) {
      const double d =
          std::abs(signed_distance(sketch.planes[static_cast<size_t>(p.plane.index)], p.position));
      if (d > 1e-9 * size)
        out.push_back(point_name(sketch, i) + " is " + num(d) + " mm off its plane #" +
                      std::to_string(p.plane.index));
    }
  }
  for (size_t k = 0; k < sketch.entities.size(); ++k) {
    const std::string who = entity_name(sketch, k);
    const Entity& e = sketch.entities[k];
    auto pos = [&](PointId p) { return sketch.points[static_cast<size_t>(p.index)].position; };
    if (const Line* l = std::get_if<Line>(&e)) {
      if (bad_point(l->start) || bad_point(l->end)) {
        out.push_back(who + " refers to a missing point");
        continue;
      }
      if (!((pos(l->end) - pos(l->start)).norm() > 1e-12 * size))
        out.push_back(who + " has zero length");
    } else if (const Circle* c = std::get_if<Circle>(&e)) {
      if (bad_point(c->center)) out.push_back(who + " refers to a missing center point");
      if (c->plane.index < 0 || c->plane.index >= nplanes)
        out.push_back(who + " has no valid plane");
      if (!(c->radius > 0) || !std::isfinite(c->radius))
        out.push_back(who + " has radius " + num(c->radius) + " (must be positive)");
    } else if (const Arc* a = std::get_if<Arc>(&e)) {
      if (bad_point(a->center) || bad_point(a->start) || bad_point(a->end)) {
        out.push_back(who + " refers to a missing point");
        continue;
      }
      if (a->plane.index < 0 || a->plane.index >= nplanes)
        out.push_back(who + " has no valid plane");
      const double r0 = (pos(a->start) - pos(a->center)).norm();
      const double r1 = (pos(a->end) - pos(a->center)).norm();
      if (!(r0 > 1e-12 * size))
        out.push_back(who + " has zero radius");
      else if (std::abs(r1 - r0) > 1e-9 * size)
        out.push_back(who + " has unequal radii " + distinct_numbers(r0, r1) + " mm");
    } else {
      const Curve& curve = std::get<Curve>(e);
      bool dangling = false;
      for (PointId p : curve.control_points) dangling = dangling || bad_point(p);
      if (dangling) {
        out.push_back(who + " refers to a missing control point");
        continue;
      }
      try {
        (void)curve_of(sketch, {static_cast<int>(k)});
      } catch (const Error& err) {
        out.push_back(who + ": " + err.message());
      }
    }
  }
  return out;
}

void validate(const Sketch& sketch) {
  const std::vector<std::string> list = problems(sketch);
  if (list.empty()) return;
  fail(ErrorCategory::InvalidGeometry, "sketch is invalid: " + internal::join_problems(list));
}

}  // namespace clay::sketch
