// Example 04 — a local FFD on a B-spline lattice: pull one top control point up, keep the bottom
// face C^1 with the space below, check the Jacobian bounds, deform a cloud of points fast and
// compare with the plain evaluation.
//
//   example_04_ffd_lattice
//
// Exits non-zero if the lattice folds or the fast path differs from the reference by more than
// 1e-13 of the lattice size.
#include <clay/deform.hpp>

#include <cstdio>
#include <random>

using namespace clay::deform;

int main() {
  Frame frame;  // X0 and the edges S, T, U (mm)
  frame.origin = {-50, -50, 0};
  frame.s = {100, 0, 0};
  frame.t = {10, 100, 0};  // any parallelepiped: skew is fine
  frame.u = {0, 0, 40};
  BSplineLattice lattice = make_bspline_lattice(frame, {3, 3, 3}, {8, 8, 8});  // the identity
  lattice.points.row(lattice.index(5, 5, 10)) +=
      Eigen::RowVector3d(0, 0, 15);                 // pull a top point up
  const FaceContinuity keep[] = {{Face::UMin, 1}};  // C^1 with the space below the lattice
  lattice = with_continuity(lattice, keep);
  const JacobianBounds j = jacobian_bounds(lattice);  // j.fold_free, j.min <= volume ratio <= j.max
  const FrozenLattice frozen(lattice);                // power form, once

  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(-0.1, 1.1);  // some points outside, left unchanged
  Points3 points(200'000, 3);
  for (Eigen::Index r = 0; r < points.rows(); ++r)
    points.row(r) = frame.point(unit(rng), unit(rng), unit(rng)).transpose();
  const Points3 out = deform_points(frozen, points);  // N x 3 rows, both cores

  double worst = 0, moved = 0;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    const Eigen::Vector3d x = points.row(r).transpose();
    worst = std::max(worst, (out.row(r).transpose() - deform_point(lattice, x)).norm());
    moved = std::max(moved, (out.row(r) - points.row(r)).norm());
  }
  const double size = (frame.s + frame.t + frame.u).norm();
  std::printf(
      "volume ratio in [%.3f, %.3f], fold free: %s; largest move %.3f mm; fast vs reference %.2e "
      "of the size\n",
      j.min, j.max, j.fold_free ? "yes" : "no", moved, worst / size);
  return j.fold_free && worst <= 1e-13 * size ? 0 : 1;
}
