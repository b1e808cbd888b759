#pragma once
/// Exact derivatives of deformed geometry with respect to the lattice points (issue #41).
///
/// A non-rational lattice's FFD X(x) = Σ_j B_j(s, t, u) L_j (Sederberg–Parry eq. (2); B_j the
/// products of Bernstein polynomials of the local coordinates of x) is linear in its points L_j,
/// and so is its exact composition with a B-spline surface: every composed control point is
/// P_k = Σ_j C_kj L_j, with C fixed by the surface, the lattice's frame and its degrees. So the
/// Jacobian of the deformed surface with respect to the lattice points is exact and constant,
/// ∂P_k/∂L_j = C_kj I_3, and its structure never depends on where the points are (compose_exact
/// gives the lightest form of each deformed surface, which does: an undisplaced lattice composes
/// at the surface's own degrees, a moved one at the full tensor degrees).
#include <clay/deform/export.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/SparseCore>

namespace clay::deform {

/// A deformed surface in the fixed form its derivatives are taken in, and the linear map from the
/// lattice points to its control points.
struct CompositionJacobian {
  /// The composition at the lattice's points: the surface's Bézier patches composed by eq. (2)
  /// at their tensor degrees (Σ_d degree_d × the degree of local coordinate d on the patch),
  /// elevated to the largest and joined C0 at every break (no knot removed). Rational when the
  /// surface is (its weights, the composed W^(l+m+n), do not depend on the lattice points).
  surface::BSplineSurface surface;
  /// Control points × lattice points (lattice.index order): surface.points = matrix ×
  /// lattice.points, coordinate by coordinate. Exact zeros are not stored.
  Eigen::SparseMatrix<double, Eigen::RowMajor> matrix;
};

/// The composition of `lattice` with `surface` and its exact Jacobian with respect to the lattice
/// points (see above): every patch composed once with the lattice's points replaced by the unit
/// vectors e_j, so column j is the composition of the scalar field B_j. Throws clay::Error:
/// InvalidGeometry for an invalid lattice or surface, OutOfDomain when the surface leaves the
/// lattice (naming the patch and the local coordinate: the FFD is the identity outside, so the
/// deformed surface is not one polynomial there; enlarge the lattice's frame).
CLAY_DEFORM_API CompositionJacobian composition_jacobian(const BezierLattice& lattice,
                                                         const surface::BSplineSurface& surface);
/// Same for a B-spline lattice: the surface split where it meets a knot plane along an
/// iso-parameter line (as compose_exact splits it), each patch composed in its Bézier cell and
/// the cell's points written as the lattice's (bezier_cells' extraction, a fixed linear map), so
/// C is sparse: a row holds the lattice points of one cell's support. Throws as above, and
/// InvalidArgument when a patch crosses a knot plane other than along an iso-parameter line
/// (no single polynomial patch is exact there).
CLAY_DEFORM_API CompositionJacobian composition_jacobian(const BSplineLattice& lattice,
                                                         const surface::BSplineSurface& surface);

}  // namespace clay::deform
