// The exact style mode's fairness energy (fairness.hpp): per knot-span cell and Gauss point, the
// order-k partial derivatives of the rational basis functions (the NURBS Book eq. 4.20 applied to
// R = N w / W), weighted by the parent's metric.
#include "fairness.hpp"

#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>

namespace clay::deform::detail {

using surface::BSplineSurface;

namespace {

constexpr int max_order = 3;

double binomial(int n, int k) {
  double c = 1;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return c;
}

// Knot spans of non-zero length: the index k with knots[k] < knots[k + 1].
std::vector<int> nonempty_spans(const surface::BSplineBasis& b) {
  std::vector<int> spans;
  const int n = static_cast<int>(b.knots.size()) - b.degree - 1;
  for (int k = b.degree; k < n; ++k)
    if (b.knots[static_cast<size_t>(k)] < b.knots[static_cast<size_t>(k + 1)]) spans.push_back(k);
  return spans;
}

// Visits every Gauss point of every cell whose (p + 1)(q + 1) supporting vertex rows pass
// `wanted(rows)`: calls visit(rows, terms, first) with those rows, per derivative term
// i + j = order its weight (binomial x metric x area x Gauss weight) and the values of
// d^order R / du^i dv^j at the point for each of those vertices, and `first` true at a cell's
// first point.
struct Term {
  double weight = 0;
  std::vector<double> values;
};

template <class Wanted, class Visit>
void for_each_point(const BSplineSurface& s, int order, Wanted&& wanted, Visit&& visit) {
  const int p = s.u.degree, q = s.v.degree;
  const auto& gu = internal::gauss_legendre(p + 1);
  const auto& gv = internal::gauss_legendre(q + 1);
  // Floor of the speeds: 1e-3 of the mean speed, from the control box over the domain widths.
  const Eigen::Vector3d lo = s.points.colwise().minCoeff(), hi = s.points.colwise().maxCoeff();
  const double size = std::max((hi - lo).norm(), 1e-300);
  const double floor_a = 1e-3 * size / (s.u.knots.back() - s.u.knots.front());
  const double floor_b = 1e-3 * size / (s.v.knots.back() - s.v.knots.front());

  const int nb = (p + 1) * (q + 1);
  std::vector<double> du(static_cast<size_t>((max_order + 1) * (p + 1)));
  std::vector<double> dv(static_cast<size_t>((max_order + 1) * (q + 1)));
  // R^(i,j) for i, j <= order, per local vertex; W^(i,j).
  std::vector<double> R(static_cast<size_t>((order + 1) * (order + 1) * nb));
  std::array<std::array<double, max_order + 1>, max_order + 1> W{};
  std::vector<Eigen::Index> rows(static_cast<size_t>(nb));
  std::vector<Term> terms(static_cast<size_t>(order + 1));
  for (auto& t : terms) t.values.resize(static_cast<size_t>(nb));
  auto r_at = [&](int i, int j, int b) -> double& {
    return R[static_cast<size_t>((i * (order + 1) + j) * nb + b)];
  };
  const int du_order = std::min(order, p), dv_order = std::min(order, q);

  for (const int ku : nonempty_spans(s.u))
    for (const int kv : nonempty_spans(s.v)) {
      for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= q; ++b)
          rows[static_cast<size_t>(a * (q + 1) + b)] = s.index(ku - p + a, kv - q + b);
      if (!wanted(rows)) continue;
      const double u0 = s.u.knots[static_cast<size_t>(ku)],
                   u1 = s.u.knots[static_cast<size_t>(ku + 1)];
      const double v0 = s.v.knots[static_cast<size_t>(kv)],
                   v1 = s.v.knots[static_cast<size_t>(kv + 1)];
      for (size_t gi = 0; gi < gu.nodes.size(); ++gi)
        for (size_t gj = 0; gj < gv.nodes.size(); ++gj) {
          const double u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * gu.nodes[gi];
          const double v = 0.5 * (v0 + v1) + 0.5 * (v1 - v0) * gv.nodes[gj];
          const double jacobian = 0.25 * (u1 - u0) * (v1 - v0) * gu.weights[gi] * gv.weights[gj];
          std::fill(du.begin(), du.end(), 0.0);
          std::fill(dv.begin(), dv.end(), 0.0);
          surface::basis_derivatives(
              s.u, ku, u, du_order,
              std::span(du.data(), static_cast<size_t>((du_order + 1) * (p + 1))));
          surface::basis_derivatives(
              s.v, kv, v, dv_order,
              std::span(dv.data(), static_cast<size_t>((dv_order + 1) * (q + 1))));
          // A^(i,j) = N_a^(i) N_b^(j) w_ab and W^(i,j) = sum A^(i,j); then R = A / W by Leibniz:
          // R^(i,j) = (A^(i,j) - sum_{(l,m) != (0,0)} C(i,l) C(j,m) W^(l,m) R^(i-l,j-m)) / W.
          for (int i = 0; i <= order; ++i)
            for (int j = 0; i + j <= order; ++j) {
              double w = 0;
              for (int a = 0; a <= p; ++a)
                for (int b = 0; b <= q; ++b) {
                  const int l = a * (q + 1) + b;
                  const double value = du[static_cast<size_t>(i * (p + 1) + a)] *
                                       dv[static_cast<size_t>(j * (q + 1) + b)] *
                                       s.weights[rows[static_cast<size_t>(l)]];
                  r_at(i, j, l) = value;  // A for now
                  w += value;
                }
              W[static_cast<size_t>(i)][static_cast<size_t>(j)] = w;
            }
          for (int total = 0; total <= order; ++total)
            for (int i = 0; i <= total; ++i) {
              const int j = total - i;
              for (int l = 0; l < nb; ++l) {
                double value = r_at(i, j, l);
                for (int a = 0; a <= i; ++a)
                  for (int b = 0; b <= j; ++b)
                    if (a + b > 0)
                      value -= binomial(i, a) * binomial(j, b) *
                               W[static_cast<size_t>(a)][static_cast<size_t>(b)] *
                               r_at(i - a, j - b, l);
                r_at(i, j, l) = value / W[0][0];
              }
            }
          // The metric: S_u, S_v of the surface itself from the first derivatives of R.
          Eigen::Vector3d su = Eigen::Vector3d::Zero(), sv = Eigen::Vector3d::Zero();
          for (int l = 0; l < nb; ++l) {
            su += r_at(1, 0, l) * s.points.row(rows[static_cast<size_t>(l)]).transpose();
            sv += r_at(0, 1, l) * s.points.row(rows[static_cast<size_t>(l)]).transpose();
          }
          const double a = std::max(su.norm(), floor_a), b = std::max(sv.norm(), floor_b);
          const double area = std::max(su.cross(sv).norm(), 1e-3 * a * b);
          for (int i = 0; i <= order; ++i) {
            Term& t = terms[static_cast<size_t>(i)];
            double metric = 1;  // a^(2i) b^(2(order - i))
            for (int r = 0; r < i; ++r) metric *= a * a;
            for (int r = i; r < order; ++r) metric *= b * b;
            t.weight = binomial(order, i) / metric * area * jacobian;
            for (int l = 0; l < nb; ++l) t.values[static_cast<size_t>(l)] = r_at(i, order - i, l);
          }
          visit(rows, terms, gi == 0 && gj == 0);
        }
    }
}

}  // namespace

Eigen::SparseMatrix<double> fairness_matrix(const BSplineSurface& s,
                                            const std::vector<Eigen::Index>& free_index,
                                            Eigen::Index free_count, int order) {
  const int nb = (s.u.degree + 1) * (s.v.degree + 1);
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd local(nb, nb);
  std::vector<Eigen::Index> cell;  // the rows of the cell `local` belongs to
  auto flush = [&] {
    for (size_t a = 0; a < cell.size(); ++a) {
      const Eigen::Index fa = free_index[static_cast<size_t>(cell[a])];
      if (fa < 0) continue;
      for (size_t b = 0; b < cell.size(); ++b) {
        const Eigen::Index fb = free_index[static_cast<size_t>(cell[b])];
        const double value = local(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
        if (fb >= 0 && value != 0) triplets.emplace_back(fa, fb, value);
      }
    }
  };
  for_each_point(
      s, order,
      [&](const std::vector<Eigen::Index>& rows) {
        return std::any_of(rows.begin(), rows.end(),
                           [&](Eigen::Index r) { return free_index[static_cast<size_t>(r)] >= 0; });
      },
      [&](const std::vector<Eigen::Index>& rows, const std::vector<Term>& terms, bool first) {
        if (first) {  // a new cell: the previous one's local matrix is complete
          flush();
          cell = rows;
          local.setZero();
        }
        for (const Term& t : terms) {
          const Eigen::Map<const Eigen::VectorXd> g(t.values.data(), nb);
          local.noalias() += t.weight * g * g.transpose();
        }
      });
  flush();
  Eigen::SparseMatrix<double> H(free_count, free_count);
  H.setFromTriplets(triplets.begin(), triplets.end());
  return H;
}

}  // namespace clay::deform::detail
