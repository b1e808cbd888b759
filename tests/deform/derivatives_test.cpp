// Exact derivatives with respect to the lattice points (derivatives.hpp, issue #41): the matrix
// against the composition it claims (C L), the pointwise FFD, the lattice's Bernstein basis
// written here from its definition, and central differences of compose_exact; its structure
// against a lattice moved by 1e-9.
#include <catch2/catch.hpp>

#include <clay/deform/compose.hpp>
#include <clay/deform/derivatives.hpp>
#include <clay/deform/direct_manipulation.hpp>
#include <clay/error.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <random>

#include "error_of.hpp"
#include "fixtures.hpp"

using namespace clay::deform;
using clay::ErrorCategory;
using clay::surface::BSplineSurface;
using clay::test::random_surface_in;

namespace {

/// C(n, k).
double binomial(int n, int k) {
  double b = 1;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

/// B_(i,j,k)(x) = b_i^l(s) b_j^m(t) b_k^n(u), (s, t, u) solved from x = X0 + s S + t T + u U.
double bernstein_basis(const BezierLattice& lattice, int i, int j, int k,
                       const Eigen::Vector3d& x) {
  Eigen::Matrix3d axes;
  axes << lattice.frame.s, lattice.frame.t, lattice.frame.u;
  const Eigen::Vector3d stu = axes.fullPivLu().solve(x - lattice.frame.origin);
  auto b = [](int n, int r, double t) {
    return binomial(n, r) * std::pow(t, r) * std::pow(1 - t, n - r);
  };
  return b(lattice.degrees[0], i, stu(0)) * b(lattice.degrees[1], j, stu(1)) *
         b(lattice.degrees[2], k, stu(2));
}

/// Σ_k R_k(u, v) c_k: the scalar field with control values `c` on the composed surface's net
/// (its rational basis R_k when it has weights).
double scalar_at(const BSplineSurface& net, const Eigen::VectorXd& c, double u, double v) {
  BSplineSurface s = net;
  s.points.setZero();
  s.points.col(0) = c;
  return clay::surface::evaluate(s, u, v).x();
}

struct Case {
  BezierLattice lattice;
  BSplineSurface surface;
};

/// A displaced lattice of degrees `degrees` and a surface of degrees (p, q) with interior knots
/// inside it, rational or not.
Case random_case(std::mt19937& rng, std::array<int, 3> degrees, int p, int q, bool rational) {
  const Frame frame = clay::test::random_frame(rng, false);
  return {clay::test::displaced(make_bezier_lattice(frame, degrees), rng),
          random_surface_in(frame, p, q, p + 3, q + 2, rational, rng)};
}

}  // namespace

TEST_CASE(
    "composition_jacobian: the control points are the matrix times the lattice points, the "
    "surface the pointwise FFD",
    "[derivatives]") {
  std::mt19937 rng(41);
  for (const bool rational : {false, true}) {
    INFO((rational ? "rational" : "polynomial") << " surface");
    const Case c = random_case(rng, {2, 3, 1}, 3, 2, rational);
    const CompositionJacobian j = composition_jacobian(c.lattice, c.surface);
    const double size = clay::test::size_of(c.lattice.points);
    CHECK(j.matrix.rows() == j.surface.points.rows());
    CHECK(j.matrix.cols() == c.lattice.points.rows());
    CHECK(j.surface.is_rational() == rational);
    CHECK((j.matrix * c.lattice.points - j.surface.points).cwiseAbs().maxCoeff() <= 1e-12 * size);
    // The surface is the deformation, point by point: D(S(u, v)) at 400 random parameters.
    std::uniform_real_distribution<double> at(0.0, 1.0);
    double worst = 0;
    for (int k = 0; k < 400; ++k) {
      const double u = at(rng), v = at(rng);
      const Eigen::Vector3d expected =
          deform_point(c.lattice, clay::surface::evaluate(c.surface, u, v));
      worst = std::max(worst, (clay::surface::evaluate(j.surface, u, v) - expected).norm());
    }
    CHECK(worst <= 1e-12 * size);
    // Tensor degrees: (l + m + n) p x (l + m + n) q for random control points.
    CHECK(j.surface.u.degree == 6 * 3);
    CHECK(j.surface.v.degree == 6 * 2);
  }
}

TEST_CASE("composition_jacobian: column j is the lattice's Bernstein basis B_j on the surface",
          "[derivatives]") {
  // dX(S(u, v)) / dL_j = B_j(s, t, u) I_3 (Sederberg–Parry eq. (2)), so the column's scalar field
  // on the composed net equals B_j at the original point: the basis written here from its
  // definition, at 50 random parameters for every lattice point.
  std::mt19937 rng(4101);
  for (const bool rational : {false, true}) {
    INFO((rational ? "rational" : "polynomial") << " surface");
    const Case c = random_case(rng, {1, 2, 2}, 2, 3, rational);
    const CompositionJacobian j = composition_jacobian(c.lattice, c.surface);
    const Eigen::MatrixXd dense = Eigen::MatrixXd(j.matrix);
    std::uniform_real_distribution<double> at(0.0, 1.0);
    double worst = 0;
    const auto n = c.lattice.counts();
    for (int a = 0; a < n[0]; ++a)
      for (int b = 0; b < n[1]; ++b)
        for (int d = 0; d < n[2]; ++d)
          for (int k = 0; k < 50; ++k) {
            const double u = at(rng), v = at(rng);
            const double expected =
                bernstein_basis(c.lattice, a, b, d, clay::surface::evaluate(c.surface, u, v));
            const double got = scalar_at(j.surface, dense.col(c.lattice.index(a, b, d)), u, v);
            worst = std::max(worst, std::abs(got - expected));
          }
    CHECK(worst <= 1e-12);
  }
}

TEST_CASE("composition_jacobian: equal to central differences of compose_exact", "[derivatives]") {
  // compose_exact's own form changes with the values (its lightest form), so the differences are
  // taken point by point: (D+(S(u, v)) − D−(S(u, v))) / 2h for a lattice point moved by ±h along
  // one axis, against the column's field times that axis. The map is linear: only rounding
  // separates them.
  std::mt19937 rng(4102);
  const Case c = random_case(rng, {2, 1, 2}, 3, 3, true);
  const CompositionJacobian j = composition_jacobian(c.lattice, c.surface);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(j.matrix);
  const double size = clay::test::size_of(c.lattice.points);
  const double h = 1e-2 * size;
  std::uniform_real_distribution<double> at(0.0, 1.0);
  std::uniform_int_distribution<int> which(0, static_cast<int>(c.lattice.points.rows()) - 1);
  double worst = 0, largest = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const int point = which(rng), axis = trial % 3;
    BezierLattice plus = c.lattice, minus = c.lattice;
    plus.points(point, axis) += h;
    minus.points(point, axis) -= h;
    const BSplineSurface up = compose_exact(plus, c.surface).surface;
    const BSplineSurface down = compose_exact(minus, c.surface).surface;
    for (int k = 0; k < 40; ++k) {
      const double u = at(rng), v = at(rng);
      const Eigen::Vector3d difference =
          (clay::surface::evaluate(up, u, v) - clay::surface::evaluate(down, u, v)) / (2 * h);
      Eigen::Vector3d exact = Eigen::Vector3d::Zero();
      exact(axis) = scalar_at(j.surface, dense.col(point), u, v);
      worst = std::max(worst, (difference - exact).norm());
      largest = std::max(largest, exact.norm());
    }
  }
  INFO("largest derivative " << largest << ", worst difference " << worst);
  CHECK(largest > 0.05);
  CHECK(worst <= 1e-10 * largest);
}

TEST_CASE("composition_jacobian: one structure at the identity and after a 1e-9 move",
          "[derivatives]") {
  // compose_exact composes an undisplaced lattice at the surface's own degrees and a moved one at
  // the full tensor degrees (the control point count jumps): the derivatives' form does not.
  std::mt19937 rng(4103);
  const Frame frame = clay::test::random_frame(rng, false);
  const BezierLattice identity = make_bezier_lattice(frame, {2, 2, 1});
  BezierLattice moved = identity;
  moved.points(moved.index(1, 1, 1), 2) += 1e-9;
  const BSplineSurface s = random_surface_in(frame, 3, 3, 5, 4, false, rng);
  const CompositionJacobian at_identity = composition_jacobian(identity, s);
  const CompositionJacobian after = composition_jacobian(moved, s);
  CHECK(compose_exact(identity, s).surface.points.rows() <
        compose_exact(moved, s).surface.points.rows());
  CHECK(at_identity.surface.u.knots == after.surface.u.knots);
  CHECK(at_identity.surface.v.knots == after.surface.v.knots);
  REQUIRE(at_identity.matrix.nonZeros() == after.matrix.nonZeros());
  CHECK(Eigen::MatrixXd(at_identity.matrix) == Eigen::MatrixXd(after.matrix));  // bit for bit
  // At the identity the composition is the surface itself.
  const double size = clay::test::size_of(identity.points);
  std::uniform_real_distribution<double> at(0.0, 1.0);
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    const double u = at(rng), v = at(rng);
    worst = std::max(worst, (clay::surface::evaluate(at_identity.surface, u, v) -
                             clay::surface::evaluate(s, u, v))
                                .norm());
  }
  CHECK(worst <= 1e-12 * size);
}

TEST_CASE("composition_jacobian: a surface that leaves the lattice is refused, naming the patch",
          "[derivatives]") {
  std::mt19937 rng(4104);
  const Frame frame = clay::test::random_frame(rng, false);
  BSplineSurface s = random_surface_in(frame, 2, 2, 4, 4, false, rng);
  // the four middle control points at t = 1.6: the surface leaves the lattice
  for (int r : {5, 6, 9, 10}) s.points.row(r) = frame.point(0.5, 1.6, 0.5).transpose();
  const auto [category, message] = clay::test::error_of([&] {
    (void)composition_jacobian(make_bezier_lattice(frame, {1, 1, 1}), s);
  });
  CHECK(category == ErrorCategory::OutOfDomain);
  CHECK_THAT(message, Catch::Matchers::Contains("composition_jacobian: surface patch (") &&
                          Catch::Matchers::Contains("enlarge the lattice frame"));
}

TEST_CASE(
    "influence_matrix and influence_transpose_product: the Jacobian of deformed points and "
    "its adjoint, against central differences of deform_point",
    "[derivatives]") {
  // f(L) = Σ_i G_i · X(x_i; L): ∂f/∂L_J = Σ_i B_J(x_i) G_i, taken here by central differences of
  // the pointwise deformation for a few lattice points and axes, for both kinds of lattice.
  std::mt19937 rng(4105);
  const Frame frame = clay::test::random_frame(rng, false);
  const BezierLattice bezier = clay::test::displaced(make_bezier_lattice(frame, {3, 2, 2}), rng);
  const BSplineLattice cells =
      clay::test::displaced(make_bspline_lattice(frame, {3, 2, 2}, {3, 2, 4}), rng);
  const clay::surface::Points3 x = clay::test::sample_points(frame, rng, 300);
  const clay::surface::Points3 g = clay::surface::Points3::Random(x.rows(), 3);
  auto check = [&](const auto& lattice) {
    const auto b = influence_matrix(lattice, x);
    const clay::surface::Points3 adjoint = influence_transpose_product(lattice, x, g);
    const double size = clay::test::size_of(lattice.points);
    double worst_point = 0;
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      worst_point = std::max(worst_point, (Eigen::Vector3d((b * lattice.points).row(i)) -
                                           deform_point(lattice, x.row(i).transpose()))
                                              .norm());
    CHECK(worst_point <= 1e-12 * size);
    const clay::surface::Points3 formed = b.transpose() * g;
    CHECK((formed - adjoint).cwiseAbs().maxCoeff() <= 1e-12 * adjoint.cwiseAbs().maxCoeff());
    auto f = [&](const auto& l) {
      double sum = 0;
      for (Eigen::Index i = 0; i < x.rows(); ++i)
        sum += g.row(i).dot(deform_point(l, x.row(i).transpose()).transpose());
      return sum;
    };
    std::uniform_int_distribution<int> which(0, static_cast<int>(lattice.points.rows()) - 1);
    for (int trial = 0; trial < 6; ++trial) {
      const int point = which(rng), axis = trial % 3;
      auto plus = lattice, minus = lattice;
      plus.points(point, axis) += 1.0;
      minus.points(point, axis) -= 1.0;
      const double difference = (f(plus) - f(minus)) / 2.0;
      CHECK(std::abs(difference - adjoint(point, axis)) <=
            1e-10 * std::max(1.0, std::abs(adjoint(point, axis))));
    }
    const auto [category, message] =
        clay::test::error_of([&] { (void)influence_transpose_product(lattice, x, g.topRows(10)); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(message, Catch::Matchers::Contains("one gradient row per point"));
  };
  check(bezier);
  check(cells);
}

TEST_CASE(
    "composition_jacobian with a B-spline lattice: sparse, the pointwise FFD, central "
    "differences, one structure",
    "[derivatives]") {
  // A sheet whose s depends on u only and t on v only meets the knot planes along iso-lines
  // (split there, as compose_exact splits it). Each row of C holds one cell's support.
  std::mt19937 rng(4106);
  const Frame frame = clay::test::random_frame(rng);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(frame, {3, 3, 2}, {3, 2, 1}), rng);
  const std::vector<double> x{0.05, 0.3, 0.6, 0.7, 0.95}, y{0.1, 0.4, 0.6, 0.9};
  std::uniform_real_distribution<double> lift(0.2, 0.8);
  BSplineSurface s = clay::test::surface_in(frame, 3, 2, 5, 4, false, rng, [&](int i, int j) {
    return Eigen::Vector3d(x[size_t(i)], y[size_t(j)], lift(rng));
  });
  for (const bool rational : {false, true}) {
    INFO((rational ? "rational" : "polynomial") << " sheet");
    if (rational)  // product weights a_i b_j: s stays a function of u alone
      for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 4; ++j)
          s.weights(s.index(i, j)) = (1.0 + 0.3 * i) * (1.5 - 0.1 * j * j);
    const CompositionJacobian j = composition_jacobian(lattice, s);
    const double size = clay::test::size_of(lattice.points);
    CHECK((j.matrix * lattice.points - j.surface.points).cwiseAbs().maxCoeff() <= 1e-12 * size);
    // Sparse: a row inside a patch holds one cell's support, (3 + 1)(3 + 1)(2 + 1) = 48 of the
    // 90 lattice points; one on a patch corner shared by 2 x 2 cells (in s and t; u has one
    // cell) their union, (3 + 2)(3 + 2)(2 + 1) = 75.
    int widest = 0, inside = 0;
    for (Eigen::Index r = 0; r < j.matrix.outerSize(); ++r) {
      const int n = static_cast<int>(j.matrix.row(r).nonZeros());
      widest = std::max(widest, n);
      inside += n <= 48 ? 1 : 0;
    }
    CHECK(widest <= 75);
    CHECK(inside > j.matrix.rows() / 2);
    std::uniform_real_distribution<double> at(0.0, 1.0);
    double worst = 0;
    for (int k = 0; k < 400; ++k) {
      const double u = at(rng), v = at(rng);
      worst = std::max(worst, (clay::surface::evaluate(j.surface, u, v) -
                               deform_point(lattice, clay::surface::evaluate(s, u, v)))
                                  .norm());
    }
    CHECK(worst <= 1e-12 * size);
    // Central differences of compose_exact, point by point, for a few lattice points and axes.
    const Eigen::MatrixXd dense = Eigen::MatrixXd(j.matrix);
    std::uniform_int_distribution<int> which(0, static_cast<int>(lattice.points.rows()) - 1);
    double miss = 0, largest = 0;
    for (int trial = 0; trial < 6; ++trial) {
      const int point = which(rng), axis = trial % 3;
      BSplineLattice plus = lattice, minus = lattice;
      plus.points(point, axis) += 0.5;
      minus.points(point, axis) -= 0.5;
      const BSplineSurface up = compose_exact(plus, s).surface;
      const BSplineSurface down = compose_exact(minus, s).surface;
      for (int k = 0; k < 30; ++k) {
        const double u = at(rng), v = at(rng);
        const double difference =
            (clay::surface::evaluate(up, u, v) - clay::surface::evaluate(down, u, v))(axis);
        const double exact = scalar_at(j.surface, dense.col(point), u, v);
        miss = std::max(miss, std::abs(difference - exact));
        largest = std::max(largest, std::abs(exact));
      }
    }
    INFO("largest " << largest << ", miss " << miss);
    CHECK(largest > 0.05);
    CHECK(miss <= 1e-10 * largest);
    // The undisplaced lattice gives the same C, bit for bit.
    const CompositionJacobian rest =
        composition_jacobian(make_bspline_lattice(frame, {3, 3, 2}, {3, 2, 1}), s);
    REQUIRE(rest.matrix.nonZeros() == j.matrix.nonZeros());
    CHECK(Eigen::MatrixXd(rest.matrix) == dense);
  }
  // A surface that crosses a knot plane obliquely has no exact composition: refused, named.
  const BSplineSurface oblique = random_surface_in(frame, 2, 2, 4, 4, false, rng);
  const auto [category, message] =
      clay::test::error_of([&] { (void)composition_jacobian(lattice, oblique); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Catch::Matchers::Contains("composition_jacobian: surface") &&
                          Catch::Matchers::Contains("crosses the lattice knot plane"));
}
