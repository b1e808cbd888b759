// Bivariate polynomials in Bernstein form (bernstein_poly.hpp).
#include "bernstein_poly.hpp"

#include <clay/internal/math.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace clay::deform::detail {

Poly constant_poly(double value) {
  Poly p(0, 0, 1);
  p.c[0] = value;
  return p;
}

/// Multiplies (or divides) coefficient (i, j) by C(du, i) C(dv, j).
void scale(Poly& p, bool divide) {
  const auto& bu = internal::binomial_row(p.du);
  const auto& bv = internal::binomial_row(p.dv);
  for (int i = 0; i <= p.du; ++i)
    for (int j = 0; j <= p.dv; ++j) {
      const double f = bu[static_cast<size_t>(i)] * bv[static_cast<size_t>(j)];
      for (int d = 0; d < p.dim; ++d) {
        if (divide)
          p.at(i, j, d) /= f;
        else
          p.at(i, j, d) *= f;
      }
    }
}

/// The matrix taking Bernstein coefficients of degree p to those of degree e <= p of the
/// power-basis truncation (a_k = C(p, k) Δ^k b_0 for k <= e, then b'_i = Σ_k C(i,k)/C(e,k) a_k).
Eigen::MatrixXd reduction_matrix(int p, int e) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(e + 1, p + 1);
  for (int i = 0; i <= e; ++i)
    for (int k = 0; k <= i; ++k) {
      const double f =
          internal::binomial(i, k) / internal::binomial(e, k) * internal::binomial(p, k);
      for (int r = 0; r <= k; ++r)
        m(i, r) += f * ((k - r) % 2 ? -1.0 : 1.0) * internal::binomial(k, r);
    }
  return m;
}

/// Degree elevation from e to p: b_i = Σ_k C(e,k) C(p−e, i−k) / C(p,i) b'_k.
Eigen::MatrixXd elevation_matrix(int e, int p) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(p + 1, e + 1);
  for (int i = 0; i <= p; ++i)
    for (int k = std::max(0, i - (p - e)); k <= std::min(e, i); ++k)
      m(i, k) =
          internal::binomial(e, k) * internal::binomial(p - e, i - k) / internal::binomial(p, i);
  return m;
}

/// Applies `m` ((new + 1) x (old + 1)) along u (dir 0) or v (dir 1) of unscaled coefficients.
Poly apply(const Poly& a, const Eigen::MatrixXd& m, int dir) {
  const int n = static_cast<int>(m.rows()) - 1;
  Poly out(dir == 0 ? n : a.du, dir == 0 ? a.dv : n, a.dim);
  for (int i = 0; i <= out.du; ++i)
    for (int j = 0; j <= out.dv; ++j)
      for (int d = 0; d < a.dim; ++d) {
        double s = 0;
        if (dir == 0)
          for (int k = 0; k <= a.du; ++k) s += m(i, k) * a.at(k, j, d);
        else
          for (int k = 0; k <= a.dv; ++k) s += m(j, k) * a.at(i, k, d);
        out.at(i, j, d) = s;
      }
  return out;
}

/// The unscaled poly written with degree `e` in direction `dir` (reduced or elevated).
Poly to_degree(const Poly& a, int e, int dir) {
  const int p = dir == 0 ? a.du : a.dv;
  if (e == p) return a;
  return apply(a, e < p ? reduction_matrix(p, e) : elevation_matrix(p, e), dir);
}

/// The exact degree in `dir`: the smallest e whose reduced form, elevated back, reproduces every
/// coefficient to `tol`. With `positive`, also require the reduced coefficients to stay > 0
/// (weights: products of positive Bernstein coefficients are positive).
int exact_degree(const Poly& a, int dir, double tol, bool positive) {
  const int p = dir == 0 ? a.du : a.dv;
  int best = p;
  for (int e = p - 1; e >= 0; --e) {
    const Poly reduced = to_degree(a, e, dir);
    if (positive &&
        std::any_of(reduced.c.begin(), reduced.c.end(), [](double x) { return !(x > 0); }))
      break;
    const Poly back = to_degree(reduced, p, dir);
    bool same = true;
    for (size_t k = 0; k < a.c.size() && same; ++k) same = std::abs(back.c[k] - a.c[k]) <= tol;
    if (!same) break;
    best = e;
  }
  return best;
}

/// Value at (x, y) in [0, 1]^2 of component d (de Casteljau), for unscaled coefficients.
double value_at(const Poly& a, double x, double y, int d) {
  std::vector<double> row(static_cast<size_t>(a.dv + 1)), col(static_cast<size_t>(a.du + 1));
  for (int i = 0; i <= a.du; ++i) {
    for (int j = 0; j <= a.dv; ++j) row[static_cast<size_t>(j)] = a.at(i, j, d);
    for (int l = 1; l <= a.dv; ++l)
      for (int j = 0; j + l <= a.dv; ++j)
        row[static_cast<size_t>(j)] =
            (1 - y) * row[static_cast<size_t>(j)] + y * row[static_cast<size_t>(j + 1)];
    col[static_cast<size_t>(i)] = row[0];
  }
  for (int l = 1; l <= a.du; ++l)
    for (int i = 0; i + l <= a.du; ++i)
      col[static_cast<size_t>(i)] =
          (1 - x) * col[static_cast<size_t>(i)] + x * col[static_cast<size_t>(i + 1)];
  return col[0];
}

/// de Casteljau split of unscaled coefficients at 1/2 in `dir`: the halves [0, 1/2], [1/2, 1].
std::pair<Poly, Poly> halve(const Poly& a, int dir) {
  Poly lo = a, hi = a;
  const int p = dir == 0 ? a.du : a.dv;
  const int other = dir == 0 ? a.dv : a.du;
  std::vector<double> w(static_cast<size_t>(p + 1));
  for (int o = 0; o <= other; ++o)
    for (int d = 0; d < a.dim; ++d) {
      auto get = [&](const Poly& q, int k) -> double {
        return dir == 0 ? q.at(k, o, d) : q.at(o, k, d);
      };
      auto put = [&](Poly& q, int k, double x) {
        if (dir == 0)
          q.at(k, o, d) = x;
        else
          q.at(o, k, d) = x;
      };
      for (int k = 0; k <= p; ++k) w[static_cast<size_t>(k)] = get(a, k);
      put(lo, 0, w[0]);
      put(hi, p, w[static_cast<size_t>(p)]);
      for (int l = 1; l <= p; ++l) {
        for (int k = 0; k + l <= p; ++k)
          w[static_cast<size_t>(k)] =
              0.5 * (w[static_cast<size_t>(k)] + w[static_cast<size_t>(k + 1)]);
        put(lo, l, w[0]);
        put(hi, p - l, w[static_cast<size_t>(p - l)]);
      }
    }
  return {lo, hi};
}

Poly derivative(const Poly& g, int dir) {
  const int p = dir == 0 ? g.du : g.dv;
  if (p == 0) return Poly(dir == 0 ? 0 : g.du, dir == 0 ? g.dv : 0, 1);
  Poly d(dir == 0 ? g.du - 1 : g.du, dir == 0 ? g.dv : g.dv - 1, 1);
  for (int i = 0; i <= d.du; ++i)
    for (int j = 0; j <= d.dv; ++j)
      d.at(i, j) = p * (dir == 0 ? g.at(i + 1, j) - g.at(i, j) : g.at(i, j + 1) - g.at(i, j));
  return d;
}

double max_coefficient(const Poly& g) { return *std::max_element(g.c.begin(), g.c.end()); }
double max_abs_coefficient(const Poly& g) {
  double m = 0;
  for (double x : g.c) m = std::max(m, std::abs(x));
  return m;
}

namespace {

/// Sign changes of a coefficient sequence, zeros skipped (Descartes' rule for the Bernstein form:
/// the number of roots in the open interval is at most this, and of the same parity).
int sign_changes(const std::vector<double>& b) {
  int changes = 0;
  double last = 0;
  for (double x : b) {
    if (x == 0) continue;
    if (last != 0 && (x < 0) != (last < 0)) ++changes;
    last = x;
  }
  return changes;
}

/// Value of a univariate Bernstein polynomial at x (de Casteljau).
double bernstein_value(std::vector<double> w, double x) {
  const size_t p = w.size() - 1;
  for (size_t l = 1; l <= p; ++l)
    for (size_t k = 0; k + l <= p; ++k) w[k] = (1 - x) * w[k] + x * w[k + 1];
  return w[0];
}

/// Isolates the roots of `b` (Bernstein coefficients on [a, c]) by halving: no sign change, no
/// root; one sign change between non-zero ends, exactly one root, refined by bisection to
/// rounding; otherwise halve. An interval narrower than 1e-13 still showing several changes holds
/// a cluster (a double root: the surface touches the plane along an iso-line): one root, its
/// middle — a split there is harmless.
void isolate(const std::vector<double>& b, double a, double c, std::vector<double>& out) {
  const int changes = sign_changes(b);
  if (changes == 0) return;
  if (changes == 1 && b.front() != 0 && b.back() != 0) {
    double lo = 0, hi = 1;
    const bool rising = b.front() < 0;
    for (int it = 0; it < 200; ++it) {
      const double m = 0.5 * (lo + hi);
      if (m <= lo || m >= hi) break;
      const double f = bernstein_value(b, m);
      if (f == 0) {
        lo = hi = m;
        break;
      }
      if ((f < 0) == rising)
        lo = m;
      else
        hi = m;
    }
    out.push_back(a + 0.5 * (lo + hi) * (c - a));
    return;
  }
  const double m = 0.5 * (a + c);
  if (c - a <= 1e-13 || m <= a || m >= c) {
    out.push_back(m);
    return;
  }
  const size_t p = b.size() - 1;
  std::vector<double> w = b, left(p + 1), right(p + 1);
  left[0] = w[0];
  right[p] = w[p];
  for (size_t l = 1; l <= p; ++l) {
    for (size_t k = 0; k + l <= p; ++k) w[k] = 0.5 * (w[k] + w[k + 1]);
    left[l] = w[0];
    right[p - l] = w[p - l];
  }
  isolate(left, a, m, out);
  if (right[0] == 0) out.push_back(m);
  isolate(right, m, c, out);
}

}  // namespace

/// Roots in (0, 1) of the univariate Bernstein polynomial `b`, each isolated with certainty
/// (isolate above): two crossings closer than any sampling step are both found.
std::vector<double> bernstein_roots(const std::vector<double>& b) {
  std::vector<double> out;
  isolate(b, 0, 1, out);
  std::sort(out.begin(), out.end());
  out.erase(std::remove_if(out.begin(), out.end(), [](double x) { return !(x > 0 && x < 1); }),
            out.end());
  return out;
}

}  // namespace clay::deform::detail
