// Barr's taper, twist and bend (Güdükbay–Özgüç §3.1) against closed forms computed here
// independently: radial scaling, rotation angles, circular arcs of radius 1/k, the paper's bend
// formula with 1/k, finite-difference Jacobians, and frames rotated by an independent rotation.
#include <catch2/catch.hpp>

#include <clay/deform.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <tuple>

#include "error_of.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using clay::ErrorCategory;
using clay::test::error_of;

static_assert(PointDeformation<Taper>);
static_assert(PointDeformation<Twist>);
static_assert(PointDeformation<Bend>);

namespace {

/// A rotation from a random unit quaternion (independent of the library's Gram–Schmidt).
Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

Eigen::Vector3d random_point(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> c(-1, 1);
  return Eigen::Vector3d(c(rng), c(rng), c(rng)) * scale;
}

/// An axis frame: origin far off, axis and reference from rotation q applied to the canonical
/// directions, the reference tilted towards the axis and both scaled (the library normalises).
AxisFrame rotated_frame(const Eigen::Matrix3d& q, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& canonical_axis,
                        const Eigen::Vector3d& canonical_ref) {
  return {origin, 3.5 * (q * canonical_axis),
          0.4 * (q * canonical_ref) + 0.25 * (q * canonical_axis)};
}

template <class D>
Eigen::Matrix3d central_differences(const D& d, const Eigen::Vector3d& x, double h) {
  Eigen::Matrix3d j;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[c] = h;
    j.col(c) = (deform_point(d, x + e) - deform_point(d, x - e)) / (2 * h);
  }
  return j;
}

double poly(const std::vector<double>& c, double z) {
  double v = 0, p = 1;
  for (double a : c) v += a * p, p *= z;  // power sum, not Horner
  return v;
}

}  // namespace

TEST_CASE("a taper scales the radial offset by r(z) about any axis", "[deform][regular]") {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3d q = random_rotation(rng);
    Taper taper{rotated_frame(q, random_point(rng, 200), Eigen::Vector3d::UnitZ(),
                              Eigen::Vector3d::UnitX()),
                {0.9, 0.004, -3e-5, 2e-7}};
    const Eigen::Vector3d a = taper.frame.axis.normalized();
    double worst = 0;
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d x = taper.frame.origin + random_point(rng, 60);
      // Independent: axial coordinate and radial offset, no basis at all.
      const double z = (x - taper.frame.origin).dot(a);
      const Eigen::Vector3d radial = x - taper.frame.origin - z * a;
      const Eigen::Vector3d expected = taper.frame.origin + z * a + poly(taper.profile, z) * radial;
      worst = std::max(worst, (deform_point(taper, x) - expected).norm());
      // The deformed point keeps its axial coordinate.
      CHECK_THAT((deform_point(taper, x) - taper.frame.origin).dot(a), WithinAbs(z, 1e-12));
    }
    CHECK(worst < 1e-12);  // points ~250 mm from the world origin
  }
}

TEST_CASE("a twist rotates about the axis by exactly theta of z", "[deform][regular]") {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3d q = random_rotation(rng);
    Twist twist{rotated_frame(q, random_point(rng, 200), Eigen::Vector3d::UnitZ(),
                              Eigen::Vector3d::UnitX()),
                {0.3, 0.02, 1e-4}};
    const Eigen::Vector3d a = twist.frame.axis.normalized();
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector3d x = twist.frame.origin + random_point(rng, 50);
      const Eigen::Vector3d y = deform_point(twist, x);
      const double z = (x - twist.frame.origin).dot(a);
      const Eigen::Vector3d v = x - twist.frame.origin - z * a;
      const Eigen::Vector3d w = y - twist.frame.origin - z * a;
      // Angle measured from the two radial offsets, right-handed about the axis (x towards y).
      const double measured = std::atan2(a.dot(v.cross(w)), v.dot(w));
      const double theta = poly(twist.angle, z);
      const double wrapped = std::remainder(measured - theta, 2 * std::numbers::pi);
      CHECK_THAT(wrapped, WithinAbs(0, 1e-12));
      CHECK_THAT(w.norm(), WithinAbs(v.norm(), 1e-12));
      CHECK_THAT((y - twist.frame.origin).dot(a), WithinAbs(z, 1e-12));
      // And against Eigen's rotation about the axis.
      const Eigen::Vector3d expected = twist.frame.origin + z * a + Eigen::AngleAxisd(theta, a) * v;
      CHECK((y - expected).norm() < 1e-12);
    }
  }
}

TEST_CASE("a bend follows the paper's formula with 1 over k", "[deform][regular]") {
  Bend bend;
  bend.y_min = -20;
  bend.y_max = 35;
  bend.center = 5;
  bend.rate = 0.03;
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> ys(-60, 80), xz(-15, 15);
  for (int i = 0; i < 300; ++i) {
    const double x = xz(rng), y = ys(rng), z = xz(rng);
    const double k = bend.rate, y0 = bend.center;
    const double yh = y <= bend.y_min ? bend.y_min : (y >= bend.y_max ? bend.y_max : y);
    const double th = k * (yh - y0), C = std::cos(th), S = std::sin(th);
    // Güdükbay–Özgüç §3.1.3 (Barr): with 1/k, as printed.
    const Eigen::Vector3d expected(x, -S * (z - 1 / k) + y0 + C * (y - yh),
                                   C * (z - 1 / k) + 1 / k + S * (y - yh));
    CHECK((deform_point(bend, {x, y, z}) - expected).norm() < 1e-12);
  }
}

TEST_CASE("a bend maps the centreline onto an arc of radius 1 over k and keeps its length",
          "[deform][regular]") {
  Bend bend;
  bend.y_min = -30;
  bend.y_max = 50;
  bend.center = 10;
  bend.rate = 0.025;  // radius 40 mm, bent by 2 rad
  const double radius = 1 / bend.rate;
  const Eigen::Vector3d centre(0, bend.center, radius);  // the bend axis [s, y0, 1/k]
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  double previous_y = 0;
  for (int i = 0; i <= 80; ++i) {
    const double y = bend.y_min + (bend.y_max - bend.y_min) * i / 80.0;
    const Eigen::Vector3d p = deform_point(bend, {0, y, 0});
    CHECK_THAT(p.x(), WithinAbs(0, 0));
    CHECK_THAT((p - centre).norm(), WithinAbs(radius, 1e-12));
    if (i > 0) {
      // Arc length between successive points = radius x the angle they subtend at the centre.
      const Eigen::Vector3d a = previous - centre, b = p - centre;
      const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
      CHECK_THAT(radius * angle, WithinAbs(y - previous_y, 1e-12));
    }
    previous = p;
    previous_y = y;
  }
  // Total arc: 80 mm of centreline subtends k x 80 = 2 rad.
  const Eigen::Vector3d a = deform_point(bend, {0, bend.y_min, 0}) - centre;
  const Eigen::Vector3d b = deform_point(bend, {0, bend.y_max, 0}) - centre;
  CHECK_THAT(std::atan2(a.cross(b).norm(), a.dot(b)), WithinAbs(2.0, 1e-13));
  // The centre of the bend stays put; beyond the region the parts move rigidly: distances kept.
  CHECK((deform_point(bend, {0, bend.center, 0}) - Eigen::Vector3d(0, bend.center, 0)).norm() <
        1e-15);
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> above(bend.y_max, bend.y_max + 40),
      below(bend.y_min - 40, bend.y_min), xz(-10, 10);
  for (int i = 0; i < 50; ++i) {
    for (auto* side : {&above, &below}) {
      const Eigen::Vector3d p(xz(rng), (*side)(rng), xz(rng)), q(xz(rng), (*side)(rng), xz(rng));
      CHECK_THAT((deform_point(bend, p) - deform_point(bend, q)).norm(),
                 WithinAbs((p - q).norm(), 1e-12));
    }
  }
}

TEST_CASE("a bend is continuous across y_min and y_max and C1 on the neutral plane",
          "[deform][regular]") {
  Bend bend;
  bend.y_min = -10;
  bend.y_max = 25;
  bend.center = 3;
  bend.rate = 0.04;
  const double eps = 1e-10;
  for (double edge : {bend.y_min, bend.y_max}) {
    for (double z : {-6.0, 0.0, 4.0}) {
      for (double x : {-5.0, 2.0}) {
        const Eigen::Vector3d lo(x, edge - eps, z), hi(x, edge + eps, z);
        CHECK((deform_point(bend, lo) - deform_point(bend, hi)).norm() < 1e-9);
        const Eigen::Matrix3d j_in = jacobian_matrix(bend, {x, edge, z});  // bent side
        const Eigen::Matrix3d j_out = jacobian_matrix(bend, edge == bend.y_max ? hi : lo);
        // x and z columns always match; the y column by the factor 1 − k z (C1 only at z = 0).
        CHECK((j_in.col(0) - j_out.col(0)).norm() < 1e-9);
        CHECK((j_in.col(2) - j_out.col(2)).norm() < 1e-9);
        CHECK((j_in.col(1) - (1 - bend.rate * z) * j_out.col(1)).norm() < 1e-9);
        if (z == 0) CHECK((j_in - j_out).norm() < 1e-9);
      }
    }
  }
}

TEST_CASE("analytic Jacobians of taper, twist and bend match central differences",
          "[deform][regular]") {
  std::mt19937 rng(15);
  const Eigen::Matrix3d q = random_rotation(rng);
  const Eigen::Vector3d o = random_point(rng, 100);
  const Taper taper{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()),
                    {1.1, -0.01, 2e-4}};
  const Twist twist{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()),
                    {0.2, 0.03, -4e-4}};
  Bend bend{rotated_frame(q, o, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()), -15, 20, 2,
            0.05};
  const Eigen::Vector3d ey = bend.frame.axis.normalized();
  double worst[3] = {0, 0, 0};
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d x = o + random_point(rng, 30);
    worst[0] = std::max(worst[0],
                        (jacobian_matrix(taper, x) - central_differences(taper, x, 1e-5)).norm());
    worst[1] = std::max(worst[1],
                        (jacobian_matrix(twist, x) - central_differences(twist, x, 1e-5)).norm());
    const double y = (x - o).dot(ey);
    if (std::abs(y - bend.y_min) > 1e-3 && std::abs(y - bend.y_max) > 1e-3)  // not across a kink
      worst[2] = std::max(worst[2],
                          (jacobian_matrix(bend, x) - central_differences(bend, x, 1e-5)).norm());
    CHECK_THAT(jacobian_matrix(twist, x).determinant(), WithinAbs(1, 1e-13));  // volume kept
    const double z = (x - o).dot(taper.frame.axis.normalized());
    CHECK_THAT(jacobian_matrix(taper, x).determinant(),
               WithinAbs(std::pow(poly(taper.profile, z), 2), 1e-13));
  }
  CHECK(worst[0] < 1e-8);
  CHECK(worst[1] < 1e-8);
  CHECK(worst[2] < 1e-8);
}

TEST_CASE("an arbitrary frame equals the canonical deformation in rotated coordinates",
          "[deform][regular]") {
  std::mt19937 rng(16);
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::Matrix3d q = random_rotation(rng);
    const Eigen::Vector3d o = random_point(rng, 300);
    const std::vector<double> profile{1.2, -0.008, 5e-5}, angle{-0.4, 0.015};
    const Taper t0{AxisFrame{}, profile},
        t1{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()), profile};
    const Twist w0{AxisFrame{}, angle},
        w1{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()), angle};
    const Bend b0{Bend{}.frame, -12, 30, 4, 0.03};
    const Bend b1{rotated_frame(q, o, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()), -12, 30,
                  4, 0.03};
    double worst = 0, worst_j = 0;
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector3d local = random_point(rng, 40);
      const Eigen::Vector3d x = o + q * local;
      worst = std::max({worst, (deform_point(t1, x) - (o + q * deform_point(t0, local))).norm(),
                        (deform_point(w1, x) - (o + q * deform_point(w0, local))).norm(),
                        (deform_point(b1, x) - (o + q * deform_point(b0, local))).norm()});
      // Jacobians transform as q J q^T.
      worst_j = std::max(
          {worst_j,
           (jacobian_matrix(t1, x) - q * jacobian_matrix(t0, local) * q.transpose()).norm(),
           (jacobian_matrix(w1, x) - q * jacobian_matrix(w0, local) * q.transpose()).norm(),
           (jacobian_matrix(b1, x) - q * jacobian_matrix(b0, local) * q.transpose()).norm()});
    }
    CHECK(worst < 1e-12);  // points ~350 mm from the world origin
    CHECK(worst_j < 1e-13);
  }
}

TEST_CASE("rate 0 and r identically 1 are the identity", "[deform][regular]") {
  std::mt19937 rng(17);
  const Taper taper;  // profile {1}
  const Twist twist;  // angle {0}
  const Bend bend;    // rate 0
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d x = random_point(rng, 500);
    CHECK((deform_point(taper, x).array() == x.array()).all());  // bit for bit
    CHECK((deform_point(twist, x).array() == x.array()).all());
    CHECK((deform_point(bend, x).array() == x.array()).all());
    CHECK(jacobian_matrix(bend, x) == Eigen::Matrix3d::Identity());
  }
  // Any frame: rounding of the rotation only.
  const Eigen::Matrix3d q = random_rotation(rng);
  const Eigen::Vector3d o = random_point(rng, 100);
  const Taper t1{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()),
                 {1.0, 0.0}};
  const Twist w1{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()),
                 {0.0, 0.0}};
  double worst = 0;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d x = o + random_point(rng, 50);
    worst = std::max({worst, (deform_point(t1, x) - x).norm() / x.norm(),
                      (deform_point(w1, x) - x).norm() / x.norm()});
  }
  CHECK(worst < 2e-15);
  // A tiny rate is accurate (no 1/k cancellation): the bend of the centreline stays on the arc.
  Bend tiny;
  tiny.rate = 1e-9;
  tiny.y_max = 10;
  const Eigen::Vector3d p = deform_point(tiny, {0, 10, 0});
  CHECK_THAT(p.y(), WithinAbs(10, 1e-14));            // sin(kL) / k = L (1 − (kL)² / 6)
  CHECK_THAT(p.z(), WithinAbs(0.5e-9 * 100, 1e-20));  // z = (1 − cos kL)/k ≈ k L² / 2
}

TEST_CASE("bulk regular deformations equal deform_point bit for bit, in place too",
          "[deform][regular]") {
  std::mt19937 rng(18);
  const Eigen::Matrix3d q = random_rotation(rng);
  const Eigen::Vector3d o = random_point(rng, 100);
  const Taper taper{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()),
                    {1, 0.01}};
  const Twist twist{rotated_frame(q, o, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()),
                    {0, 0.02}};
  const Bend bend{rotated_frame(q, o, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()), -20, 20,
                  0, 0.03};
  const int n = 40000;  // more than 2 x 16,384: two workers
  Points3 points(n, 3);
  for (int r = 0; r < n; ++r) points.row(r) = (o + random_point(rng, 60)).transpose();
  auto same = [&](const auto& d) {
    const Points3 out = deform_points(d, points, DeformOptions{2});
    Points3 in_place = points;
    deform_points(d, in_place, in_place, DeformOptions{2});
    bool equal = out.rows() == n && (out.array() == in_place.array()).all();
    for (int r = 0; r < n; r += 7)
      equal = equal &&
              (deform_point(d, points.row(r).transpose()).transpose().array() == out.row(r).array())
                  .all();
    return equal;
  };
  CHECK(same(taper));
  CHECK(same(twist));
  CHECK(same(bend));
  CHECK(same(Bend{}));  // rate 0: the copy path
  CHECK(deform_points(twist, Points3(0, 3)).rows() == 0);
}

TEST_CASE("bad regular deformations are rejected naming the field and the fix",
          "[deform][regular]") {
  Taper taper;
  taper.frame.axis.setZero();
  auto [category, what] = error_of([&] { validate(taper); });
  CHECK(category == ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("taper frame: axis (0, 0, 0) has zero length") &&
                       Contains("non-zero direction"));

  Twist twist;
  twist.frame.reference = {0, 0, -2};  // parallel to the axis
  CHECK_THAT(error_of([&] { deform_points(twist, Points3::Zero(3, 3)); }).second,
             Contains("twist frame: reference (0, 0, -2) is parallel to the axis") &&
                 Contains("across the axis"));
  twist = Twist{};
  twist.frame.origin.x() = std::numeric_limits<double>::infinity();
  CHECK_THAT(error_of([&] { validate(twist); }).second,
             Contains("origin (inf, 0, 0) is not finite"));
  twist = Twist{};
  twist.angle = {0, std::numeric_limits<double>::quiet_NaN()};
  CHECK_THAT(error_of([&] { validate(twist); }).second, Contains("angle[1] = nan is not finite"));
  taper = Taper{};
  taper.profile.clear();
  CHECK_THAT(error_of([&] { validate(taper); }).second,
             Contains("profile is empty") && Contains("constant"));
  taper.profile.assign(65, 0.0);
  CHECK_THAT(error_of([&] { validate(taper); }).second, Contains("65 coefficients, more than 64"));

  Bend bend;
  bend.rate = std::numeric_limits<double>::quiet_NaN();
  std::tie(category, what) = error_of([&] { deform_points(bend, Points3::Zero(2, 3)); });
  CHECK(category == ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("bend: rate = nan is not finite") && Contains("rad/mm"));
  bend.rate = 0.1;
  bend.y_min = 5;
  bend.y_max = 1;
  CHECK_THAT(error_of([&] { validate(bend, "hood bend"); }).second,
             Contains("hood bend: y_min = 5 > y_max = 1") && Contains("give y_min <= y_max"));
  CHECK(problems(Bend{}).empty());  // rate 0 is valid: the identity
  CHECK_THAT(
      error_of([&] { deform_points(Twist{}, Points3::Zero(2, 3), DeformOptions{-3}); }).second,
      Contains("DeformOptions::threads = -3"));
  CHECK_THAT(error_of([&] {
               validate(AxisFrame{{0, 0, 0}, {1, 0, 0}, {0, 0, 0}});
             }).second,
             Contains("axis frame: reference (0, 0, 0) has zero length"));
}
