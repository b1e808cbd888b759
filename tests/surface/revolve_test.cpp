#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include "random_geometry.hpp"

using namespace clay::surface;
using Catch::Matchers::WithinAbs;

namespace {

/// A wiggly 3D cubic profile at distance 20..60 mm from the z axis.
BSplineCurve wiggly_profile(std::mt19937& rng, bool rational) {
  BSplineCurve c = clay::test::random_curve(rng, 3, 7, rational, true, 1, 10.0);
  for (Eigen::Index i = 0; i < c.points.rows(); ++i) {
    c.points(i, 0) += 40.0;      // x in [30, 50]
    c.points(i, 2) += 15.0 * i;  // climbing in z
  }
  return c;
}

/// Largest |radius and height of S(u, v)| - |those of profile(v)| about `axis`, on a grid.
double revolution_error(const BSplineSurface& s, const BSplineCurve& profile, const Axis& axis) {
  const Eigen::Vector3d a = axis.direction.normalized();
  double worst = 0;
  for (double v : linspace(profile.basis.domain().first, profile.basis.domain().second, 61)) {
    const Eigen::Vector3d c = evaluate(profile, v) - axis.point;
    const double hc = c.dot(a), rc = (c - hc * a).norm();
    for (double u : linspace(0.0, 1.0, 73)) {
      const Eigen::Vector3d q = evaluate(s, u, v) - axis.point;
      const double hq = q.dot(a), rq = (q - hq * a).norm();
      worst = std::max({worst, std::abs(hq - hc), std::abs(rq - rc)});
    }
  }
  return worst;
}

}  // namespace

TEST_CASE("circular arcs are exact and close exactly", "[revolve]") {
  const Eigen::Vector3d c(1, 2, 3), x = Eigen::Vector3d(1, 1, 0).normalized(),
                                    y = Eigen::Vector3d(-1, 1, 0).normalized();
  for (double sweep :
       {0.3, std::numbers::pi / 2, 2.0, std::numbers::pi, 4.0, 2 * std::numbers::pi}) {
    const BSplineCurve arc = circular_arc(c, x, y, 7.5, 0.25, 0.25 + sweep);
    double worst = 0;
    for (double t : linspace(0, 1, 201))
      worst = std::max(worst, std::abs((evaluate(arc, t) - c).norm() - 7.5));
    CHECK(worst < 1e-14 * 10);
    CHECK(
        (evaluate(arc, 1.0) - (c + 7.5 * (std::cos(0.25 + sweep) * x + std::sin(0.25 + sweep) * y)))
            .norm() < 1e-13);
  }
  const BSplineCurve full = circular_arc(c, x, y, 7.5, 0.0, 2 * std::numbers::pi);
  CHECK(full.points.row(0) == full.points.row(full.points.rows() - 1));
  CHECK(full.basis.count() == 9);
  CHECK_THROWS_AS(circular_arc(c, x, x, 1.0, 0.0, 1.0), clay::Error);
  CHECK_THROWS_AS(circular_arc(c, x, y, -1.0, 0.0, 1.0), clay::Error);
  CHECK_THROWS_AS(circular_arc(c, x, y, 1.0, 1.0, 1.0), clay::Error);
}

TEST_CASE("revolved points lie at the exact radius and height of their profile point",
          "[revolve]") {
  std::mt19937 rng(71);
  for (bool rational : {false, true}) {
    const BSplineCurve profile = wiggly_profile(rng, rational);
    for (double angle : {45.0, 90.0, 135.0, 200.0, 300.0, 360.0}) {
      for (const Axis& axis :
           {Axis{}, Axis{Eigen::Vector3d(5, -3, 2), Eigen::Vector3d(0.1, 0.05, 1.0)}}) {
        const BuiltSurface built = revolve(profile, axis, angle);
        const double size = 100.0;
        INFO("angle " << angle << ", rational profile " << rational);
        CHECK(revolution_error(built.surface, profile, axis) < 1e-12 * size);
        CHECK(built.report.exact);
        CHECK(built.report.max_deviation_mm < 1e-12 * size);
        CHECK(built.surface.is_rational());
        CHECK(built.surface.u.degree == 2);
        CHECK(built.surface.v.knots == profile.basis.knots);
        // The end iso-curve is the profile turned by the angle about the axis.
        const Eigen::AngleAxisd turn(angle * std::numbers::pi / 180.0, axis.direction.normalized());
        double worst = 0;
        for (double v : linspace(0.0, 1.0, 31)) {
          const Eigen::Vector3d expect = axis.point + turn * (evaluate(profile, v) - axis.point);
          worst = std::max(worst, (evaluate(built.surface, 1.0, v) - expect).norm());
          CHECK((evaluate(built.surface, 0.0, v) - evaluate(profile, v)).norm() < 1e-12 * size);
        }
        CHECK(worst < 1e-12 * size);
      }
    }
  }
}

TEST_CASE("a full revolution closes exactly and a profile ending on the axis makes a pole",
          "[revolve]") {
  // Quarter circle from the equator to the north pole: a hemisphere of radius 25.
  const BSplineCurve quarter =
      circular_arc(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ(),
                   25.0, 0.0, std::numbers::pi / 2);
  const BuiltSurface dome = revolve(quarter, Axis{}, 360.0);
  const BSplineSurface& s = dome.surface;
  for (int j = 0; j < s.count_v(); ++j)
    CHECK(s.points.row(s.index(0, j)) == s.points.row(s.index(s.count_u() - 1, j)));
  double worst = 0;
  for (double u : linspace(0, 1, 41))
    for (double v : linspace(0, 1, 41))
      worst = std::max(worst, std::abs(evaluate(s, u, v).norm() - 25.0));
  CHECK(worst < 1e-13 * 25.0);
  CHECK((evaluate(s, 0.37, 1.0) - Eigen::Vector3d(0, 0, 25)).norm() < 1e-13);
}

TEST_CASE("STEP export of a revolved surface keeps it rational and exact", "[revolve][exchange]") {
  std::mt19937 rng(72);
  const BSplineCurve profile = wiggly_profile(rng, false);
  const BuiltSurface built = revolve(profile, Axis{}, 270.0);
  const std::filesystem::path dir = std::filesystem::path(CLAY_TEST_OUTPUT_DIR) / "revolve";
  std::filesystem::create_directories(dir);
  const ExchangeReport report = write_step({built.surface}, dir / "revolved.step");
  CHECK(report.valid);
  const auto back = read_step(dir / "revolved.step");
  REQUIRE(back.size() == 1);
  CHECK(back[0].is_rational());
  CHECK(identical(back[0], built.surface));
  CHECK(revolution_error(back[0], profile, Axis{}) < 1e-12 * 100.0);
}

TEST_CASE("revolve refuses an axis of zero length", "[revolve][errors]") {
  std::mt19937 rng(73);
  const BSplineCurve profile = wiggly_profile(rng, false);
  try {
    revolve(profile, Axis{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}, 90.0);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidArgument);
    CHECK_THAT(e.what(), Catch::Contains("axis direction has length 0"));
  }
}

TEST_CASE("revolve refuses angles outside 0 to 360 degrees", "[revolve][errors]") {
  std::mt19937 rng(74);
  const BSplineCurve profile = wiggly_profile(rng, false);
  for (double bad : {0.0, -10.0, 360.5, std::nan("")})
    CHECK_THROWS_WITH(revolve(profile, Axis{}, bad), Catch::Contains("outside (0, 360]"));
}

TEST_CASE("revolve refuses a profile crossing the axis", "[revolve][errors]") {
  const BSplineCurve line =
      make_curve(1, {0, 0, 1, 1}, (Points3(2, 3) << -10, 0, 0, 10, 0, 30).finished());
  try {
    revolve(line, Axis{}, 360.0);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidGeometry);
    CHECK_THAT(e.what(),
               Catch::Contains("crosses the axis") || Catch::Contains("touches the axis"));
  }
}

TEST_CASE("revolve refuses a profile touching the axis between its ends", "[revolve][errors]") {
  const BSplineCurve vee =
      make_curve(1, {0, 0, 0.5, 1, 1}, (Points3(3, 3) << 10, 0, 0, 0, 0, 10, 10, 0, 20).finished());
  CHECK_THROWS_WITH(revolve(vee, Axis{}, 180.0), Catch::Contains("touches the axis at t = 0.5"));
}

TEST_CASE("revolve refuses a profile lying on the axis", "[revolve][errors]") {
  const BSplineCurve on_axis =
      make_curve(1, {0, 0, 1, 1}, (Points3(2, 3) << 0, 0, 0, 0, 0, 30).finished());
  CHECK_THROWS_WITH(revolve(on_axis, Axis{}, 90.0), Catch::Contains("lies on the axis"));
}

TEST_CASE("revolve refuses a profile that crosses itself", "[revolve][errors]") {
  // A "Z" in the x-z plane, 20 to 40 mm from the axis: its first and last segments cross at
  // (30, 0, 15), at t = 0.5 and t = 2.5.
  const BSplineCurve zee =
      make_curve(1, {0, 0, 1, 2, 3, 3},
                 (Points3(4, 3) << 20, 0, 0, 40, 0, 30, 40, 0, 0, 20, 0, 30).finished());
  try {
    revolve(zee, Axis{}, 360.0);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidGeometry);
    CHECK_THAT(
        e.what(),
        Catch::Contains(
            "revolve: the profile crosses itself at t = 0.5 and t = 2.5 (point (30, 0, 15)") &&
            Catch::Contains("the revolved surface would intersect itself"));
  }
}
