#pragma once
// Bivariate polynomials in Bernstein form, the algebra of the exact composition (internal to
// clay_deform): products, degree changes, exact degree tests, evaluation, subdivision, partial
// derivatives (compose.cpp, patch_containment.cpp).
#include <Eigen/Core>

#include <cstddef>
#include <utility>
#include <vector>

namespace clay::deform::detail {

/// A bivariate polynomial of degrees (du, dv) in Bernstein form with `dim` values per
/// coefficient: value d of coefficient (i, j) at ((i * (dv + 1) + j) * dim + d). "Scaled" polys
/// hold C(du, i) C(dv, j) times the Bernstein coefficients, so that a product is a plain 2D
/// convolution (exact Bernstein multiplication: B_i^a B_k^b = C(a,i) C(b,k) / C(a+b,i+k)
/// B_{i+k}^{a+b}).
struct Poly {
  int du = 0, dv = 0, dim = 1;
  std::vector<double> c;

  Poly() = default;
  Poly(int du_, int dv_, int dim_)
      : du(du_), dv(dv_), dim(dim_), c(static_cast<size_t>((du_ + 1) * (dv_ + 1) * dim_), 0.0) {}
  double& at(int i, int j, int d = 0) {
    return c[static_cast<size_t>((i * (dv + 1) + j) * dim + d)];
  }
  double at(int i, int j, int d = 0) const {
    return c[static_cast<size_t>((i * (dv + 1) + j) * dim + d)];
  }
};

// Inline: the composition's hot loop; the compiler specializes it at each call (1.4x faster than
// an out-of-line call in bench_compose).
/// out += a * b for scaled polys (b scalar-valued); out has degrees a + b and a's dim.
inline void mul_add(const Poly& a, const Poly& b, Poly& out) {
  const int arow = (a.dv + 1) * a.dim;
  const int orow = (out.dv + 1) * out.dim;
  for (int k = 0; k <= b.du; ++k)
    for (int l = 0; l <= b.dv; ++l) {
      const double f = b.at(k, l);
      if (f == 0) continue;
      for (int i = 0; i <= a.du; ++i) {
        const double* src = a.c.data() + i * arow;
        double* dst = out.c.data() + (i + k) * orow + l * out.dim;
        for (int x = 0; x < arow; ++x) dst[x] += f * src[x];
      }
    }
}

inline Poly multiply(const Poly& a, const Poly& b) {
  Poly out(a.du + b.du, a.dv + b.dv, a.dim);
  mul_add(a, b, out);
  return out;
}

Poly constant_poly(double value);

/// Multiplies (or divides) coefficient (i, j) by C(du, i) C(dv, j).
void scale(Poly& p, bool divide);

/// The matrix taking Bernstein coefficients of degree p to those of degree e <= p of the
/// power-basis truncation (a_k = C(p, k) Δ^k b_0 for k <= e, then b'_i = Σ_k C(i,k)/C(e,k) a_k).
Eigen::MatrixXd reduction_matrix(int p, int e);

/// Degree elevation from e to p: b_i = Σ_k C(e,k) C(p−e, i−k) / C(p,i) b'_k.
Eigen::MatrixXd elevation_matrix(int e, int p);

/// Applies `m` ((new + 1) x (old + 1)) along u (dir 0) or v (dir 1) of unscaled coefficients.
Poly apply(const Poly& a, const Eigen::MatrixXd& m, int dir);

/// The unscaled poly written with degree `e` in direction `dir` (reduced or elevated).
Poly to_degree(const Poly& a, int e, int dir);

/// The exact degree in `dir`: the smallest e whose reduced form, elevated back, reproduces every
/// coefficient to `tol`. With `positive`, also require the reduced coefficients to stay > 0
/// (weights: products of positive Bernstein coefficients are positive).
int exact_degree(const Poly& a, int dir, double tol, bool positive);

/// Value at (x, y) in [0, 1]^2 of component d (de Casteljau), for unscaled coefficients.
double value_at(const Poly& a, double x, double y, int d = 0);

/// de Casteljau split of unscaled coefficients at 1/2 in `dir`: the halves [0, 1/2], [1/2, 1].
std::pair<Poly, Poly> halve(const Poly& a, int dir);

/// Bernstein coefficients of ∂g/∂x (dir 0) or ∂g/∂y (dir 1) of a dim-1 poly, degree one lower
/// (the zero poly of degree 0 when g has degree 0 there).
Poly derivative(const Poly& g, int dir);
/// The largest coefficient of a dim-1 poly, and the largest in absolute value.
double max_coefficient(const Poly& g);
double max_abs_coefficient(const Poly& g);

/// Roots in (0, 1) of the univariate Bernstein polynomial `b` (its coefficients on [0, 1]),
/// increasing, each isolated with certainty by halving (Descartes' rule of signs) and refined by
/// bisection to rounding: two crossings closer than any sampling step are both found. A cluster
/// narrower than 1e-13 (a double root) counts once, at its middle.
std::vector<double> bernstein_roots(const std::vector<double>& b);

}  // namespace clay::deform::detail
