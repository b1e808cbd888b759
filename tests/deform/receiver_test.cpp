// Receiver profiles (issue #38 item 2): conformance, and the certified fit of a surface a
// receiver would not take, checked against the surface itself at sampled parameters.
#include <catch2/catch.hpp>

#include <clay/deform/compose.hpp>
#include <clay/deform/receiver.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <cmath>
#include <string>

#include "error_of.hpp"
#include "shapes.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;
using namespace clay::test;
namespace surface = clay::surface;

namespace {

/// A dome, 100 x 100 mm, of `degree` on `count` x `count` control points.
surface::BSplineSurface dome(int degree, int count) {
  const auto b = surface::clamped_uniform_basis(degree, count);
  const auto xi = surface::greville_abscissae(b);
  surface::Points3 p(count * count, 3);
  for (int i = 0; i < count; ++i)
    for (int j = 0; j < count; ++j) {
      const double x = 100 * xi[static_cast<size_t>(i)], y = 100 * xi[static_cast<size_t>(j)];
      p.row(i * count + j) << x, y, 20 * std::sin(0.03 * x) * std::sin(0.03 * y);
    }
  return surface::make_surface(b, b, p);
}

}  // namespace

TEST_CASE("receiver profiles: the table, and what each takes", "[receiver]") {
  std::string names;
  for (const ReceiverProfile& p : receiver_profiles()) names += std::string(p.name) + " ";
  CHECK(names == "exact opencascade catia class_a bicubic ");
  CHECK(receiver_profile("catia").max_degree == 15);
  CHECK(receiver_profile("class_a").max_count_per_direction == 32);
  const auto [category, message] = error_of([] { receiver_profile("alias"); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("no receiver profile \"alias\"") && Contains("class_a, bicubic"));

  const surface::BSplineSurface nine = dome(9, 12);
  CHECK(conformance_problems(nine, receiver_profile("opencascade")).empty());
  CHECK(conformance_problems(nine, receiver_profile("catia")).empty());
  const auto class_a = conformance_problems(nine, receiver_profile("class_a"));
  REQUIRE(class_a.size() == 2);
  CHECK_THAT(class_a[0], Contains("degree 9 in u is above the class_a profile's 5"));
  const auto bicubic = conformance_problems(dome(2, 5), receiver_profile("bicubic"));
  CHECK_THAT(bicubic.front(), Contains("degree 2 in u is below the bicubic profile's 3"));
  CHECK_THAT(conformance_problems(dome(3, 40), receiver_profile("class_a")).front(),
             Contains("40 control points in u are more than the class_a profile's 32"));
}

TEST_CASE("fit_to_profile: unchanged, elevated exactly, or refitted within a certified bound",
          "[receiver]") {
  RefitOptions fit;
  fit.tolerance_mm = 0.01;
  fit.relative_tolerance = 0;
  // Conforming: the same surface.
  const surface::BSplineSurface cubic = dome(3, 8);
  const ProfileFit same = fit_to_profile(cubic, receiver_profile("bicubic"), fit);
  CHECK_FALSE(same.refitted);
  CHECK(surface::identical(same.surface, cubic));
  // Too low for bicubic: elevated exactly, nothing fitted.
  const surface::BSplineSurface quadric = dome(2, 6);
  const ProfileFit raised = fit_to_profile(quadric, receiver_profile("bicubic"), fit);
  CHECK(raised.elevated);
  CHECK(raised.surface.u.degree == 3);
  CHECK(raised.bound_mm == 0);
  CHECK(grid_gap(raised.surface, quadric) <= 1e-12);
  // Too high for CATIA: a certified bicubic, within its bound of the surface.
  const surface::BSplineSurface high = dome(18, 20);
  const ProfileFit catia = fit_to_profile(high, receiver_profile("catia"), fit, "surface 'hood'");
  CHECK(catia.refitted);
  CHECK(catia.surface.u.degree == 3);
  CHECK(catia.bound_mm <= 0.01);
  CHECK(catia.bound_mm == catia.report.certified_bound_mm);
  CHECK(grid_gap(catia.surface, high) <= catia.bound_mm);
  // Too dense for class A: a quintic net of at most 32 x 32, certified.
  const surface::BSplineSurface dense = dome(3, 60);
  const ProfileFit a = fit_to_profile(dense, receiver_profile("class_a"), fit);
  CHECK(a.refitted);
  CHECK(a.surface.u.degree == 5);
  CHECK(a.surface.u.count() <= 32);
  CHECK(a.surface.v.count() <= 32);
  CHECK(conformance_problems(a.surface, receiver_profile("class_a")).empty());
  const double gap = grid_gap(a.surface, dense);
  INFO("class A: " << a.surface.u.count() << " x " << a.surface.v.count() << ", sampled " << gap
                   << " mm, certified " << a.bound_mm << " mm");
  CHECK(gap <= a.bound_mm);
  CHECK(a.bound_mm <= 0.01);
}

TEST_CASE("fit_to_profile: what cannot conform is refused, named", "[receiver][errors]") {
  RefitOptions fit;
  fit.tolerance_mm = 1e-9;  // no 32 x 32 quintic comes this close to a dense bicubic
  fit.relative_tolerance = 0;
  surface::BSplineSurface dense = dome(3, 60);
  dense.points(dense.points.rows() / 2, 2) += 3;  // a bump no light net follows to 1e-9
  const auto [category, message] =
      error_of([&] { fit_to_profile(dense, receiver_profile("class_a"), fit, "surface 'panel'"); });
  CHECK(category == ErrorCategory::ToleranceNotMet);
  CHECK_THAT(message, Contains("surface 'panel' does not conform to the class_a profile") &&
                          Contains("misses the tolerance"));
  // Above degree 25 there is no exact form to write.
  const surface::BSplineSurface too_high = dome(26, 27);
  const auto [exact_category, exact_message] =
      error_of([&] { fit_to_profile(too_high, receiver_profile("exact"), fit, "surface 'x'"); });
  CHECK(exact_category == ErrorCategory::DegreeLimit);
  CHECK_THAT(exact_message, Contains("surface 'x' cannot be written exactly"));
}
