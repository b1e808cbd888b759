// Lattices as data: eq. (1) coordinates, undisplaced points, identity, outside points, the
// Bézier / B-spline agreement and the Bézier cells of a B-spline lattice.
#include <catch2/catch.hpp>

#include <clay/deform/lattice.hpp>

#include <random>

#include "fixtures.hpp"
#include "random_geometry.hpp"

using namespace clay::deform;
using Catch::Matchers::WithinAbs;
using clay::test::random_frame;
using clay::test::sample_points;
using clay::test::size_of;

namespace {

/// Largest |f(x) - g(x)| / size over the rows of `points`.
template <class F, class G>
double worst_difference(const clay::surface::Points3& points, double size, F f, G g) {
  double worst = 0;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    const Eigen::Vector3d x = points.row(r).transpose();
    worst = std::max(worst, (f(x) - g(x)).norm() / size);
  }
  return worst;
}

Eigen::Vector3d same(const Eigen::Vector3d& x) { return x; }

}  // namespace

TEST_CASE("local coordinates invert X = X0 + sS + tT + uU (Sederberg-Parry eq. 1)", "[deform]") {
  std::mt19937 rng(1);
  for (bool left : {false, true}) {
    const Frame f = random_frame(rng, left);
    std::uniform_real_distribution<double> c(-0.5, 1.5);
    for (int n = 0; n < 100; ++n) {
      const Eigen::Vector3d stu(c(rng), c(rng), c(rng));
      const Eigen::Vector3d back = local_coordinates(f, f.point(stu[0], stu[1], stu[2]));
      CHECK((back - stu).norm() < 1e-13);
      CHECK(inside(stu) == (stu.minCoeff() >= 0 && stu.maxCoeff() <= 1));
    }
  }
}

TEST_CASE("undisplaced Bezier control points are X0 + i/l S + j/m T + k/n U", "[deform]") {
  std::mt19937 rng(2);
  const Frame f = random_frame(rng);
  const BezierLattice L = make_bezier_lattice(f, {2, 3, 4});
  REQUIRE(L.points.rows() == 3 * 4 * 5);
  for (int i = 0; i <= 2; ++i)
    for (int j = 0; j <= 3; ++j)
      for (int k = 0; k <= 4; ++k) {
        const Eigen::Vector3d expected = f.origin + i / 2.0 * f.s + j / 3.0 * f.t + k / 4.0 * f.u;
        CHECK((L.points.row(L.index(i, j, k)).transpose() - expected).norm() < 1e-13);
      }
}

TEST_CASE("undisplaced Bezier lattices are the identity", "[deform]") {
  std::mt19937 rng(3);
  for (auto degrees : {std::array{1, 1, 1}, std::array{2, 3, 1}, std::array{3, 3, 3},
                       std::array{5, 2, 4}, std::array{7, 1, 6}}) {
    for (bool left : {false, true}) {
      const BezierLattice L = make_bezier_lattice(random_frame(rng, left), degrees);
      const double size = size_of(L.points);
      const auto points = sample_points(L.frame, rng, 200);
      const double worst = worst_difference(
          points, size, [&](const Eigen::Vector3d& x) { return deform_point(L, x); }, same);
      INFO("degrees " << degrees[0] << degrees[1] << degrees[2] << " relative error " << worst);
      CHECK(worst < 1e-12);
    }
  }
}

TEST_CASE("undisplaced B-spline lattices are the identity, clamped, uniform and random knots",
          "[deform]") {
  std::mt19937 rng(4);
  struct Case {
    std::array<int, 3> degrees, cells;
  };
  for (const Case& c : {Case{{1, 1, 1}, {1, 1, 1}}, Case{{3, 3, 3}, {8, 8, 8}},
                        Case{{2, 3, 1}, {3, 5, 2}}, Case{{4, 2, 5}, {2, 7, 3}}}) {
    for (LatticeKnots knots : {LatticeKnots::Clamped, LatticeKnots::Uniform}) {
      const BSplineLattice L = make_bspline_lattice(random_frame(rng), c.degrees, c.cells, knots);
      const double size = size_of(L.points);
      const auto points = sample_points(L.frame, rng, 200);
      const double worst = worst_difference(
          points, size, [&](const Eigen::Vector3d& x) { return deform_point(L, x); }, same);
      INFO("relative error " << worst);
      CHECK(worst < 1e-12);
    }
  }
  // Non-uniform knots with repeated interior knots (C^0 joins included).
  for (int n = 0; n < 4; ++n) {
    std::array<clay::surface::BSplineBasis, 3> bases;
    for (int d = 0; d < 3; ++d)
      bases[static_cast<size_t>(d)] =
          clay::test::random_basis(rng, 1 + (n + d) % 3, 6 + d, n % 2 == 0, 2);
    const BSplineLattice L = make_bspline_lattice(random_frame(rng), bases);
    const double size = size_of(L.points);
    const auto points = sample_points(L.frame, rng, 200);
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      const Eigen::Vector3d x = points.row(r).transpose();
      CHECK((deform_point(L, x) - x).norm() / size < 1e-12);
    }
  }
}

TEST_CASE("points outside the lattice are left unchanged", "[deform]") {
  std::mt19937 rng(5);
  const BezierLattice B =
      clay::test::displaced(make_bezier_lattice(random_frame(rng), {3, 2, 3}), rng);
  const BSplineLattice S =
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {4, 4, 4}), rng);
  for (int r = 0; r < 100; ++r) {
    // One local coordinate beyond a face, the others anywhere.
    std::uniform_real_distribution<double> c(-1.0, 2.0), out(1e-9, 0.5);
    Eigen::Vector3d stu(c(rng), c(rng), c(rng));
    const int d = r % 3;
    stu[d] = (r % 2 == 0) ? -out(rng) : 1 + out(rng);
    const Eigen::Vector3d xb = B.frame.point(stu[0], stu[1], stu[2]);
    const Eigen::Vector3d xs = S.frame.point(stu[0], stu[1], stu[2]);
    CHECK(deform_point(B, xb) == xb);
    CHECK(deform_point(S, xs) == xs);
  }
}

TEST_CASE("a Bezier lattice equals the one-cell clamped B-spline lattice", "[deform]") {
  std::mt19937 rng(6);
  for (auto degrees : {std::array{1, 2, 3}, std::array{3, 3, 3}, std::array{4, 1, 2}}) {
    const Frame f = random_frame(rng);
    const BezierLattice B = clay::test::displaced(make_bezier_lattice(f, degrees), rng, 0.3);
    BSplineLattice S = make_bspline_lattice(f, degrees, {1, 1, 1});
    REQUIRE(S.points.rows() == B.points.rows());
    S.points = B.points;  // same storage order, same control points
    const double size = size_of(B.points);
    const auto points = sample_points(f, rng, 300);
    const double worst = worst_difference(
        points, size, [&](const Eigen::Vector3d& x) { return deform_point(B, x); },
        [&](const Eigen::Vector3d& x) { return deform_point(S, x); });
    INFO("relative difference " << worst);
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("Bezier cells reproduce the B-spline lattice pointwise", "[deform]") {
  std::mt19937 rng(7);
  std::vector<BSplineLattice> lattices = {
      make_bspline_lattice(random_frame(rng), {3, 3, 3}, {4, 3, 5}),
      make_bspline_lattice(random_frame(rng), {2, 1, 3}, {3, 4, 2}, LatticeKnots::Uniform),
  };
  std::array<clay::surface::BSplineBasis, 3> bases = {clay::test::random_basis(rng, 3, 8, true, 3),
                                                      clay::test::random_basis(rng, 2, 6, false, 2),
                                                      clay::test::random_basis(rng, 4, 7, true, 1)};
  lattices.push_back(make_bspline_lattice(random_frame(rng), bases));
  for (BSplineLattice L : lattices) {
    L = clay::test::displaced(std::move(L), rng, 0.3);
    const BezierCells cells = bezier_cells(L);
    const auto n = cells.counts();
    REQUIRE(cells.cells.size() == static_cast<size_t>(n[0] * n[1] * n[2]));
    const double size = size_of(L.points);
    const auto points = sample_points(L.frame, rng, 400);
    double worst = 0;
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      const Eigen::Vector3d x = points.row(r).transpose();
      const Eigen::Vector3d stu = local_coordinates(L.frame, x);
      std::array<int, 3> c{};
      for (int d = 0; d < 3; ++d) {
        const auto& br = cells.breaks[static_cast<size_t>(d)];
        c[static_cast<size_t>(d)] =
            static_cast<int>(std::upper_bound(br.begin() + 1, br.end() - 1, stu[d]) - br.begin()) -
            1;
      }
      const Eigen::Vector3d from_cell = deform_point(cells.cell(c[0], c[1], c[2]), x);
      worst = std::max(worst, (from_cell - deform_point(L, x)).norm() / size);
    }
    INFO("relative difference " << worst);
    CHECK(worst < 1e-12);
  }
}
