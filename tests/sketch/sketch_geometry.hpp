#pragma once
// Test geometry for the sketch module: noisy strokes from known curves and independent measures
// (distance between curves, bending energy), none of them using the code under test.
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace clay::test {

/// Standard normal deviates by Box–Muller on std::mt19937 (portable: the standard distributions
/// are not specified bit for bit across standard libraries).
class Gaussian {
 public:
  explicit Gaussian(unsigned seed) : rng_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    // Two uniforms in (0, 1] from 32-bit words.
    const double u1 = (static_cast<double>(rng_()) + 1.0) / 4294967296.0;
    const double u2 = static_cast<double>(rng_()) / 4294967296.0;
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * std::numbers::pi * u2);
  }
  Eigen::RowVector3d vector(double sigma) {
    const double x = (*this)(), y = (*this)(), z = (*this)();
    return sigma * Eigen::RowVector3d(x, y, z);
  }

 private:
  std::mt19937 rng_;
  double spare_ = 0;
  bool has_spare_ = false;
};

/// A curve given as a function of t in [0, 1] (point, first and second derivative).
struct Analytic {
  std::function<Eigen::Vector3d(double)> point, d1, d2;
};

inline Analytic analytic(const surface::BSplineCurve& c) {
  const double a = c.basis.domain().first;  // not a structured binding: Clang 14 cannot capture one
  const double s = c.basis.domain().second - a;
  return {
      [=](double t) { return surface::evaluate(c, a + s * t); },
      [=](double t) { return Eigen::Vector3d(s * surface::derivatives(c, a + s * t, 1).d1); },
      [=](double t) { return Eigen::Vector3d(s * s * surface::derivatives(c, a + s * t, 2).d2); }};
}

/// `count` points along the curve at evenly spaced t in [0, 1], plus noise of `sigma` per
/// coordinate.
inline surface::Points3 noisy_samples(const Analytic& c, int count, double sigma, Gaussian& g) {
  surface::Points3 out(count, 3);
  for (int i = 0; i < count; ++i)
    out.row(i) = c.point(double(i) / (count - 1)).transpose() + g.vector(sigma);
  return out;
}

/// Dense polyline of a curve: `count` points at evenly spaced t.
inline surface::Points3 polyline(const Analytic& c, int count) {
  surface::Points3 out(count, 3);
  for (int i = 0; i < count; ++i) out.row(i) = c.point(double(i) / (count - 1)).transpose();
  return out;
}

/// Distance from q to a polyline (segments).
inline double distance_to_polyline(const Eigen::Vector3d& q, const surface::Points3& poly) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i + 1 < poly.rows(); ++i) {
    const Eigen::Vector3d a = poly.row(i).transpose(), b = poly.row(i + 1).transpose();
    const Eigen::Vector3d ab = b - a;
    const double f = std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + f * ab - q).squaredNorm());
  }
  return std::sqrt(best);
}

/// Symmetric (Hausdorff-like) distance between two curves: the largest distance from `samples`
/// points of each to a `dense`-point polyline of the other.
inline double curve_distance(const Analytic& a, const Analytic& b, int samples = 600,
                             int dense = 6000) {
  const surface::Points3 pa = polyline(a, dense), pb = polyline(b, dense);
  double worst = 0;
  for (int i = 0; i < samples; ++i) {
    const double t = double(i) / (samples - 1);
    worst = std::max(worst, distance_to_polyline(a.point(t), pb));
    worst = std::max(worst, distance_to_polyline(b.point(t), pa));
  }
  return worst;
}

/// Bending energy int kappa^2 ds = int |C' x C''|^2 / |C'|^5 dt by composite Simpson's rule on
/// `intervals` subintervals of each of the `breaks` intervals (put breaks at the knots).
inline double bending_energy(const Analytic& c, const std::vector<double>& breaks,
                             int intervals = 200) {
  auto f = [&](double t) {
    const Eigen::Vector3d d1 = c.d1(t), d2 = c.d2(t);
    return d1.cross(d2).squaredNorm() / std::pow(d1.norm(), 5);
  };
  double total = 0;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double lo = breaks[k], h = (breaks[k + 1] - lo) / intervals;
    double s = f(lo) + f(breaks[k + 1]);
    for (int i = 1; i < intervals; ++i) s += (i % 2 ? 4.0 : 2.0) * f(lo + i * h);
    total += s * h / 3.0;
  }
  return total;
}

/// The curve's distinct knots mapped to [0, 1] (breaks for bending_energy of analytic(curve)).
inline std::vector<double> unit_breaks(const surface::BSplineCurve& c) {
  const auto [a, b] = c.basis.domain();
  std::vector<double> out;
  for (double k : c.basis.knots) {
    const double u = (k - a) / (b - a);
    if (u < 0 || u > 1) continue;
    if (out.empty() || u != out.back()) out.push_back(u);
  }
  return out;
}

}  // namespace clay::test
