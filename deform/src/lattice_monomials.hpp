#pragma once
// The FFD of a Bézier lattice as a polynomial in (s, t, u) in the power basis (internal to
// clay_deform): which monomials s^a t^b u^c it really has, and so its true total degree.
// A trilinear lattice whose corners move by one vector is an affine map: its monomials are 1, s,
// t and u, total degree 1, although the tensor-product degrees (1, 1, 1) would compose to three
// times the surface's degree. compose_exact composes such lattices monomial by monomial
// (issue #20: "composed degree from the lattice's true total degree").
#include <clay/deform/lattice.hpp>

#include <Eigen/Core>

#include <array>
#include <vector>

namespace clay::deform::detail {

/// X(s, t, u) = Σ coefficients[k] s^a t^b u^c over exponents[k] = (a, b, c), the monomials whose
/// coefficient is not zero up to the rounding of the conversion from the Bernstein form.
struct LatticeMonomials {
  std::vector<std::array<int, 3>> exponents;
  std::vector<Eigen::Vector3d> coefficients;
  int total_degree = 0;  ///< max a + b + c over the monomials
  /// Σ |coefficients| of the non-constant monomials over the largest offset |P_ijk − P_000|:
  /// how much the power basis magnifies rounding when the terms are summed. About 1 to 3 for an
  /// affine lattice; it grows like C(l, a) C(a, i) with the degrees.
  double amplification = 0;
  /// True when the monomials were found (not for lattices of more than `max_monomial_points`
  /// control points) and the power basis loses at most ~1e-13 of the size to rounding, so
  /// composing term by term stays exact to 1e-12 of the size.
  bool usable() const noexcept { return !exponents.empty() && amplification <= 1e3; }
};

/// Lattices with more control points are not expanded (the expansion costs (Π (d + 1)(d + 2) / 2)
/// operations, and their power basis is too ill-conditioned to be of use).
inline constexpr int max_monomial_points = 1000;

/// The monomials of the lattice's FFD (Sederberg–Parry eq. (2) expanded: B_i^l(s) =
/// Σ_{a >= i} C(l, a) C(a, i) (-1)^(a-i) s^a). A coefficient counts as zero when it is below
/// 64 (l + m + n + 1) ε times the sum of the magnitudes that made it: rounding, not shape.
LatticeMonomials lattice_monomials(const BezierLattice& lattice);

}  // namespace clay::deform::detail
