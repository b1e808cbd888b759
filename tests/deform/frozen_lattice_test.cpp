// The fast path (power basis, Horner, blocks, threads) against the reference evaluations.
#include <catch2/catch.hpp>

#include <clay/deform/frozen_lattice.hpp>

#include <random>
#include <vector>

#include "fixtures.hpp"
#include "random_geometry.hpp"

using namespace clay::deform;
using clay::test::random_frame;
using clay::test::size_of;

static_assert(PointDeformation<BezierLattice>);
static_assert(PointDeformation<BSplineLattice>);
static_assert(PointDeformation<FrozenLattice>);

namespace {

/// Points inside, outside, on the six faces, on edges and corners, in an order that mixes cells.
Points3 test_points(const Frame& f, std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> in(0.0, 1.0), wide(-0.3, 1.3);
  std::uniform_int_distribution<int> pick(0, 1);
  Points3 p(n, 3);
  for (int r = 0; r < n; ++r) {
    Eigen::Vector3d stu(in(rng), in(rng), in(rng));
    switch (r % 5) {
      case 0:  // anywhere around the lattice, a third of them outside
        stu = Eigen::Vector3d(wide(rng), wide(rng), wide(rng));
        break;
      case 1:  // on a face
        stu[r % 3] = pick(rng);
        break;
      case 2:  // on an edge or a corner
        stu[r % 3] = pick(rng);
        stu[(r + 1) % 3] = pick(rng);
        if (r % 7 == 0) stu[(r + 2) % 3] = pick(rng);
        break;
      default:
        break;
    }
    p.row(r) = f.point(stu[0], stu[1], stu[2]).transpose();
  }
  return p;
}

/// Largest difference between the rows of `fast` and the reference, relative to `size`.
template <class Lattice>
double worst_relative(const Lattice& L, const Points3& points, const Points3& fast, double size) {
  double worst = 0;
  for (Eigen::Index r = 0; r < points.rows(); ++r)
    worst = std::max(worst, (fast.row(r).transpose() -
                             deform_point(L, Eigen::Vector3d(points.row(r).transpose())))
                                .norm());
  return worst / size;
}

template <class Lattice>
void check_against_reference(const Lattice& L, std::mt19937& rng, int n) {
  const FrozenLattice frozen(L);
  const Points3 points = test_points(L.frame, rng, n);
  const double size = size_of(L.points);
  for (int threads : {1, 2}) {
    const Points3 rows = deform_points(frozen, points, DeformOptions{threads});
    const double worst = worst_relative(L, points, rows, size);
    INFO("threads " << threads << ": rows, largest relative difference " << worst);
    CHECK(worst < 1e-13);
    // Structure of arrays, then in place (the same numbers as out of place).
    std::vector<double> x(static_cast<size_t>(n)), y(x.size()), z(x.size());
    for (int r = 0; r < n; ++r) {
      x[static_cast<size_t>(r)] = points(r, 0);
      y[static_cast<size_t>(r)] = points(r, 1);
      z[static_cast<size_t>(r)] = points(r, 2);
    }
    std::vector<double> ox(x.size()), oy(x.size()), oz(x.size());
    deform_points(frozen, PointColumns{x, y, z}, MutablePointColumns{ox, oy, oz},
                  DeformOptions{threads});
    Points3 columns(n, 3);
    for (int r = 0; r < n; ++r)
      columns.row(r) << ox[static_cast<size_t>(r)], oy[static_cast<size_t>(r)],
          oz[static_cast<size_t>(r)];
    CHECK(worst_relative(L, points, columns, size) < 1e-13);
    deform_points(frozen, PointColumns{x, y, z}, MutablePointColumns{x, y, z},
                  DeformOptions{threads});
    CHECK((x == ox && y == oy && z == oz));
    // Interleaved buffers (a NumPy (n, 3) array): the same numbers as the row form, and in place.
    std::vector<double> xyz(points.data(), points.data() + points.size()), out(xyz.size());
    deform_points(frozen, xyz, out, DeformOptions{threads});
    Points3 interleaved = Eigen::Map<const Points3>(out.data(), n, 3);
    CHECK(worst_relative(L, points, interleaved, size) < 1e-13);
    deform_points(frozen, xyz, xyz, DeformOptions{threads});
    CHECK(xyz == out);
  }
  // One point at a time through the same power form.
  for (int r = 0; r < std::min(50, n); ++r) {
    const Eigen::Vector3d x = points.row(r).transpose();
    CHECK((deform_point(frozen, x) - deform_point(L, x)).norm() / size < 1e-13);
  }
}

}  // namespace

TEST_CASE("fast evaluation equals de Casteljau for Bezier lattices, one and two threads",
          "[deform]") {
  std::mt19937 rng(31);
  // Sizes that are not multiples of the block, above the two-thread threshold.
  for (auto degrees :
       {std::array{3, 3, 3}, std::array{2, 2, 2}, std::array{1, 1, 1}, std::array{2, 4, 3}}) {
    const BezierLattice L =
        clay::test::displaced(make_bezier_lattice(random_frame(rng), degrees), rng, 0.3);
    INFO("degrees " << degrees[0] << degrees[1] << degrees[2]);
    check_against_reference(L, rng, 33'003);
  }
  // Tiny inputs: fewer points than a block.
  const BezierLattice L =
      clay::test::displaced(make_bezier_lattice(random_frame(rng), {3, 3, 3}), rng);
  check_against_reference(L, rng, 5);
}

TEST_CASE("fast evaluation equals de Boor for B-spline lattices, one and two threads", "[deform]") {
  std::mt19937 rng(32);
  check_against_reference(
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {8, 8, 8}), rng,
                            0.3),
      rng, 40'001);
  // Several sort chunks (32,768 points) per thread, so that each chunk's output runs fused with
  // the next one's locate, the last chunk shorter and ending in a partial block (4 chunks and
  // 13 points on one thread; 2 chunks and 8 or 5 points a thread on two).
  check_against_reference(
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {8, 8, 8}), rng,
                            0.3),
      rng, 131'085);
  check_against_reference(
      clay::test::displaced(
          make_bspline_lattice(random_frame(rng), {2, 3, 1}, {3, 5, 2}, LatticeKnots::Uniform), rng,
          0.3),
      rng, 20'000);
  // Non-uniform knots (binary-search cell lookup) and degrees without a specialized kernel.
  const std::array<clay::surface::BSplineBasis, 3> bases = {
      clay::test::random_basis(rng, 3, 7, true, 2), clay::test::random_basis(rng, 4, 6, false, 1),
      clay::test::random_basis(rng, 2, 5, true, 2)};
  check_against_reference(
      clay::test::displaced(make_bspline_lattice(random_frame(rng), bases), rng, 0.3), rng, 35'000);
  // Non-uniform cubic: the specialized kernel with the out-of-line cell search.
  const std::array<clay::surface::BSplineBasis, 3> cubic = {
      clay::test::random_basis(rng, 3, 9, true, 1), clay::test::random_basis(rng, 3, 6, true, 1),
      clay::test::random_basis(rng, 3, 8, false, 1)};
  check_against_reference(
      clay::test::displaced(make_bspline_lattice(random_frame(rng), cubic), rng, 0.3), rng, 35'000);
  check_against_reference(
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {2, 2, 2}), rng),
      rng, 3);
}

TEST_CASE("deform_points on lattices freezes once and matches the frozen lattice", "[deform]") {
  std::mt19937 rng(33);
  const BSplineLattice S =
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {2, 3, 4}), rng);
  const Points3 p = test_points(S.frame, rng, 1000);
  CHECK(deform_points(S, p) == deform_points(FrozenLattice(S), p));
  const BezierLattice B =
      clay::test::displaced(make_bezier_lattice(random_frame(rng), {3, 1, 2}), rng);
  CHECK(deform_points(B, p) == deform_points(FrozenLattice(B), p));
  const FrozenLattice f(S);
  CHECK(f.cells() == std::array{2, 3, 4});
  CHECK(f.degrees() == std::array{3, 3, 3});
}
