#include "curve_tools.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace clay::sketch::detail {

GaussRule gauss_legendre(int n) {
  // Newton on the Legendre polynomial P_n from Chebyshev-like starts (Numerical Recipes' gauleg).
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

Eigen::Vector3d curvature_vector(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2) {
  const double s2 = d1.squaredNorm();
  return d1.cross(d2).cross(d1) / (s2 * s2);
}

}  // namespace clay::sketch::detail
