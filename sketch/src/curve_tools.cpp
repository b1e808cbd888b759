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

double project_from(const surface::BSplineCurve& curve, const Eigen::Vector3d& q, double t0,
                    bool periodic) {
  const auto [a, b] = curve.basis.domain();
  const double period = b - a;
  auto fold = [&](double t) {
    if (periodic) {
      t = a + std::fmod(t - a, period);
      if (t < a) t += period;
      return t >= b ? a : t;
    }
    return std::clamp(t, a, b);
  };
  double t = fold(t0);
  surface::CurveDerivatives d = surface::derivatives(curve, t, 2);
  double f = (d.point - q).squaredNorm();
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector3d r = d.point - q;
    const double tt = d.d1.squaredNorm();
    if (!(tt > 0.0)) break;
    const double g = r.dot(d.d1);
    double h = tt + r.dot(d.d2);
    if (!(h > 0.1 * tt)) h = tt;  // Gauss–Newton where the Hessian is not safely positive
    double step = -g / h;
    step = std::clamp(step, -0.25 * period, 0.25 * period);
    bool accepted = false;
    double tn = t, fn = f;
    surface::CurveDerivatives dn;
    for (int ls = 0; ls < 30; ++ls) {
      tn = fold(t + step);
      dn = surface::derivatives(curve, tn, 2);
      fn = (dn.point - q).squaredNorm();
      if (fn <= f) {
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) break;
    const double moved = std::abs(tn - t);
    t = tn;
    d = dn;
    f = fn;
    if (moved <= 1e-15 * period) break;
  }
  return t;
}

double closest_parameter(const surface::BSplineCurve& curve, const Eigen::Vector3d& q,
                         int per_span) {
  const auto ts = surface::span_samples(curve.basis, per_span);
  // Newton from the three best samples, the nearest foot kept.
  std::vector<std::pair<double, double>> ranked;
  ranked.reserve(ts.size());
  for (double t : ts) ranked.emplace_back((surface::evaluate(curve, t) - q).squaredNorm(), t);
  const size_t keep = std::min<size_t>(3, ranked.size());
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep), ranked.end());
  double best_t = ranked.front().second, best = ranked.front().first;
  for (size_t k = 0; k < keep; ++k) {
    const double t = project_from(curve, q, ranked[k].second, false);
    const double f = (surface::evaluate(curve, t) - q).squaredNorm();
    if (f < best) {
      best = f;
      best_t = t;
    }
  }
  return best_t;
}

Eigen::Vector3d curvature_vector(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2) {
  const double s2 = d1.squaredNorm();
  return d1.cross(d2).cross(d1) / (s2 * s2);
}

}  // namespace clay::sketch::detail
