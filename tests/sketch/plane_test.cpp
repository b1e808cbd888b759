#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/sketch/plane.hpp>  // alone: normal() must compile from it

#include <cmath>
#include <limits>
#include <random>

#include "error_of.hpp"

using namespace clay::sketch;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;

TEST_CASE("make_plane: orthonormal right-handed axes around the given normal", "[plane]") {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d origin(100 * u(rng), 100 * u(rng), 100 * u(rng));
    const Eigen::Vector3d normal(u(rng), u(rng), u(rng));
    const SketchPlane plane = make_plane(origin, normal);
    CHECK(problems(plane).empty());
    CHECK_THAT(plane.x_axis.norm(), WithinAbs(1.0, 1e-15));
    CHECK_THAT(plane.y_axis.norm(), WithinAbs(1.0, 1e-15));
    CHECK_THAT(plane.x_axis.dot(plane.y_axis), WithinAbs(0.0, 1e-15));
    CHECK((plane.normal() - normal.normalized()).norm() < 1e-15);
    CHECK(plane.origin == origin);
  }
}

TEST_CASE("make_plane: the x axis follows the given direction, projected into the plane",
          "[plane]") {
  const SketchPlane plane =
      make_plane(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(1, 1, 5));
  CHECK((plane.x_axis - Eigen::Vector3d(1, 1, 0).normalized()).norm() < 1e-15);
  CHECK((plane.y_axis - Eigen::Vector3d(-1, 1, 0).normalized()).norm() < 1e-15);
  CHECK((plane.normal() - Eigen::Vector3d::UnitZ()).norm() < 1e-15);
}

TEST_CASE("to_plane and to_world: coordinates along the axes, projection along the normal",
          "[plane]") {
  const SketchPlane plane =
      make_plane(Eigen::Vector3d(10, -20, 5), Eigen::Vector3d(1, 2, 2), Eigen::Vector3d(2, -1, 0));
  const Eigen::Vector2d xy(12.5, -7.25);
  const Eigen::Vector3d in_plane = to_world(plane, xy);
  CHECK((to_plane(plane, in_plane) - xy).norm() < 1e-13);
  CHECK_THAT(signed_distance(plane, in_plane), WithinAbs(0.0, 1e-13));
  // A point off the plane lands on its foot point's coordinates; the offset is the distance.
  const Eigen::Vector3d off = in_plane + 3.5 * plane.normal();
  CHECK((to_plane(plane, off) - xy).norm() < 1e-13);
  CHECK_THAT(signed_distance(plane, off), WithinAbs(3.5, 1e-13));
  // Independent: the coordinates are the dot products with the axes.
  CHECK_THAT(to_plane(plane, off).x(), WithinAbs((off - plane.origin).dot(plane.x_axis), 1e-13));
}

TEST_CASE("sketch plane validation names the plane and the broken rule", "[plane]") {
  SketchPlane bad;
  bad.x_axis = Eigen::Vector3d(2, 0, 0);
  auto found = problems(bad, "plane 'door'");
  REQUIRE(found.size() == 1);
  CHECK_THAT(found[0], Contains("plane 'door': x axis has length 2"));
  bad = SketchPlane{};
  bad.y_axis = Eigen::Vector3d(1, 1, 0).normalized();
  found = problems(bad);
  REQUIRE(found.size() == 1);
  CHECK_THAT(found[0], Contains("not orthogonal"));
  bad = SketchPlane{};
  bad.origin.x() = std::numeric_limits<double>::quiet_NaN();
  const auto [category, what] = clay::test::error_of([&] { validate(bad, "plane 'roof'"); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("plane 'roof': origin has a non-finite coordinate"));
}

TEST_CASE("make_plane refuses a zero normal and an x direction along the normal", "[plane]") {
  auto [c1, w1] =
      clay::test::error_of([] { make_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()); });
  CHECK(c1 == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(w1, Contains("normal has zero length"));
  auto [c2, w2] = clay::test::error_of([] {
    make_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0, -3));
  });
  CHECK(c2 == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(w2, Contains("parallel to the normal"));
}
