#include <catch2/catch.hpp>

#include <clay/constraints.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "error_of.hpp"

using namespace clay::constraints;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using clay::ErrorCategory;
using clay::sketch::Sketch;
using clay::test::error_of;

namespace {

constexpr double pi = std::numbers::pi;

Eigen::Vector3d at(const Sketch& s, PointId p) { return clay::sketch::position(s, p); }

double deg(double radians) { return radians * 180 / pi; }

/// Angle (degrees, counterclockwise in the xy plane) turning direction a into direction b.
double turn(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return deg(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)));
}

struct Rectangle {
  Sketch sketch;
  std::vector<PointId> corners;  // 8 points: each side owns its two ends
  std::vector<EntityId> sides;   // bottom, right, top, left (counterclockwise)
  std::vector<Constraint> constraints;
};

/// A rectangle drawn crookedly: separate end points per side, joined by coincident constraints,
/// with horizontal/vertical sides, width 40, height 25 and the first corner fixed.
Rectangle crooked_rectangle(double width = 40, double height = 25, bool fix = true) {
  Rectangle r;
  const PlaneId plane = r.sketch.add_plane({});
  const std::vector<Eigen::Vector2d> drawn = {{0.3, -0.2},  {41.0, 0.8},  {39.5, 0.4}, {40.6, 26.1},
                                              {40.2, 24.3}, {-0.7, 25.9}, {0.5, 24.6}, {-0.4, 0.6}};
  for (const Eigen::Vector2d& p : drawn) r.corners.push_back(r.sketch.add_point(plane, p));
  for (int k = 0; k < 4; ++k)
    r.sides.push_back(r.sketch.add_line(r.corners[static_cast<size_t>(2 * k)],
                                        r.corners[static_cast<size_t>(2 * k + 1)]));
  for (int k = 0; k < 4; ++k)
    r.constraints.push_back(coincident(r.corners[static_cast<size_t>(2 * k + 1)],
                                       r.corners[static_cast<size_t>((2 * k + 2) % 8)]));
  r.constraints.push_back(horizontal(r.sides[0]));
  r.constraints.push_back(vertical(r.sides[1]));
  r.constraints.push_back(horizontal(r.sides[2]));
  r.constraints.push_back(vertical(r.sides[3]));
  r.constraints.push_back(distance(r.corners[0], r.corners[1], width));
  r.constraints.push_back(distance(r.corners[2], r.corners[3], height));
  if (fix) r.constraints.push_back(fixed(r.corners[0]));
  return r;
}

}  // namespace

TEST_CASE(
    "a rectangle with horizontal, vertical and distance constraints has 0 DOF and exact sizes",
    "[constraints]") {
  const Rectangle r = crooked_rectangle();
  const SolveResult result = solve(r.sketch, r.constraints);
  const SolveReport& rep = result.report;
  INFO(rep.summary.brief());
  REQUIRE(rep.summary.converged());
  CHECK(rep.degrees_of_freedom == 0);
  CHECK_THAT(rep.brief(), Contains(rep.summary.brief()) && Contains("0 degrees of freedom"));
  CHECK(rep.redundant.empty());
  CHECK(rep.conflicting.empty());
  CHECK(rep.max_residual <= 1e-10);
  const Sketch& s = result.sketch;
  // Independent checks: corners from the solved positions.
  const Eigen::Vector3d a = at(s, r.corners[0]), b = at(s, r.corners[1]);
  const Eigen::Vector3d c = at(s, r.corners[3]), d = at(s, r.corners[5]);
  CHECK_THAT((a - Eigen::Vector3d(0.3, -0.2, 0)).norm(), WithinAbs(0, 1e-12));  // fixed
  CHECK_THAT((b - a).norm(), WithinAbs(40, 1e-10));
  CHECK_THAT((c - b).norm(), WithinAbs(25, 1e-10));
  CHECK_THAT(std::abs((b - a).y()), WithinAbs(0, 1e-12));
  CHECK_THAT(std::abs((c - b).x()), WithinAbs(0, 1e-12));
  CHECK_THAT(std::abs((d - c).y()), WithinAbs(0, 1e-12));
  for (int k = 0; k < 4; ++k)  // joints coincide exactly (substituted)
    CHECK((at(s, r.corners[static_cast<size_t>(2 * k + 1)]) -
           at(s, r.corners[static_cast<size_t>((2 * k + 2) % 8)]))
              .norm() == 0);
  CHECK(rep.substituted > 0);
  CHECK(rep.components == 1);
}

TEST_CASE("degrees of freedom count what is left to move", "[constraints]") {
  Rectangle r = crooked_rectangle(40, 25, false);  // not fixed: it can slide in x and y
  CHECK(solve(r.sketch, r.constraints).report.degrees_of_freedom == 2);
  r.constraints.pop_back();  // no height: 3
  CHECK(solve(r.sketch, r.constraints).report.degrees_of_freedom == 3);
  Sketch free_line;
  const PlaneId plane = free_line.add_plane({});
  const EntityId l =
      free_line.add_line(free_line.add_point(plane, {0, 0}), free_line.add_point(plane, {3, 1}));
  CHECK(solve(free_line, {}).report.degrees_of_freedom == 4);
  CHECK(solve(free_line, {horizontal(l)}).report.degrees_of_freedom == 3);
  Sketch space;  // free 3D points: 3 unknowns each
  const PointId p = space.add_point({0, 0, 0}), q = space.add_point({1, 2, 3});
  CHECK(solve(space, {distance(p, q, 5)}).report.degrees_of_freedom == 5);
}

TEST_CASE("a triangle whose three angles do not sum to 180 degrees is conflicting, naming them",
          "[constraints]") {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  const PointId a = s.add_point(plane, {0, 0}), b = s.add_point(plane, {10, 0}),
                c = s.add_point(plane, {4, 7});
  const EntityId ab = s.add_line(a, b), bc = s.add_line(b, c), ca = s.add_line(c, a);
  std::vector<Constraint> cs = {
      fixed(a),           distance(a, b, 10), horizontal(ab),
      angle(ab, bc, 120), angle(bc, ca, 130), angle(ca, ab, 120)};  // turns sum to 370, not 360
  const SolveResult result = solve(s, cs);
  const SolveReport& rep = result.report;
  INFO(rep.summary.brief());
  CHECK(rep.summary.termination == clay::Termination::Failed);
  REQUIRE(rep.conflicting.size() == 1);
  CHECK(rep.conflicting[0].constraints == std::vector<int>{3, 4, 5});
  CHECK_THAT(rep.conflicting[0].message, Contains("angle 120 degrees from line #0 to line #1"));
  CHECK(rep.redundant.empty());

  // The same triangle with consistent angles (exterior turns 120 + 130 + 110 = 360): solved,
  // and the third angle is named redundant.
  cs[5] = angle(ca, ab, 110);
  const SolveResult ok = solve(s, cs);
  INFO(ok.report.summary.brief());
  REQUIRE(ok.report.summary.converged());
  REQUIRE(ok.report.redundant.size() == 1);
  CHECK(ok.report.redundant[0].constraints == std::vector<int>{3, 4, 5});
  CHECK(ok.report.degrees_of_freedom == 0);
  const Sketch& t = ok.sketch;
  CHECK_THAT(turn(at(t, b) - at(t, a), at(t, c) - at(t, b)), WithinAbs(120, 1e-8));
  CHECK_THAT(turn(at(t, c) - at(t, b), at(t, a) - at(t, c)), WithinAbs(130, 1e-8));
}

TEST_CASE("a redundant dimension is named redundant, a contradicting one conflicting",
          "[constraints]") {
  Rectangle r = crooked_rectangle();
  r.constraints.push_back(distance(r.corners[4], r.corners[5], 40));  // top width again: consistent
  SolveResult result = solve(r.sketch, r.constraints);
  INFO(result.report.summary.brief());
  REQUIRE(result.report.summary.converged());
  REQUIRE(result.report.redundant.size() == 1);
  const std::vector<int>& set = result.report.redundant[0].constraints;
  CHECK(std::count(set.begin(), set.end(), 8) == 1);   // the bottom width
  CHECK(std::count(set.begin(), set.end(), 11) == 1);  // the top width
  CHECK(result.report.degrees_of_freedom == 0);

  r.constraints.back() = distance(r.corners[4], r.corners[5], 41);  // contradicts the bottom
  result = solve(r.sketch, r.constraints);
  CHECK(!result.report.summary.converged());
  REQUIRE(result.report.conflicting.size() == 1);
  const std::vector<int>& clash = result.report.conflicting[0].constraints;
  CHECK(std::count(clash.begin(), clash.end(), 8) == 1);
  CHECK(std::count(clash.begin(), clash.end(), 11) == 1);

  // Substituted equalities are diagnosed too: two fixes of one coincident pair at two places.
  Sketch s;
  const PlaneId plane = s.add_plane({});
  const PointId p = s.add_point(plane, {0, 0}), q = s.add_point(plane, {1, 0});
  const SolveResult twice = solve(s, {fixed(p), fixed(q), coincident(p, q)});
  REQUIRE(twice.report.conflicting.size() == 1);
  CHECK(twice.report.conflicting[0].constraints == std::vector<int>{0, 1, 2});
}

TEST_CASE("G1 and G2 joints between B-spline curves hold to 1e-9", "[constraints]") {
  using clay::surface::derivatives;
  Sketch s;
  clay::surface::Points3 p1(4, 3), p2(5, 3);
  p1 << 0, 0, 0, 10, 5, 2, 20, 6, -1, 30, 2, 3;
  p2 << 31, 1, 4, 38, -4, 6, 45, -2, 2, 52, 3, 0, 60, 1, 1;
  const EntityId c1 = s.add_curve(clay::surface::make_curve(3, {0, 0, 0, 0, 1, 1, 1, 1}, p1));
  const EntityId c2 = s.add_curve(clay::surface::make_curve(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1}, p2));
  const auto& cp1 = std::get<clay::sketch::Curve>(s.entities[0]).control_points;
  const auto& cp2 = std::get<clay::sketch::Curve>(s.entities[1]).control_points;
  for (int joint = 1; joint <= 2; ++joint) {
    std::vector<Constraint> cs = {fixed(cp1[0]), fixed(cp1[1]), fixed(cp2.back())};
    cs.push_back(joint == 1 ? tangent(end_of(c1), start_of(c2))
                            : curvature(end_of(c1), start_of(c2)));
    const SolveResult result = solve(s, cs);
    INFO(result.report.summary.brief());
    REQUIRE(result.report.summary.converged());
    CHECK(result.report.flipped.empty());
    const auto a = derivatives(clay::sketch::curve_of(result.sketch, c1), 1.0, 2);
    const auto b = derivatives(clay::sketch::curve_of(result.sketch, c2), 0.0, 2);
    CHECK((a.point - b.point).norm() <= 1e-12);
    const double angle_between = std::atan2(a.d1.cross(b.d1).norm(), a.d1.dot(b.d1));
    CHECK(angle_between <= 1e-9);
    if (joint == 2) {  // curvature vectors k = (C' x C'') x C' / |C'|^4
      auto kappa = [](const Eigen::Vector3d& d1, const Eigen::Vector3d& d2) -> Eigen::Vector3d {
        return d1.cross(d2).cross(d1) / std::pow(d1.norm(), 4);
      };
      const Eigen::Vector3d ka = kappa(a.d1, a.d2), kb = kappa(b.d1, b.d2);
      INFO("curvature " << ka.transpose() << " vs " << kb.transpose());
      CHECK((ka - kb).norm() <= 1e-9 * std::max(1.0, ka.norm()));
      CHECK(ka.norm() > 1e-4);  // a real curvature was matched, not zero against zero
    }
  }
}

TEST_CASE("a line tangent to an arc, an arc of given radius and a curve end along a direction",
          "[constraints]") {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  const PointId center = s.add_point(plane, {0, 0});
  const PointId a0 = s.add_point(plane, {5, 0}), a1 = s.add_point(plane, {0, 5});
  const EntityId arc = s.add_arc(center, a0, a1, plane);
  const PointId l0 = s.add_point(plane, {0.3, 5.2}), l1 = s.add_point(plane, {-10, 6});
  const EntityId line = s.add_line(l0, l1);
  const SolveResult result = solve(
      s, {fixed(center), fixed(a0), tangent(end_of(arc), start_of(line)), distance(l0, l1, 10)});
  INFO(result.report.summary.brief());
  REQUIRE(result.report.summary.converged());
  CHECK(result.report.redundant.empty());
  const Sketch& t = result.sketch;
  const Eigen::Vector3d c = at(t, center), e = at(t, a1), q = at(t, l1);
  CHECK_THAT((e - c).norm(), WithinAbs(5, 1e-10));
  CHECK_THAT(std::abs((e - c).dot(q - e)) / (q - e).norm(), WithinAbs(0, 1e-10));  // radius ⟂ line
  CHECK_THAT((q - e).norm(), WithinAbs(10, 1e-10));
  // the line leaves the arc in the arc's direction of travel (counterclockwise)
  CHECK(Eigen::Vector3d::UnitZ().cross(e - c).dot(q - e) > 0);
  CHECK(result.report.degrees_of_freedom == 1);  // the arc's end can still slide round

  Sketch sp;
  clay::surface::Points3 p(4, 3);
  p << 0, 0, 0, 3, 1, 0, 6, -1, 2, 9, 0, 1;
  const EntityId curve = sp.add_curve(clay::surface::make_curve(3, {0, 0, 0, 0, 1, 1, 1, 1}, p));
  const auto& cps = std::get<clay::sketch::Curve>(sp.entities[0]).control_points;
  const Eigen::Vector3d dir(1, 2, 2);
  const SolveResult r2 =
      solve(sp, {fixed(cps[0]), fixed(cps[2]), fixed(cps[3]), end_tangent(start_of(curve), dir)});
  REQUIRE(r2.report.summary.converged());
  const auto d = clay::surface::derivatives(clay::sketch::curve_of(r2.sketch, curve), 0.0, 1);
  CHECK(d.d1.normalized().dot(dir.normalized()) >= 1 - 1e-15);
}

TEST_CASE("each planar constraint holds in an independent measurement", "[constraints]") {
  Sketch s;
  const PlaneId plane = s.add_plane(clay::sketch::make_plane({1, 2, 3}, {0, 1, 1}));
  auto pt = [&](double x, double y) { return s.add_point(plane, {x, y}); };
  const PointId a = pt(0, 0), b = pt(10, 1), c = pt(1, 5), d = pt(9, 9), m = pt(4, 1),
                p = pt(3, -4), q = pt(6, 7), on = pt(12, 3);
  const EntityId ab = s.add_line(a, b), cd = s.add_line(c, d);
  const PointId e = pt(2, 8), f = pt(2.5, 14);
  const EntityId ef = s.add_line(e, f);
  const PointId cc = pt(20, 0);
  const EntityId circle = s.add_circle(cc, 3, plane);
  const PointId oc = pt(24, 1);
  const PointId ac = pt(-10, 0), as = pt(-5, 0), ae = pt(-10, 5);
  const EntityId arc = s.add_arc(ac, as, ae, plane);
  const std::vector<Constraint> cs = {fixed(a),
                                      fixed(b),
                                      parallel(ab, cd),
                                      distance(c, ab, 6),
                                      equal_length(ab, cd),
                                      perpendicular(ab, ef),
                                      midpoint(m, ab),
                                      symmetric(p, q, ab),
                                      point_on(on, ab),
                                      fixed(cc),
                                      radius(circle, 4),
                                      point_on(oc, circle),
                                      distance(e, c, 2),
                                      fixed(ac),
                                      radius(arc, 7)};
  const SolveResult result = solve(s, cs);
  INFO(result.report.summary.brief());
  REQUIRE(result.report.summary.converged());
  const Sketch& t = result.sketch;
  const clay::sketch::SketchPlane& pl = t.planes[0];
  auto uv = [&](PointId id) {
    const Eigen::Vector2d x = clay::sketch::to_plane(pl, at(t, id));
    return Eigen::Vector3d(x.x(), x.y(), 0);
  };
  for (size_t i = 0; i < t.points.size(); ++i)
    CHECK(std::abs(clay::sketch::signed_distance(pl, t.points[i].position)) < 1e-12);
  const Eigen::Vector3d u = uv(b) - uv(a), v = uv(d) - uv(c), w = uv(f) - uv(e);
  CHECK(std::abs(u.cross(v).z()) / (u.norm() * v.norm()) < 1e-10);
  CHECK(u.dot(v) > 0);                                                     // kept its sense
  CHECK_THAT(u.cross(uv(c) - uv(a)).z() / u.norm(), WithinAbs(6, 1e-10));  // on the side it started
  CHECK_THAT(u.norm() - v.norm(), WithinAbs(0, 1e-10));
  CHECK(std::abs(u.dot(w)) / (u.norm() * w.norm()) < 1e-10);
  CHECK((uv(m) - (uv(a) + uv(b)) / 2).norm() < 1e-10);
  const Eigen::Vector3d mid = (uv(p) + uv(q)) / 2;
  CHECK(std::abs(u.cross(mid - uv(a)).z()) / u.norm() < 1e-10);
  CHECK(std::abs(u.dot(uv(q) - uv(p))) / u.norm() < 1e-10);
  CHECK(std::abs(u.cross(uv(on) - uv(a)).z()) / u.norm() < 1e-10);
  CHECK_THAT(std::get<clay::sketch::Circle>(t.entities[3]).radius, WithinAbs(4, 1e-10));
  CHECK_THAT((at(t, oc) - at(t, cc)).norm(), WithinAbs(4, 1e-10));
  CHECK_THAT((at(t, e) - at(t, c)).norm(), WithinAbs(2, 1e-10));
  CHECK_THAT((at(t, as) - at(t, ac)).norm(), WithinAbs(7, 1e-10));
  CHECK_THAT((at(t, ae) - at(t, ac)).norm(), WithinAbs(7, 1e-10));  // the arc's implicit equation
}

TEST_CASE("drag moves the dragged point and keeps the constraints", "[constraints]") {
  const Rectangle r = crooked_rectangle(40, 25, false);
  SolveOptions options;
  options.drag = {{r.corners[0], {5, 7, 0}}};
  const SolveResult result = solve(r.sketch, r.constraints, options);
  INFO(result.report.summary.brief());
  REQUIRE(result.report.summary.converged());
  const Sketch& s = result.sketch;
  CHECK((at(s, r.corners[0]) - Eigen::Vector3d(5, 7, 0)).norm() < 1e-6);
  CHECK_THAT((at(s, r.corners[1]) - at(s, r.corners[0])).norm(), WithinAbs(40, 1e-10));
  CHECK_THAT((at(s, r.corners[3]) - at(s, r.corners[2])).norm(), WithinAbs(25, 1e-10));
  // A dragged point held by a fixed constraint stays; the rest follows as little as possible.
  const Rectangle fixed_rect = crooked_rectangle();
  const SolveResult held = solve(fixed_rect.sketch, fixed_rect.constraints, options);
  REQUIRE(held.report.summary.converged());
  CHECK((at(held.sketch, fixed_rect.corners[0]) - Eigen::Vector3d(0.3, -0.2, 0)).norm() < 1e-12);
}

TEST_CASE("a solution that turns a joint into a cusp is reported as flipped", "[constraints]") {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  const PointId a = s.add_point(plane, {0, 0}), b = s.add_point(plane, {10, 0});
  const PointId c = s.add_point(plane, {10, 0.5}), d = s.add_point(plane, {5, 1});
  const EntityId first = s.add_line(a, b), second = s.add_line(c, d);
  // The second line starts drawn back over the first: the nearest G1 solution points backwards.
  const SolveResult result =
      solve(s, {fixed(a), fixed(b), tangent(end_of(first), start_of(second)), distance(c, d, 5)});
  INFO(result.report.summary.brief());
  REQUIRE(result.report.summary.converged());                              // the equations hold ...
  CHECK((at(result.sketch, d) - Eigen::Vector3d(5, 0, 0)).norm() < 1e-9);  // ... as a cusp
  CHECK(result.report.flipped == std::vector<int>{2});
  CHECK_THAT(result.report.summary.message, Contains("orientation flipped for constraint #2"));
}

TEST_CASE("independent rectangles are separate components", "[constraints]") {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  std::vector<Constraint> cs;
  for (int k = 0; k < 5; ++k) {
    const Rectangle r = crooked_rectangle();
    const int offset = static_cast<int>(s.points.size());
    const int eoffset = static_cast<int>(s.entities.size());
    for (const auto& p : r.sketch.points)
      s.add_point(plane, {p.position.x() + 50 * k, p.position.y()});
    for (const auto& e : r.sketch.entities) {
      const auto& l = std::get<clay::sketch::Line>(e);
      s.add_line({l.start.index + offset}, {l.end.index + offset});
    }
    for (Constraint c : r.constraints) {
      if (c.kind() == ConstraintKind::Fixed) continue;
      // The rectangle's constraints, moved to its copy's points and lines (typed alternatives).
      if (auto* q = std::get_if<Coincident>(&c.requirement))
        q->a.index += offset, q->b.index += offset;
      else if (auto* h = std::get_if<Horizontal>(&c.requirement))
        h->line.index += eoffset;
      else if (auto* v = std::get_if<Vertical>(&c.requirement))
        v->line.index += eoffset;
      else if (auto* d = std::get_if<Distance>(&c.requirement))
        d->a.index += offset, d->b.index += offset;
      else
        FAIL("the rectangle uses a constraint kind this test does not move");
      cs.push_back(c);
    }
  }
  const SolveResult result = solve(s, cs);
  REQUIRE(result.report.summary.converged());
  CHECK(result.report.components == 5);
  CHECK(result.report.degrees_of_freedom == 10);
}

TEST_CASE("bad constraints raise clay::Error naming the constraint", "[constraints]") {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  const PointId a = s.add_point(plane, {0, 0}), b = s.add_point(plane, {1, 0});
  const PointId free_point = s.add_point({0, 0, 5});
  const EntityId l = s.add_line(a, b);
  const EntityId circle = s.add_circle(a, 2, plane);
  const EntityId slanted = s.add_line(b, free_point);
  auto category_and = [&](const std::vector<Constraint>& cs, const std::string& text) {
    const auto [category, message] = error_of([&] { (void)solve(s, cs); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(message, Contains(text));
  };
  category_and({fixed(a), distance(a, PointId{9}, 1)},
               "constraint #1: refers to point #9, which does not exist");
  category_and({horizontal(EntityId{7})},
               "constraint #0: refers to entity #7, which does not exist");
  category_and({horizontal(circle)}, "circle #1 is not a line");
  category_and({horizontal(slanted)}, "needs its points in one sketch plane");
  category_and({distance(a, b, 0)}, "must be positive; use coincident");
  category_and({distance(a, b, NAN)}, "not finite");
  category_and({angle(l, l, 30)}, "two different lines");
  category_and({coincident(a, a)}, "coincident with itself");
  category_and({radius(l, 3)}, "is not a circle or an arc");
  category_and({tangent(end_of(circle), start_of(l))}, "has no ends");
  category_and({end_tangent(end_of(l), Eigen::Vector3d::Zero())}, "zero vector");
  SolveOptions bad;
  bad.residual_tolerance = 0;
  const auto [category, message] = error_of([&] { (void)solve(s, {}, bad); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("SolveOptions::residual_tolerance"));
}

TEST_CASE("points on curves and arcs, equal radii, and joints across planes and 3D",
          "[constraints]") {
  Sketch s;
  const PlaneId xy = s.add_plane({});
  const PlaneId tilted = s.add_plane(clay::sketch::make_plane({0, 0, 10}, {1, 0, 1}));
  // A free 3D cubic and a point that must lie on it.
  clay::surface::Points3 cp(5, 3);
  cp << 0, 0, 0, 5, 8, 2, 12, -3, 4, 18, 6, -2, 25, 0, 1;
  const EntityId curve =
      s.add_curve(clay::surface::make_curve(3, {0, 0, 0, 0, 0.4, 1, 1, 1, 1}, cp));
  const std::vector<PointId> cps = std::get<clay::sketch::Curve>(s.entities[0]).control_points;
  const PointId near = s.add_point({11, 3, 5});
  // A circle and an arc of equal radius in the xy plane, a point on the arc's circle.
  const PointId cc = s.add_point(xy, {40, 0});
  const EntityId circle = s.add_circle(cc, 3, xy);
  const PointId ac = s.add_point(xy, {60, 0}), as = s.add_point(xy, {65, 0}),
                ae = s.add_point(xy, {60, 5});
  const EntityId arc = s.add_arc(ac, as, ae, xy);
  const PointId on_arc = s.add_point(xy, {57, -3});
  // A point of the tilted plane made coincident with a free point (a world-frame equation).
  const Eigen::Vector3d spot = clay::sketch::to_world(s.planes[1], {3, -1});
  const PointId in_plane = s.add_point(tilted, {1, 1}),
                loose = s.add_point(spot + Eigen::Vector3d(0.5, 0.2, -0.3));
  // A line of the tilted plane joined G1 to the 3D curve's end.
  const PointId l0 = s.add_point(tilted, {2, 2}), l1 = s.add_point(tilted, {8, 3});
  const EntityId line = s.add_line(l0, l1);
  std::vector<Constraint> cs = {fixed(cps[0]),
                                fixed(cps[1]),
                                fixed(cps[2]),
                                point_on(near, curve),
                                fixed(cc),
                                fixed(ac),
                                radius(circle, 4),
                                equal_radius(circle, arc),
                                point_on(on_arc, arc),
                                coincident(in_plane, loose),
                                distance(loose, l0, 3),
                                tangent(end_of(line), end_of(curve)),
                                distance(l0, l1, 6)};
  const SolveResult result = solve(s, cs);
  INFO(result.report.summary.brief());
  REQUIRE(result.report.summary.converged());
  CHECK(result.report.conflicting.empty());
  CHECK(result.report.redundant.empty());
  const Sketch& t = result.sketch;
  // The point lies on the curve: its distance to a fine sample, refined by bisection, is ~0.
  const auto c = clay::sketch::curve_of(t, curve);
  double best = INFINITY, t_best = 0;
  for (int i = 0; i <= 20000; ++i) {
    const double u = i / 20000.0;
    const double d = (clay::surface::evaluate(c, u) - at(t, near)).norm();
    if (d < best) best = d, t_best = u;
  }
  for (int iter = 0; iter < 60; ++iter) {  // golden-free refinement: ternary search near the sample
    const double h = 1.0 / 20000.0 / (1 << std::min(iter, 30));
    for (double u : {t_best - h, t_best + h}) {
      const double d = (clay::surface::evaluate(c, std::clamp(u, 0.0, 1.0)) - at(t, near)).norm();
      if (d < best) best = d, t_best = std::clamp(u, 0.0, 1.0);
    }
  }
  CHECK(best < 1e-9);
  CHECK_THAT(std::get<clay::sketch::Circle>(t.entities[1]).radius, WithinAbs(4, 1e-10));
  CHECK_THAT((at(t, as) - at(t, ac)).norm(), WithinAbs(4, 1e-10));
  CHECK_THAT((at(t, ae) - at(t, ac)).norm(), WithinAbs(4, 1e-10));
  CHECK_THAT((at(t, on_arc) - at(t, ac)).norm(), WithinAbs(4, 1e-10));
  CHECK((at(t, in_plane) - at(t, loose)).norm() < 1e-10);  // a world-frame coincidence
  CHECK_THAT((at(t, loose) - at(t, l0)).norm(), WithinAbs(3, 1e-10));
  const auto d_line = clay::surface::derivatives(clay::sketch::curve_of(t, line), 1.0, 1);
  const auto d_curve = clay::surface::derivatives(c, 1.0, 1);
  CHECK((d_line.point - d_curve.point).norm() < 1e-10);
  // line ends where the curve ends, so the G1 joint has the line arriving against the curve's
  // direction: the curve's end tangent points back along the line.
  CHECK(std::atan2(d_line.d1.cross(-d_curve.d1).norm(), d_line.d1.dot(-d_curve.d1)) < 1e-9);
  for (size_t i = 0; i < t.points.size(); ++i)
    if (!t.points[i].plane.free())
      CHECK(std::abs(clay::sketch::signed_distance(
                t.planes[static_cast<size_t>(t.points[i].plane.index)], t.points[i].position)) <
            1e-12);
}

// Issue #18: under-constrained sketches (the normal state while a stylist draws) must converge.
// Levenberg–Marquardt damped with diag(JᵀJ) let a nearly zero Jacobian column (a free end's
// coordinate) swing: a line with a fixed start and a length of 10, its end drawn at (0.02, 10.5),
// stopped after 101 iterations at residual 0.508.
namespace {

/// One line from a fixed start at the origin to `end`, with a length of 10: 1 DOF.
Sketch free_end_line(const Eigen::Vector2d& end, std::vector<Constraint>& constraints) {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  const PointId a = s.add_point(plane, {0, 0});
  const PointId b = s.add_point(plane, end);
  s.add_line(a, b);
  constraints = {fixed(a), distance(a, b, 10)};
  return s;
}

/// A horizontal/vertical staircase of n segments (own end points, coincident joints, a length
/// each, first point fixed) drawn off by up to ±1 mm, with the last `free` vertical constraints
/// removed: `free` degrees of freedom.
Sketch staircase_with_freedom(int n, int free, std::vector<Constraint>& constraints,
                              double drawn_off = 1.0) {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  Eigen::Vector2d corner(0, 0);
  std::vector<PointId> ends;
  constraints.clear();
  unsigned state = 12345;
  auto jitter = [&] {
    state = state * 1103515245u + 12345u;
    return drawn_off * (((state >> 8) % 2001) / 1000.0 - 1.0);
  };
  std::vector<int> verticals;
  for (int k = 0; k < n; ++k) {
    const double length = 10 + k % 3;
    const Eigen::Vector2d next =
        corner + (k % 2 == 0 ? Eigen::Vector2d(length, 0) : Eigen::Vector2d(0, length));
    const PointId a = s.add_point(plane, corner + Eigen::Vector2d(jitter(), jitter()));
    const PointId b = s.add_point(plane, next + Eigen::Vector2d(jitter(), jitter()));
    const EntityId line = s.add_line(a, b);
    if (k > 0)
      constraints.push_back(coincident(ends.back(), a));
    else
      constraints.push_back(fixed(a));
    ends.push_back(b);
    constraints.push_back(distance(a, b, length));
    if (k % 2 == 0)
      constraints.push_back(horizontal(line));
    else
      verticals.push_back(static_cast<int>(constraints.size())),
          constraints.push_back(vertical(line));
    corner = next;
  }
  for (int k = 0; k < free; ++k)
    constraints.erase(constraints.begin() +
                      verticals[verticals.size() - 1 - static_cast<size_t>(k)]);
  return s;
}

}  // namespace

TEST_CASE("a line with a fixed start and a length converges whatever direction its free end takes",
          "[constraints]") {
  // Every free-DOF direction around the circle, and ends a hair off vertical and horizontal, each
  // drawn 5 % too long or too short.
  std::vector<Eigen::Vector2d> ends;
  for (int k = 0; k < 72; ++k) {
    const double a = k * 5.0 * pi / 180;
    ends.push_back(10.5 * Eigen::Vector2d(std::cos(a), std::sin(a)));
    ends.push_back(9.5 * Eigen::Vector2d(std::cos(a + 1e-3), std::sin(a + 1e-3)));
  }
  for (double e : {0.02, -0.02, 1e-6, 0.0})
    for (double r : {10.5, 9.5, 30.0, 0.5}) {
      ends.push_back({e, r});
      ends.push_back({r, e});
      ends.push_back({-r, e});
      ends.push_back({e, -r});
    }
  int worst_iterations = 0;
  for (const Eigen::Vector2d& end : ends) {
    std::vector<Constraint> c;
    const Sketch s = free_end_line(end, c);
    const SolveResult r = solve(s, c);
    INFO("end drawn at (" << end.x() << ", " << end.y() << "): " << r.report.summary.brief());
    REQUIRE(r.report.summary.termination == clay::Termination::Converged);
    REQUIRE(r.report.max_residual <= 1e-10);
    // The independent measurement: the solved end is 10 from the fixed start, which stayed put.
    CHECK_THAT((at(r.sketch, PointId{1}) - at(r.sketch, PointId{0})).norm(), WithinAbs(10, 1e-10));
    CHECK(at(r.sketch, PointId{0}).norm() == 0);
    CHECK(r.report.degrees_of_freedom == 1);
    // The least change: the end moves along the line's direction (a minimum-norm step), it does
    // not swing round the circle.
    const Eigen::Vector3d drawn = clay::sketch::position(s, PointId{1});
    CHECK((at(r.sketch, PointId{1}).normalized() - drawn.normalized()).norm() < 1e-9);
    worst_iterations = std::max(worst_iterations, r.report.summary.iterations);
  }
  CHECK(worst_iterations <=
        20);  // 5 for ends drawn near the circle, 17 for one drawn 20 times too short
}

TEST_CASE(
    "staircases of up to 1,000 segments with 1 to 10 free verticals converge in few iterations",
    "[constraints]") {
  int worst_iterations = 0;
  // Drawn off by up to 1 mm, and nearly exactly (0.02 mm: the free ends then start nearly
  // vertical, where Marquardt's damping swung them).
  for (double drawn_off : {1.0, 0.02})
    for (int n : {10, 100, 1000})
      for (int free : {1, 2, 5, 10}) {
        if (free > n / 2) continue;  // only the odd segments are vertical
        std::vector<Constraint> c;
        const Sketch s = staircase_with_freedom(n, free, c, drawn_off);
        const SolveResult r = solve(s, c);
        INFO(n << " segments, " << free << " DOF: " << r.report.summary.brief());
        REQUIRE(r.report.summary.termination == clay::Termination::Converged);
        REQUIRE(r.report.max_residual <= 1e-10);
        CHECK(r.report.degrees_of_freedom == free);
        // Independent check of the chain: each segment's length, joints closed.
        for (int k = 0; k < n; ++k) {
          const Eigen::Vector3d a = at(r.sketch, PointId{2 * k}),
                                b = at(r.sketch, PointId{2 * k + 1});
          CHECK_THAT((b - a).norm(), WithinAbs(10 + k % 3, 1e-10));
          if (k > 0) CHECK((a - at(r.sketch, PointId{2 * k - 1})).norm() < 1e-10);
        }
        worst_iterations = std::max(worst_iterations, r.report.summary.iterations);
      }
  CHECK(worst_iterations <= 25);
}

TEST_CASE("SolveOptions lists every bad field", "[solve]") {
  clay::constraints::SolveOptions o;
  o.residual_tolerance = 0;
  o.max_iterations = 0;
  o.rank_tolerance = 1;
  CHECK(o.problems().size() == 3);
  CHECK_THROWS_AS(o.validate(), clay::Error);
}

TEST_CASE("a constraint is a typed requirement, the factories and the structs build the same",
          "[constraints]") {
  const PointId a{0}, b{1};
  const Constraint made = distance(a, b, 12.5);
  const Constraint typed{Distance{a, b, 12.5}, "rig.constraints[0]"};
  CHECK(made.kind() == ConstraintKind::Distance);
  CHECK(typed.kind() == ConstraintKind::Distance);
  const Distance& d = std::get<Distance>(made.requirement);
  CHECK(d.a.index == 0);
  CHECK(d.b.index == 1);
  CHECK(d.mm == 12.5);
  CHECK(constraint_name(typed, 4) == "rig.constraints[0]");
  CHECK(constraint_name(made, 4) == "constraint #4");
  // Every kind is an alternative at its enum's index.
  CHECK(static_cast<int>(
            end_tangent(clay::constraints::CurveEnd{}, Eigen::Vector3d::UnitX()).kind()) ==
        static_cast<int>(std::variant_size_v<Requirement>) - 1);
  CHECK(std::holds_alternative<Tangent>(tangent({}, {}).requirement));
}

TEST_CASE(
    "a constraint on a freehand curve's ends is spread over the curve, not dumped at its ends",
    "[constraints]") {
  // Issue #40: a distance between a fitted stroke's ends moved only its last control point (the
  // minimum-norm step), a hook of the whole change at the end. Ten control points of a wavy
  // planar cubic from (0, 0) to about (95, 0), its start fixed and its ends pulled 110 mm apart.
  Sketch s;
  const PlaneId plane = s.add_plane(clay::sketch::make_plane({0, 0, 0}, {0, 0, 1}));
  clay::surface::Points3 p(10, 3);
  for (int k = 0; k < 10; ++k) p.row(k) << 10.5 * k, 6 * std::sin(0.7 * k), 0;
  const std::vector<double> knots{0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7};
  const EntityId curve = s.add_curve(clay::surface::make_curve(3, knots, p), plane);
  const auto cps = std::get<clay::sketch::Curve>(s.entities[0]).control_points;
  const clay::surface::BSplineCurve before = clay::sketch::curve_of(s, curve);
  const double drawn = (p.row(9) - p.row(0)).norm();
  const std::vector<Constraint> cs{fixed(cps[0]), distance(cps[0], cps[9], 110.0)};
  auto measure = [&](const SolveResult& r) {
    REQUIRE(r.report.summary.converged());
    const clay::surface::BSplineCurve after = clay::sketch::curve_of(r.sketch, curve);
    CHECK_THAT((r.sketch.points[static_cast<std::size_t>(cps[9].index)].position -
                r.sketch.points[static_cast<std::size_t>(cps[0].index)].position)
                   .norm(),
               WithinAbs(110, 1e-9));
    double deviation = 0;
    for (int k = 0; k <= 700; ++k) {
      const double t = 7.0 * k / 700;
      deviation =
          std::max(deviation,
                   (clay::surface::evaluate(after, t) - clay::surface::evaluate(before, t)).norm());
    }
    // The hook: how much the curve's second derivative changes, at its worst (its bending).
    double bending = 0;
    for (int k = 0; k <= 700; ++k) {
      const double t = 7.0 * k / 700;
      bending = std::max(bending, (clay::surface::derivatives(after, t, 2).d2 -
                                   clay::surface::derivatives(before, t, 2).d2)
                                      .norm());
    }
    return std::pair{deviation, bending};
  };
  SolveOptions ends_only;
  ends_only.spread_curve_changes = false;
  const auto [hook_deviation, hook_bending] = measure(solve(s, cs, ends_only));
  const SolveResult spread = solve(s, cs);
  const auto [deviation, bending] = measure(spread);
  const double change = 110 - drawn;  // how far the constraint moves the end
  // Neither leaves the end's own change (the convex hull property); spread, the second
  // derivative changes a tenth as much (the change is shared by ten control points, in
  // proportion, a stretch), and the middle control point moves by 5/9 of the end's change.
  CHECK(hook_deviation <= change + 1e-9);
  CHECK(deviation <= change + 1e-9);
  INFO("largest change of C'': " << hook_bending << " with the end alone, " << bending
                                 << " spread");
  CHECK(bending < hook_bending / 5);
  const Eigen::Vector3d middle =
      spread.sketch.points[static_cast<std::size_t>(cps[5].index)].position;
  CHECK_THAT((middle - Eigen::Vector3d(p.row(5))).norm(), WithinAbs(change * 5 / 9, 0.01 * change));
}
