#pragma once
/// Summary — the outcome of iterative work (projection, fitting, solving, refitting).
/// Not converging is an outcome reported here, not an exception (Ceres' Solver::Summary).
#include <clay/surface/export.hpp>

#include <string>

namespace clay {

/// How an iterative computation ended.
enum class Termination {
  Converged,     ///< the convergence criterion was met
  NotConverged,  ///< the iteration limit was reached; the result is the best found
  Failed,        ///< no usable result (the message says why)
};

/// Outcome of an iterative computation.
struct CLAY_SURFACE_API Summary {
  Termination termination = Termination::Failed;
  std::string message;          ///< what happened, in words
  int iterations = 0;           ///< iterations performed
  double initial_residual = 0;  ///< residual before the first iteration (units of the problem)
  double final_residual = 0;    ///< residual at the end

  /// True when termination == Converged.
  bool converged() const noexcept { return termination == Termination::Converged; }
  /// One line: "converged in 4 iterations, residual 3.2e-13 (from 1.1e-01): <message>".
  std::string brief() const;
};

}  // namespace clay
