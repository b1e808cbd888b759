// Jacobian as a Bernstein polynomial (Sederberg–Parry §4): identity, enclosure of sampled values,
// agreement with the analytic derivative, folds.
#include <catch2/catch.hpp>

#include <clay/deform/jacobian.hpp>

#include <Eigen/LU>

#include <random>

#include "fixtures.hpp"

using namespace clay::deform;
using clay::test::random_frame;

namespace {

/// det(dX_fd/dX) by central differences of the reference deformation (independent of the
/// Bernstein product and of jacobian_matrix).
template <class Lattice>
double determinant_by_differences(const Lattice& L, const Eigen::Vector3d& x) {
  const double h = 1e-5 * std::min({L.frame.s.norm(), L.frame.t.norm(), L.frame.u.norm()});
  Eigen::Matrix3d J;
  for (int d = 0; d < 3; ++d) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(d) * h;
    J.col(d) = (deform_point(L, x + e) - deform_point(L, x - e)) / (2 * h);
  }
  return J.determinant();
}

}  // namespace

TEST_CASE("the identity lattice has Jacobian exactly one", "[deform]") {
  std::mt19937 rng(21);
  for (bool left : {false, true}) {
    const Frame f = random_frame(rng, left);
    for (auto degrees : {std::array{1, 1, 1}, std::array{3, 3, 3}, std::array{2, 4, 1}}) {
      const BernsteinVolume J = jacobian_bernstein(make_bezier_lattice(f, degrees));
      CHECK(J.degrees == std::array{3 * degrees[0] - 1, 3 * degrees[1] - 1, 3 * degrees[2] - 1});
      CHECK((J.coefficients.array() - 1).abs().maxCoeff() < 1e-13);
      const JacobianBounds b = jacobian_bounds(make_bezier_lattice(f, degrees));
      CHECK_THAT(b.min, Catch::Matchers::WithinAbs(1.0, 1e-13));
      CHECK_THAT(b.max, Catch::Matchers::WithinAbs(1.0, 1e-13));
      CHECK(b.fold_free);
    }
    const JacobianBounds s = jacobian_bounds(make_bspline_lattice(f, {3, 2, 3}, {4, 3, 5}));
    CHECK_THAT(s.min, Catch::Matchers::WithinAbs(1.0, 1e-12));
    CHECK_THAT(s.max, Catch::Matchers::WithinAbs(1.0, 1e-12));
  }
}

TEST_CASE("Jacobian bounds enclose sampled determinants", "[deform]") {
  std::mt19937 rng(22);
  for (bool left : {false, true}) {
    const BezierLattice B =
        clay::test::displaced(make_bezier_lattice(random_frame(rng, left), {3, 2, 3}), rng, 0.2);
    const BernsteinVolume J = jacobian_bernstein(B);
    const JacobianBounds b = jacobian_bounds(B);
    INFO("Bezier bounds [" << b.min << ", " << b.max << "]");
    CHECK(b.min < b.max);
    std::uniform_real_distribution<double> c(0.01, 0.99);
    for (int n = 0; n < 200; ++n) {
      const Eigen::Vector3d stu(c(rng), c(rng), c(rng));
      const Eigen::Vector3d x = B.frame.point(stu[0], stu[1], stu[2]);
      const double fd = determinant_by_differences(B, x);
      const double analytic = jacobian_matrix(B, x).determinant();
      CHECK(fd >= b.min - 1e-8);
      CHECK(fd <= b.max + 1e-8);
      CHECK_THAT(analytic, Catch::Matchers::WithinAbs(fd, 1e-7));
      // The Bernstein form is the determinant itself, not only a bound.
      CHECK_THAT(evaluate(J, stu[0], stu[1], stu[2]), Catch::Matchers::WithinAbs(analytic, 1e-12));
    }
  }
  const BSplineLattice S = clay::test::displaced(
      make_bspline_lattice(random_frame(rng), {3, 3, 2}, {3, 2, 4}), rng, 0.2);
  const JacobianBounds b = jacobian_bounds(S);
  std::uniform_real_distribution<double> c(0.01, 0.99);
  for (int n = 0; n < 200; ++n) {
    const Eigen::Vector3d x = S.frame.point(c(rng), c(rng), c(rng));
    const double fd = determinant_by_differences(S, x);
    CHECK(fd >= b.min - 1e-8);
    CHECK(fd <= b.max + 1e-8);
    CHECK_THAT(jacobian_matrix(S, x).determinant(), Catch::Matchers::WithinAbs(fd, 1e-7));
  }
}

TEST_CASE("a lattice folded through its neighbours is not fold-free", "[deform]") {
  std::mt19937 rng(23);
  const Frame f = random_frame(rng);
  // Bézier: the middle plane i = 1 of a quadratic lattice pushed past the plane i = 2.
  BezierLattice B = make_bezier_lattice(f, {2, 2, 2});
  for (int j = 0; j <= 2; ++j)
    for (int k = 0; k <= 2; ++k) B.points.row(B.index(1, j, k)) += f.s.transpose();
  const JacobianBounds b = jacobian_bounds(B);
  CHECK(!b.fold_free);
  // And it really folds: dX/ds = 2 (P2 − P1) = −S at s = 1.
  CHECK(jacobian_matrix(B, f.point(1.0, 0.5, 0.5)).determinant() < 0);
  CHECK(determinant_by_differences(B, f.point(0.99, 0.5, 0.5)) < 0);

  // B-spline: one interior control point pushed through its neighbour along T.
  BSplineLattice S = make_bspline_lattice(f, {2, 2, 2}, {3, 3, 3});
  const Eigen::Index r = S.index(2, 2, 2);
  S.points.row(r) += 0.9 * f.t.transpose();
  CHECK(!jacobian_bounds(S).fold_free);
  // A small push keeps it fold-free.
  BSplineLattice gentle = make_bspline_lattice(f, {2, 2, 2}, {3, 3, 3});
  gentle.points.row(r) += 0.05 * f.t.transpose();
  CHECK(jacobian_bounds(gentle).fold_free);
}
