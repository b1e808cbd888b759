// solve(): substitution, Ceres solve, rank / dependency diagnosis (see solve.hpp).
#include "equations.hpp"

#include <clay/constraints/solve.hpp>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <ceres/ceres.h>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <Eigen/SparseQR>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <numeric>
#include <set>

namespace clay::constraints {

std::vector<std::string> SolveOptions::problems() const {
  std::vector<std::string> out;
  auto bad = [&out](const std::string& field, double value, const std::string& rule) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", value);
    out.push_back("SolveOptions::" + field + " = " + buffer + " breaks the rule " + rule);
  };
  if (!(residual_tolerance > 0 && residual_tolerance <= 1e-3))
    bad("residual_tolerance", residual_tolerance, "0 < residual_tolerance <= 1e-3");
  if (max_iterations < 1) bad("max_iterations", max_iterations, ">= 1");
  if (!(rank_tolerance > 0 && rank_tolerance <= 1e-2))
    bad("rank_tolerance", rank_tolerance, "0 < rank_tolerance <= 1e-2");
  for (size_t k = 0; k < drag.size(); ++k)
    if (!internal::all_finite(drag[k].target))
      out.push_back("SolveOptions::drag[" + std::to_string(k) + "]: the target is not finite");
  return out;
}

void SolveOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

namespace detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Union-find over integers with path halving.
struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[static_cast<size_t>(x)] != x) {
      parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
      x = parent[static_cast<size_t>(x)];
    }
    return x;
  }
  /// Joins the classes of a and b; false when they were one class already.
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    return true;
  }
};

/// The substitution: scalar -> class representative, which classes are fixed (and to what),
/// and the constraints whose equalities closed a cycle or clashed with a fixed value.
struct Reduction {
  std::vector<int> rep;        // per scalar
  std::vector<int> block;      // per scalar: Ceres block index, -1 when fixed
  std::vector<double> fixed;   // per scalar (valid at reps): fixed value
  std::vector<char> is_fixed;  // per scalar (valid at reps)
  std::vector<double> values;  // per block
  std::set<int> flagged;       // constraints involved in a dependency found here
  int substituted = 0;
};

Reduction reduce(const Model& m) {
  const size_t n = m.scalars.size();
  UnionFind uf(n);
  std::vector<double> fixed_value(n, 0);
  std::vector<char> fixed(n, 0);
  Reduction red;
  // Equalities first, then fixes on the merged classes.
  for (const Equation& eq : m.equations) {
    if (!eq.substitutable || eq.kind != EqKind::EqualScalar) continue;
    if (!uf.unite(eq.scalars[0], eq.scalars[1])) red.flagged.insert(eq.constraint);
  }
  for (const Equation& eq : m.equations) {
    if (!eq.substitutable || eq.kind != EqKind::FixScalar) continue;
    const int r = uf.find(eq.scalars[0]);
    if (fixed[static_cast<size_t>(r)]) {
      red.flagged.insert(eq.constraint);  // fixed twice: redundant, or conflicting when apart
    } else {
      fixed[static_cast<size_t>(r)] = 1;
      fixed_value[static_cast<size_t>(r)] = eq.data[0];
    }
  }
  // Fixes flagged above name only the later fix; the diagnosis on the unsubstituted system
  // finds the whole circuit.
  red.rep.resize(n);
  red.block.assign(n, -1);
  red.fixed.assign(n, 0);
  red.is_fixed.assign(n, 0);
  std::vector<double> sum(n, 0);
  std::vector<int> count(n, 0);
  for (size_t s = 0; s < n; ++s) {
    const int r = uf.find(static_cast<int>(s));
    red.rep[s] = r;
    sum[static_cast<size_t>(r)] += m.scalars[s].value;
    ++count[static_cast<size_t>(r)];
  }
  int blocks = 0;
  for (size_t s = 0; s < n; ++s) {
    if (red.rep[s] != static_cast<int>(s)) continue;
    if (fixed[s]) {
      red.is_fixed[s] = 1;
      red.fixed[s] = fixed_value[s];
    } else {
      red.block[s] = blocks++;
      red.values.push_back(sum[s] / count[s]);
    }
  }
  for (size_t s = 0; s < n; ++s) {
    const int r = red.rep[s];
    red.block[s] = red.block[static_cast<size_t>(r)];
    red.is_fixed[s] = red.is_fixed[static_cast<size_t>(r)];
    red.fixed[s] = red.fixed[static_cast<size_t>(r)];
  }
  red.substituted = static_cast<int>(n) - blocks;
  return red;
}

/// One equation as a Ceres cost: slots read from parameter blocks (each one scalar) or constants.
class EquationCost {
 public:
  EquationCost(const Model& m, const Equation& eq, std::vector<int> slot_param,
               std::vector<double> slot_const, double weight)
      : m_(m),
        eq_(eq),
        slot_param_(std::move(slot_param)),
        slot_const_(std::move(slot_const)),
        weight_(weight) {}

  template <class T>
  bool operator()(T const* const* params, T* r) const {
    const size_t n = slot_param_.size();
    if (n <= 8) return run<T, 8>(params, r);
    if (n <= 32) return run<T, 32>(params, r);
    std::vector<T> v(n);
    gather(params, v.data());
    return finish(v.data(), r);
  }

 private:
  template <class T, size_t N>
  bool run(T const* const* params, T* r) const {
    std::array<T, N> v;
    gather(params, v.data());
    return finish(v.data(), r);
  }
  template <class T>
  void gather(T const* const* params, T* v) const {
    for (size_t i = 0; i < slot_param_.size(); ++i)
      v[i] = slot_param_[i] >= 0 ? params[slot_param_[i]][0] : T(slot_const_[i]);
  }
  template <class T>
  bool finish(const T* v, T* r) const {
    residuals(m_, eq_, v, r);
    if (weight_ != 1)
      for (int i = 0; i < eq_.rows; ++i) r[i] *= weight_;
    return true;
  }

  const Model& m_;
  const Equation& eq_;
  std::vector<int> slot_param_;
  std::vector<double> slot_const_;
  double weight_;
};

/// A Ceres problem over one-scalar parameter blocks (`values`, not copied: the problem reads and
/// writes them), one residual block per equation.
struct CeresSystem {
  ceres::Problem problem;
  std::vector<double*> blocks;
  std::vector<ceres::ResidualBlockId> residual_ids;
  std::vector<int> equation_of_row;  // per Jacobian row
  std::vector<const Equation*> equations;

  CeresSystem() : problem(problem_options()) {}
  static ceres::Problem::Options problem_options() {
    ceres::Problem::Options o;
    o.enable_fast_removal = false;
    return o;
  }

  void add_blocks(std::vector<double>& values) {
    blocks.reserve(values.size());
    for (double& v : values) {
      problem.AddParameterBlock(&v, 1);
      blocks.push_back(&v);
    }
  }

  /// Adds an equation; `block_of(scalar)` gives the block index (or -1 with `constant_of`).
  template <class BlockOf, class ConstantOf>
  void add(const Model& m, const Equation& eq, int index, BlockOf block_of, ConstantOf constant_of,
           double weight = 1) {
    std::vector<int> unique;  // block indices used, in first-use order
    std::vector<int> slot_param, slot_const_index;
    std::vector<double> slot_const;
    for (int s : eq.scalars) {
      const int b = block_of(s);
      if (b < 0) {
        slot_param.push_back(-1);
        slot_const.push_back(constant_of(s));
        continue;
      }
      auto it = std::find(unique.begin(), unique.end(), b);
      if (it == unique.end()) {
        unique.push_back(b);
        it = unique.end() - 1;
      }
      slot_param.push_back(static_cast<int>(it - unique.begin()));
      slot_const.push_back(0);
    }
    if (unique.empty()) return;  // a constant equation: no unknown to move
    auto* cost = new ceres::DynamicAutoDiffCostFunction<EquationCost, 8>(
        new EquationCost(m, eq, std::move(slot_param), std::move(slot_const), weight));
    std::vector<double*> params;
    for (int b : unique) {
      cost->AddParameterBlock(1);
      params.push_back(blocks[static_cast<size_t>(b)]);
    }
    cost->SetNumResiduals(eq.rows);
    residual_ids.push_back(problem.AddResidualBlock(cost, nullptr, params));
    for (int r = 0; r < eq.rows; ++r) equation_of_row.push_back(index);
    equations.push_back(&eq);
  }

  /// The Jacobian (rows: residual blocks in order; columns: blocks in order).
  Eigen::SparseMatrix<double> jacobian() {
    if (residual_ids.empty() || blocks.empty())
      return Eigen::SparseMatrix<double>(static_cast<Eigen::Index>(equation_of_row.size()),
                                         static_cast<Eigen::Index>(blocks.size()));
    ceres::Problem::EvaluateOptions eo;
    eo.parameter_blocks = blocks;
    eo.residual_blocks = residual_ids;
    eo.apply_loss_function = false;
    ceres::CRSMatrix crs;
    double cost = 0;
    problem.Evaluate(eo, &cost, nullptr, nullptr, &crs);
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(crs.values.size());
    for (int r = 0; r < crs.num_rows; ++r)
      for (int k = crs.rows[static_cast<size_t>(r)]; k < crs.rows[static_cast<size_t>(r) + 1]; ++k)
        t.emplace_back(r, crs.cols[static_cast<size_t>(k)], crs.values[static_cast<size_t>(k)]);
    Eigen::SparseMatrix<double> J(crs.num_rows, crs.num_cols);
    J.setFromTriplets(t.begin(), t.end());
    return J;
  }
};

/// Stops Levenberg–Marquardt once every residual is far below the tolerance (Ceres itself has
/// no absolute stopping rule and would polish rounding errors).
class StopWhenSolved : public ceres::IterationCallback {
 public:
  explicit StopWhenSolved(double cost) : cost_(cost) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    return s.cost <= cost_ ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  double cost_;
};

void run_ceres(CeresSystem& sys, const Model& m, const SolveOptions& options, bool stop_early,
               int* iterations) {
  if (sys.residual_ids.empty()) return;
  ceres::Solver::Options o;
  o.minimizer_type = ceres::TRUST_REGION;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.linear_solver_type = sys.blocks.size() <= 64 ? ceres::DENSE_QR : ceres::SPARSE_NORMAL_CHOLESKY;
  o.max_num_iterations = options.max_iterations;
  o.function_tolerance = 1e-16;
  o.gradient_tolerance = 1e-30;
  o.parameter_tolerance = 1e-16;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  o.num_threads = 1;
  // Start nearly as Gauss–Newton (most sketches are close to a solution); LM damps when a step
  // fails. Measured on the zigzag chain of 1,000 segments: 15 iterations instead of 29.
  o.initial_trust_region_radius = 1e12;
  // Levenberg's damping μI, not Marquardt's μ diag(JᵀJ) (Ceres' default, with Jacobi column
  // scaling). A sketch being drawn is under-constrained: J has a null space, and a column that is
  // nearly zero there (the free end of a line drawn nearly vertical has ∂|b−a|/∂x ≈ 0.002) is
  // barely damped by its own tiny diagonal, so Marquardt's step swings along the null direction:
  // a line with a fixed start and a length of 10, its end drawn at (0.02, 10.5), took 101
  // iterations and stopped at residual 0.508. With μI the step is the minimum-norm Gauss–Newton
  // step as μ → 0 (it lies in the row space of J: nothing moves that need not), which converges
  // quadratically on under-determined systems of full row rank. docs/constraints.md, "Damping".
  o.jacobi_scaling = false;
  o.min_lm_diagonal = 1.0;
  o.max_lm_diagonal = 1.0;
  StopWhenSolved stop(0.5 * std::pow(1e-3 * options.residual_tolerance, 2));
  if (stop_early) o.callbacks.push_back(&stop);
  (void)m;
  ceres::Solver::Summary summary;
  ceres::Solve(o, &sys.problem, &summary);
  *iterations += static_cast<int>(summary.iterations.size());
}

/// Residuals of every equation at unreduced values.
std::vector<std::vector<double>> all_residuals(const Model& m, const std::vector<double>& x) {
  std::vector<std::vector<double>> out;
  out.reserve(m.equations.size());
  std::vector<double> v;
  for (const Equation& eq : m.equations) {
    v.clear();
    for (int s : eq.scalars) v.push_back(x[static_cast<size_t>(s)]);
    std::vector<double> r(static_cast<size_t>(eq.rows));
    residuals(m, eq, v.data(), r.data());
    out.push_back(std::move(r));
  }
  return out;
}

/// Column- and row-normalised copy (unit columns, then unit rows; zero rows and columns stay).
Eigen::SparseMatrix<double> normalised(Eigen::SparseMatrix<double> J) {
  Eigen::VectorXd col(J.cols());
  for (Eigen::Index c = 0; c < J.cols(); ++c) col[c] = J.col(c).norm();
  for (Eigen::Index c = 0; c < J.cols(); ++c)
    if (col[c] > 0) J.col(c) /= col[c];
  Eigen::SparseMatrix<double, Eigen::RowMajor> R = J;
  for (Eigen::Index r = 0; r < R.rows(); ++r) {
    const double n = R.row(r).norm();
    if (n > 0) R.row(r) /= n;
  }
  return Eigen::SparseMatrix<double>(R);
}

/// Rank of J and, for every dependent row, the rows it depends on (its fundamental circuit):
/// sparse QR of J^T with the given ordering; dead columns of J^T are dependent rows of J.
template <class Ordering>
int dependent_rows(const Eigen::SparseMatrix<double>& J, double threshold, bool circuits,
                   std::vector<std::vector<int>>* out) {
  if (J.rows() == 0) return 0;  // no equations: nothing depends, rank 0
  if (J.cols() == 0) {          // no unknowns: every equation is dependent (constant)
    for (Eigen::Index r = 0; r < J.rows(); ++r) out->push_back({static_cast<int>(r)});
    return 0;
  }
  const Eigen::SparseMatrix<double> A = normalised(J).transpose();
  Eigen::SparseQR<Eigen::SparseMatrix<double>, Ordering> qr;
  qr.setPivotThreshold(threshold);
  qr.compute(A);
  if (qr.info() != Eigen::Success)
    throw Error(ErrorCategory::Internal, "solve: the sparse QR of the constraint Jacobian failed");
  const int rank = static_cast<int>(qr.rank());
  const auto& perm = qr.colsPermutation().indices();
  if (!circuits) {
    for (Eigen::Index k = rank; k < A.cols(); ++k) out->push_back({perm[k]});
    return rank;
  }
  const Eigen::SparseMatrix<double> R = qr.matrixR();
  const Eigen::SparseMatrix<double> R11 = R.topLeftCorner(rank, rank);
  for (Eigen::Index k = rank; k < A.cols(); ++k) {
    std::vector<int> rows{perm[k]};
    if (rank > 0) {
      const Eigen::VectorXd rhs = R.col(k).head(rank);
      const Eigen::VectorXd x = R11.triangularView<Eigen::Upper>().solve(rhs);
      const double big = x.cwiseAbs().maxCoeff();
      for (Eigen::Index j = 0; j < rank; ++j)
        if (std::abs(x[j]) > 1e-9 * std::max(big, 1e-300) && big > 1e-12) rows.push_back(perm[j]);
    }
    out->push_back(std::move(rows));
  }
  return rank;
}

std::string constraint_list(const std::vector<int>& ids, const std::vector<Constraint>& constraints,
                            const sketch::Sketch& sketch) {
  std::string text;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (i) text += ", ";
    const Constraint& c = constraints[static_cast<size_t>(ids[i])];
    text += constraint_name(c, ids[i]) + " (" + describe(c, sketch) + ")";
  }
  return text;
}

}  // namespace
}  // namespace detail

namespace detail {

/// SolveOptions::spread_curve_changes: for each B-spline curve entity, the displacement of its
/// control points from `start` whose second differences are least (plus 1e-8 of its own norm, so
/// that one held point translates the curve) with the held ones as solved, written into the
/// blocks of its free control points. A control point is held when a (non-substituted) equation
/// uses one of its scalars, when it is fixed or shares its block with another scalar
/// (substituted), so that no equation's residual changes. Returns whether anything moved.
bool spread_curve_changes(const sketch::Sketch& sketch, const Model& m, const Reduction& red,
                          const std::vector<double>& start, std::vector<double>& values) {
  const std::size_t n = m.scalars.size();
  std::vector<char> used(n, 0);
  for (const Equation& eq : m.equations)
    if (!eq.substitutable)
      for (int s : eq.scalars)
        if (s >= 0 && static_cast<std::size_t>(s) < n) used[static_cast<std::size_t>(s)] = 1;
  std::vector<int> sharing(values.size(), 0);
  for (std::size_t s = 0; s < n; ++s)
    if (red.block[s] >= 0) ++sharing[static_cast<std::size_t>(red.block[s])];
  auto value_of = [&](std::size_t s) {
    return red.block[s] >= 0 ? values[static_cast<std::size_t>(red.block[s])] : red.fixed[s];
  };
  bool moved_any = false;
  for (const sketch::Entity& entity : sketch.entities) {
    const auto* curve = std::get_if<sketch::Curve>(&entity);
    if (!curve || curve->control_points.size() < 3) continue;
    const auto count = static_cast<Eigen::Index>(curve->control_points.size());
    const PointRef& first = m.point_vars[static_cast<std::size_t>(curve->control_points[0].index)];
    const int dim = first.dim;
    std::vector<char> held(static_cast<std::size_t>(count), 0);
    Eigen::MatrixXd delta = Eigen::MatrixXd::Zero(count, dim);
    double largest = 0, size = 0;
    for (Eigen::Index k = 0; k < count; ++k) {
      const PointRef& v = m.point_vars[static_cast<std::size_t>(
          curve->control_points[static_cast<std::size_t>(k)].index)];
      if (v.dim != dim) return moved_any;  // mixed planar and free points: left as solved
      for (int i = 0; i < dim; ++i) {
        const auto s = static_cast<std::size_t>(v.offset + i);
        const int b = red.block[s];
        if (b < 0 || used[s] || sharing[static_cast<std::size_t>(b)] > 1)
          held[static_cast<std::size_t>(k)] = 1;
        delta(k, i) = value_of(s) - start[s];
        size = std::max(size, std::abs(start[s]));
      }
      if (held[static_cast<std::size_t>(k)]) largest = std::max(largest, delta.row(k).norm());
    }
    const long free = std::count(held.begin(), held.end(), 0);
    if (free == 0 || !(largest > 1e-12 * std::max(1.0, size))) continue;
    // A = D2^T D2 + 1e-8 I over all control points; the free rows solved with the held ones known.
    Eigen::MatrixXd a = 1e-8 * Eigen::MatrixXd::Identity(count, count);
    for (Eigen::Index k = 1; k + 1 < count; ++k) {
      const Eigen::Index idx[3] = {k - 1, k, k + 1};
      const double c[3] = {1, -2, 1};
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) a(idx[r], idx[q]) += c[r] * c[q];
    }
    std::vector<Eigen::Index> f, h;
    for (Eigen::Index k = 0; k < count; ++k)
      (held[static_cast<std::size_t>(k)] ? h : f).push_back(k);
    Eigen::MatrixXd aff(f.size(), f.size()), afh(f.size(), h.size()), dh(h.size(), dim);
    for (std::size_t r = 0; r < f.size(); ++r) {
      for (std::size_t q = 0; q < f.size(); ++q) aff(r, q) = a(f[r], f[q]);
      for (std::size_t q = 0; q < h.size(); ++q) afh(r, q) = a(f[r], h[q]);
    }
    for (std::size_t q = 0; q < h.size(); ++q) dh.row(q) = delta.row(h[q]);
    const Eigen::MatrixXd df = aff.ldlt().solve(-afh * dh);
    for (std::size_t r = 0; r < f.size(); ++r) {
      const PointRef& v = m.point_vars[static_cast<std::size_t>(
          curve->control_points[static_cast<std::size_t>(f[r])].index)];
      for (int i = 0; i < dim; ++i) {
        const auto s = static_cast<std::size_t>(v.offset + i);
        values[static_cast<std::size_t>(red.block[s])] = start[s] + df(r, i);
      }
    }
    moved_any = true;
  }
  return moved_any;
}

}  // namespace detail

SolveResult solve(const sketch::Sketch& sketch, const std::vector<Constraint>& constraints,
                  const SolveOptions& options) {
  using namespace detail;
  options.validate();
  const Clock::time_point t0 = Clock::now();
  const Model m = build_model(sketch, constraints);
  for (size_t k = 0; k < options.drag.size(); ++k) {
    const int p = options.drag[k].point.index;
    if (p < 0 || p >= static_cast<int>(sketch.points.size()))
      throw Error(ErrorCategory::InvalidArgument,
                  "SolveOptions::drag[" + std::to_string(k) + "]: point #" + std::to_string(p) +
                      " does not exist (the sketch has " + std::to_string(sketch.points.size()) +
                      " points)");
  }
  const size_t n = m.scalars.size();
  Reduction red = reduce(m);

  SolveReport report;
  report.unknowns = static_cast<int>(n);
  report.substituted = red.substituted;

  auto block_of = [&](int s) { return red.block[static_cast<size_t>(s)]; };
  auto constant_of = [&](int s) { return red.fixed[static_cast<size_t>(s)]; };
  auto expand = [&](const std::vector<double>& values) {
    std::vector<double> x(n);
    for (size_t s = 0; s < n; ++s)
      x[s] = red.block[s] >= 0 ? values[static_cast<size_t>(red.block[s])] : red.fixed[s];
    return x;
  };
  std::vector<double> start(n);
  for (size_t s = 0; s < n; ++s) start[s] = m.scalars[s].value;

  int iterations = 0;
  std::vector<double> values = red.values;
  const std::vector<double> initial = values;
  auto add_bounds = [&](CeresSystem& sys) {
    for (size_t s = 0; s < n; ++s) {
      const int b = red.block[s];
      if (b < 0 || red.rep[s] != static_cast<int>(s)) continue;
      if (std::isfinite(m.scalars[s].lower))
        sys.problem.SetParameterLowerBound(sys.blocks[static_cast<size_t>(b)], 0,
                                           m.scalars[s].lower);
      if (std::isfinite(m.scalars[s].upper))
        sys.problem.SetParameterUpperBound(sys.blocks[static_cast<size_t>(b)], 0,
                                           m.scalars[s].upper);
    }
  };

  // Drag: first pull the dragged points with the constraints as heavy equations and a light
  // pull of everything else toward where it was.
  std::vector<Equation> drag_equations;
  if (!options.drag.empty()) {
    for (const Drag& d : options.drag) {
      Equation eq;
      eq.kind = EqKind::Target;
      const PointRef& v = m.point_vars[static_cast<size_t>(d.point.index)];
      eq.points.push_back({0, v.dim, v.plane});
      for (int i = 0; i < v.dim; ++i) eq.scalars.push_back(v.offset + i);
      eq.planar = v.dim == 2;
      eq.plane = v.plane;
      Eigen::Vector3d target = d.target;
      if (eq.planar) {
        const Eigen::Vector2d ab =
            clay::sketch::to_plane(m.planes[static_cast<size_t>(v.plane)], d.target);
        target = {ab.x(), ab.y(), 0};
      }
      eq.data = {target.x(), target.y(), target.z()};
      eq.rows = v.dim;
      drag_equations.push_back(std::move(eq));
    }
    std::vector<Equation> anchors;
    for (size_t b = 0; b < values.size(); ++b) {
      Equation eq;
      eq.kind = EqKind::FixScalar;
      eq.scalars = {-1 - static_cast<int>(b)};  // a block, not a scalar: see anchor_block below
      eq.data = {initial[b]};
      anchors.push_back(std::move(eq));
    }
    CeresSystem pull;
    pull.add_blocks(values);
    add_bounds(pull);
    for (size_t e = 0; e < m.equations.size(); ++e)
      if (!m.equations[e].substitutable)
        pull.add(m, m.equations[e], static_cast<int>(e), block_of, constant_of, 1e2);
    for (const Equation& eq : drag_equations) pull.add(m, eq, -1, block_of, constant_of, 1.0);
    auto anchor_block = [](int s) { return -1 - s; };
    for (const Equation& eq : anchors) pull.add(m, eq, -1, anchor_block, constant_of, 1e-4);
    run_ceres(pull, m, options, false, &iterations);
  }

  CeresSystem sys;
  sys.add_blocks(values);
  add_bounds(sys);
  for (size_t e = 0; e < m.equations.size(); ++e)
    if (!m.equations[e].substitutable)
      sys.add(m, m.equations[e], static_cast<int>(e), block_of, constant_of);
  report.equations = static_cast<int>(sys.equation_of_row.size());
  run_ceres(sys, m, options, true, &iterations);
  // The free control points of curves take the least-bending share of their held ones' change;
  // no equation uses them, so the solve from there only confirms (it stops at once).
  if (options.spread_curve_changes && spread_curve_changes(sketch, m, red, start, values))
    run_ceres(sys, m, options, true, &iterations);
  report.solve_seconds = seconds_since(t0);

  const std::vector<double> x = expand(values);
  const std::vector<std::vector<double>> res = all_residuals(m, x);
  std::vector<double> worst_of(constraints.size(), 0.0);
  for (size_t e = 0; e < m.equations.size(); ++e)
    for (double r : res[e]) {
      report.max_residual = std::max(report.max_residual, std::abs(r));
      if (m.equations[e].constraint >= 0) {
        double& w = worst_of[static_cast<size_t>(m.equations[e].constraint)];
        w = std::max(w, std::abs(r));
      }
    }

  // Components of the reduced system (blocks joined by an equation).
  {
    UnionFind uf(values.size());
    std::vector<char> used(values.size(), 0);
    for (const Equation* eq : sys.equations) {
      int first = -1;
      for (int s : eq->scalars) {
        const int b = red.block[static_cast<size_t>(s)];
        if (b < 0) continue;
        used[static_cast<size_t>(b)] = 1;
        if (first < 0)
          first = b;
        else
          uf.unite(first, b);
      }
    }
    std::set<int> roots;
    for (size_t b = 0; b < values.size(); ++b)
      if (used[b]) roots.insert(uf.find(static_cast<int>(b)));
    report.components = static_cast<int>(roots.size());
  }

  // Flips: orientation at the start against the solution.
  for (const Equation& eq : m.equations) {
    if (eq.constraint < 0) continue;
    const double before = orientation(m, eq, start.data());
    const double after = orientation(m, eq, x.data());
    if (before != 0 && after != before) report.flipped.push_back(eq.constraint);
  }
  std::sort(report.flipped.begin(), report.flipped.end());
  report.flipped.erase(std::unique(report.flipped.begin(), report.flipped.end()),
                       report.flipped.end());

  const Clock::time_point t1 = Clock::now();
  if (options.diagnose) {
    // Rank of the reduced system: degrees of freedom, and whether anything depends.
    std::vector<std::vector<int>> dead;
    const Eigen::SparseMatrix<double> J = sys.jacobian();
    const int rank =
        dependent_rows<Eigen::COLAMDOrdering<int>>(J, options.rank_tolerance, false, &dead);
    report.degrees_of_freedom = static_cast<int>(values.size()) - rank;
    std::set<int> flagged = red.flagged;
    for (const auto& d : dead)
      flagged.insert(
          sys.equations.empty()
              ? -1
              : m.equations[static_cast<size_t>(sys.equation_of_row[static_cast<size_t>(d[0])])]
                    .constraint);
    // Equations left without unknowns (all their scalars fixed or merged) depend on the
    // substitutions that emptied them.
    for (size_t e = 0; e < m.equations.size(); ++e) {
      const Equation& eq = m.equations[e];
      if (eq.substitutable) continue;
      bool any = false;
      for (int s : eq.scalars) any = any || red.block[static_cast<size_t>(s)] >= 0;
      if (!any) flagged.insert(eq.constraint);
    }
    flagged.erase(-1);
    if (!flagged.empty()) {
      // Circuits on the unsubstituted system of the parts that hold a dependency.
      UnionFind parts(n);
      for (const Equation& eq : m.equations)
        for (size_t i = 1; i < eq.scalars.size(); ++i) parts.unite(eq.scalars[0], eq.scalars[i]);
      std::set<int> bad_parts;
      for (const Equation& eq : m.equations)
        if (flagged.count(eq.constraint)) bad_parts.insert(parts.find(eq.scalars[0]));
      std::vector<double> full;  // the unsubstituted scalars of those parts
      std::vector<int> full_block(n, -1);
      for (size_t s = 0; s < n; ++s)
        if (bad_parts.count(parts.find(static_cast<int>(s)))) {
          full_block[s] = static_cast<int>(full.size());
          full.push_back(x[s]);
        }
      CeresSystem whole;
      whole.add_blocks(full);
      for (size_t e = 0; e < m.equations.size(); ++e) {
        const Equation& eq = m.equations[e];
        if (!bad_parts.count(parts.find(eq.scalars[0]))) continue;
        whole.add(
            m, eq, static_cast<int>(e), [&](int s) { return full_block[static_cast<size_t>(s)]; },
            [&](int s) { return x[static_cast<size_t>(s)]; });
      }
      std::vector<std::vector<int>> circuits;
      dependent_rows<Eigen::NaturalOrdering<int>>(whole.jacobian(), options.rank_tolerance, true,
                                                  &circuits);
      std::set<std::vector<int>> seen;
      for (const auto& rows : circuits) {
        std::set<int> ids;
        bool implicit = false;
        for (int r : rows) {
          const int c =
              m.equations[static_cast<size_t>(whole.equation_of_row[static_cast<size_t>(r)])]
                  .constraint;
          if (c >= 0)
            ids.insert(c);
          else
            implicit = true;
        }
        std::vector<int> list(ids.begin(), ids.end());
        if (list.empty() || !seen.insert(list).second) continue;
        Dependency dep;
        dep.constraints = list;
        for (int c : list)
          dep.conflicting =
              dep.conflicting || worst_of[static_cast<size_t>(c)] > options.residual_tolerance;
        dep.message = std::string(dep.conflicting ? "conflicting: " : "redundant: ") +
                      constraint_list(list, constraints, sketch) +
                      (implicit ? " (with the equal radii of an arc)" : "");
        (dep.conflicting ? report.conflicting : report.redundant).push_back(std::move(dep));
      }
    }
  }
  report.diagnose_seconds = seconds_since(t1);

  // Summary.
  Summary& s = report.summary;
  s.iterations = iterations;
  s.final_residual = report.max_residual;
  {
    double r0 = 0;
    for (const auto& row : all_residuals(m, start))
      for (double r : row) r0 = std::max(r0, std::abs(r));
    s.initial_residual = r0;
  }
  const std::string dof =
      report.degrees_of_freedom >= 0
          ? ", " + std::to_string(report.degrees_of_freedom) + " degrees of freedom left"
          : "";
  if (!report.conflicting.empty()) {
    s.termination = Termination::Failed;
    s.message = std::to_string(report.conflicting.size()) + " conflicting set(s): ";
    for (size_t k = 0; k < report.conflicting.size(); ++k)
      s.message += (k ? "; " : "") + report.conflicting[k].message;
  } else if (report.max_residual <= options.residual_tolerance) {
    s.termination = Termination::Converged;
    s.message = "all " + std::to_string(constraints.size()) + " constraints hold" + dof;
    if (!report.redundant.empty())
      for (size_t k = 0; k < report.redundant.size(); ++k)
        s.message +=
            (k ? "; " : "; " + std::to_string(report.redundant.size()) + " redundant set(s): ") +
            report.redundant[k].message;
  } else {
    s.termination = Termination::NotConverged;
    s.message = "largest residual " + std::to_string(report.max_residual) + " after " +
                std::to_string(iterations) + " iterations" + dof;
  }
  if (!report.flipped.empty())
    s.message +=
        "; orientation flipped for " + constraint_list(report.flipped, constraints, sketch);

  // Write back.
  SolveResult result{sketch, std::move(report)};
  for (size_t i = 0; i < sketch.points.size(); ++i) {
    const PointRef& v = m.point_vars[i];
    const double* p = x.data() + v.offset;
    result.sketch.points[i].position =
        v.dim == 3 ? Eigen::Vector3d(p[0], p[1], p[2])
                   : clay::sketch::to_world(m.planes[static_cast<size_t>(v.plane)],
                                            Eigen::Vector2d(p[0], p[1]));
  }
  for (size_t k = 0; k < sketch.entities.size(); ++k)
    if (m.radius_var[k] >= 0)
      std::get<sketch::Circle>(result.sketch.entities[k]).radius =
          x[static_cast<size_t>(m.radius_var[k])];
  return result;
}

std::string SolveReport::brief() const {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "; largest residual %.3g, %d unknowns (%d substituted), %s",
                max_residual, unknowns, substituted,
                degrees_of_freedom < 0
                    ? "degrees of freedom not diagnosed"
                    : (std::to_string(degrees_of_freedom) + " degrees of freedom").c_str());
  return summary.brief() + buffer;
}

}  // namespace clay::constraints
