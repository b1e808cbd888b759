#pragma once
// Random frames, displaced lattices and sample points for the deform tests (fixed seeds).
#include <clay/deform/lattice.hpp>

#include <Eigen/Core>

#include <random>

namespace clay::test {

/// A skewed, non-axis-aligned frame with edges of length 20-60 mm around a far-off origin; with
/// `left_handed` the U edge is mirrored (negative volume).
inline deform::Frame random_frame(std::mt19937& rng, bool left_handed = false) {
  std::uniform_real_distribution<double> c(-1.0, 1.0);
  std::uniform_real_distribution<double> len(20.0, 60.0);
  deform::Frame f;
  f.origin = Eigen::Vector3d(c(rng), c(rng), c(rng)) * 100.0;
  const Eigen::Vector3d a = Eigen::Vector3d(c(rng), c(rng), c(rng)).normalized();
  Eigen::Vector3d b = Eigen::Vector3d(c(rng), c(rng), c(rng));
  b = (b - 0.6 * b.dot(a) * a).normalized();  // skewed, not orthogonal
  Eigen::Vector3d n = a.cross(b).normalized();
  n = (n + 0.3 * a - 0.2 * b).normalized();
  f.s = len(rng) * a;
  f.t = len(rng) * b;
  f.u = len(rng) * (left_handed ? -n : n);
  return f;
}

/// Size of a lattice: the diagonal of its control points' bounding box (mm).
inline double size_of(const surface::Points3& points) {
  return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
}

/// Every control point moved by up to `amount` times the smallest edge length, at random.
template <class Lattice>
Lattice displaced(Lattice lattice, std::mt19937& rng, double amount = 0.15) {
  std::uniform_real_distribution<double> c(-1.0, 1.0);
  const double edge =
      std::min({lattice.frame.s.norm(), lattice.frame.t.norm(), lattice.frame.u.norm()});
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    lattice.points.row(r) += amount * edge * Eigen::RowVector3d(c(rng), c(rng), c(rng));
  return lattice;
}

/// `n` points X0 + s S + t T + u U with local coordinates uniform in [lo, hi].
inline surface::Points3 sample_points(const deform::Frame& f, std::mt19937& rng, int n,
                                      double lo = 0.0, double hi = 1.0) {
  std::uniform_real_distribution<double> c(lo, hi);
  surface::Points3 p(n, 3);
  for (int r = 0; r < n; ++r) p.row(r) = f.point(c(rng), c(rng), c(rng)).transpose();
  return p;
}

}  // namespace clay::test
