#include <clay/deform/jacobian.hpp>

#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/LU>

#include <algorithm>
#include <vector>

#include "bernstein.hpp"
#include "cell_extraction.hpp"

namespace clay::deform {

namespace {

using Index3 = std::array<int, 3>;

size_t size_of(Index3 deg) {
  return static_cast<size_t>(deg[0] + 1) * static_cast<size_t>(deg[1] + 1) *
         static_cast<size_t>(deg[2] + 1);
}

BernsteinVolume zeros(Index3 deg) {
  BernsteinVolume v;
  v.degrees = deg;
  v.coefficients = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(size_of(deg)));
  return v;
}

/// Coordinate c of the derivative of the lattice along direction d, a Bernstein polynomial of
/// one degree less in d: p (P_{i+1} − P_i) (the hodograph).
BernsteinVolume derivative(const BezierLattice& lattice, int d, int c) {
  Index3 deg = lattice.degrees;
  const int p = deg[static_cast<size_t>(d)];
  deg[static_cast<size_t>(d)] -= 1;
  BernsteinVolume v = zeros(deg);
  Eigen::Index r = 0;
  for (int i = 0; i <= deg[0]; ++i)
    for (int j = 0; j <= deg[1]; ++j)
      for (int k = 0; k <= deg[2]; ++k) {
        const int next[3] = {i + (d == 0), j + (d == 1), k + (d == 2)};
        v.coefficients[r++] = p * (lattice.points(lattice.index(next[0], next[1], next[2]), c) -
                                   lattice.points(lattice.index(i, j, k), c));
      }
  return v;
}

/// Exact product of two Bernstein polynomials (degrees add): with scaled coefficients
/// c_I C(a+b, I) = sum_{i + i' = I} a_i C(a, i) b_i' C(b, i'), per direction.
BernsteinVolume product(const BernsteinVolume& A, const BernsteinVolume& B) {
  const Index3 da = A.degrees, db = B.degrees;
  const Index3 dc = {da[0] + db[0], da[1] + db[1], da[2] + db[2]};
  BernsteinVolume C = zeros(dc);
  auto scale = [](int n) {
    std::vector<double> s(static_cast<size_t>(n + 1));
    for (int i = 0; i <= n; ++i) s[static_cast<size_t>(i)] = internal::binomial(n, i);
    return s;
  };
  std::array<std::vector<double>, 3> sa, sb, sc;
  for (int d = 0; d < 3; ++d) {
    sa[static_cast<size_t>(d)] = scale(da[static_cast<size_t>(d)]);
    sb[static_cast<size_t>(d)] = scale(db[static_cast<size_t>(d)]);
    sc[static_cast<size_t>(d)] = scale(dc[static_cast<size_t>(d)]);
  }
  auto at = [](const Index3& deg, int i, int j, int k) {
    return static_cast<Eigen::Index>((i * (deg[1] + 1) + j) * (deg[2] + 1) + k);
  };
  for (int i = 0; i <= da[0]; ++i)
    for (int j = 0; j <= da[1]; ++j)
      for (int k = 0; k <= da[2]; ++k) {
        const double a = A.coefficients[at(da, i, j, k)] * sa[0][static_cast<size_t>(i)] *
                         sa[1][static_cast<size_t>(j)] * sa[2][static_cast<size_t>(k)];
        if (a == 0) continue;
        for (int i2 = 0; i2 <= db[0]; ++i2)
          for (int j2 = 0; j2 <= db[1]; ++j2)
            for (int k2 = 0; k2 <= db[2]; ++k2)
              C.coefficients[at(dc, i + i2, j + j2, k + k2)] +=
                  a * B.coefficients[at(db, i2, j2, k2)] * sb[0][static_cast<size_t>(i2)] *
                  sb[1][static_cast<size_t>(j2)] * sb[2][static_cast<size_t>(k2)];
      }
  for (int i = 0; i <= dc[0]; ++i)
    for (int j = 0; j <= dc[1]; ++j)
      for (int k = 0; k <= dc[2]; ++k)
        C.coefficients[at(dc, i, j, k)] /= sc[0][static_cast<size_t>(i)] *
                                           sc[1][static_cast<size_t>(j)] *
                                           sc[2][static_cast<size_t>(k)];
  return C;
}

/// a − b for polynomials of the same degrees.
BernsteinVolume difference(BernsteinVolume a, const BernsteinVolume& b) {
  a.coefficients -= b.coefficients;
  return a;
}

Eigen::Matrix3d edges(const Frame& f) {
  Eigen::Matrix3d F;
  F.col(0) = f.s;
  F.col(1) = f.t;
  F.col(2) = f.u;
  return F;
}

}  // namespace

double evaluate(const BernsteinVolume& v, double s, double t, double u) {
  const Index3 deg = v.degrees;
  std::vector<double> c(v.coefficients.data(), v.coefficients.data() + v.coefficients.size());
  // de Casteljau in u (last index), then t, then s, collapsing in place.
  const double x[3] = {s, t, u};
  int n0 = deg[0] + 1, n1 = deg[1] + 1, n2 = deg[2] + 1;
  for (int line = 0; line < n0 * n1; ++line) {
    double* a = c.data() + line * n2;
    for (int level = 1; level < n2; ++level)
      for (int k = 0; k < n2 - level; ++k) a[k] = (1 - x[2]) * a[k] + x[2] * a[k + 1];
    c[static_cast<size_t>(line)] = a[0];
  }
  for (int i = 0; i < n0; ++i) {
    double* a = c.data() + i * n1;
    for (int level = 1; level < n1; ++level)
      for (int j = 0; j < n1 - level; ++j) a[j] = (1 - x[1]) * a[j] + x[1] * a[j + 1];
    c[static_cast<size_t>(i)] = a[0];
  }
  for (int level = 1; level < n0; ++level)
    for (int i = 0; i < n0 - level; ++i)
      c[static_cast<size_t>(i)] =
          (1 - x[0]) * c[static_cast<size_t>(i)] + x[0] * c[static_cast<size_t>(i) + 1];
  return c[0];
}

BernsteinVolume jacobian_bernstein(const BezierLattice& lattice) {
  validate(lattice);
  // Sederberg–Parry §4: det(X_s, X_t, X_u) = X_s . (X_t x X_u), each a Bernstein polynomial.
  std::array<std::array<BernsteinVolume, 3>, 3> D;  // D[direction][coordinate]
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 3; ++c)
      D[static_cast<size_t>(d)][static_cast<size_t>(c)] = derivative(lattice, d, c);
  const auto& Xs = D[0];
  const auto& Xt = D[1];
  const auto& Xu = D[2];
  const BernsteinVolume cx = difference(product(Xt[1], Xu[2]), product(Xt[2], Xu[1]));
  const BernsteinVolume cy = difference(product(Xt[2], Xu[0]), product(Xt[0], Xu[2]));
  const BernsteinVolume cz = difference(product(Xt[0], Xu[1]), product(Xt[1], Xu[0]));
  BernsteinVolume det = product(Xs[0], cx);
  det.coefficients += product(Xs[1], cy).coefficients;
  det.coefficients += product(Xs[2], cz).coefficients;
  // Volume ratio: divide by the frame's volume S x T . U (chain rule through eq. (1)).
  det.coefficients /= lattice.frame.volume();
  return det;
}

std::vector<BernsteinVolume> jacobian_bernstein(const BSplineLattice& lattice) {
  const BezierCells cells = bezier_cells(lattice);
  std::vector<BernsteinVolume> out;
  out.reserve(cells.cells.size());
  for (const BezierLattice& cell : cells.cells) out.push_back(jacobian_bernstein(cell));
  return out;
}

namespace {

JacobianBounds bounds_of(const std::vector<BernsteinVolume>& volumes) {
  JacobianBounds b;
  b.min = volumes.front().coefficients.minCoeff();
  b.max = volumes.front().coefficients.maxCoeff();
  for (const auto& v : volumes) {
    b.min = std::min(b.min, v.coefficients.minCoeff());
    b.max = std::max(b.max, v.coefficients.maxCoeff());
  }
  b.fold_free = b.min > 0;
  return b;
}

}  // namespace

JacobianBounds jacobian_bounds(const BezierLattice& lattice) {
  return bounds_of({jacobian_bernstein(lattice)});
}

JacobianBounds jacobian_bounds(const BSplineLattice& lattice) {
  return bounds_of(jacobian_bernstein(lattice));
}

namespace {

/// The hodographs D[direction][coordinate] of a lattice's points.
using Hodographs = std::array<std::array<BernsteinVolume, 3>, 3>;

Hodographs hodographs(const BezierLattice& lattice) {
  Hodographs D;
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 3; ++c)
      D[static_cast<size_t>(d)][static_cast<size_t>(c)] = derivative(lattice, d, c);
  return D;
}

/// a × b per coordinate, for Bernstein vectors.
std::array<BernsteinVolume, 3> cross(const std::array<BernsteinVolume, 3>& a,
                                     const std::array<BernsteinVolume, 3>& b) {
  return {difference(product(a[1], b[2]), product(a[2], b[1])),
          difference(product(a[2], b[0]), product(a[0], b[2])),
          difference(product(a[0], b[1]), product(a[1], b[0]))};
}

/// Values and the dense gradient (coefficients x 3 × points) of one Bézier lattice.
std::pair<Eigen::VectorXd, Eigen::MatrixXd> constraints_dense(const BezierLattice& lattice) {
  validate(lattice);
  const Hodographs x = hodographs(lattice);
  // e_s · (X_t × X_u) + e_t · (X_u × X_s) + e_u · (X_s × X_t)
  const std::array<std::array<BernsteinVolume, 3>, 3> cofactors = {
      cross(x[1], x[2]), cross(x[2], x[0]), cross(x[0], x[1])};
  const double volume = lattice.frame.volume();
  const Eigen::VectorXd values = jacobian_bernstein(lattice).coefficients;
  Eigen::MatrixXd gradient = Eigen::MatrixXd::Zero(values.size(), 3 * lattice.points.rows());
  BezierLattice unit = lattice;
  unit.points.setZero();
  for (Eigen::Index j = 0; j < lattice.points.rows(); ++j)
    for (int c = 0; c < 3; ++c) {
      unit.points(j, c) = 1;
      for (int d = 0; d < 3; ++d)
        gradient.col(3 * j + c) +=
            product(derivative(unit, d, c),
                    cofactors[static_cast<size_t>(d)][static_cast<size_t>(c)])
                .coefficients;
      unit.points(j, c) = 0;
    }
  gradient /= volume;
  return {values, gradient};
}

}  // namespace

JacobianConstraints jacobian_constraints(const BezierLattice& lattice) {
  auto [values, dense] = constraints_dense(lattice);
  JacobianConstraints out;
  out.values = std::move(values);
  out.gradient = dense.sparseView();
  return out;
}

JacobianConstraints jacobian_constraints(const BSplineLattice& lattice) {
  const BezierCells cells = bezier_cells(lattice);
  std::array<std::vector<surface::SpanExtraction>, 3> spans;
  for (std::size_t d = 0; d < 3; ++d) spans[d] = surface::bezier_extraction(lattice.bases[d]);
  const auto n = cells.counts();
  std::vector<double> values;
  std::vector<Eigen::Triplet<double>> entries;
  for (int ci = 0; ci < n[0]; ++ci)
    for (int cj = 0; cj < n[1]; ++cj)
      for (int ck = 0; ck < n[2]; ++ck) {
        const BezierLattice& cell = cells.cell(ci, cj, ck);
        const auto [v, g] = constraints_dense(cell);
        const detail::CellExtraction e = detail::cell_extraction(lattice, cell, spans, ci, cj, ck);
        const auto first_row = static_cast<int>(values.size());
        values.insert(values.end(), v.data(), v.data() + v.size());
        for (Eigen::Index q = 0; q < e.matrix.cols(); ++q)  // lattice point e.points[q]
          for (int c = 0; c < 3; ++c) {
            Eigen::VectorXd d = Eigen::VectorXd::Zero(v.size());
            for (Eigen::Index p = 0; p < e.matrix.rows(); ++p)
              if (e.matrix(p, q) != 0) d += e.matrix(p, q) * g.col(3 * p + c);
            for (Eigen::Index r = 0; r < d.size(); ++r)
              if (d[r] != 0)
                entries.emplace_back(first_row + static_cast<int>(r),
                                     3 * e.points[static_cast<size_t>(q)] + c, d[r]);
          }
      }
  JacobianConstraints out;
  out.values =
      Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  out.gradient.resize(out.values.size(), 3 * lattice.points.rows());
  out.gradient.setFromTriplets(entries.begin(), entries.end());
  return out;
}

Eigen::Matrix3d jacobian_matrix(const BezierLattice& lattice, const Eigen::Vector3d& x) {
  Eigen::Vector3d local;
  if (!detail::clamped_local(lattice.frame, x, local)) return Eigen::Matrix3d::Identity();
  Eigen::Matrix3d M;  // columns dX/ds, dX/dt, dX/du
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 3; ++c)
      M(c, d) = evaluate(derivative(lattice, d, c), local[0], local[1], local[2]);
  return M * edges(lattice.frame).inverse();
}

Eigen::Matrix3d jacobian_matrix(const BSplineLattice& lattice, const Eigen::Vector3d& x) {
  Eigen::Vector3d local;
  if (!detail::clamped_local(lattice.frame, x, local)) return Eigen::Matrix3d::Identity();
  std::array<int, 3> span;
  std::array<std::vector<double>, 3> N;  // row 0 values, row 1 first derivatives
  std::array<int, 3> p;
  for (int d = 0; d < 3; ++d) {
    const auto& basis = lattice.bases[static_cast<size_t>(d)];
    p[static_cast<size_t>(d)] = basis.degree;
    span[static_cast<size_t>(d)] = surface::find_span(basis, local[d]);
    N[static_cast<size_t>(d)].resize(static_cast<size_t>(2 * (basis.degree + 1)));
    surface::basis_derivatives(basis, span[static_cast<size_t>(d)], local[d], 1,
                               N[static_cast<size_t>(d)]);
  }
  auto value = [&](int d, int q, int order) {
    return N[static_cast<size_t>(d)]
            [static_cast<size_t>(order * (p[static_cast<size_t>(d)] + 1) + q)];
  };
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (int i = 0; i <= p[0]; ++i)
    for (int j = 0; j <= p[1]; ++j)
      for (int k = 0; k <= p[2]; ++k) {
        const Eigen::Vector3d P =
            lattice.points
                .row(lattice.index(span[0] - p[0] + i, span[1] - p[1] + j, span[2] - p[2] + k))
                .transpose();
        M.col(0) += value(0, i, 1) * value(1, j, 0) * value(2, k, 0) * P;
        M.col(1) += value(0, i, 0) * value(1, j, 1) * value(2, k, 0) * P;
        M.col(2) += value(0, i, 0) * value(1, j, 0) * value(2, k, 1) * P;
      }
  return M * edges(lattice.frame).inverse();
}

}  // namespace clay::deform
