// Direct manipulation (Hsu–Hughes–Kaufman §3): targets reached, the displacement of least norm
// (against a dense SVD pseudo-inverse of a B built here from unit-displaced lattices), the
// least-squares compromise of conflicting requests, locked and tied control points, errors.
#include <catch2/catch.hpp>

#include <clay/deform/continuity.hpp>
#include <clay/deform/direct_manipulation.hpp>

#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "error_of.hpp"
#include "fixtures.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using clay::ErrorCategory;
using clay::test::error_of;
using clay::test::random_frame;
using clay::test::sample_points;

namespace {

/// B of eq. (2) built without the library's basis code: column c is the deformation of the
/// selected points by the lattice whose control points are all zero but P_c = (1, 0, 0).
template <class Lattice>
Eigen::MatrixXd dense_influence(const Lattice& lattice, const Points3& x) {
  Lattice unit = lattice;
  Eigen::MatrixXd b(x.rows(), lattice.points.rows());
  for (Eigen::Index c = 0; c < lattice.points.rows(); ++c) {
    unit.points.setZero();
    unit.points(c, 0) = 1.0;
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      b(i, c) = deform_point(unit, Eigen::Vector3d(x.row(i).transpose())).x();
  }
  return b;
}

/// Images of the selected points under the lattice, by the reference deform_point.
template <class Lattice>
Points3 images_of(const Lattice& lattice, const Points3& x) {
  Points3 out(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    out.row(i) = deform_point(lattice, Eigen::Vector3d(x.row(i).transpose())).transpose();
  return out;
}

/// Minimal-norm least-squares solution of a X = rhs by a dense SVD (singular values below
/// 1e-10 of the largest count as zero).
Eigen::MatrixXd svd_solve(const Eigen::MatrixXd& a, const Eigen::MatrixXd& rhs) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-10);
  return svd.solve(rhs);
}

std::vector<PointMove> moves_of(const Points3& x, const Points3& targets) {
  std::vector<PointMove> moves;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    moves.push_back({x.row(i).transpose(), targets.row(i).transpose()});
  return moves;
}

/// Largest distance between the selected points' images under `lattice` and the targets.
template <class Lattice>
double worst_miss(const Lattice& lattice, const Points3& x, const Points3& targets) {
  return (images_of(lattice, x) - targets).rowwise().norm().maxCoeff();
}

/// Feasible request on a displaced lattice: targets hit, the displacement equals the SVD
/// pseudo-inverse solution, and a solution plus a null-space vector is longer.
template <class Lattice>
void check_minimal_norm(const Lattice& lattice, std::mt19937& rng, int count) {
  const Points3 x = sample_points(lattice.frame, rng, count, 0.1, 0.9);
  std::uniform_real_distribution<double> c(-5.0, 5.0);
  Points3 targets = images_of(lattice, x);
  for (Eigen::Index i = 0; i < targets.rows(); ++i)
    targets.row(i) += Eigen::RowVector3d(c(rng), c(rng), c(rng));
  const auto moves = moves_of(x, targets);
  const auto result = manipulate(lattice, moves);
  INFO(result.report.brief());
  CHECK(result.report.feasible);
  CHECK(result.report.rank == count);
  CHECK(result.report.requested == count);
  CHECK_THAT(result.report.residual, WithinAbs(0.0, 1e-10));
  CHECK(worst_miss(result.lattice, x, targets) < 1e-10);  // evaluated independently
  CHECK(result.report.achieved_max_error < 1e-10);

  const Eigen::MatrixXd b = dense_influence(lattice, x);
  const Eigen::MatrixXd dq = targets - images_of(lattice, x);
  const Eigen::MatrixXd expected = svd_solve(b, dq);
  const Eigen::MatrixXd dp = result.lattice.points - lattice.points;
  CHECK((dp - expected).cwiseAbs().maxCoeff() < 1e-10);
  CHECK_THAT(result.report.displacement_norm, WithinAbs(expected.norm(), 1e-10));

  // Any other solution is longer: add a null-space vector of B.
  Eigen::JacobiSVD<Eigen::MatrixXd> full(b, Eigen::ComputeFullV);
  const Eigen::VectorXd null = full.matrixV().col(b.cols() - 1);
  CHECK((b * null).norm() < 1e-12);
  Lattice other = result.lattice;
  other.points.col(1) += 0.5 * null;
  CHECK(worst_miss(other, x, targets) < 1e-10);
  // |ΔP + 0.5 v|² = |ΔP|² + 0.25: ΔP lies in the row space of B, orthogonal to v.
  const double other_norm = (other.points - lattice.points).norm();
  CHECK_THAT(other_norm * other_norm - expected.squaredNorm(), WithinAbs(0.25, 1e-9));
}

}  // namespace

TEST_CASE("influence matrix equals the unit-displacement construction and sums to one",
          "[deform]") {
  std::mt19937 rng(41);
  const BSplineLattice s = make_bspline_lattice(random_frame(rng), {3, 2, 3}, {2, 3, 2});
  const Points3 x = sample_points(s.frame, rng, 7);
  const Eigen::MatrixXd b(influence_matrix(s, x));
  CHECK((b - dense_influence(s, x)).cwiseAbs().maxCoeff() < 1e-14);
  CHECK((b.rowwise().sum().array() - 1.0).abs().maxCoeff() < 1e-14);  // partition of unity
  const auto sparse = influence_matrix(s, x);
  for (Eigen::Index i = 0; i < sparse.outerSize(); ++i)
    CHECK(sparse.row(i).nonZeros() <= 4 * 3 * 4);  // (p+1)(q+1)(r+1)

  const BezierLattice z = make_bezier_lattice(random_frame(rng), {2, 3, 1});
  const Points3 y = sample_points(z.frame, rng, 5);
  CHECK((Eigen::MatrixXd(influence_matrix(z, y)) - dense_influence(z, y)).cwiseAbs().maxCoeff() <
        1e-14);
}

TEST_CASE("one point moves by the closed form of eq. 4", "[deform]") {
  std::mt19937 rng(42);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {3, 3, 3}), rng);
  const Points3 x = sample_points(lattice.frame, rng, 1, 0.2, 0.8);
  const Eigen::Vector3d image = deform_point(lattice, Eigen::Vector3d(x.row(0).transpose()));
  const PointMove move{x.row(0).transpose(), image + Eigen::Vector3d(3.0, -2.0, 4.0)};
  const auto result = manipulate(lattice, std::span(&move, 1));
  // Hsu eq. (4): B⁺ = Bᵀ / |B|², so ΔP = Bᵀ Δq / |B|².
  const Eigen::VectorXd b = dense_influence(lattice, x).row(0).transpose();
  const Eigen::MatrixXd expected = b * Eigen::RowVector3d(3.0, -2.0, 4.0) / b.squaredNorm();
  CHECK((Eigen::MatrixXd(result.lattice.points - lattice.points) - expected).cwiseAbs().maxCoeff() <
        1e-12);
  CHECK((deform_point(result.lattice, move.point) - move.target).norm() < 1e-10);
  CHECK_THAT(result.report.displacement_norm, WithinAbs(std::sqrt(29.0) / b.norm(), 1e-10));
}

TEST_CASE("feasible requests reach their targets with the least displacement", "[deform]") {
  std::mt19937 rng(43);
  SECTION("B-spline lattice, 9 points") {
    check_minimal_norm(
        clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 2}, {2, 3, 2}), rng),
        rng, 9);
  }
  SECTION("uniform-knot B-spline lattice, 5 points") {
    check_minimal_norm(
        clay::test::displaced(make_bspline_lattice(random_frame(rng, true), {2, 2, 2}, {3, 2, 3},
                                                   LatticeKnots::Uniform),
                              rng),
        rng, 5);
  }
  SECTION("Bezier lattice, 6 points") {
    check_minimal_norm(
        clay::test::displaced(make_bezier_lattice(random_frame(rng), {3, 2, 3}), rng), rng, 6);
  }
}

TEST_CASE("the same point pulled to two targets gets the least-squares compromise", "[deform]") {
  std::mt19937 rng(44);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {2, 2, 2}), rng);
  const Eigen::Vector3d x = lattice.frame.point(0.3, 0.6, 0.45);
  const Eigen::Vector3d image = deform_point(lattice, x);
  const Eigen::Vector3d t1 = image + Eigen::Vector3d(4.0, 0.0, 1.0);
  const Eigen::Vector3d t2 = image + Eigen::Vector3d(-2.0, 3.0, 1.0);
  const PointMove moves[] = {{x, t1}, {x, t2}};
  const auto result = manipulate(lattice, moves);
  const auto& r = result.report;
  INFO(r.summary.message);
  CHECK_FALSE(r.feasible);
  CHECK(r.rank == 1);
  // Both rows of B are equal: the least-squares image is the midpoint, each target missed by
  // half the distance, residual sqrt(2) times that.
  const double half = (t1 - t2).norm() / 2;
  CHECK((deform_point(result.lattice, x) - (t1 + t2) / 2).norm() < 1e-10);
  CHECK_THAT(r.achieved_max_error, WithinAbs(half, 1e-10));
  CHECK_THAT(r.residual, WithinAbs(std::sqrt(2.0) * half, 1e-10));
  CHECK_THAT(r.summary.message, Contains("cannot be met") && Contains("refine the lattice"));
  // Minimal norm: the one-point move to the midpoint (eq. (4)).
  const PointMove mid{x, (t1 + t2) / 2};
  const auto single = manipulate(lattice, std::span(&mid, 1));
  CHECK((result.lattice.points - single.lattice.points).cwiseAbs().maxCoeff() < 1e-10);
  // The same request twice is consistent: feasible, rank 1, the one-point move.
  const PointMove twice[] = {mid, mid};
  const auto repeated = manipulate(lattice, twice);
  CHECK(repeated.report.feasible);
  CHECK(repeated.report.rank == 1);
  CHECK_THAT(repeated.report.summary.message, Contains("some requests repeat others"));
  CHECK((repeated.lattice.points - single.lattice.points).cwiseAbs().maxCoeff() < 1e-10);
}

TEST_CASE("an over-determined request reports the least-squares residual of a dense solve",
          "[deform]") {
  std::mt19937 rng(45);
  const BezierLattice lattice =
      clay::test::displaced(make_bezier_lattice(random_frame(rng), {1, 1, 1}), rng);
  const Points3 x = sample_points(lattice.frame, rng, 12, 0.05, 0.95);
  std::uniform_real_distribution<double> c(-3.0, 3.0);
  Points3 targets = images_of(lattice, x);
  for (Eigen::Index i = 0; i < targets.rows(); ++i)
    targets.row(i) += Eigen::RowVector3d(c(rng), c(rng), c(rng));
  const auto result = manipulate(lattice, moves_of(x, targets));
  CHECK(result.report.rank == 8);
  CHECK(result.report.unknowns == 8);
  CHECK_FALSE(result.report.feasible);
  const Eigen::MatrixXd b = dense_influence(lattice, x);
  const Eigen::MatrixXd dq = targets - images_of(lattice, x);
  const Eigen::MatrixXd dp = svd_solve(b, dq);
  CHECK_THAT(result.report.residual, WithinAbs((b * dp - dq).norm(), 1e-10));
  CHECK((Eigen::MatrixXd(result.lattice.points - lattice.points) - dp).cwiseAbs().maxCoeff() <
        1e-10);
  const Eigen::MatrixXd reached = images_of(lattice, x) + b * dp;
  CHECK((Eigen::MatrixXd(images_of(result.lattice, x)) - reached).cwiseAbs().maxCoeff() < 1e-10);
  CHECK_THAT(result.report.achieved_max_error,
             WithinAbs((reached - targets).rowwise().norm().maxCoeff(), 1e-10));
}

TEST_CASE("locked control points keep their positions bit for bit", "[deform]") {
  std::mt19937 rng(46);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {3, 3, 3}, {3, 3, 3}), rng);
  const FaceContinuity faces[] = {{Face::SMin, 1}, {Face::UMax, 0}};
  DirectManipulationOptions options;
  options.locked = locked_control_points(lattice, faces);
  const Points3 x = sample_points(lattice.frame, rng, 6, 0.15, 0.85);
  Points3 targets = images_of(lattice, x);
  targets.col(2).array() += 2.0;
  const auto result = manipulate(lattice, moves_of(x, targets), options);
  INFO(result.report.brief());
  CHECK(result.report.feasible);
  CHECK(worst_miss(result.lattice, x, targets) < 1e-10);
  int moved = 0;
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r) {
    if (options.locked[static_cast<size_t>(r)]) {
      CHECK((result.lattice.points.row(r).array() == lattice.points.row(r).array()).all());
    } else if ((result.lattice.points.row(r) - lattice.points.row(r)).norm() > 0) {
      ++moved;
    }
  }
  CHECK(moved > 0);
  // Minimal norm over the free control points: SVD on B's free columns.
  const Eigen::MatrixXd b = dense_influence(lattice, x);
  std::vector<Eigen::Index> free;
  for (Eigen::Index r = 0; r < b.cols(); ++r)
    if (!options.locked[static_cast<size_t>(r)]) free.push_back(r);
  Eigen::MatrixXd bf(b.rows(), static_cast<Eigen::Index>(free.size()));
  for (size_t k = 0; k < free.size(); ++k) bf.col(static_cast<Eigen::Index>(k)) = b.col(free[k]);
  const Eigen::MatrixXd dp = svd_solve(bf, Eigen::MatrixXd(targets - images_of(lattice, x)));
  for (size_t k = 0; k < free.size(); ++k)
    CHECK((result.lattice.points.row(free[k]) - lattice.points.row(free[k]) -
           dp.row(static_cast<Eigen::Index>(k)))
              .norm() < 1e-10);

  SECTION("a point moved only by locked control points stays, and says so") {
    // On the face s = 0 only the face plane acts (clamped knots), and it is locked; eq. (1)
    // rounds s to about 1e-17, so the free plane i = 2 acts with weights ~s² (not a 1e34 move).
    const PointMove on_face{
        lattice.frame.point(0.0, 0.5, 0.5),
        deform_point(lattice, lattice.frame.point(0.0, 0.5, 0.5)) + Eigen::Vector3d(1, 0, 0)};
    const auto stuck = manipulate(lattice, std::span(&on_face, 1), options);
    CHECK(stuck.report.rank == 0);
    CHECK_FALSE(stuck.report.feasible);
    CHECK_THAT(stuck.report.achieved_max_error, WithinAbs(1.0, 1e-12));
    CHECK_THAT(stuck.report.residual, WithinAbs(1.0, 1e-12));
    CHECK(stuck.report.displacement_norm == 0.0);
    CHECK_THAT(stuck.report.summary.message, Contains("all locked"));
  }
}

TEST_CASE("tied control points move together, minimal norm over B S", "[deform]") {
  std::mt19937 rng(47);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(random_frame(rng), {2, 2, 2}, {3, 3, 3}), rng);
  const Eigen::Index M = lattice.points.rows();
  DirectManipulationOptions options;
  options.tied = {{lattice.index(2, 2, 2), lattice.index(2, 2, 3), lattice.index(2, 3, 2)},
                  {lattice.index(1, 1, 1), lattice.index(3, 3, 3)},
                  {lattice.index(0, 0, 0), lattice.index(1, 2, 2)}};
  options.locked.assign(static_cast<size_t>(M), false);
  options.locked[static_cast<size_t>(lattice.index(0, 0, 0))] = true;  // locks the third group
  const Points3 x = sample_points(lattice.frame, rng, 5, 0.2, 0.8);
  Points3 targets = images_of(lattice, x);
  targets.col(0).array() -= 1.5;
  targets.col(1).array() += 0.5;
  const auto result = manipulate(lattice, moves_of(x, targets), options);
  INFO(result.report.brief());
  CHECK(result.report.feasible);
  CHECK(worst_miss(result.lattice, x, targets) < 1e-10);
  const Points3 dp = result.lattice.points - lattice.points;
  for (size_t g = 0; g < 2; ++g)
    for (const Eigen::Index r : options.tied[g])
      CHECK((dp.row(r) - dp.row(options.tied[g][0])).norm() < 1e-12);
  CHECK(dp.row(lattice.index(0, 0, 0)).norm() == 0.0);
  CHECK(dp.row(lattice.index(1, 2, 2)).norm() == 0.0);
  CHECK(dp.row(lattice.index(2, 2, 2)).norm() > 0.0);

  // Hsu eq. (6)-(7): S maps the unknowns (free rows, then groups) to the rows; ΔP = S (B S)⁺ Δq.
  std::vector<std::vector<Eigen::Index>> unknowns = {options.tied[0], options.tied[1]};
  std::vector<bool> taken(static_cast<size_t>(M), false);
  for (const auto& g : options.tied)
    for (const Eigen::Index r : g) taken[static_cast<size_t>(r)] = true;
  for (Eigen::Index r = 0; r < M; ++r)
    if (!taken[static_cast<size_t>(r)]) unknowns.push_back({r});
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(M, static_cast<Eigen::Index>(unknowns.size()));
  for (size_t c = 0; c < unknowns.size(); ++c)
    for (const Eigen::Index r : unknowns[c]) s(r, static_cast<Eigen::Index>(c)) = 1.0;
  const Eigen::MatrixXd b = dense_influence(lattice, x);
  const Eigen::MatrixXd expected =
      s * svd_solve(b * s, Eigen::MatrixXd(targets - images_of(lattice, x)));
  CHECK((Eigen::MatrixXd(dp) - expected).cwiseAbs().maxCoeff() < 1e-10);
}

TEST_CASE("a manipulator factorizes once and follows dragged targets", "[deform]") {
  std::mt19937 rng(48);
  const BezierLattice lattice =
      clay::test::displaced(make_bezier_lattice(random_frame(rng), {3, 3, 3}), rng);
  const Points3 x = sample_points(lattice.frame, rng, 4, 0.1, 0.9);
  const DirectManipulator<BezierLattice> drag(lattice, x);
  CHECK(drag.rank() == 4);
  CHECK(drag.unknowns() == 64);
  CHECK((drag.images() - images_of(lattice, x)).cwiseAbs().maxCoeff() < 1e-13);
  for (double step : {1.0, 2.5}) {
    Points3 targets = drag.images();
    targets.col(2).array() += step;
    const auto result = drag.move(targets);
    CHECK(worst_miss(result.lattice, x, targets) < 1e-10);
    CHECK(result.report.summary.converged());
    CHECK(result.report.summary.final_residual == result.report.achieved_max_error);
    const auto once = manipulate(lattice, moves_of(x, targets));
    CHECK((result.lattice.points - once.lattice.points).cwiseAbs().maxCoeff() == 0.0);
  }
  // A copy shares the factorization (read-only) and answers bit for bit alike, also after the
  // original is gone.
  auto copy = std::make_unique<DirectManipulator<BezierLattice>>(drag);
  const DirectManipulator<BezierLattice> second = *copy;
  copy.reset();
  Points3 targets = drag.images();
  targets.col(0).array() -= 0.75;
  CHECK((second.move(targets).lattice.points - drag.move(targets).lattice.points)
            .cwiseAbs()
            .maxCoeff() == 0.0);
  CHECK(second.rank() == drag.rank());
}

TEST_CASE("direct manipulation rejects bad requests naming the culprit", "[deform]") {
  const BSplineLattice lattice = make_bspline_lattice(Frame{}, {2, 2, 2}, {2, 2, 2});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SECTION("a point outside the lattice") {
    const PointMove moves[] = {{{0.5, 0.5, 0.5}, {0.5, 0.5, 0.6}}, {{0.2, 1.5, 0.5}, {0, 0, 0}}};
    const auto [category, what] = error_of([&] { manipulate(lattice, moves); });
    CHECK(category == ErrorCategory::OutOfDomain);
    CHECK_THAT(what, Contains("selected point #1") && Contains("outside the lattice"));
  }
  SECTION("non-finite points and targets") {
    const PointMove bad_point[] = {{{nan, 0.5, 0.5}, {0.5, 0.5, 0.6}}};
    auto [category, what] = error_of([&] { manipulate(lattice, bad_point); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains("selected point #0") && Contains("not finite"));
    const PointMove bad_target[] = {{{0.5, 0.5, 0.5}, {0.5, 0.5, 0.6}},
                                    {{0.4, 0.5, 0.5}, {0.5, nan, 0.6}}};
    CHECK_THAT(error_of([&] { manipulate(lattice, bad_target); }).second,
               Contains("target #1") && Contains("not finite"));
  }
  SECTION("an empty request and a target count that does not match") {
    CHECK_THAT(error_of([&] { manipulate(lattice, std::span<const PointMove>()); }).second,
               Contains("no point selected"));
    const DirectManipulator<BSplineLattice> drag(lattice, Points3::Constant(2, 3, 0.5));
    CHECK_THAT(error_of([&] { drag.move(Points3::Zero(3, 3)); }).second,
               Contains("3 targets for 2 selected points"));
  }
  SECTION("bad options") {
    const PointMove move[] = {{{0.5, 0.5, 0.5}, {0.5, 0.5, 0.6}}};
    DirectManipulationOptions o;
    o.rank_tolerance = 0;
    auto [category, what] = error_of([&] { manipulate(lattice, move, o); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains("rank_tolerance = 0") && Contains("0 < rank_tolerance < 1"));
    o = {};
    o.relative_tolerance = -1;
    CHECK_THAT(error_of([&] { o.validate(); }).second, Contains("tolerance = -1"));
    o = {};
    o.locked.assign(5, false);
    CHECK_THAT(error_of([&] { manipulate(lattice, move, o); }).second,
               Contains("locked has 5 entries") && Contains("64 control points"));
    o = {};
    o.tied = {{3}};
    CHECK_THAT(error_of([&] { o.validate(); }).second, Contains("tied[0] has 1 control point"));
    o.tied = {{3, 4}, {5, 4}};
    CHECK_THAT(error_of([&] { o.validate(); }).second,
               Contains("tied[1] holds the row 4") && Contains("already tied"));
    o.tied = {{3, -1}};
    CHECK_THAT(error_of([&] { o.validate(); }).second, Contains("row -1"));
    o.tied = {{3, 64}};
    CHECK_THAT(error_of([&] { manipulate(lattice, move, o); }).second,
               Contains("tied[0] holds the row 64") && Contains("[0, 64)"));
  }
  SECTION("an invalid lattice") {
    BSplineLattice broken = lattice;
    broken.points(3, 1) = nan;
    const PointMove move[] = {{{0.5, 0.5, 0.5}, {0.5, 0.5, 0.6}}};
    CHECK(error_of([&] { manipulate(broken, move); }).first == ErrorCategory::InvalidGeometry);
    CHECK(error_of([&] { influence_matrix(broken, Points3::Constant(1, 3, 0.5)); }).first ==
          ErrorCategory::InvalidGeometry);
  }
}

TEST_CASE("docs snippet: lift one point and pin another with the bottom kept C1", "[deform]") {
  Frame frame;
  frame.origin = {-50, -50, 0};
  frame.s = {100, 0, 0};
  frame.t = {10, 100, 0};
  frame.u = {0, 0, 40};
  BSplineLattice lattice = make_bspline_lattice(frame, {3, 3, 3}, {8, 8, 8});
  const FaceContinuity keep[] = {{Face::UMin, 1}};
  DirectManipulationOptions options;
  options.locked = locked_control_points(lattice, keep);
  const PointMove moves[] = {
      {frame.point(0.5, 0.5, 0.9), frame.point(0.5, 0.5, 0.9) + Eigen::Vector3d(0, 0, 12)},
      {frame.point(0.3, 0.7, 0.9), frame.point(0.3, 0.7, 0.9)}};
  const auto [moved, report] = manipulate(lattice, moves, options);
  INFO(report.brief());
  CHECK(report.feasible);
  CHECK(report.rank == 2);
  for (const PointMove& m : moves) CHECK((deform_point(moved, m.point) - m.target).norm() < 1e-10);
  for (size_t r = 0; r < options.locked.size(); ++r)
    if (options.locked[r])
      CHECK((moved.points.row(static_cast<Eigen::Index>(r)).array() ==
             lattice.points.row(static_cast<Eigen::Index>(r)).array())
                .all());
  CHECK_THAT(report.brief(), Contains("feasible: 2 points, rank 2"));
}
