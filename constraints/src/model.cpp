// The constraint system as scalar unknowns and equations (see equations.hpp).
#include "equations.hpp"

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cstdio>

namespace clay::constraints::detail {
namespace {

using sketch::Arc;
using sketch::Circle;
using sketch::Curve;
using sketch::Line;

std::string num(double x) { return internal::with_digits(x, 6); }

/// Builds the equations of one constraint; knows the sketch, the model and the constraint index.
class Builder {
 public:
  Builder(const sketch::Sketch& s, Model& m) : s_(s), m_(m) {}

  void add(const Lowered& c, int k) {
    k_ = k;
    c_ = &c;
    const std::string who = name();
    if (!std::isfinite(c.value) || !internal::all_finite(c.direction))
      fail(who + ": its value is not finite; give a finite number");
    switch (c.kind) {
      case ConstraintKind::Fixed: {
        need(1, 0, 0);
        const PointRef& p = var(point(0));
        for (int i = 0; i < p.dim; ++i) {
          Equation eq = make(EqKind::FixScalar);
          eq.scalars = {p.offset + i};
          eq.data = {m_.scalars[static_cast<size_t>(p.offset + i)].value};
          eq.substitutable = true;
          push(std::move(eq));
        }
        return;
      }
      case ConstraintKind::Coincident:
        need(2, 0, 0);
        if (point(0) == point(1))
          fail(who + ": a point cannot be coincident with itself; name two points");
        coincide(point(0), point(1));
        return;
      case ConstraintKind::PointOnCurve:
        need(1, 1, 0);
        point_on(point(0), entity(0));
        return;
      case ConstraintKind::Horizontal:
      case ConstraintKind::Vertical: {
        need(0, 1, 0);
        const Line& l = line(0);
        planar({l.start, l.end});
        const int axis = c.kind == ConstraintKind::Horizontal ? 1 : 0;
        Equation eq = make(EqKind::EqualScalar);
        eq.scalars = {var(l.start).offset + axis, var(l.end).offset + axis};
        eq.substitutable = true;
        push(std::move(eq));
        return;
      }
      case ConstraintKind::Parallel:
      case ConstraintKind::Perpendicular:
      case ConstraintKind::Angle: {
        need(0, 2, 0);
        const Line& a = line(0);
        const Line& b = line(1);
        if (entity(0) == entity(1)) fail(who + ": give two different lines");
        Equation eq = make(c.kind == ConstraintKind::Parallel        ? EqKind::Parallel
                           : c.kind == ConstraintKind::Perpendicular ? EqKind::Perpendicular
                                                                     : EqKind::Angle);
        eq.planar = true;
        eq.plane = planar({a.start, a.end, b.start, b.end});
        for (sketch::PointId p : {a.start, a.end, b.start, b.end}) add_point(eq, p);
        if (c.kind == ConstraintKind::Angle) {
          if (!(c.value > 0 && c.value <= 180))
            fail(who + ": angle " + num(c.value) +
                 " degrees is outside (0, 180]; use parallel for 0");
          const double turn = start_cross(eq);
          eq.data = {c.value * std::numbers::pi / 180.0, turn < 0 ? -1.0 : 1.0};
        }
        push(std::move(eq));
        return;
      }
      case ConstraintKind::PointLineDistance: {
        {
          need(1, 1, 0);
          const Line& l = line(0);
          if (!(c.value >= 0)) fail(who + ": distance " + num(c.value) + " must not be negative");
          Equation eq = make(EqKind::PointLine);
          eq.planar = true;
          eq.plane = planar({point(0), l.start, l.end});
          for (sketch::PointId p : {point(0), l.start, l.end}) add_point(eq, p);
          const double side = start_cross_point_line(eq);
          eq.data = {side < 0 ? -c.value : c.value};
          push(std::move(eq));
          return;
        }
      }
      case ConstraintKind::Distance: {
        need(2, 0, 0);
        if (!(c.value > 0))
          fail(who + ": distance " + num(c.value) + " must be positive; use coincident for 0");
        if (point(0) == point(1)) fail(who + ": give two different points");
        Equation eq = make(EqKind::Distance);
        frame(eq, {point(0), point(1)});
        eq.data = {c.value};
        push(std::move(eq));
        return;
      }
      case ConstraintKind::Radius: {
        need(0, 1, 0);
        if (!(c.value > 0)) fail(who + ": radius " + num(c.value) + " must be positive");
        Equation eq = make(EqKind::RadiusValue);
        add_radius(eq, 0);
        eq.data.insert(eq.data.begin(), c.value);
        push(std::move(eq));
        return;
      }
      case ConstraintKind::EqualLength: {
        need(0, 2, 0);
        if (entity(0) == entity(1)) fail(who + ": give two different lines");
        const Line& a = line(0);
        const Line& b = line(1);
        Equation eq = make(EqKind::EqualLength);
        frame(eq, {a.start, a.end, b.start, b.end});
        push(std::move(eq));
        return;
      }
      case ConstraintKind::EqualRadius: {
        need(0, 2, 0);
        if (entity(0) == entity(1)) fail(who + ": give two different circles or arcs");
        Equation eq = make(EqKind::EqualRadius);
        eq.data = {0, 0, 0, 0};
        for (int which = 0; which < 2; ++which) {
          const sketch::Entity& e = ent(which);
          if (const Circle* circle = std::get_if<Circle>(&e)) {
            eq.data[static_cast<size_t>(which)] = 1;
            eq.data[static_cast<size_t>(2 + which)] = static_cast<double>(eq.scalars.size());
            eq.scalars.push_back(m_.radius_var[static_cast<size_t>(entity(which).index)]);
            (void)circle;
          } else if (const Arc* arc = std::get_if<Arc>(&e)) {
            eq.data[static_cast<size_t>(2 + which)] = static_cast<double>(eq.points.size());
            add_point(eq, arc->center);
            add_point(eq, arc->start);
          } else {
            fail(who + ": " + sketch::describe(s_, entity(which)) + " is not a circle or an arc");
          }
        }
        decide_frame(eq);
        push(std::move(eq));
        return;
      }
      case ConstraintKind::Midpoint: {
        need(1, 1, 0);
        const Line& l = line(0);
        Equation eq = make(EqKind::Midpoint);
        frame(eq, {point(0), l.start, l.end});
        eq.rows = eq.planar ? 2 : 3;
        push(std::move(eq));
        return;
      }
      case ConstraintKind::Symmetric: {
        need(2, 1, 0);
        const Line& l = line(0);
        if (point(0) == point(1)) fail(who + ": give two different points");
        Equation eq = make(EqKind::Symmetric);
        eq.planar = true;
        eq.plane = planar({point(0), point(1), l.start, l.end});
        for (sketch::PointId p : {point(0), point(1), l.start, l.end}) add_point(eq, p);
        eq.rows = 2;
        push(std::move(eq));
        return;
      }
      case ConstraintKind::Tangent:
      case ConstraintKind::Curvature:
        joint(c.kind == ConstraintKind::Curvature);
        return;
      case ConstraintKind::EndTangent:
        end_tangent();
        return;
    }
    fail(who + ": unknown constraint kind");
  }

  /// The implicit equal-radius equation of arc `index`.
  void arc_radius(const Arc& arc, int index) {
    k_ = -1;
    c_ = nullptr;
    Equation eq = make(EqKind::ArcRadius);
    eq.entity = index;
    eq.planar = true;
    eq.plane = arc.plane.index;
    for (sketch::PointId p : {arc.center, arc.start, arc.end}) add_point(eq, p);
    push(std::move(eq));
  }

 private:
  std::string name() const {
    return c_ && !c_->label.empty() ? c_->label : "constraint #" + std::to_string(k_);
  }
  [[noreturn]] void fail(const std::string& message) const {
    throw Error(ErrorCategory::InvalidArgument, message);
  }

  void need(size_t points, size_t entities, size_t ends) const {
    if (c_->points.size() != points || c_->entities.size() != entities || c_->ends.size() != ends)
      fail(name() + ": needs " + std::to_string(points) + " points, " + std::to_string(entities) +
           " entities and " + std::to_string(ends) + " curve ends, got " +
           std::to_string(c_->points.size()) + ", " + std::to_string(c_->entities.size()) +
           " and " + std::to_string(c_->ends.size()) + "; make it with the factory functions");
    for (size_t i = 0; i < points; ++i) {
      const int p = c_->points[i].index;
      if (p < 0 || p >= static_cast<int>(s_.points.size()))
        fail(name() + ": refers to point #" + std::to_string(p) +
             ", which does not exist (the sketch has " + std::to_string(s_.points.size()) +
             " points)");
    }
    for (size_t i = 0; i < entities; ++i) check_entity(c_->entities[i]);
  }
  void check_entity(sketch::EntityId e) const {
    if (e.index < 0 || e.index >= static_cast<int>(s_.entities.size()))
      fail(name() + ": refers to entity #" + std::to_string(e.index) +
           ", which does not exist (the sketch has " + std::to_string(s_.entities.size()) +
           " entities)");
  }

  sketch::PointId point(size_t i) const { return c_->points[i]; }
  sketch::EntityId entity(int i) const { return c_->entities[static_cast<size_t>(i)]; }
  const sketch::Entity& ent(int i) const {
    return s_.entities[static_cast<size_t>(entity(i).index)];
  }
  const Line& line(int i) const {
    const Line* l = std::get_if<Line>(&ent(i));
    if (!l) fail(name() + ": " + sketch::describe(s_, entity(i)) + " is not a line");
    return *l;
  }
  const PointRef& var(sketch::PointId p) const {
    return m_.point_vars[static_cast<size_t>(p.index)];
  }

  Equation make(EqKind kind) const {
    Equation eq;
    eq.kind = kind;
    eq.constraint = k_;
    return eq;
  }
  void push(Equation eq) { m_.equations.push_back(std::move(eq)); }

  /// The common plane of the points; a planar constraint on points not in one plane is an error.
  int planar(std::initializer_list<sketch::PointId> points) const {
    int plane = -2;
    for (sketch::PointId p : points) {
      const int pl = var(p).plane;
      if (pl < 0 || (plane != -2 && pl != plane))
        fail(name() + ": needs its points in one sketch plane, but " + sketch::describe(s_, p) +
             (pl < 0 ? " is a free 3D point" : " lies in plane #" + std::to_string(pl)) +
             "; create the geometry in one plane");
      plane = pl;
    }
    return plane;
  }

  void add_point(Equation& eq, sketch::PointId p) const {
    const PointRef& v = var(p);
    PointRef r{static_cast<int>(eq.scalars.size()), v.dim, v.plane};
    for (int i = 0; i < v.dim; ++i) eq.scalars.push_back(v.offset + i);
    eq.points.push_back(r);
  }

  /// Planar frame when every point of the equation lies in one plane, else world.
  void decide_frame(Equation& eq) const {
    int plane = -2;
    bool one = !eq.points.empty();
    for (const PointRef& r : eq.points) {
      if (r.plane < 0 || (plane != -2 && r.plane != plane)) one = false;
      plane = r.plane;
    }
    eq.planar = one;
    eq.plane = one ? plane : -1;
  }
  void frame(Equation& eq, std::initializer_list<sketch::PointId> points) const {
    for (sketch::PointId p : points) add_point(eq, p);
    decide_frame(eq);
  }

  int add_extra(Equation& eq, double value, double lower = -INFINITY, double upper = INFINITY) {
    const int scalar = static_cast<int>(m_.scalars.size());
    m_.scalars.push_back({value, lower, upper});
    eq.scalars.push_back(scalar);
    return static_cast<int>(eq.scalars.size()) - 1;
  }

  /// Slot values of an equation at the start.
  std::vector<double> start_values(const Equation& eq) const {
    std::vector<double> v;
    for (int s : eq.scalars) v.push_back(m_.scalars[static_cast<size_t>(s)].value);
    return v;
  }
  double start_cross(const Equation& eq) const {
    const std::vector<double> v = start_values(eq);
    const V3<double> d1 = point_at(m_, eq, v.data(), 1) - point_at(m_, eq, v.data(), 0);
    const V3<double> d2 = point_at(m_, eq, v.data(), 3) - point_at(m_, eq, v.data(), 2);
    return cross_z<double>(d1, d2);
  }
  double start_cross_point_line(const Equation& eq) const {
    const std::vector<double> v = start_values(eq);
    const V3<double> p = point_at(m_, eq, v.data(), 0), a = point_at(m_, eq, v.data(), 1),
                     b = point_at(m_, eq, v.data(), 2);
    return cross_z<double>(b - a, p - a);
  }

  void coincide(sketch::PointId a, sketch::PointId b) {
    const PointRef& va = var(a);
    const PointRef& vb = var(b);
    if (va.dim == vb.dim && va.plane == vb.plane) {
      for (int i = 0; i < va.dim; ++i) {
        Equation eq = make(EqKind::EqualScalar);
        eq.scalars = {va.offset + i, vb.offset + i};
        eq.substitutable = true;
        push(std::move(eq));
      }
      return;
    }
    Equation eq = make(EqKind::PointsEqual);
    frame(eq, {a, b});
    eq.rows = 3;
    push(std::move(eq));
  }

  void add_radius(Equation& eq, int which) {
    const sketch::Entity& e = ent(which);
    if (std::get_if<Circle>(&e)) {
      eq.scalars.push_back(m_.radius_var[static_cast<size_t>(entity(which).index)]);
      eq.data = {1};
    } else if (const Arc* arc = std::get_if<Arc>(&e)) {
      add_point(eq, arc->center);
      add_point(eq, arc->start);
      eq.planar = true;
      eq.plane = arc->plane.index;
      eq.data = {0};
    } else {
      fail(name() + ": " + sketch::describe(s_, entity(which)) + " is not a circle or an arc");
    }
  }

  void point_on(sketch::PointId p, sketch::EntityId e) {
    const sketch::Entity& entity_value = s_.entities[static_cast<size_t>(e.index)];
    const Eigen::Vector3d start = s_.points[static_cast<size_t>(p.index)].position;
    if (const Line* l = std::get_if<Line>(&entity_value)) {
      if (l->start == p || l->end == p) fail(name() + ": the point is an end of the line already");
      Equation eq = make(EqKind::PointOnLine);
      frame(eq, {p, l->start, l->end});
      const Eigen::Vector3d a = position(l->start), d = position(l->end) - a;
      eq.extra = add_extra(eq, (start - a).dot(d) / d.squaredNorm());
      eq.rows = eq.planar ? 2 : 3;
      push(std::move(eq));
    } else if (const Circle* c = std::get_if<Circle>(&entity_value)) {
      Equation eq = make(EqKind::PointOnCircle);
      frame(eq, {p, c->center});
      eq.scalars.push_back(m_.radius_var[static_cast<size_t>(e.index)]);
      eq.extra = static_cast<int>(eq.scalars.size()) - 1;
      eq.data = {c->radius};
      eq.rows = eq.planar ? 1 : 2;
      if (!eq.planar) eq.plane = c->plane.index;
      push(std::move(eq));
    } else if (const Arc* a = std::get_if<Arc>(&entity_value)) {
      Equation eq = make(EqKind::PointOnArc);
      frame(eq, {p, a->center, a->start});
      eq.data = {(position(a->start) - position(a->center)).norm()};
      eq.rows = eq.planar ? 1 : 2;
      if (!eq.planar) eq.plane = a->plane.index;
      push(std::move(eq));
    } else {
      const Curve& spline = std::get<Curve>(entity_value);
      if (spline.degree > 30)
        fail(name() + ": curve degree " + std::to_string(spline.degree) + " is above 30");
      for (sketch::PointId q : spline.control_points)
        if (q == p) fail(name() + ": the point is a control point of the curve already");
      Equation eq = make(EqKind::PointOnCurve);
      add_point(eq, p);
      for (sketch::PointId q : spline.control_points) add_point(eq, q);
      decide_frame(eq);
      eq.rows = eq.planar ? 2 : 3;
      eq.data = {static_cast<double>(spline.degree), static_cast<double>(spline.knots.size())};
      eq.data.insert(eq.data.end(), spline.knots.begin(), spline.knots.end());
      for (Eigen::Index i = 0; i < spline.weights.size(); ++i) eq.data.push_back(spline.weights[i]);
      // Start parameter: the nearest of a fine sample (Ceres refines it as an unknown).
      const surface::BSplineCurve curve = sketch::curve_of(s_, e);
      const std::vector<double> ts = surface::span_samples(curve.basis, 32);
      double best = ts.front(), nearest = INFINITY;
      for (double t : ts) {
        const double d = (surface::evaluate(curve, t) - start).squaredNorm();
        if (d < nearest) nearest = d, best = t;
      }
      const auto [lo, hi] = curve.basis.domain();
      eq.extra = add_extra(eq, best, lo, hi);
      push(std::move(eq));
    }
  }

  Eigen::Vector3d position(sketch::PointId p) const {
    return s_.points[static_cast<size_t>(p.index)].position;
  }

  /// End point and end specification of a curve end (line, arc or B-spline curve).
  sketch::PointId end_point(const CurveEnd& end) const {
    const sketch::Entity& e = s_.entities[static_cast<size_t>(end.curve.index)];
    if (const Line* l = std::get_if<Line>(&e)) return end.at_start ? l->start : l->end;
    if (const Arc* a = std::get_if<Arc>(&e)) return end.at_start ? a->start : a->end;
    if (const Curve* c = std::get_if<Curve>(&e))
      return end.at_start ? c->control_points.front() : c->control_points.back();
    fail(name() + ": " + sketch::describe(s_, end.curve) +
         " has no ends (a full circle); use an arc");
  }

  EndSpec end_spec(Equation& eq, const CurveEnd& end) const {
    const sketch::Entity& e = s_.entities[static_cast<size_t>(end.curve.index)];
    EndSpec spec;
    spec.at_start = end.at_start;
    auto add = [&](sketch::PointId p) {
      spec.points.push_back(static_cast<int>(eq.points.size()));
      add_point(eq, p);
    };
    if (const Line* l = std::get_if<Line>(&e)) {
      add(l->start);
      add(l->end);
      spec.n0 = end.at_start ? std::vector<double>{1, 0} : std::vector<double>{0, 1};
      spec.n1 = {-1, 1};
      spec.n2 = {0, 0};
      spec.w = {1, 1};
    } else if (const Arc* a = std::get_if<Arc>(&e)) {
      spec.arc = true;
      add(a->center);
      add(end.at_start ? a->start : a->end);
    } else {
      const Curve& c = std::get<Curve>(e);
      const surface::BSplineBasis basis{c.degree, c.knots};
      const auto [lo, hi] = basis.domain();
      const double t = end.at_start ? lo : hi;
      const int span = surface::find_span(basis, t);
      const int p = c.degree;
      std::vector<double> ders(static_cast<size_t>(3 * (p + 1)));
      surface::basis_derivatives(basis, span, t, std::min(2, p), ders);
      if (p < 2) std::fill(ders.begin() + 2 * (p + 1), ders.end(), 0.0);
      for (int i = 0; i <= p; ++i) {
        const int idx = span - p + i;
        add(c.control_points[static_cast<size_t>(idx)]);
        spec.n0.push_back(ders[static_cast<size_t>(i)]);
        spec.n1.push_back(ders[static_cast<size_t>(p + 1 + i)]);
        spec.n2.push_back(ders[static_cast<size_t>(2 * (p + 1) + i)]);
        spec.w.push_back(c.weights[idx]);
      }
    }
    return spec;
  }

  void check_end(const CurveEnd& end) const {
    check_entity(end.curve);
    (void)end_point(end);
  }

  void joint(bool curvature) {
    need(0, 0, 2);
    const CurveEnd a = c_->ends[0], b = c_->ends[1];
    check_end(a);
    check_end(b);
    if (a.curve == b.curve && a.at_start == b.at_start)
      fail(name() + ": give two different curve ends");
    const sketch::PointId pa = end_point(a), pb = end_point(b);
    if (!(pa == pb)) coincide(pa, pb);
    Equation eq = make(EqKind::Joint);
    eq.ends.push_back(end_spec(eq, a));
    eq.ends.push_back(end_spec(eq, b));
    decide_frame(eq);
    const int dim = eq.planar ? 2 : 3;
    eq.rows = curvature ? 2 * dim : dim;
    const std::vector<double> v = start_values(eq);
    V3<double> ca, a1, a2, cb, b1, b2;
    end_derivatives(m_, eq, eq.ends[0], v.data(), ca, a1, a2);
    end_derivatives(m_, eq, eq.ends[1], v.data(), cb, b1, b2);
    const V3<double> out_a = a.at_start ? V3<double>(-a1) : a1;
    const double alpha = out_a.norm() > 0 ? b1.norm() / out_a.norm() : 1.0;
    eq.extra = add_extra(eq, alpha > 0 ? alpha : 1.0);
    if (curvature) {
      const double beta =
          out_a.squaredNorm() > 0 ? (b2 - a2 * alpha * alpha).dot(out_a) / out_a.squaredNorm() : 0;
      add_extra(eq, beta);
    }
    push(std::move(eq));
  }

  void end_tangent() {
    need(0, 0, 1);
    const CurveEnd end = c_->ends[0];
    check_end(end);
    const double length = c_->direction.norm();
    if (!(length > 0))
      fail(name() + ": the tangent direction is the zero vector; give a direction");
    Equation eq = make(EqKind::EndTangent);
    eq.ends.push_back(end_spec(eq, end));
    decide_frame(eq);
    Eigen::Vector3d dir = c_->direction / length;
    if (eq.planar) {
      const sketch::SketchPlane& pl = m_.planes[static_cast<size_t>(eq.plane)];
      if (std::abs(dir.dot(pl.normal())) > 1e-9)
        fail(name() + ": the direction leaves plane #" + std::to_string(eq.plane) +
             " of the curve; give a direction in the plane");
      dir = Eigen::Vector3d(dir.dot(pl.x_axis), dir.dot(pl.y_axis), 0);
    }
    eq.data = {dir.x(), dir.y(), dir.z()};
    eq.rows = eq.planar ? 2 : 3;
    const std::vector<double> v = start_values(eq);
    V3<double> c, d1, d2;
    end_derivatives(m_, eq, eq.ends[0], v.data(), c, d1, d2);
    const double alpha = d1.dot(dir);
    eq.extra = add_extra(eq, alpha > 0 ? alpha : std::max(d1.norm(), 1e-3));
    push(std::move(eq));
  }

  const sketch::Sketch& s_;
  Model& m_;
  int k_ = -1;
  const Lowered* c_ = nullptr;
};

}  // namespace

Model build_model(const sketch::Sketch& sketch, const std::vector<Constraint>& constraints) {
  sketch::validate(sketch);
  Model m;
  m.planes = sketch.planes;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const sketch::SketchPoint& p : sketch.points) {
    lo = lo.cwiseMin(p.position);
    hi = hi.cwiseMax(p.position);
    PointRef r;
    r.offset = static_cast<int>(m.scalars.size());
    r.plane = p.plane.index;
    if (p.plane.free()) {
      r.dim = 3;
      for (int i = 0; i < 3; ++i) m.scalars.push_back({p.position[i]});
    } else {
      r.dim = 2;
      const Eigen::Vector2d ab =
          sketch::to_plane(sketch.planes[static_cast<size_t>(p.plane.index)], p.position);
      m.scalars.push_back({ab.x()});
      m.scalars.push_back({ab.y()});
    }
    m.point_vars.push_back(r);
  }
  m.size = sketch.points.empty() ? 1.0 : std::max(1.0, (hi - lo).norm());
  m.radius_var.assign(sketch.entities.size(), -1);
  for (size_t k = 0; k < sketch.entities.size(); ++k)
    if (const Circle* c = std::get_if<Circle>(&sketch.entities[k])) {
      m.radius_var[k] = static_cast<int>(m.scalars.size());
      m.scalars.push_back({c->radius});
    }
  Builder builder(sketch, m);
  for (size_t k = 0; k < sketch.entities.size(); ++k)
    if (const Arc* a = std::get_if<Arc>(&sketch.entities[k]))
      builder.arc_radius(*a, static_cast<int>(k));
  for (size_t k = 0; k < constraints.size(); ++k) {
    const Lowered flat = lower(constraints[k]);
    builder.add(flat, static_cast<int>(k));
  }
  return m;
}

double orientation(const Model& m, const Equation& eq, const double* values) {
  std::vector<double> v;
  for (int s : eq.scalars) v.push_back(values[s]);
  switch (eq.kind) {
    case EqKind::Angle:
    case EqKind::Parallel:
    case EqKind::Perpendicular: {
      const V3<double> d1 = point_at(m, eq, v.data(), 1) - point_at(m, eq, v.data(), 0);
      const V3<double> d2 = point_at(m, eq, v.data(), 3) - point_at(m, eq, v.data(), 2);
      const double x = eq.kind == EqKind::Parallel ? d1.dot(d2) : cross_z<double>(d1, d2);
      return x < 0 ? -1 : 1;
    }
    case EqKind::PointLine: {
      if (eq.data[0] == 0) return 0;  // on the line: no side to keep
      const V3<double> p = point_at(m, eq, v.data(), 0), a = point_at(m, eq, v.data(), 1),
                       b = point_at(m, eq, v.data(), 2);
      return cross_z<double>(b - a, p - a) < 0 ? -1 : 1;
    }
    case EqKind::Joint:
    case EqKind::EndTangent:
      return v[static_cast<size_t>(eq.extra)] < 0 ? -1 : 1;
    default:
      return 0;
  }
}

}  // namespace clay::constraints::detail
