#pragma once
// Random frames, displaced lattices, sample points and surfaces inside a frame for the deform
// tests (fixed seeds).
#include <clay/deform/lattice.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_surface.hpp>

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

/// A surface of degrees (p, q) with a clamped, non-uniform knot vector of `cu` x `cv` control
/// points, control point (i, j) at frame.point(local(i, j)), weights in [0.5, 2] when rational.
template <class Local>
surface::BSplineSurface surface_in(const deform::Frame& frame, int p, int q, int cu, int cv,
                                   bool rational, std::mt19937& rng, const Local& local) {
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), weight(0.5, 2.0);
  auto basis = [&](int d, int n) {
    surface::BSplineBasis b = surface::clamped_uniform_basis(d, n);
    const double h = 1.0 / (n - d);
    for (int k = d + 1; k < n; ++k) b.knots[static_cast<size_t>(k)] += jitter(rng) * h;
    return b;
  };
  surface::BSplineSurface s;
  s.u = basis(p, cu);
  s.v = basis(q, cv);
  s.points.resize(cu * cv, 3);
  s.weights = Eigen::VectorXd::Ones(cu * cv);
  for (int i = 0; i < cu; ++i)
    for (int j = 0; j < cv; ++j) {
      const Eigen::Vector3d l = local(i, j);
      s.points.row(s.index(i, j)) = frame.point(l.x(), l.y(), l.z()).transpose();
      if (rational) s.weights(s.index(i, j)) = weight(rng);
    }
  surface::validate(s);
  return s;
}

/// Random control points with local coordinates in [0.05, 0.95]: the surface lies in the lattice.
inline surface::BSplineSurface random_surface_in(const deform::Frame& frame, int p, int q, int cu,
                                                 int cv, bool rational, std::mt19937& rng) {
  std::uniform_real_distribution<double> c(0.05, 0.95);
  return surface_in(frame, p, q, cu, cv, rational, rng,
                    [&](int, int) { return Eigen::Vector3d(c(rng), c(rng), c(rng)); });
}

}  // namespace clay::test
