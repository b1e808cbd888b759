// Every bad input raises clay::Error naming the culprit and the fix.
#include <catch2/catch.hpp>

#include <clay/deform.hpp>

#include <limits>
#include <span>
#include <vector>

#include "error_of.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;

TEST_CASE("a zero-volume frame is rejected", "[deform]") {
  Frame f;
  f.u = f.s + 2 * f.t;  // coplanar with S and T
  const auto [category, what] = error_of([&] { make_bezier_lattice(f, {2, 2, 2}); });
  CHECK(category == ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("coplanar") && Contains("zero volume") && Contains("independent edge"));
  CHECK(error_of([&] {
          make_bspline_lattice(f, {3, 3, 3}, {2, 2, 2});
        }).first == ErrorCategory::InvalidGeometry);
}

TEST_CASE("a degree below one is rejected", "[deform]") {
  const auto [category, what] = error_of([] { make_bezier_lattice(Frame{}, {3, 0, 3}); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Contains("degree along t = 0") && Contains("1 <= degree"));
  BezierLattice L = make_bezier_lattice(Frame{}, {2, 2, 2});
  L.degrees[2] = 0;
  CHECK_THAT(error_of([&] { validate(L); }).second, Contains("degree along u = 0"));
}

TEST_CASE("a wrong control point count is rejected", "[deform]") {
  BSplineLattice S = make_bspline_lattice(Frame{}, {3, 3, 3}, {2, 2, 2});
  S.points.conservativeResize(S.points.rows() - 1, 3);
  const auto [category, what] = error_of([&] { FrozenLattice{S}; });
  CHECK(category == ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("124 control points") && Contains("5 x 5 x 5 = 125"));
}

TEST_CASE("non-finite values are rejected naming the control point or the frame vector",
          "[deform]") {
  BezierLattice L = make_bezier_lattice(Frame{}, {2, 3, 1});
  L.points(L.index(1, 2, 0), 1) = std::numeric_limits<double>::quiet_NaN();
  const auto [category, what] = error_of([&] { jacobian_bounds(L); });
  CHECK(category == ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("P_1,2,0") && Contains("not finite"));
  Frame f;
  f.origin.x() = std::numeric_limits<double>::infinity();
  CHECK_THAT(error_of([&] { make_bezier_lattice(f, {1, 1, 1}); }).second, Contains("origin X0"));
}

TEST_CASE("bad options and arguments are rejected naming the field", "[deform]") {
  const BezierLattice L = make_bezier_lattice(Frame{}, {1, 1, 1});
  const Points3 p = Points3::Zero(4, 3);
  const auto [category, what] = error_of([&] { deform_points(L, p, DeformOptions{-1}); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Contains("DeformOptions::threads = -1") && Contains("0 <= threads"));
  CHECK_THAT(error_of([] {
               make_bspline_lattice(Frame{}, {3, 3, 3}, {2, 0, 2});
             }).second,
             Contains("cells along t = 0"));
  const FaceContinuity too_smooth[] = {{Face::TMin, 4}};
  CHECK_THAT(error_of([&] { locked_control_points(L, too_smooth); }).second,
             Contains("FaceContinuity{t_min}.order = 4") && Contains("0 <= order <= 1"));
  std::vector<double> a(3), b(2);
  CHECK_THAT(error_of([&] {
               deform_points(FrozenLattice(L), PointColumns{a, a, a}, MutablePointColumns{a, a, b});
             }).second,
             Contains("same size"));
  std::vector<double> seven(7), six(6);
  const auto interleaved = error_of([&] {
    deform_points(FrozenLattice(L), std::span<const double>(seven), std::span<double>(seven));
  });
  CHECK(interleaved.first == ErrorCategory::InvalidArgument);
  CHECK_THAT(interleaved.second, Contains("7 in") && Contains("multiple of 3"));
  CHECK_THAT(error_of([&] {
               deform_points(FrozenLattice(L), std::span<const double>(six), std::span<double>(a));
             }).second,
             Contains("6 in and 3 out"));
}

TEST_CASE("a B-spline basis whose domain is not the unit interval is rejected", "[deform]") {
  auto basis = clay::surface::clamped_uniform_basis(2, 4, 0.0, 2.0);
  const auto [category, what] = error_of([&] {
    make_bspline_lattice(Frame{}, {clay::surface::clamped_uniform_basis(2, 4), basis,
                                   clay::surface::clamped_uniform_basis(2, 4)});
  });
  CHECK(category == ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("t basis") && Contains("is not [0, 1]"));
}

TEST_CASE("Options structs list every bad field, not only the first", "[deform][errors]") {
  RefitOptions refit;
  refit.degree = 0;
  refit.relative_tolerance = -1;
  refit.tolerance_mm = 0.01;  // one tolerance > 0: the negative one is the only tolerance problem
  refit.certificate_share = 2;
  const auto list = refit.problems();
  REQUIRE(list.size() == 3);
  CHECK_THAT(list[0], Contains("degree = 0"));
  CHECK_THAT(list[1], Contains("tolerance = -1"));
  CHECK_THAT(list[2], Contains("certificate_share = 2"));
  const auto [category, what] = error_of([&] { refit.validate(); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Contains("degree = 0") && Contains("tolerance = -1") &&
                       Contains("certificate_share = 2"));
  CHECK(RefitOptions{}.problems().empty());

  // Nested options: the parts' problems are gathered too.
  SurfaceDeformationOptions both;
  both.compose.check_samples = -1;
  both.refit = RefitOptions{};
  both.refit->max_iterations = 0;
  CHECK(both.problems().size() == 2);

  StyleOptions style;
  style.lambda = 2;
  style.bound_samples = 1;
  style.projection.starts = 0;
  CHECK(style.problems().size() == 3);

  DirectManipulationOptions direct;
  direct.relative_tolerance = 0;
  direct.tied = {{1}, {-2, 3}};
  CHECK(direct.problems().size() == 3);

  FreezeOptions freeze;
  freeze.max_iterations = 0;
  freeze.threads = -1;
  CHECK(freeze.problems().size() == 2);
  ComposeOptions compose;
  compose.knot_tolerance = 1;
  compose.check_samples = 100;
  CHECK(compose.problems().size() == 2);
}
