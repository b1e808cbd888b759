#include <catch2/catch.hpp>

#include <clay/sketch/entities.hpp>
#include <clay/surface/evaluate.hpp>

#include <cmath>
#include <numbers>

#include "error_of.hpp"

using namespace clay::sketch;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using clay::ErrorCategory;
using clay::test::error_of;

TEST_CASE("entities read back as exact B-spline curves", "[sketch]") {
  Sketch s;
  const PlaneId plane = s.add_plane(make_plane({0, 0, 1}, {0, 0, 1}));
  const PointId c = s.add_point(plane, {1, 1}), a = s.add_point(plane, {4, 1}),
                b = s.add_point(plane, {1, 4});
  const EntityId line = s.add_line(a, b);
  const EntityId arc = s.add_arc(c, a, b, plane);
  const EntityId circle = s.add_circle(c, 2, plane);
  clay::surface::Points3 cp(4, 3);
  cp << 0, 0, 0, 1, 2, 0, 3, 2, 1, 4, 0, 2;
  const EntityId curve = s.add_curve(clay::surface::make_curve(3, {0, 0, 0, 0, 2, 2, 2, 2}, cp));
  CHECK(describe(s, line) == "line #0");
  CHECK(describe(s, arc) == "arc #1");
  CHECK(describe(s, circle) == "circle #2");
  CHECK(describe(s, curve) == "curve #3");
  CHECK(s.points.size() == 7);  // the curve's four control points are sketch points
  CHECK(problems(s).empty());

  const auto l = curve_of(s, line);
  CHECK((clay::surface::evaluate(l, 0.5) - (position(s, a) + position(s, b)) / 2).norm() < 1e-15);
  const auto arc_curve = curve_of(s, arc);
  const Eigen::Vector3d center = position(s, c);
  for (double t : {0.0, 0.3, 0.7, 1.0}) {
    const Eigen::Vector3d p = clay::surface::evaluate(arc_curve, t);
    CHECK_THAT((p - center).norm(), WithinAbs(3, 1e-14));
    CHECK_THAT(p.z(), WithinAbs(1, 1e-15));
    CHECK(p.x() >= center.x() - 1e-12);  // the quarter from a counterclockwise to b
    CHECK(p.y() >= center.y() - 1e-12);
  }
  CHECK((clay::surface::evaluate(arc_curve, 1.0) - position(s, b)).norm() < 1e-14);
  const auto full = curve_of(s, circle);
  CHECK_THAT((clay::surface::evaluate(full, 0.4) - center).norm(), WithinAbs(2, 1e-14));
  const auto spline = curve_of(s, curve);
  CHECK((clay::surface::evaluate(spline, 2.0) - Eigen::Vector3d(4, 0, 2)).norm() == 0);
}

TEST_CASE("degenerate or dangling entities raise clay::Error naming them", "[sketch]") {
  Sketch s;
  const PlaneId plane = s.add_plane({});
  const PointId a = s.add_point(plane, {0, 0}), b = s.add_point(plane, {0, 0}),
                c = s.add_point(plane, {1, 0});
  const PointId free_point = s.add_point({0, 0, 1});
  auto message_of = [](const std::function<void()>& f) { return error_of(f).second; };
  CHECK_THAT(message_of([&] { s.add_line(a, b); }), Contains("zero length"));
  CHECK_THAT(message_of([&] { s.add_line(a, a); }), Contains("zero length"));
  CHECK_THAT(message_of([&] { s.add_line(a, PointId{42}); }), Contains("point #42 does not exist"));
  CHECK_THAT(message_of([&] { s.add_circle(a, 0, plane); }), Contains("radius 0 must be positive"));
  CHECK_THAT(message_of([&] { s.add_circle(free_point, 1, plane); }),
             Contains("is not a point of plane #0"));
  CHECK_THAT(message_of([&] { s.add_circle(a, 1, PlaneId{}); }),
             Contains("circles and arcs need a plane"));
  const PointId far = s.add_point(plane, {0, 2});
  CHECK_THAT(message_of([&] { s.add_arc(a, c, far, plane); }),
             Contains("different distances from the center"));
  CHECK_THAT(message_of([&] { s.add_arc(a, c, c, plane); }), Contains("start and end coincide"));
  CHECK_THAT(message_of([&] { s.add_point({NAN, 0, 0}); }), Contains("non-finite"));
  CHECK_THAT(message_of([&] {
               s.add_point(PlaneId{3}, {0, 0});
             }),
             Contains("plane #3 does not exist"));
  clay::surface::Points3 cp(3, 3);
  cp << 0, 0, 0, 1, 1, 0, 2, 0, 0;
  const auto unclamped = clay::surface::make_curve(2, {0, 1, 2, 3, 4, 5}, cp);
  CHECK_THAT(message_of([&] { s.add_curve(unclamped); }), Contains("not clamped"));
  clay::surface::Points3 lifted = cp;
  lifted(1, 2) = 0.5;
  CHECK_THAT(message_of([&] {
               s.add_curve(clay::surface::make_curve(2, {0, 0, 0, 1, 1, 1}, lifted), plane);
             }),
             Contains("control point 1 is 0.5 mm off plane #0"));
  clay::surface::Points3 point_like = clay::surface::Points3::Zero(3, 3);
  CHECK_THAT(message_of([&] {
               s.add_curve(clay::surface::make_curve(2, {0, 0, 0, 1, 1, 1}, point_like));
             }),
             Contains("zero length"));

  // A sketch edited by hand is checked as a whole.
  Sketch edited = s;
  edited.entities.push_back(Line{a, PointId{99}});
  edited.points[0].position.z() = 0.25;  // off its plane
  const std::vector<std::string> list = problems(edited);
  REQUIRE(list.size() == 2);
  CHECK_THAT(list[0], Contains("point #0 is 0.25 mm off its plane #0"));
  CHECK_THAT(list[1], Contains("line #0 refers to a missing point"));
  CHECK_THAT(message_of([&] { validate(edited); }), Contains("sketch is invalid"));
  CHECK_THAT(message_of([&] { (void)curve_of(s, EntityId{5}); }),
             Contains("entity #5 does not exist"));
  CHECK_THAT(message_of([&] { (void)position(s, PointId{-1}); }),
             Contains("point #-1 does not exist"));
}
