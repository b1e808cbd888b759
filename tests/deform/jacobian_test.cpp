// Jacobian as a Bernstein polynomial (Sederberg–Parry §4): identity, enclosure of sampled values,
// agreement with the analytic derivative, folds.
#include <catch2/catch.hpp>

#include <clay/deform/jacobian.hpp>

#include <Eigen/LU>

#include <functional>
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

namespace {

/// The 5-point central difference of f at 0, exact for a cubic (to rounding).
Eigen::VectorXd cubic_derivative(const std::function<Eigen::VectorXd(double)>& f, double h) {
  return (8 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12 * h);
}

/// Every Jacobian coefficient of a lattice (cells concatenated for a B-spline one).
Eigen::VectorXd coefficients_of(const BezierLattice& l) {
  return jacobian_bernstein(l).coefficients;
}
Eigen::VectorXd coefficients_of(const BSplineLattice& l) {
  std::vector<double> all;
  for (const auto& cell : jacobian_bernstein(l))
    all.insert(all.end(), cell.coefficients.data(),
               cell.coefficients.data() + cell.coefficients.size());
  return Eigen::Map<Eigen::VectorXd>(all.data(), static_cast<Eigen::Index>(all.size()));
}

template <class Lattice>
void check_constraints(Lattice lattice, std::mt19937& rng) {
  std::normal_distribution<double> normal(0, 0.05 * lattice.frame.s.norm());
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    for (int c = 0; c < 3; ++c) lattice.points(r, c) += normal(rng);
  const JacobianConstraints k = jacobian_constraints(lattice);
  const Eigen::VectorXd expected = coefficients_of(lattice);
  REQUIRE(k.values.size() == expected.size());
  CHECK((k.values - expected).cwiseAbs().maxCoeff() == 0);
  REQUIRE(k.gradient.cols() == 3 * lattice.points.rows());
  // Along a random direction of every point and along single coordinates: the coefficients are
  // cubic in the points, so the 5-point difference is exact to rounding.
  clay::surface::Points3 direction(lattice.points.rows(), 3);
  for (Eigen::Index r = 0; r < direction.rows(); ++r)
    for (int c = 0; c < 3; ++c) direction(r, c) = normal(rng);
  auto along = [&](const clay::surface::Points3& d) {
    return cubic_derivative(
        [&](double h) {
          Lattice moved = lattice;
          moved.points += h * d;
          return coefficients_of(moved);
        },
        1e-2);
  };
  const Eigen::Map<const Eigen::VectorXd> flat(direction.data(), direction.size());  // row-major
  const Eigen::VectorXd d = along(direction);
  CHECK((k.gradient * flat - d).cwiseAbs().maxCoeff() <= 1e-10 * d.cwiseAbs().maxCoeff());
  for (const auto& [point, axis] : {std::pair{0, 2}, std::pair{5, 0}, std::pair{11, 1}}) {
    clay::surface::Points3 unit = clay::surface::Points3::Zero(lattice.points.rows(), 3);
    unit(point, axis) = 1;
    const Eigen::VectorXd e = along(unit);
    const Eigen::VectorXd column = Eigen::MatrixXd(k.gradient).col(3 * point + axis);
    CHECK((column - e).cwiseAbs().maxCoeff() <= 1e-10 * std::max(1.0, e.cwiseAbs().maxCoeff()));
  }
}

}  // namespace

TEST_CASE("jacobian_constraints: the coefficients and their exact gradient against differences",
          "[deform]") {
  std::mt19937 rng(41);
  for (bool left : {false, true}) {
    const Frame f = random_frame(rng, left);
    check_constraints(make_bezier_lattice(f, {2, 2, 1}), rng);
    check_constraints(make_bezier_lattice(f, {3, 2, 2}), rng);
    check_constraints(make_bspline_lattice(f, {2, 2, 2}, {2, 1, 2}), rng);
  }
  // A B-spline lattice's rows hold one cell's support only.
  const JacobianConstraints k =
      jacobian_constraints(make_bspline_lattice(random_frame(rng, false), {2, 2, 2}, {3, 3, 3}));
  const Eigen::Index per_row = k.gradient.row(0).nonZeros();
  CHECK(per_row <= 3 * 27);
  CHECK(k.gradient.cols() == 3 * 125);
}
