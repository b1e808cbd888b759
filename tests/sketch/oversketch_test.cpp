#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/sketch/oversketch.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

#include "error_of.hpp"
#include "sketch/sketch_geometry.hpp"

using namespace clay::sketch;
using Catch::Matchers::Contains;
using clay::surface::BSplineCurve;
using clay::surface::Points3;

namespace {

/// A nonplanar clamped cubic, about 170 mm long, 9 control points.
BSplineCurve old_curve() {
  Points3 p(9, 3);
  p << 0, 0, 0,     //
      20, 15, 5,    //
      40, 25, 10,   //
      60, 20, 15,   //
      80, 5, 10,    //
      100, -5, 5,   //
      120, 0, 0,    //
      140, 15, -5,  //
      160, 20, 0;
  return clay::surface::make_curve(
      3, {0, 0, 0, 0, 1. / 6, 2. / 6, 3. / 6, 4. / 6, 5. / 6, 1, 1, 1, 1}, p);
}

/// Points of the old curve on [a, b] pushed out by a smooth bump height * sin^2 (zero value and
/// slope at both ends), plus noise.
Points3 bumped(const BSplineCurve& c, double a, double b, double height, int count, double sigma,
               unsigned seed) {
  clay::test::Gaussian g(seed);
  Points3 out(count, 3);
  for (int i = 0; i < count; ++i) {
    const double u = double(i) / (count - 1);
    const double bump = height * std::pow(std::sin(std::numbers::pi * u), 2);
    out.row(i) = (clay::surface::evaluate(c, a + (b - a) * u) + bump * Eigen::Vector3d(0, 0.6, 0.8))
                     .transpose() +
                 g.vector(sigma);
  }
  return out;
}

/// Left and right limits at the breakpoint t, from the Bézier segments of the result (an
/// independent path from the oversketch's own measurement).
struct Sides {
  clay::surface::CurveDerivatives left, right;
};
Sides sides(const BSplineCurve& c, double t) {
  Sides s;
  for (const auto& seg : clay::surface::extract_bezier(c)) {
    const auto [a, b] = seg.basis.domain();
    if (b == t) s.left = clay::surface::derivatives(seg, b, 2);
    if (a == t) s.right = clay::surface::derivatives(seg, a, 2);
  }
  return s;
}

double angle(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

Eigen::Vector3d kappa(const clay::surface::CurveDerivatives& d) {
  return d.d1.cross(d.d2).cross(d.d1) / std::pow(d.d1.squaredNorm(), 2);
}

/// Largest distance from the stroke points to the curve (dense polyline of the whole curve).
double stroke_to_curve(const Points3& stroke, const BSplineCurve& c) {
  const Points3 poly = clay::test::polyline(clay::test::analytic(c), 6000);
  double worst = 0;
  for (Eigen::Index i = 0; i < stroke.rows(); ++i)
    worst = std::max(worst, clay::test::distance_to_polyline(stroke.row(i).transpose(), poly));
  return worst;
}

/// Largest distance between the old and new curve on [a, b] (same parameters).
double unchanged(const BSplineCurve& old, const BSplineCurve& now, double a, double b) {
  double worst = 0;
  for (double t : clay::surface::linspace(a, b, 200))
    worst =
        std::max(worst, (clay::surface::evaluate(old, t) - clay::surface::evaluate(now, t)).norm());
  return worst;
}

}  // namespace

TEST_CASE("oversketch G1: joints exact, kept parts unchanged, new part follows the stroke",
          "[oversketch]") {
  const BSplineCurve old = old_curve();
  const Stroke stroke{bumped(old, 0.3, 0.7, 6.0, 160, 0.01, 3), std::nullopt};
  OversketchOptions o;
  o.fit.tolerance_mm = 0.05;
  const OversketchResult r = oversketch(old, stroke, o);
  INFO(r.summary.brief());
  CHECK(r.summary.converged());
  CHECK(r.curve.basis.degree == 3);
  CHECK(r.curve.basis.domain() == old.basis.domain());
  CHECK(std::abs(r.cut_start - 0.3) < 1e-3);
  CHECK(std::abs(r.cut_end - 0.7) < 1e-3);
  REQUIRE(r.start_joint);
  REQUIRE(r.end_joint);
  for (const auto& j : {*r.start_joint, *r.end_joint}) {
    CHECK(j.gap == 0.0);
    CHECK(j.tangent_angle <= 1e-9);
  }
  // Independent: the Bézier segments on both sides of each joint.
  for (double t : {r.cut_start, r.cut_end}) {
    const Sides s = sides(r.curve, t);
    CHECK((s.left.point - s.right.point).norm() <= 1e-12);
    CHECK(angle(s.left.d1, s.right.d1) <= 1e-9);
  }
  // Kept parts: the old curve, pointwise.
  CHECK(unchanged(old, r.curve, 0.0, r.cut_start) <= 1e-12 * 170);
  CHECK(unchanged(old, r.curve, r.cut_end, 1.0) <= 1e-12 * 170);
  // The new part follows the stroke within the tolerance.
  CHECK(r.max_deviation_mm <= o.fit.tolerance_mm);
  CHECK(stroke_to_curve(stroke.points, r.curve) <= o.fit.tolerance_mm + 1e-4);
  // brief(): the cut, both joints (gap 0, so "gap 0 mm"), the verdict.
  CHECK_THAT(r.brief(), Catch::Matchers::StartsWith("replaced [0.3") &&
                            Catch::Matchers::Contains("gap 0 mm, angle") &&
                            Catch::Matchers::Contains("at start") &&
                            Catch::Matchers::Contains("at end") &&
                            Catch::Matchers::EndsWith("; converged"));
}

TEST_CASE("oversketch G2: curvature vectors agree across both joints", "[oversketch]") {
  const BSplineCurve old = old_curve();
  const Stroke stroke{bumped(old, 0.25, 0.6, -5.0, 150, 0.01, 4), std::nullopt};
  OversketchOptions o;
  o.continuity = Continuity::G2;
  o.fit.tolerance_mm = 0.05;
  const OversketchResult r = oversketch(old, stroke, o);
  INFO(r.summary.brief());
  CHECK(r.summary.converged());
  REQUIRE(r.start_joint);
  REQUIRE(r.end_joint);
  for (const auto& j : {*r.start_joint, *r.end_joint}) {
    CHECK(j.gap == 0.0);
    CHECK(j.tangent_angle <= 1e-9);
    CHECK(j.curvature_difference <= 1e-9);
  }
  for (double t : {r.cut_start, r.cut_end}) {
    const Sides s = sides(r.curve, t);
    CHECK(angle(s.left.d1, s.right.d1) <= 1e-9);
    const Eigen::Vector3d kl = kappa(s.left), kr = kappa(s.right);
    CHECK((kl - kr).norm() <= 1e-9 * std::max(kl.norm(), kr.norm()));
  }
  CHECK(unchanged(old, r.curve, 0.0, r.cut_start) <= 1e-12 * 170);
  CHECK(unchanged(old, r.curve, r.cut_end, 1.0) <= 1e-12 * 170);
  CHECK(stroke_to_curve(stroke.points, r.curve) <= o.fit.tolerance_mm + 1e-4);
}

TEST_CASE("oversketch: a stroke drawn backwards replaces the same part", "[oversketch]") {
  const BSplineCurve old = old_curve();
  Stroke stroke{bumped(old, 0.3, 0.7, 6.0, 160, 0.01, 3), std::nullopt};
  OversketchOptions o;
  o.fit.tolerance_mm = 0.05;
  const OversketchResult forward = oversketch(old, stroke, o);
  stroke.points = stroke.points.colwise().reverse().eval();
  const OversketchResult backward = oversketch(old, stroke, o);
  CHECK(backward.cut_start == forward.cut_start);
  CHECK(backward.cut_end == forward.cut_end);
  REQUIRE(backward.start_joint);
  CHECK(backward.start_joint->tangent_angle <= 1e-9);
  CHECK(backward.end_joint->tangent_angle <= 1e-9);
  CHECK(stroke_to_curve(stroke.points, backward.curve) <= o.fit.tolerance_mm + 1e-4);
}

TEST_CASE("oversketch over the curve's end replaces its tail", "[oversketch]") {
  const BSplineCurve old = old_curve();
  // From C(0.6) the stroke rises away from the curve, runs over its end point 4 mm above it and
  // goes on 25 mm along the end tangent.
  const Eigen::Vector3d up(0, 0, 1);
  const Eigen::Vector3d end = clay::surface::evaluate(old, 1.0);
  const Eigen::Vector3d tangent = clay::surface::derivatives(old, 1.0, 1).d1.normalized();
  Stroke stroke;
  const int along = 120, past = 40;
  stroke.points.resize(along + past, 3);
  for (int i = 0; i < along; ++i) {
    const double u = double(i) / along;
    stroke.points.row(i) =
        (clay::surface::evaluate(old, 0.6 + 0.4 * u) + 4.0 * u * u * (3 - 2 * u) * up).transpose();
  }
  for (int i = 0; i < past; ++i)
    stroke.points.row(along + i) = (end + 4.0 * up + 25.0 * (i + 1.0) / past * tangent).transpose();
  OversketchOptions o;
  o.fit.tolerance_mm = 0.05;
  const OversketchResult r = oversketch(old, stroke, o);
  INFO(r.summary.brief());
  CHECK(r.summary.converged());
  REQUIRE(r.start_joint);
  CHECK_FALSE(r.end_joint);
  CHECK(r.cut_end == 1.0);
  CHECK(std::abs(r.cut_start - 0.6) < 1e-6);
  CHECK(r.start_joint->tangent_angle <= 1e-9);
  CHECK(angle(sides(r.curve, r.cut_start).left.d1, sides(r.curve, r.cut_start).right.d1) <= 1e-9);
  CHECK(unchanged(old, r.curve, 0.0, r.cut_start) <= 1e-12 * 170);
  // The new tail ends at the stroke's end.
  CHECK((clay::surface::evaluate(r.curve, 1.0) - stroke.points.row(along + past - 1).transpose())
            .norm() <= o.fit.tolerance_mm);
  CHECK(stroke_to_curve(stroke.points, r.curve) <= o.fit.tolerance_mm + 1e-4);
}

TEST_CASE("oversketch keeps a rational curve's kept parts exact", "[oversketch]") {
  // A rational quadratic half circle, radius 50; the stroke flattens its middle.
  const BSplineCurve old =
      clay::surface::circular_arc(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                                  Eigen::Vector3d::UnitY(), 50.0, 0.0, std::numbers::pi);
  REQUIRE(old.is_rational());
  Stroke stroke;
  stroke.points.resize(100, 3);
  for (int i = 0; i < 100; ++i) {
    const double a = std::numbers::pi * (0.3 + 0.4 * i / 99.0);
    const double r = 50.0 - 3.0 * std::pow(std::sin(std::numbers::pi * i / 99.0), 2);
    stroke.points.row(i) << r * std::cos(a), r * std::sin(a), 0;
  }
  OversketchOptions o;
  o.fit.tolerance_mm = 0.05;
  const OversketchResult r = oversketch(old, stroke, o);
  INFO(r.summary.brief());
  CHECK(r.summary.converged());
  CHECK(r.curve.basis.degree == 2);
  REQUIRE(r.start_joint);
  REQUIRE(r.end_joint);
  CHECK(r.start_joint->tangent_angle <= 1e-9);
  CHECK(r.end_joint->tangent_angle <= 1e-9);
  CHECK(unchanged(old, r.curve, 0.0, r.cut_start) <= 1e-12 * 100);
  CHECK(unchanged(old, r.curve, r.cut_end, 1.0) <= 1e-12 * 100);
  // The kept parts are still on the circle.
  for (double t : clay::surface::linspace(0.0, r.cut_start, 50))
    CHECK(std::abs(clay::surface::evaluate(r.curve, t).norm() - 50.0) <= 1e-12 * 50);
}

TEST_CASE("oversketch refuses a stroke end beyond the capture distance, naming it",
          "[oversketch]") {
  const BSplineCurve old = old_curve();
  Stroke stroke{bumped(old, 0.3, 0.7, 6.0, 100, 0.0, 1), std::nullopt};
  stroke.points.row(99) += Eigen::RowVector3d(0, 0, 30);
  const auto [category, what] = clay::test::error_of([&] { oversketch(old, stroke); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Contains("the stroke's last point is 29.1"));  // to its foot on the curve
  CHECK_THAT(what, Contains("capture distance 10 mm"));
}

TEST_CASE("oversketch refuses a degree-1 curve", "[oversketch]") {
  Points3 p(3, 3);
  p << 0, 0, 0, 50, 10, 0, 100, 0, 0;
  const BSplineCurve polyline = clay::surface::make_curve(1, {0, 0, 0.5, 1, 1}, p);
  Stroke stroke;
  stroke.points.resize(20, 3);
  for (int i = 0; i < 20; ++i) stroke.points.row(i) << 20 + 2.0 * i, 5, 0;
  const auto [category, what] = clay::test::error_of([&] { oversketch(polyline, stroke); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("degree 1"));
}

TEST_CASE("oversketch refuses a stroke whose ends meet the curve at one point", "[oversketch]") {
  const BSplineCurve old = old_curve();
  // A small loop leaving C(0.5) and coming back to it.
  const Eigen::Vector3d at = clay::surface::evaluate(old, 0.5);
  Stroke stroke;
  stroke.points.resize(40, 3);
  for (int i = 0; i < 40; ++i) {
    const double a = 2 * std::numbers::pi * i / 39;
    stroke.points.row(i) =
        (at + Eigen::Vector3d(0, 0, 5 * (1 - std::cos(a))) + Eigen::Vector3d(0, 4 * std::sin(a), 0))
            .transpose();
  }
  stroke.points.row(39) = at.transpose();
  const auto [category, what] = clay::test::error_of([&] { oversketch(old, stroke); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Contains("both ends of the stroke meet the curve at the same point"));
}

TEST_CASE("oversketch refuses a stroke covering the whole curve", "[oversketch]") {
  const BSplineCurve old = old_curve();
  // The whole curve 2 mm higher, and 20 mm more at each end.
  const Eigen::Vector3d t0 = clay::surface::derivatives(old, 0.0, 1).d1.normalized();
  const Eigen::Vector3d t1 = clay::surface::derivatives(old, 1.0, 1).d1.normalized();
  Stroke stroke;
  stroke.points.resize(120, 3);
  const Eigen::Vector3d lift(0, 0, 2);
  for (int i = 0; i < 10; ++i)
    stroke.points.row(i) =
        (clay::surface::evaluate(old, 0.0) + lift - 2.0 * (10 - i) * t0).transpose();
  for (int i = 0; i < 100; ++i)
    stroke.points.row(10 + i) = (clay::surface::evaluate(old, i / 99.0) + lift).transpose();
  for (int i = 0; i < 10; ++i)
    stroke.points.row(110 + i) =
        (clay::surface::evaluate(old, 1.0) + lift + 2.0 * (i + 1) * t1).transpose();
  const auto [category, what] = clay::test::error_of([&] { oversketch(old, stroke); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Contains("covers the whole curve"));
}

TEST_CASE("bad oversketch options are refused, naming the field", "[oversketch]") {
  const BSplineCurve old = old_curve();
  const Stroke stroke{bumped(old, 0.3, 0.7, 6.0, 50, 0.0, 1), std::nullopt};
  OversketchOptions o;
  o.capture_distance = 0;
  auto [c1, w1] = clay::test::error_of([&] { oversketch(old, stroke, o); });
  CHECK(c1 == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(w1, Contains("OversketchOptions::capture_distance = 0"));
  o = {};
  o.continuity = static_cast<Continuity>(7);
  CHECK_THAT(clay::test::error_of([&] { oversketch(old, stroke, o); }).second,
             Contains("OversketchOptions::continuity = 7"));
  o = {};
  o.fit.tolerance_mm = -1;
  CHECK_THAT(clay::test::error_of([&] { oversketch(old, stroke, o); }).second,
             Contains("FitOptions::tolerance_mm = -1"));
}
