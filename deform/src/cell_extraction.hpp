#pragma once
// A B-spline lattice's Bézier cell as a fixed linear map of the lattice's points (bezier_cells'
// extraction), shared by the derivatives of compositions (derivatives.cpp) and of the Jacobian's
// coefficients (jacobian.cpp). Private to clay_deform.
#include <clay/deform/lattice.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

namespace clay::deform::detail {

/// Cell (ci, cj, ck)'s Bézier points from the lattice's: point (i, j, k) of the cell is
/// Σ ea(i, ii) eb(j, jj) ec(k, kk) P(first + (ii, jj, kk)), so cell point r =
/// Σ_q matrix(r, q) lattice point points[q], E = ea ⊗ eb ⊗ ec over the cell's support.
struct CellExtraction {
  Eigen::MatrixXd matrix;   ///< cell points x support points, both in the cell's index order
  std::vector<int> points;  ///< the support's lattice point indices (lattice.index order)
};

/// `spans`: surface::bezier_extraction of the lattice's three bases.
inline CellExtraction cell_extraction(
    const BSplineLattice& lattice, const BezierLattice& cell,
    const std::array<std::vector<surface::SpanExtraction>, 3>& spans, int ci, int cj, int ck) {
  const auto& ea = spans[0][static_cast<std::size_t>(ci)];
  const auto& eb = spans[1][static_cast<std::size_t>(cj)];
  const auto& ec = spans[2][static_cast<std::size_t>(ck)];
  const auto n = cell.counts();
  const Eigen::Index m = cell.points.rows();
  CellExtraction out{Eigen::MatrixXd(m, m), std::vector<int>(static_cast<std::size_t>(m))};
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k)
        for (int ii = 0; ii < n[0]; ++ii)
          for (int jj = 0; jj < n[1]; ++jj)
            for (int kk = 0; kk < n[2]; ++kk) {
              out.matrix(cell.index(i, j, k), cell.index(ii, jj, kk)) =
                  ea.matrix(i, ii) * eb.matrix(j, jj) * ec.matrix(k, kk);
              out.points[static_cast<std::size_t>(cell.index(ii, jj, kk))] =
                  static_cast<int>(lattice.index(ea.first + ii, eb.first + jj, ec.first + kk));
            }
  return out;
}

}  // namespace clay::deform::detail
