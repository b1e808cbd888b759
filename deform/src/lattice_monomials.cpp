// The power-basis monomials of a Bézier lattice's FFD (lattice_monomials.hpp).
#include "lattice_monomials.hpp"

#include <clay/internal/math.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clay::deform::detail {

namespace {

/// M[a][i] = C(l, a) C(a, i) (-1)^(a - i): s^a's coefficient in B_i^l(s).
Eigen::MatrixXd bernstein_to_power(int l) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(l + 1, l + 1);
  for (int a = 0; a <= l; ++a)
    for (int i = 0; i <= a; ++i)
      m(a, i) = internal::binomial(l, a) * internal::binomial(a, i) * ((a - i) % 2 ? -1.0 : 1.0);
  return m;
}

}  // namespace

LatticeMonomials lattice_monomials(const BezierLattice& lattice) {
  const auto [l, m, n] = lattice.degrees;
  LatticeMonomials out;
  if ((l + 1) * (m + 1) * (n + 1) > max_monomial_points) return out;
  const Eigen::MatrixXd ms = bernstein_to_power(l), mt = bernstein_to_power(m),
                        mu = bernstein_to_power(n);
  // Offsets from P_000: every coefficient but the constant one is a zero-sum combination of the
  // points, so it does not change, and its rounding is relative to the lattice, not its position.
  const Eigen::Vector3d origin = lattice.points.row(0).transpose();
  const double eps = std::numeric_limits<double>::epsilon();
  const double rounding = 64.0 * (l + m + n + 1) * eps;
  double extent = 0;
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    extent = std::max(extent, (lattice.points.row(r).transpose() - origin).norm());
  double sum = 0;
  for (int a = 0; a <= l; ++a)
    for (int b = 0; b <= m; ++b)
      for (int c = 0; c <= n; ++c) {
        Eigen::Vector3d coefficient = Eigen::Vector3d::Zero();
        double magnitude = 0;
        for (int i = 0; i <= a; ++i)
          for (int j = 0; j <= b; ++j)
            for (int k = 0; k <= c; ++k) {
              const double f = ms(a, i) * mt(b, j) * mu(c, k);
              const Eigen::Vector3d offset =
                  lattice.points.row(lattice.index(i, j, k)).transpose() - origin;
              coefficient += f * offset;
              magnitude += std::abs(f) * offset.norm();
            }
        if (a + b + c == 0) {
          coefficient = origin;
        } else if (coefficient.norm() <= rounding * magnitude) {
          continue;
        }
        if (a + b + c > 0) sum += coefficient.norm();
        out.exponents.push_back({a, b, c});
        out.coefficients.push_back(coefficient);
        out.total_degree = std::max(out.total_degree, a + b + c);
      }
  out.amplification = extent > 0 ? sum / extent : 0;
  return out;
}

}  // namespace clay::deform::detail
