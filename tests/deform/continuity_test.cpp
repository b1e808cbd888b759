// Local deformations (Sederberg–Parry §3.1): locked planes and C^k joins with undeformed space.
#include <catch2/catch.hpp>

#include <clay/deform/continuity.hpp>
#include <clay/deform/jacobian.hpp>

#include <random>
#include <vector>

#include "fixtures.hpp"

using namespace clay::deform;
using clay::test::random_frame;

namespace {

int count_locked(const std::vector<bool>& v) {
  return static_cast<int>(std::count(v.begin(), v.end(), true));
}

/// Largest |dX_fd/dX − I| over points on the face s = 0 (analytic derivative), and over the same
/// points by central differences straddling the face (identity outside, lattice inside).
template <class Lattice>
std::pair<double, double> derivative_jump_on_s_min(const Lattice& L, std::mt19937& rng) {
  std::uniform_real_distribution<double> c(0.05, 0.95);
  double analytic = 0, differences = 0;
  const double h = 1e-6 * L.frame.s.norm();
  Eigen::Vector3d normal = L.frame.t.cross(L.frame.u).normalized();
  if (normal.dot(L.frame.s) < 0) normal = -normal;  // pointing into the lattice
  for (int n = 0; n < 50; ++n) {
    const Eigen::Vector3d x = L.frame.point(0.0, c(rng), c(rng));
    analytic = std::max(analytic, (jacobian_matrix(L, x) - Eigen::Matrix3d::Identity()).norm());
    // Across the face: the derivative along the face normal, from both sides at once.
    const Eigen::Vector3d d =
        (deform_point(L, x + h * normal) - deform_point(L, x - h * normal)) / (2 * h);
    differences = std::max(differences, (d - normal).norm());
  }
  return {analytic, differences};
}

}  // namespace

TEST_CASE("locked planes: face plane and k more for Bezier and clamped lattices", "[deform]") {
  std::mt19937 rng(11);
  const BezierLattice B = make_bezier_lattice(random_frame(rng), {3, 3, 3});
  const FaceContinuity c1[] = {{Face::SMin, 1}};
  CHECK(count_locked(locked_control_points(B, c1)) == 2 * 16);
  const std::vector<bool> locked = locked_control_points(B, c1);
  CHECK(locked[static_cast<size_t>(B.index(1, 3, 2))]);
  CHECK(!locked[static_cast<size_t>(B.index(2, 0, 0))]);
  const FaceContinuity two[] = {{Face::SMin, 0}, {Face::UMax, 2}};
  // 16 on s = 0, 48 on the three u planes, 12 counted twice.
  CHECK(count_locked(locked_control_points(B, two)) == 16 + 48 - 12);

  const BSplineLattice S = make_bspline_lattice(random_frame(rng), {3, 3, 3}, {4, 4, 4});
  const FaceContinuity t2[] = {{Face::TMax, 2}};
  CHECK(count_locked(locked_control_points(S, t2)) == 3 * 49);
  // Unclamped uniform knots: every function of the first span touches the face, so p planes.
  const BSplineLattice U =
      make_bspline_lattice(random_frame(rng), {3, 3, 3}, {4, 4, 4}, LatticeKnots::Uniform);
  const FaceContinuity u0[] = {{Face::UMin, 0}};
  CHECK(count_locked(locked_control_points(U, u0)) == 3 * 49);
}

TEST_CASE("local C1 deformation matches the undeformed space across the fixed face", "[deform]") {
  std::mt19937 rng(12);
  const FaceContinuity faces[] = {{Face::SMin, 1}, {Face::TMax, 1}};
  {
    const BezierLattice free =
        clay::test::displaced(make_bezier_lattice(random_frame(rng), {3, 3, 3}), rng, 0.2);
    const BezierLattice local = with_continuity(free, faces);
    const auto [analytic, differences] = derivative_jump_on_s_min(local, rng);
    INFO("Bezier: analytic " << analytic << ", differences " << differences);
    CHECK(analytic < 1e-9);
    CHECK(differences < 1e-5);
    // The same lattice without the reset does jump (the test can fail).
    CHECK(derivative_jump_on_s_min(free, rng).first > 1e-3);
  }
  for (LatticeKnots knots : {LatticeKnots::Clamped, LatticeKnots::Uniform}) {
    const BSplineLattice free = clay::test::displaced(
        make_bspline_lattice(random_frame(rng), {3, 2, 3}, {3, 4, 2}, knots), rng, 0.2);
    const BSplineLattice local = with_continuity(free, faces);
    const auto [analytic, differences] = derivative_jump_on_s_min(local, rng);
    INFO("B-spline: analytic " << analytic << ", differences " << differences);
    CHECK(analytic < 1e-9);
    CHECK(differences < 1e-5);
    CHECK(derivative_jump_on_s_min(free, rng).first > 1e-3);
  }
}

TEST_CASE("C0 keeps positions but not derivatives on the face", "[deform]") {
  std::mt19937 rng(13);
  const FaceContinuity c0[] = {{Face::UMin, 0}};
  const BezierLattice L = with_continuity(
      clay::test::displaced(make_bezier_lattice(random_frame(rng), {2, 2, 3}), rng, 0.2), c0);
  std::uniform_real_distribution<double> c(0.0, 1.0);
  double jump = 0;
  for (int n = 0; n < 30; ++n) {
    const Eigen::Vector3d x = L.frame.point(c(rng), c(rng), 0.0);
    CHECK((deform_point(L, x) - x).norm() < 1e-12 * L.frame.u.norm());
    jump = std::max(jump, (jacobian_matrix(L, x) - Eigen::Matrix3d::Identity()).norm());
  }
  CHECK(jump > 1e-3);
}
