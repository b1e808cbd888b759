#pragma once
// Least-squares curve fits with fixed ends (internal), shared by make_compatible's knot merges
// and the curves taken from a surface.
#include <clay/surface/basis.hpp>

#include <Eigen/Core>
#include <Eigen/QR>

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

namespace clay::surface::detail {

/// Chebyshev-Lobatto parameters, `per` intervals in every interval of `breaks` (sorted), the last
/// break added.
inline std::vector<double> lobatto_parameters(const std::vector<double>& breaks, int per) {
  std::vector<double> t;
  for (size_t s = 0; s + 1 < breaks.size(); ++s)
    for (int k = 0; k < per; ++k)
      t.push_back(breaks[s] +
                  (breaks[s + 1] - breaks[s]) * 0.5 * (1 - std::cos(std::numbers::pi * k / per)));
  t.push_back(breaks.back());
  return t;
}

/// The control points (basis.count() rows, as many columns as target gives) minimising
/// sum_r |sum_j N_j(t_r) Q_j - target(t_r)|^2 with Q_0 = target(t_0) and Q_last =
/// target(t_last) (the ends interpolated): column-pivoted QR on the interior columns.
inline Eigen::MatrixXd fit_with_ends(const BSplineBasis& basis, const std::vector<double>& t,
                                     const std::function<Eigen::RowVectorXd(double)>& target) {
  const int p = basis.degree;
  const int n = basis.count();
  const auto rows = static_cast<Eigen::Index>(t.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rows, n);
  Eigen::MatrixXd f;
  std::vector<double> values(static_cast<size_t>(p + 1));
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double tr = t[static_cast<size_t>(r)];
    const int span = find_span(basis, tr);
    basis_functions(basis, span, tr, values);
    for (int j = 0; j <= p; ++j) a(r, span - p + j) = values[static_cast<size_t>(j)];
    const Eigen::RowVectorXd y = target(tr);
    if (r == 0) f.resize(rows, y.size());
    f.row(r) = y;
  }
  Eigen::MatrixXd net(n, f.cols());
  net.row(0) = f.row(0);
  net.row(n - 1) = f.row(rows - 1);
  f -= a.col(0) * net.row(0) + a.col(n - 1) * net.row(n - 1);
  if (n > 2) net.middleRows(1, n - 2) = a.middleCols(1, n - 2).colPivHouseholderQr().solve(f);
  return net;
}

}  // namespace clay::surface::detail
