// clay/clayform.hpp brings the whole API in one include, and clay/version.hpp agrees with the
// library loaded and with the project's version (issue #19's embedder kit).
#include <catch2/catch.hpp>

#include <clay/clayform.hpp>

#include <string>

TEST_CASE("the umbrella header compiles alone and the version is the project's", "[embedding]") {
  CHECK(clay::version() == CLAYFORM_VERSION_STRING);
  CHECK(std::string(clay::version()) == CLAY_PROJECT_VERSION);  // from CMake's project(VERSION)
  const clay::Version v = clay::version_numbers();
  CHECK(v == clay::header_version);
  CHECK(std::to_string(v.major) + "." + std::to_string(v.minor) + "." + std::to_string(v.patch) ==
        CLAY_PROJECT_VERSION);
  // One entry point of each module, through the one include.
  using namespace clay;
  const surface::BSplineCurve line =
      surface::make_curve(1, {0, 0, 1, 1}, (surface::Points3(2, 3) << 0, 0, 0, 3, 4, 0).finished());
  CHECK(surface::evaluate(line, 1.0).norm() == 5);
  sketch::Sketch s;
  const auto a = s.add_point(Eigen::Vector3d(0, 0, 0)), b = s.add_point(Eigen::Vector3d(1, 0, 0));
  CHECK(constraints::solve(s, {constraints::fixed(a), constraints::distance(a, b, 2)})
            .report.summary.converged());
  CHECK(deform::kind_name(deform::Deformation{deform::Taper{}}) == std::string_view("taper"));
  CHECK(recipe::check_recipe(R"({"format": "clayform.recipe", "version": 1})").empty());
}
