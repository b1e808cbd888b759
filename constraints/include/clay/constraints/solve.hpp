#pragma once
/// solve(): the geometric constraint solver, with degrees of freedom and a diagnosis of redundant
/// and conflicting constraints.
///
/// How (see docs/constraints.md): trivial equalities (coincident, horizontal, vertical, fixed)
/// are substituted by union-find; the sketch splits into connected components; the remaining
/// equations are solved by Levenberg–Marquardt (Ceres, automatic differentiation, sparse
/// Cholesky). The Jacobian taken from Ceres at the solution is column- and row-normalised and
/// factorised by a sparse rank-revealing QR (Eigen SparseQR, COLAMD): its rank gives the degrees
/// of freedom; a dependent equation gives the smallest set of constraints it depends on (its
/// fundamental circuit), "redundant" when they all hold after the solve, "conflicting" otherwise.
#include <clay/constraints/constraint.hpp>
#include <clay/constraints/export.hpp>
#include <clay/summary.hpp>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace clay::constraints {

/// A point dragged toward a target (world, mm) by solve(): see SolveOptions::drag.
struct Drag {
  PointId point;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
};

/// Settings of solve().
struct CLAY_CONSTRAINTS_API SolveOptions {
  double residual_tolerance = 1e-10;  ///< largest residual (mm, or radians for angles) of a solved
                                      ///< constraint; in (0, 1e-3]
  int max_iterations = 100;           ///< Levenberg–Marquardt iterations, >= 1
  double rank_tolerance = 1e-9;  ///< pivot threshold of the rank-revealing QR on the normalised
                                 ///< Jacobian, in (0, 1e-2]
  bool diagnose = true;          ///< compute degrees of freedom and dependencies after the solve
  /// Points pulled to targets while everything else changes as little as possible: the solve
  /// first minimises |p − target|² + 1e-8 |x − start|² + 1e4 |constraint residuals|² (the
  /// constraints as heavy equations), then solves the constraints alone from there.
  std::vector<Drag> drag;
  /// A B-spline curve entity whose constrained control points moved (a distance or a tangent at
  /// its ends) has the change spread over its other control points, as the displacement of least
  /// bending (minimum sum of squared second differences of the control points' displacements,
  /// the moved ones held): the minimum-norm solve alone moves only what the constraints name,
  /// leaving hooks of the whole change at a freehand curve's ends (issue #40). Control points
  /// that any equation uses, or that share a point with another entity, keep the solver's value.
  bool spread_curve_changes = true;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// A set of constraints that depend on each other (a circuit: remove any one and the rest are
/// independent).
struct Dependency {
  std::vector<int> constraints;  ///< indices into the constraint list, ascending
  bool conflicting = false;      ///< true: they cannot all hold (some residual > tolerance);
                                 ///< false: redundant (they all hold; any one can go)
  std::string message;           ///< "conflicting: constraint #3 (angle ...), #4 (...)"
};

/// What solve() found.
struct CLAY_CONSTRAINTS_API SolveReport {
  Summary summary;                    ///< Converged when every constraint holds within tolerance
  double max_residual = 0;            ///< largest |residual| after the solve (mm or radians)
  int unknowns = 0;                   ///< scalar unknowns before substitution
  int substituted = 0;                ///< unknowns removed by union-find substitution
  int equations = 0;                  ///< scalar equations left after substitution
  int components = 0;                 ///< independent parts solved together
  int degrees_of_freedom = -1;        ///< remaining DOF (unknowns − rank); -1 when not diagnosed
  std::vector<Dependency> redundant;  ///< redundant sets (consistent, removable)
  std::vector<Dependency> conflicting;  ///< conflicting sets (the sketch cannot satisfy them)
  std::vector<int> flipped;             ///< constraints whose orientation (turn sense, side, arc
                                        ///< direction) differs from the start: a different solution
  double solve_seconds = 0;             ///< wall time of the solve
  double diagnose_seconds = 0;          ///< wall time of the rank / dependency analysis

  /// One line: the summary, the largest residual, the unknowns and the degrees of freedom.
  std::string brief() const;
};

/// The solved sketch and its report.
struct SolveResult {
  sketch::Sketch sketch;  ///< positions (and circle radii) after the solve
  SolveReport report;
};

/// Solves the constraints on the sketch. The result's sketch satisfies them to
/// options.residual_tolerance when report.summary.converged(); otherwise it is the least-squares
/// compromise and the report names the conflicting sets. Throws clay::Error: InvalidArgument for a
/// constraint that refers to a missing point/entity or to an entity of the wrong kind (naming
/// "constraint #k" and the reference), for a planar constraint on entities not in one plane, for a
/// non-positive distance/radius or a non-finite value, and for bad options; InvalidGeometry for an
/// invalid sketch (sketch::validate).
CLAY_CONSTRAINTS_API SolveResult solve(const sketch::Sketch& sketch,
                                       const std::vector<Constraint>& constraints,
                                       const SolveOptions& options = {});

}  // namespace clay::constraints
