#pragma once
// Random valid B-spline curves and surfaces for property tests (fixed seeds: reproducible).
#include <clay/surface/bspline_surface.hpp>

#include <algorithm>
#include <random>
#include <vector>

namespace clay::test {

/// A random knot vector for `count` control points of degree `degree` on [a, b]: clamped or
/// not, with interior knots of multiplicity up to `max_interior_multiplicity` (<= degree).
inline surface::BSplineBasis random_basis(std::mt19937& rng, int degree, int count, bool clamped,
                                          int max_interior_multiplicity = 1, double a = 0.0,
                                          double b = 1.0) {
  surface::BSplineBasis basis;
  basis.degree = degree;
  const int m = count + degree + 1;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> mult_pick(
      1, std::max(1, std::min(max_interior_multiplicity, degree)));
  std::vector<double> knots;
  if (clamped) {
    knots.assign(static_cast<size_t>(degree + 1), a);
    const int interior = m - 2 * (degree + 1);
    std::vector<double> values;
    while (static_cast<int>(values.size()) < interior) {
      const double t = a + (b - a) * (0.05 + 0.9 * unit(rng));
      const int mult = std::min(mult_pick(rng), interior - static_cast<int>(values.size()));
      for (int k = 0; k < mult; ++k) values.push_back(t);
    }
    std::sort(values.begin(), values.end());
    knots.insert(knots.end(), values.begin(), values.end());
    knots.insert(knots.end(), static_cast<size_t>(degree + 1), b);
  } else {
    // Unclamped: distinct increasing knots around [a, b], with domain ends a and b exactly.
    std::vector<double> values;
    for (int i = 0; i < m; ++i)
      values.push_back(static_cast<double>(i) + 0.5 * (unit(rng) - 0.5) * 0.8);
    std::sort(values.begin(), values.end());
    const double lo = values[static_cast<size_t>(degree)];
    const double hi = values[static_cast<size_t>(count)];
    for (double& t : values) t = a + (b - a) * (t - lo) / (hi - lo);
    values[static_cast<size_t>(degree)] = a;
    values[static_cast<size_t>(count)] = b;
    knots = values;
  }
  basis.knots = knots;
  return basis;
}

/// A random surface with coordinates in [-size, size] and, when rational, weights in [0.3, 3].
inline surface::BSplineSurface random_surface(std::mt19937& rng, int degree_u, int degree_v,
                                              int count_u, int count_v, bool rational,
                                              bool clamped = true, int max_mult = 1,
                                              double size = 100.0) {
  surface::BSplineSurface s;
  s.u = random_basis(rng, degree_u, count_u, clamped, max_mult);
  s.v = random_basis(rng, degree_v, count_v, clamped, max_mult, -1.0, 2.0);
  std::uniform_real_distribution<double> coord(-size, size);
  std::uniform_real_distribution<double> weight(0.3, 3.0);
  s.points.resize(static_cast<Eigen::Index>(count_u) * count_v, 3);
  for (Eigen::Index r = 0; r < s.points.rows(); ++r)
    s.points.row(r) << coord(rng), coord(rng), coord(rng);
  s.weights = Eigen::VectorXd::Ones(s.points.rows());
  if (rational)
    for (Eigen::Index r = 0; r < s.weights.size(); ++r) s.weights[r] = weight(rng);
  return s;
}

/// A random curve, same conventions as random_surface.
inline surface::BSplineCurve random_curve(std::mt19937& rng, int degree, int count, bool rational,
                                          bool clamped = true, int max_mult = 1,
                                          double size = 100.0) {
  surface::BSplineCurve c;
  c.basis = random_basis(rng, degree, count, clamped, max_mult);
  std::uniform_real_distribution<double> coord(-size, size);
  std::uniform_real_distribution<double> weight(0.3, 3.0);
  c.points.resize(count, 3);
  for (Eigen::Index r = 0; r < c.points.rows(); ++r)
    c.points.row(r) << coord(rng), coord(rng), coord(rng);
  c.weights = Eigen::VectorXd::Ones(count);
  if (rational)
    for (Eigen::Index r = 0; r < c.weights.size(); ++r) c.weights[r] = weight(rng);
  return c;
}

}  // namespace clay::test

#include <clay/surface/evaluate.hpp>

namespace clay::test {

/// Largest distance between two surfaces over an n x n grid of their common domain, divided by
/// the size of the first one's control box (a relative deviation).
inline double relative_deviation(const surface::BSplineSurface& a, const surface::BSplineSurface& b,
                                 int n = 41) {
  const auto [ua, ub] = a.u.domain();
  const auto [va, vb] = a.v.domain();
  const auto us = surface::linspace(ua, ub, n);
  const auto vs = surface::linspace(va, vb, n);
  double worst = 0;
  for (double u : us)
    for (double v : vs)
      worst = std::max(worst, (surface::evaluate(a, u, v) - surface::evaluate(b, u, v)).norm());
  const auto [lo, hi] = surface::control_box(a);
  return worst / (hi - lo).norm();
}

/// Same for curves, on n samples.
inline double relative_deviation(const surface::BSplineCurve& a, const surface::BSplineCurve& b,
                                 int n = 201) {
  const auto [ta, tb] = a.basis.domain();
  double worst = 0;
  for (double t : surface::linspace(ta, tb, n))
    worst = std::max(worst, (surface::evaluate(a, t) - surface::evaluate(b, t)).norm());
  const Eigen::Vector3d lo = a.points.colwise().minCoeff(), hi = a.points.colwise().maxCoeff();
  return worst / (hi - lo).norm();
}

}  // namespace clay::test
