#pragma once
// Small numerical tools shared by every module (internal, not installed): binomial coefficients
// and Gauss–Legendre quadrature.
#include <clay/error.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

namespace clay::internal {

/// Largest n of binomial_row.
inline constexpr int max_binomial_row = 255;

/// Row n of Pascal's triangle as doubles, 0 <= n <= max_binomial_row: exact (integers below 2^53)
/// up to n = 56, correctly rounded sums beyond. Built once, thread-safe (a function-local static).
inline const std::vector<double>& binomial_row(int n) {
  static const std::vector<std::vector<double>> table = [] {
    std::vector<std::vector<double>> t(max_binomial_row + 1);
    for (size_t r = 0; r < t.size(); ++r) {
      t[r].assign(r + 1, 1.0);
      for (size_t k = 1; k < r; ++k) t[r][k] = t[r - 1][k - 1] + t[r - 1][k];
    }
    return t;
  }();
  // Every caller's degrees are bounded far below (lattices 3 x 63); past the table is a bug.
  if (n < 0 || n > max_binomial_row)
    throw Error(ErrorCategory::Internal, "binomial_row(" + std::to_string(n) +
                                             "): beyond the table of rows 0.." +
                                             std::to_string(max_binomial_row));
  return table[static_cast<size_t>(n)];
}

/// C(n, k) as a double; 0 when k < 0 or k > n. n <= max_binomial_row.
inline double binomial(int n, int k) {
  return k < 0 || k > n ? 0.0 : binomial_row(n)[static_cast<size_t>(k)];
}

/// Nodes and weights of an n-point Gauss–Legendre rule on [-1, 1] (exact for degree 2n - 1).
struct GaussRule {
  std::vector<double> nodes, weights;
};

/// The n-point rule, n >= 1: Newton on the Legendre polynomial P_n from the asymptotic starts
/// cos(pi (i + 3/4) / (n + 1/2)) (Numerical Recipes' gauleg), to machine precision.
inline GaussRule gauss_legendre(int n) {
  GaussRule rule;
  rule.nodes.resize(static_cast<size_t>(n));
  rule.weights.resize(static_cast<size_t>(n));
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = 0.0;
      for (int k = 1; k <= n; ++k) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p2) / k;
      }
      dp = n * (x * p0 - p1) / (x * x - 1.0);
      const double dx = p0 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    rule.nodes[static_cast<size_t>(i)] = -x;
    rule.nodes[static_cast<size_t>(n - 1 - i)] = x;
    rule.weights[static_cast<size_t>(i)] = w;
    rule.weights[static_cast<size_t>(n - 1 - i)] = w;
  }
  return rule;
}

/// The 8-point rule, as constants (the hot loops of arc length, area and the self-intersection
/// search use it).
inline constexpr std::array<double, 8> gauss8_nodes = {
    -0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
    0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
inline constexpr std::array<double, 8> gauss8_weights = {
    0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
    0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

/// The integral of f over [a, b] by the 8-point Gauss–Legendre rule (exact for degree 15).
template <class F>
double gauss_legendre_8(double a, double b, F f) {
  double sum = 0;
  for (size_t g = 0; g < gauss8_nodes.size(); ++g)
    sum += gauss8_weights[g] * f(0.5 * (a + b) + 0.5 * (b - a) * gauss8_nodes[g]);
  return 0.5 * (b - a) * sum;
}

}  // namespace clay::internal
