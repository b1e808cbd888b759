#pragma once
// The fairness energy of the exact style mode: a Galerkin discretization of one continuous
// functional of the displacement field D(u, v) = sum R_ij(u, v) d_ij, so that refining the net
// (exact knot insertion, which keeps the parametrization) converges to one shape instead of
// following the control net. Order 2 is the thin-plate energy (a fourth-order problem: position
// and tangent plane can be held at the bound, G1); order 3 the energy of the third derivatives (a
// sixth-order problem: curvature too, G2):
//   E_k(D) = integral over the domain of
//            sum_{i + j = k} C(k, i) |d^k D / du^i dv^j|^2 / (a^(2i) b^(2j)) |S_u x S_v| du dv,
// with a = |S_u| and b = |S_v| the parent's speeds at (u, v) (floored at 1e-3 of the surface's
// mean speed, so a collapsed edge does not blow up the weight), which turns parameter
// derivatives into approximately arc-length ones: the energy is nearly that of the displaced
// surface measured in mm, and independent of how the net is spaced. Integrated per knot-span cell
// by the (p + 1) x (q + 1)-point Gauss–Legendre rule.
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace clay::deform::detail {

/// The energy's matrix H over the free vertices, E_k = sum over x, y, z of d^T H d (style_exact
/// reports E_k of its result this way):
/// free_index[r] is the unknown of vertex r or -1 for a fixed one (d = 0). Needs degree >= order
/// in u and v (else the order-k derivatives vanish inside the spans and H is singular).
Eigen::SparseMatrix<double> fairness_matrix(const surface::BSplineSurface& s,
                                            const std::vector<Eigen::Index>& free_index,
                                            Eigen::Index free_count, int order);

}  // namespace clay::deform::detail
