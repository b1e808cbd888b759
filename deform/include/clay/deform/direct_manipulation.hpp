#pragma once
/// Direct manipulation of FFD lattices (Hsu, Hughes & Kaufman 1992, §3): "move this object point
/// there", for one or many points at once, becomes the control point displacement of least norm
/// that does it, ΔP = (B S)⁺ ΔQ (eqs. (2)-(7)), or the least-squares compromise when the request
/// cannot be met, with the miss reported.
///
/// Conventions (docs/deform.md):
/// - A selected point is given by its position X in the *undeformed* space, the space the lattice
///   frame is laid in: its local coordinates (s, t, u) (Sederberg–Parry eq. (1)) are what Hsu et
///   al. compute once per object point. Its current deformed image is deform_point(lattice, X);
///   the target is where that image must go: Δq = target − deform_point(lattice, X).
/// - B (eq. (2)) is the N x M matrix of basis products: row i holds N_a(s_i) N_b(t_i) N_c(u_i) at
///   column index(a, b, c) (the lattice's s-major order), (p+1)(q+1)(r+1) non-zeros per row for a
///   B-spline lattice, all (l+1)(m+1)(n+1) Bernstein products for a Bézier lattice.
/// - Locked control points (e.g. locked_control_points(...) in continuity.hpp, to keep C^k with
///   the space around) are not unknowns: they keep their position bit for bit.
/// - Tied control points are Hsu et al.'s S matrix (eq. (6)): each group moves by one common
///   displacement. The unknowns are one displacement per free control point and one per group;
///   the minimal norm is taken over these unknowns, a group counting once (eq. (7)). Without ties
///   that is the Frobenius norm of the lattice's displacement.
/// - The solve is dense: a complete orthogonal decomposition of B S restricted to the unknowns
///   that act on some selected point (N x m, m <= M); its rank-revealing QR is the full-rank
///   factorization B S = C D of eq. (3). Cost O(N² m): ~11 ms for 100 points on a cubic 8³-cell
///   lattice, then ~0.7 ms per move of the targets (DirectManipulator).
#include <clay/deform/export.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/summary.hpp>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace clay::deform {

/// One "move this point there" request.
struct PointMove {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< selected point X, undeformed space (mm)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  ///< where its deformed image goes (mm)
};

/// Settings of direct manipulation.
struct CLAY_DEFORM_API DirectManipulationOptions {
  /// Empty, or one entry per control point (row of lattice.points): true = the point must not
  /// move (e.g. locked_control_points(lattice, faces)).
  std::vector<bool> locked;
  /// Hsu et al.'s S matrix as groups of control point rows, each of >= 2 distinct rows, no row in
  /// two groups: the rows of a group move by one common displacement. A group holding a locked
  /// row is locked as a whole.
  std::vector<std::vector<Eigen::Index>> tied;
  /// Rank threshold, in (0, 1): pivots of the decomposition of B S at most rank_tolerance count
  /// as zero. B is dimensionless (rows of basis products summing to 1), so this bounds the
  /// amplification: no direction needing more than about 1 / rank_tolerance mm of control
  /// displacement per mm of image motion is used (duplicate points, points closer than the
  /// lattice can tell apart, points only locked planes reach but for rounding-sized weights);
  /// those get the least-squares compromise instead of a huge move.
  double rank_tolerance = 1e-10;
  /// Relative to the lattice size (|S|² + |T|² + |U|²)^(1/2), > 0: the request is feasible when
  /// every selected point's new image is within relative_tolerance × size of its target.
  double relative_tolerance = 1e-7;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// What a direct manipulation achieved.
struct CLAY_DEFORM_API DirectManipulationReport {
  int requested = 0;    ///< number of point moves N
  int unknowns = 0;     ///< free control points and tie groups that act on some selected point (m)
  int rank = 0;         ///< numerical rank of B S on those unknowns (<= min(N, m))
  double residual = 0;  ///< ||B S ΔP − ΔQ||_F (mm): the least-squares residual
  double achieved_max_error = 0;  ///< max_i |deform_point(new lattice, X_i) − target_i| (mm)
  double displacement_norm = 0;   ///< Frobenius norm of new − old lattice.points (mm)
  bool feasible = false;          ///< achieved_max_error <= tolerance × size
  /// Converged when feasible; NotConverged for a least-squares compromise; Failed when no free
  /// control point acts on the points. The message says what happened, in words;
  /// final_residual = achieved_max_error.
  Summary summary;

  /// One line, e.g. "feasible: 3 points moved, rank 3 of 3, largest miss 2.1e-14 mm".
  std::string brief() const;
};

/// The manipulated lattice and the report.
template <class Lattice>
struct DirectManipulationResult {
  Lattice lattice;                  ///< the input lattice with ΔP added to its control points
  DirectManipulationReport report;  ///< rank, residual, misses, displacement norm
};

/// B of eq. (2) for the selected points (N x 3 rows, undeformed space): N x M, row-major, the
/// basis products of each point's local coordinates (see above). Throws clay::Error:
/// InvalidGeometry for an invalid lattice, InvalidArgument for a non-finite point, OutOfDomain
/// for a point outside the lattice (naming its index and local coordinates).
CLAY_DEFORM_API Eigen::SparseMatrix<double, Eigen::RowMajor> influence_matrix(
    const BSplineLattice& lattice, const Points3& points);
/// Same for a Bézier lattice (Bernstein products, Sederberg–Parry eq. (2)).
CLAY_DEFORM_API Eigen::SparseMatrix<double, Eigen::RowMajor> influence_matrix(
    const BezierLattice& lattice, const Points3& points);

/// Bᵀ G without forming B (issue #41, adjoint users): row J of the result is Σ_i B_J(x_i) G_i,
/// the gradient with respect to lattice point J of a function whose gradient with respect to the
/// deformed points X(x_i) is G (points.rows() x 3); lattice.points.rows() x 3. No matrix is
/// formed (10^6 points: 0.2 s for a tricubic Bézier lattice, where forming B takes 2.1 s and 768
/// MB; bench_deform). Throws as influence_matrix, and InvalidArgument when G's rows do not match
/// the points'.
CLAY_DEFORM_API Points3 influence_transpose_product(const BSplineLattice& lattice,
                                                    const Points3& points, const Points3& g);
/// Same for a Bézier lattice.
CLAY_DEFORM_API Points3 influence_transpose_product(const BezierLattice& lattice,
                                                    const Points3& points, const Points3& g);

/// The stateful solver: fixes the lattice, the selected points and the options, and factorizes
/// B S once ("B⁺ need be computed only once", Hsu et al. §3.1), so that dragging the targets
/// costs a solve per move. Lattice is BSplineLattice or BezierLattice.
template <class Lattice>
class CLAY_DEFORM_API DirectManipulator {
 public:
  /// Selected points: N x 3 rows, undeformed space, N >= 1. Throws clay::Error: InvalidGeometry
  /// for an invalid lattice; InvalidArgument for no points, a non-finite point, bad options
  /// (including locked of the wrong size, a tied row outside [0, M) or in two groups);
  /// OutOfDomain for a point outside the lattice, naming its index.
  DirectManipulator(const Lattice& lattice, const Points3& points,
                    const DirectManipulationOptions& options = {});

  /// Moves the selected points' images to `targets` (N x 3 rows, same order):
  /// ΔP = (B S)⁺ (targets − current images) (Hsu–Hughes–Kaufman eqs. (5), (7)), minimal norm,
  /// least squares when over-determined. Throws clay::Error(InvalidArgument) for a row count
  /// other than N or a non-finite target (naming the row).
  DirectManipulationResult<Lattice> move(const Points3& targets) const;

  /// Current deformed images deform_point(lattice, X_i) of the selected points (N x 3).
  const Points3& images() const noexcept;
  /// Number of unknowns m (columns of B S that act on some selected point).
  int unknowns() const noexcept;
  /// Numerical rank of B S.
  int rank() const noexcept;

 private:
  // The factorization lives in the source (pimpl), so no Eigen decomposition is part of the API;
  // copies share it read-only, which is safe since every member function is const.
  struct State;
  std::shared_ptr<const State> state_;
};

/// One-off direct manipulation: DirectManipulator(lattice, points, options).move(targets).
/// Same throws (a request is named by its index in `moves`).
CLAY_DEFORM_API DirectManipulationResult<BSplineLattice> manipulate(
    const BSplineLattice& lattice, std::span<const PointMove> moves,
    const DirectManipulationOptions& options = {});
/// Same for a Bézier lattice.
CLAY_DEFORM_API DirectManipulationResult<BezierLattice> manipulate(
    const BezierLattice& lattice, std::span<const PointMove> moves,
    const DirectManipulationOptions& options = {});

// Exported here too: an instantiation is no more visible than its arguments, and the lattices,
// which have no out-of-line members, are not marked.
extern template class CLAY_DEFORM_API DirectManipulator<BSplineLattice>;
extern template class CLAY_DEFORM_API DirectManipulator<BezierLattice>;

}  // namespace clay::deform
