#pragma once
/// The Jacobian of an FFD, its trivariate Bernstein form and the bounds it gives (Sederberg–Parry
/// §4): the smallest Bernstein coefficient > 0 proves the deformation has no fold (it is locally
/// injective everywhere in the lattice), and the extreme coefficients bound the volume change.
///
/// Normalization: the Jacobian reported is the volume ratio det(dX_fd / dX), the determinant of
/// the map in world coordinates, = det(dX_fd/ds, dX_fd/dt, dX_fd/du) / (S × T · U). The identity
/// (undisplaced lattice) has Jacobian exactly 1, whatever the frame's size, skew or handedness.
#include <clay/deform/export.hpp>
#include <clay/deform/lattice.hpp>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <vector>

namespace clay::deform {

/// A scalar trivariate Bernstein polynomial on the unit cube: degrees (a, b, c) and coefficient
/// c_ijk at (i (b+1) + j)(c+1) + k of `coefficients` (the lattice's s-major order).
struct BernsteinVolume {
  std::array<int, 3> degrees{0, 0, 0};  ///< degrees along s, t, u (>= 0)
  Eigen::VectorXd coefficients;         ///< (a+1)(b+1)(c+1) Bernstein coefficients, s-major
};

/// Value at local coordinates (s, t, u) in [0, 1]^3 by de Casteljau's algorithm.
CLAY_DEFORM_API double evaluate(const BernsteinVolume& volume, double s, double t, double u);

/// Bounds of the Jacobian from the Bernstein coefficients (convex hull property).
struct JacobianBounds {
  double min = 1;         ///< smallest coefficient: a lower bound of the volume ratio
  double max = 1;         ///< largest coefficient: an upper bound of the volume ratio
  bool fold_free = true;  ///< min > 0: no fold anywhere in the lattice (sufficient, not
                          ///< necessary: false means a fold could not be excluded)
};

/// The Jacobian (volume ratio, see above) of a Bézier lattice as a Bernstein polynomial of degrees
/// (3l − 1, 3m − 1, 3n − 1): det(X_s, X_t, X_u) formed by exact Bernstein products of the
/// derivative lattices l ΔP, m ΔP, n ΔP (Sederberg–Parry §4). Throws clay::Error(InvalidGeometry)
/// for an invalid lattice.
CLAY_DEFORM_API BernsteinVolume jacobian_bernstein(const BezierLattice& lattice);

/// Per Bézier cell of a B-spline lattice (bezier_cells order): each cell's Jacobian on the cell's
/// own unit cube.
CLAY_DEFORM_API std::vector<BernsteinVolume> jacobian_bernstein(const BSplineLattice& lattice);

/// min / max of the coefficients of jacobian_bernstein(lattice) and fold_free = min > 0.
CLAY_DEFORM_API JacobianBounds jacobian_bounds(const BezierLattice& lattice);
/// Same over all cells of a B-spline lattice.
CLAY_DEFORM_API JacobianBounds jacobian_bounds(const BSplineLattice& lattice);

/// The Jacobian's Bernstein coefficients as an optimiser's constraints (issue #41): keeping every
/// value above a floor > 0 keeps the lattice fold-free with a bounded volume ratio.
struct JacobianConstraints {
  /// Every coefficient of jacobian_bernstein (a B-spline lattice: cell after cell in
  /// bezier_cells order), each a cubic polynomial in the lattice points.
  Eigen::VectorXd values;
  /// Their exact gradient: values x 3 × points, column 3 j + c the derivative with respect to
  /// coordinate c of point j. det(X_s, X_t, X_u) is trilinear in its columns, so the derivative
  /// along a unit move e of one coordinate is e_s · (X_t × X_u) + e_t · (X_u × X_s) +
  /// e_u · (X_s × X_t) (e_s its s-hodograph), formed by the same exact Bernstein products.
  Eigen::SparseMatrix<double, Eigen::RowMajor> gradient;
};

/// The constraints of a Bézier lattice. Throws clay::Error(InvalidGeometry) for an invalid
/// lattice.
CLAY_DEFORM_API JacobianConstraints jacobian_constraints(const BezierLattice& lattice);
/// Same for a B-spline lattice: each cell's gradient taken through its Bézier extraction (a
/// fixed linear map from the lattice's points), so a row holds the cell's support only.
CLAY_DEFORM_API JacobianConstraints jacobian_constraints(const BSplineLattice& lattice);

/// The 3 x 3 derivative dX_fd / dX at x (world coordinates) from the derivative of eq. (2) by
/// de Casteljau; the identity outside the lattice. Precondition: a valid lattice.
CLAY_DEFORM_API Eigen::Matrix3d jacobian_matrix(const BezierLattice& lattice,
                                                const Eigen::Vector3d& x);
/// Same for a B-spline lattice (basis derivatives, The NURBS Book A2.3).
CLAY_DEFORM_API Eigen::Matrix3d jacobian_matrix(const BSplineLattice& lattice,
                                                const Eigen::Vector3d& x);

}  // namespace clay::deform
