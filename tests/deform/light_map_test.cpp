// The light form of a lattice step as a linear map of the lattice's points (issue #38, studio
// drags): checked against refit_deformed's own light form at the points it was fitted for, and,
// with the points moved, against a least squares solved here in one piece (the Kronecker product
// of the two collocations, QR) on samples of the pointwise lattice (deform_point).
#include <catch2/catch.hpp>

#include <clay/deform/light_map.hpp>
#include <clay/deform/refit.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/primitives.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <vector>

#include "error_of.hpp"
#include "shapes.hpp"

using namespace clay::deform;
using clay::ErrorCategory;
using clay::test::error_of;
using namespace clay::test;
namespace surface = clay::surface;

namespace {

/// A bicubic dome, 100 x 100 mm, its corner at the origin.
surface::BSplineSurface dome() {
  const auto b = surface::clamped_uniform_basis(3, 7);
  const auto x = surface::greville_abscissae(b);
  surface::Points3 p(49, 3);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) {
      const double u = 100 * x[static_cast<size_t>(i)], v = 100 * x[static_cast<size_t>(j)];
      p.row(i * 7 + j) << u, v, 25 * std::sin(0.03 * u) * std::sin(0.03 * v);
    }
  return surface::make_surface(b, b, p);
}

/// Chebyshev–Lobatto parameters, degree + 1 intervals per span (refit.hpp's fit), by hand.
std::vector<double> lobatto(const surface::BSplineBasis& b) {
  std::vector<double> breaks = b.knots;
  breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
  const int n = b.degree + 1;
  std::vector<double> t;
  for (std::size_t s = 0; s + 1 < breaks.size(); ++s)
    for (int k = 0; k < n; ++k)
      t.push_back(breaks[s] +
                  (breaks[s + 1] - breaks[s]) * 0.5 * (1 - std::cos(std::numbers::pi * k / n)));
  t.push_back(breaks.back());
  return t;
}

/// The least-squares net on the bases of `shape` of D(S) sampled at lobatto() parameters, solved
/// as one system (A_u ⊗ A_v) c = f by QR.
surface::BSplineSurface least_squares_here(const Deformation& d, const surface::BSplineSurface& s,
                                           const surface::BSplineSurface& shape) {
  const auto us = lobatto(shape.u), vs = lobatto(shape.v);
  const int cu = shape.u.count(), cv = shape.v.count();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(Eigen::Index(us.size() * vs.size()), cu * cv);
  Eigen::MatrixXd f(a.rows(), 3);
  std::vector<double> nu(static_cast<size_t>(shape.u.degree + 1)),
      nv(static_cast<size_t>(shape.v.degree + 1));
  for (std::size_t r = 0; r < us.size(); ++r)
    for (std::size_t q = 0; q < vs.size(); ++q) {
      const auto row = Eigen::Index(r * vs.size() + q);
      const int su = surface::find_span(shape.u, us[r]), sv = surface::find_span(shape.v, vs[q]);
      surface::basis_functions(shape.u, su, us[r], nu);
      surface::basis_functions(shape.v, sv, vs[q], nv);
      for (int i = 0; i <= shape.u.degree; ++i)
        for (int j = 0; j <= shape.v.degree; ++j)
          a(row, (su - shape.u.degree + i) * cv + sv - shape.v.degree + j) =
              nu[static_cast<size_t>(i)] * nv[static_cast<size_t>(j)];
      const Eigen::Vector3d x = surface::evaluate(s, us[r], vs[q]);
      f.row(row) =
          std::visit([&](const auto& l) -> Eigen::Vector3d { return deform_point(l, x); }, d)
              .transpose();
    }
  const Eigen::MatrixXd c = a.colPivHouseholderQr().solve(f);
  return surface::make_surface(shape.u, shape.v, c);
}

double largest_difference(const surface::BSplineSurface& a, const surface::BSplineSurface& b) {
  REQUIRE(a.points.rows() == b.points.rows());
  return (a.points - b.points).rowwise().norm().maxCoeff();
}

RefitOptions light_options() {
  RefitOptions o;
  o.degree = 3;
  o.keep_breakpoints = false;
  o.relative_tolerance = 5e-4;
  return o;
}

/// A (3, 3, 1) Bézier lattice around the dome, one inner top point moved (4, -3, 18) mm.
BezierLattice raised_lattice() {
  BezierLattice lattice = make_bezier_lattice(box_frame(), {3, 3, 1});
  lattice.points.row(lattice.index(1, 2, 1)) += Eigen::RowVector3d(4, -3, 18);
  return lattice;
}

/// A frame over the dome's part at x > 30 mm (u > 0.3).
Frame half_frame() {
  Frame half;
  half.origin = {30, -10, -20};
  half.s = {90, 0, 0};
  half.t = {0, 120, 0};
  half.u = {0, 0, 60};
  return half;
}

/// `light` made rational (one weight 2): not a net a light form has.
surface::BSplineSurface rational_copy(const surface::BSplineSurface& light) {
  surface::BSplineSurface rational = light;
  rational.weights = Eigen::VectorXd::Constant(rational.points.rows(), 1.0);
  rational.weights[3] = 2;
  return rational;
}

/// `call` throws clay::Error(InvalidArgument) with a message that contains `says`.
template <class Call>
void check_refused(Call&& call, const std::string& says) {
  const auto [category, message] = error_of(std::forward<Call>(call));
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Catch::Matchers::Contains(says));
}

}  // namespace

TEST_CASE("lattice_light_map: the light form again at its own points, the moved one's fit after",
          "[light_map]") {
  const surface::BSplineSurface s = dome();
  const BezierLattice lattice = raised_lattice();
  const RefitResult light = refit_deformed(Deformation(lattice), s, light_options());
  REQUIRE(light.report.certified);
  INFO(light.surface.points.rows());
  REQUIRE(light.surface.points.rows() > 16);   // a net of its own, not the 4 x 4 of a single span
  REQUIRE(light.surface.points.rows() < 400);  // small enough to solve whole here
  const LatticeLightMap map = lattice_light_map(lattice, s, light.surface);
  CHECK(map.weights.rows() == light.surface.points.rows());
  CHECK(map.weights.cols() == 32);
  CHECK(map.outside.isZero(0));  // the dome lies inside the frame
  CHECK(applies_to(map, lattice, s));

  // At the points the light form was fitted for: that light form, to rounding.
  CHECK(largest_difference(light_net(map, lattice), light.surface) < 1e-10 * 100);

  // Two points moved (a drag): the net refit would give on the same knots, solved here whole.
  BezierLattice moved = lattice;
  moved.points.row(moved.index(2, 1, 1)) += Eigen::RowVector3d(-6, 5, 22);
  moved.points.row(moved.index(0, 0, 0)) += Eigen::RowVector3d(0, 0, -9);
  const surface::BSplineSurface preview = light_net(map, moved);
  const surface::BSplineSurface expected = least_squares_here(moved, s, light.surface);
  CHECK(preview.u.knots == light.surface.u.knots);
  CHECK(largest_difference(preview, expected) < 1e-9 * 100);
  // It moved by what the lattice did, not by rounding.
  CHECK(largest_difference(preview, light.surface) > 1);
}

TEST_CASE("lattice_light_map: a B-spline lattice over part of the surface (the rest stays)",
          "[light_map]") {
  const surface::BSplineSurface s = dome();
  BSplineLattice lattice = make_bspline_lattice(half_frame(), {2, 2, 1}, {3, 2, 1});
  const RefitResult light = refit_deformed(Deformation(lattice), s, light_options());
  const LatticeLightMap map = lattice_light_map(lattice, s, light.surface);
  CHECK_FALSE(map.outside.isZero(0));  // the samples at u < 0.3 are left where they are
  lattice.points.row(lattice.index(2, 1, 1)) += Eigen::RowVector3d(2, 3, 12);
  const surface::BSplineSurface preview = light_net(map, lattice);
  CHECK(largest_difference(preview, least_squares_here(lattice, s, light.surface)) < 1e-9 * 100);
  // Far from the lattice the surface has not moved (the fit of the identity, to its tolerance).
  CHECK((surface::evaluate(preview, 0.02, 0.5) - surface::evaluate(s, 0.02, 0.5)).norm() < 0.05);
}

TEST_CASE("light_fit: the moved lattice's fit of another input at once, as the map would give",
          "[light_map]") {
  // A drag upstream of the lattice (a style's target) changes the lattice's input at every
  // update: light_fit fits it on the last light form's knots without a map.
  const surface::BSplineSurface s = dome();
  const BezierLattice lattice = raised_lattice();
  const RefitResult light = refit_deformed(Deformation(lattice), s, light_options());
  surface::BSplineSurface input = s;  // the input pushed up in its middle, as a style does
  for (Eigen::Index r = 0; r < input.points.rows(); ++r)
    input.points(r, 2) +=
        6 *
        std::exp(-(input.points.row(r).head<2>() - Eigen::RowVector2d(50, 50)).squaredNorm() / 800);
  const surface::BSplineSurface fitted = light_fit(lattice, input, light.surface);
  CHECK(fitted.u.knots == light.surface.u.knots);
  CHECK(fitted.v.knots == light.surface.v.knots);
  CHECK(largest_difference(fitted, least_squares_here(lattice, input, light.surface)) < 1e-9 * 100);
  CHECK(largest_difference(fitted, light_net(lattice_light_map(lattice, input, light.surface),
                                             lattice)) < 1e-10 * 100);
  CHECK(largest_difference(fitted, light.surface) > 1);  // it followed the input's push
  // A B-spline lattice over part of the surface: the rest is fitted where it is.
  BSplineLattice partial = make_bspline_lattice(half_frame(), {2, 2, 1}, {3, 2, 1});
  partial.points.row(partial.index(2, 1, 1)) += Eigen::RowVector3d(2, 3, 12);
  CHECK(largest_difference(light_fit(partial, input, light.surface),
                           least_squares_here(partial, input, light.surface)) < 1e-9 * 100);

  check_refused([&] { light_fit(flare(), input, light.surface); }, "light_fit: the deformation");
  check_refused([&] { light_fit(lattice, input, rational_copy(light.surface)); },
                "light_fit: the light form is rational");
}

TEST_CASE("lattice_light_map: other lattices, inputs and kinds are named", "[light_map][errors]") {
  const surface::BSplineSurface s = dome();
  const BezierLattice lattice = make_bezier_lattice(box_frame(), {3, 3, 1});
  const RefitResult light = refit_deformed(Deformation(bulge()), s, light_options());
  const LatticeLightMap map = lattice_light_map(lattice, s, light.surface);

  BezierLattice wider = lattice;
  wider.frame.s *= 1.5;
  CHECK_FALSE(applies_to(map, wider, s));
  CHECK_FALSE(applies_to(map, make_bezier_lattice(box_frame(), {2, 3, 1}), s));
  surface::BSplineSurface other = s;
  other.points(10, 2) += 1e-9;
  CHECK_FALSE(applies_to(map, lattice, other));
  CHECK_FALSE(applies_to(map, flare(), s));

  check_refused([&] { light_net(map, wider); }, "make a new map");
  check_refused([&] { lattice_light_map(flare(), s, light.surface); }, "refit it");
  check_refused([&] { lattice_light_map(lattice, s, rational_copy(light.surface)); }, "rational");
}
