#include <clay/deform/direct_manipulation.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>

#include <Eigen/QR>  // the complete orthogonal decomposition

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "messages.hpp"

namespace clay::deform {

namespace {

using detail::format;
using internal::all_finite;

/// All Bernstein polynomials of degree n at t (The NURBS Book A1.3), written to b[0..n].
void all_bernstein(int n, double t, std::vector<double>& b) {
  b.assign(static_cast<size_t>(n + 1), 0.0);
  b[0] = 1.0;
  const double t1 = 1.0 - t;
  for (int j = 1; j <= n; ++j) {
    double saved = 0.0;
    for (int k = 0; k < j; ++k) {
      const double temp = b[static_cast<size_t>(k)];
      b[static_cast<size_t>(k)] = saved + t1 * temp;
      saved = t * temp;
    }
    b[static_cast<size_t>(j)] = saved;
  }
}

/// The non-zero basis functions of one direction at local coordinate v: index of the first and
/// their values.
struct DirectionBasis {
  int first = 0;
  std::vector<double> values;
};

DirectionBasis direction_basis(const BSplineLattice& lattice, int d, double v) {
  const surface::BSplineBasis& basis = lattice.bases[static_cast<size_t>(d)];
  DirectionBasis out;
  const int span = surface::find_span(basis, v);
  out.values.resize(static_cast<size_t>(basis.degree + 1));
  surface::basis_functions(basis, span, v, out.values);
  out.first = span - basis.degree;
  return out;
}

DirectionBasis direction_basis(const BezierLattice& lattice, int d, double v) {
  DirectionBasis out;
  all_bernstein(lattice.degrees[static_cast<size_t>(d)], v, out.values);
  return out;
}

/// Checks the selected points (finite, inside) and returns their clamped local coordinates.
std::vector<Eigen::Vector3d> selected_locals(const Frame& frame, const Points3& points) {
  std::vector<Eigen::Vector3d> locals(static_cast<size_t>(points.rows()));
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d x = points.row(i).transpose();
    if (!all_finite(x))
      throw Error(ErrorCategory::InvalidArgument, "direct manipulation: selected point #" +
                                                      std::to_string(i) + " " + format(x) +
                                                      " is not finite; give finite coordinates");
    const Eigen::Vector3d local = local_coordinates(frame, x);
    if (!inside(local))
      throw Error(ErrorCategory::OutOfDomain,
                  "direct manipulation: selected point #" + std::to_string(i) + " " + format(x) +
                      " has local coordinates (s, t, u) = " + format(local) +
                      " outside the lattice [0, 1]^3: no control point moves it; select points "
                      "inside the lattice frame (undeformed space)");
    locals[static_cast<size_t>(i)] = local.cwiseMax(0.0).cwiseMin(1.0);
  }
  return locals;
}

/// B (Hsu–Hughes–Kaufman eq. (2)): row i holds the tensor products of the three directions' basis
/// values at point i. Written row by row straight into the compressed arrays: a row's columns
/// increase with the loops (the lattice's s-major index order), so nothing is sorted (10^6
/// points through triplets took 10.5 s, most of it Eigen's sort and transpose; bench_deform
/// jacobian_points).
template <class Lattice>
Eigen::SparseMatrix<double, Eigen::RowMajor> influence(const Lattice& lattice,
                                                       const Points3& points) {
  validate(lattice);
  const auto locals = selected_locals(lattice.frame, points);
  std::vector<int> outer(locals.size() + 1, 0), inner;
  std::vector<double> values;
  for (size_t i = 0; i < locals.size(); ++i) {
    DirectionBasis b[3];
    for (int d = 0; d < 3; ++d) b[d] = direction_basis(lattice, d, locals[i][d]);
    if (i == 0) {  // every row has at most this many: reserve once
      const size_t per_row = b[0].values.size() * b[1].values.size() * b[2].values.size();
      inner.reserve(per_row * locals.size());
      values.reserve(per_row * locals.size());
    }
    for (size_t a = 0; a < b[0].values.size(); ++a)
      for (size_t c = 0; c < b[1].values.size(); ++c)
        for (size_t e = 0; e < b[2].values.size(); ++e) {
          const double w = b[0].values[a] * b[1].values[c] * b[2].values[e];
          if (w == 0.0) continue;
          inner.push_back(static_cast<int>(lattice.index(b[0].first + static_cast<int>(a),
                                                         b[1].first + static_cast<int>(c),
                                                         b[2].first + static_cast<int>(e))));
          values.push_back(w);
        }
    if (inner.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
      throw Error(ErrorCategory::InvalidArgument,
                  "influence_matrix: " + std::to_string(points.rows()) +
                      " points give more non-zeros than one matrix indexes (2^31); give the "
                      "points in parts");
    outer[i + 1] = static_cast<int>(inner.size());
  }
  return Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>>(
      points.rows(), lattice.points.rows(), static_cast<Eigen::Index>(values.size()), outer.data(),
      inner.data(), values.data());
}

/// Σ_i B(x_i)ᵀ G_i, point by point (influence_transpose_product).
template <class Lattice>
Points3 transpose_product(const Lattice& lattice, const Points3& points, const Points3& g) {
  validate(lattice);
  if (g.rows() != points.rows())
    throw Error(ErrorCategory::InvalidArgument,
                "influence_transpose_product: G has " + std::to_string(g.rows()) + " rows for " +
                    std::to_string(points.rows()) + " points; give one gradient row per point");
  const auto locals = selected_locals(lattice.frame, points);
  Points3 out = Points3::Zero(lattice.points.rows(), 3);
  for (size_t i = 0; i < locals.size(); ++i) {
    DirectionBasis b[3];
    for (int d = 0; d < 3; ++d) b[d] = direction_basis(lattice, d, locals[i][d]);
    const Eigen::RowVector3d gi = g.row(static_cast<Eigen::Index>(i));
    for (size_t a = 0; a < b[0].values.size(); ++a)
      for (size_t c = 0; c < b[1].values.size(); ++c) {
        const double ac = b[0].values[a] * b[1].values[c];
        for (size_t e = 0; e < b[2].values.size(); ++e)
          out.row(lattice.index(b[0].first + static_cast<int>(a), b[1].first + static_cast<int>(c),
                                b[2].first + static_cast<int>(e))) += (ac * b[2].values[e]) * gi;
      }
  }
  return out;
}

double lattice_size(const Frame& f) {
  return std::sqrt(f.s.squaredNorm() + f.t.squaredNorm() + f.u.squaredNorm());
}

}  // namespace

// ---- options and report ---------------------------------------------------------------------

std::vector<std::string> DirectManipulationOptions::problems() const {
  std::vector<std::string> out;
  if (!(std::isfinite(rank_tolerance) && rank_tolerance > 0 && rank_tolerance < 1))
    out.push_back("DirectManipulationOptions::rank_tolerance = " + format(rank_tolerance) +
                  " breaks the rule 0 < rank_tolerance < 1; give a small relative threshold "
                  "such as 1e-10");
  if (!(std::isfinite(relative_tolerance) && relative_tolerance > 0))
    out.push_back("DirectManipulationOptions::relative_tolerance = " + format(relative_tolerance) +
                  " breaks the rule relative_tolerance > 0 (finite, relative to the lattice size); "
                  "give e.g. 1e-7");
  std::set<Eigen::Index> seen;
  for (size_t g = 0; g < tied.size(); ++g) {
    const std::string name = "DirectManipulationOptions::tied[" + std::to_string(g) + "]";
    if (tied[g].size() < 2)
      out.push_back(name + " has " + std::to_string(tied[g].size()) +
                    " control point(s), breaking the rule of at least 2 per group; "
                    "drop the group or add the rows it ties");
    for (const Eigen::Index r : tied[g]) {
      if (r < 0)
        out.push_back(name + " holds the row " + std::to_string(r) +
                      ", breaking the rule row >= 0; give control point rows (lattice.index)");
      if (!seen.insert(r).second)
        out.push_back(name + " holds the row " + std::to_string(r) +
                      " that is already tied (in this or an earlier group); merge the groups "
                      "that share it");
    }
  }
  return out;
}

void DirectManipulationOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string DirectManipulationReport::brief() const {
  return std::string(feasible ? "feasible" : "not feasible") + ": " + std::to_string(requested) +
         " points, rank " + std::to_string(rank) + " of " + std::to_string(unknowns) +
         " unknowns, largest miss " + format(achieved_max_error, 3) + " mm, residual " +
         format(residual, 3) + " mm, displacement " + format(displacement_norm, 3) + " mm";
}

// ---- influence matrix -----------------------------------------------------------------------

Eigen::SparseMatrix<double, Eigen::RowMajor> influence_matrix(const BSplineLattice& lattice,
                                                              const Points3& points) {
  return influence(lattice, points);
}

Eigen::SparseMatrix<double, Eigen::RowMajor> influence_matrix(const BezierLattice& lattice,
                                                              const Points3& points) {
  return influence(lattice, points);
}

Points3 influence_transpose_product(const BSplineLattice& lattice, const Points3& points,
                                    const Points3& g) {
  return transpose_product(lattice, points, g);
}

Points3 influence_transpose_product(const BezierLattice& lattice, const Points3& points,
                                    const Points3& g) {
  return transpose_product(lattice, points, g);
}

// ---- the solver -----------------------------------------------------------------------------

/// The factorization and what it was made for (pimpl: no Eigen decomposition in the header).
template <class Lattice>
struct DirectManipulator<Lattice>::State {
  Lattice lattice;
  Points3 points, images;
  DirectManipulationOptions options;
  double size = 0;
  Eigen::MatrixXd a;  ///< B S on the unknowns, N x m
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  std::vector<std::vector<Eigen::Index>> columns;  ///< control point rows of each unknown
  int rank = 0;
};

template <class Lattice>
DirectManipulator<Lattice>::DirectManipulator(const Lattice& lattice, const Points3& points,
                                              const DirectManipulationOptions& options)
    : state_([&] {
        // Built once, then shared read-only by every copy (move() is const).
        auto st = std::make_shared<State>();
        State& s = *st;
        s.lattice = lattice;
        s.points = points;
        s.options = options;
        validate(s.lattice);
        s.options.validate();
        if (s.points.rows() == 0)
          throw Error(ErrorCategory::InvalidArgument,
                      "direct manipulation: no point selected; give at least one point to move");
        const Eigen::Index M = s.lattice.points.rows();
        if (!s.options.locked.empty() && static_cast<Eigen::Index>(s.options.locked.size()) != M)
          throw Error(ErrorCategory::InvalidArgument,
                      "DirectManipulationOptions::locked has " +
                          std::to_string(s.options.locked.size()) + " entries for a lattice of " +
                          std::to_string(M) +
                          " control points; give one entry per control point, or none");
        for (size_t g = 0; g < s.options.tied.size(); ++g)
          for (const Eigen::Index r : s.options.tied[g])
            if (r >= M)
              throw Error(ErrorCategory::InvalidArgument,
                          "DirectManipulationOptions::tied[" + std::to_string(g) +
                              "] holds the row " + std::to_string(r) +
                              ", outside the lattice's rows [0, " + std::to_string(M) +
                              "); give rows lattice.index(i, j, k)");
        s.size = lattice_size(s.lattice.frame);

        // The unknowns before restriction: Hsu's S (eq. (6)) compressed to a vector, unknown[r] =
        // the unknown row r follows, or -1 when locked; a group with a locked row is locked as a
        // whole.
        std::vector<Eigen::Index> unknown(static_cast<size_t>(M), -2);
        std::vector<std::vector<Eigen::Index>> members;
        auto is_locked = [&](Eigen::Index r) {
          return !s.options.locked.empty() && s.options.locked[static_cast<size_t>(r)];
        };
        for (const auto& group : s.options.tied) {
          const bool locked = std::any_of(group.begin(), group.end(), is_locked);
          for (const Eigen::Index r : group)
            unknown[static_cast<size_t>(r)] =
                locked ? -1 : static_cast<Eigen::Index>(members.size());
          if (!locked) members.push_back(group);
        }
        for (Eigen::Index r = 0; r < M; ++r) {
          if (unknown[static_cast<size_t>(r)] != -2) continue;
          if (is_locked(r)) {
            unknown[static_cast<size_t>(r)] = -1;
          } else {
            unknown[static_cast<size_t>(r)] = static_cast<Eigen::Index>(members.size());
            members.push_back({r});
          }
        }

        // B (eq. (2)), then B S restricted to the unknowns acting on some selected point: the
        // others would get a zero displacement in the minimal-norm solution anyway.
        const Eigen::SparseMatrix<double, Eigen::RowMajor> b = influence(s.lattice, s.points);
        std::vector<Eigen::Index> column(members.size(), -1);
        for (Eigen::Index i = 0; i < b.outerSize(); ++i)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(b, i); it; ++it) {
            const Eigen::Index g = unknown[static_cast<size_t>(it.col())];
            if (g < 0 || column[static_cast<size_t>(g)] >= 0) continue;
            column[static_cast<size_t>(g)] = static_cast<Eigen::Index>(s.columns.size());
            s.columns.push_back(members[static_cast<size_t>(g)]);
          }
        s.a = Eigen::MatrixXd::Zero(s.points.rows(), static_cast<Eigen::Index>(s.columns.size()));
        for (Eigen::Index i = 0; i < b.outerSize(); ++i)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(b, i); it; ++it) {
            const Eigen::Index g = unknown[static_cast<size_t>(it.col())];
            if (g >= 0) s.a(i, column[static_cast<size_t>(g)]) += it.value();  // Hsu eq. (6): B S
          }

        s.images.resize(s.points.rows(), 3);
        for (Eigen::Index i = 0; i < s.points.rows(); ++i)
          s.images.row(i) =
              deform_point(s.lattice, Eigen::Vector3d(s.points.row(i).transpose())).transpose();

        if (s.a.cols() > 0) {
          // Rank-revealing QR + RZ: the full-rank factorization B S = C D of eq. (3). B is
          // dimensionless (its rows sum to 1), so pivots are compared with rank_tolerance itself,
          // not with the largest pivot: a point that only tiny weights reach (on a face next to
          // locked planes) gets no move rather than a huge one. Eigen's threshold is relative to
          // the largest pivot, which is the largest column norm (the first column pivot).
          s.cod.setThreshold(s.options.rank_tolerance / s.a.colwise().norm().maxCoeff());
          s.cod.compute(s.a);
          s.rank = static_cast<int>(s.cod.rank());
        }
        return std::shared_ptr<const State>(std::move(st));
      }()) {}

template <class Lattice>
DirectManipulationResult<Lattice> DirectManipulator<Lattice>::move(const Points3& targets) const {
  const State& s = *state_;
  const Eigen::Index n = s.points.rows();
  if (targets.rows() != n)
    throw Error(ErrorCategory::InvalidArgument,
                "direct manipulation: " + std::to_string(targets.rows()) + " targets for " +
                    std::to_string(n) + " selected points; give one target per selected point");
  for (Eigen::Index i = 0; i < n; ++i)
    if (!all_finite(targets.row(i)))
      throw Error(ErrorCategory::InvalidArgument,
                  "direct manipulation: target #" + std::to_string(i) + " " +
                      format(Eigen::Vector3d(targets.row(i).transpose())) +
                      " is not finite; give finite coordinates");

  // Δq = target − current image (eq. (2)), ΔP = (B S)⁺ Δq (eqs. (5), (7)).
  const Eigen::MatrixXd dq = targets - s.images;
  Eigen::MatrixXd dp = Eigen::MatrixXd::Zero(s.a.cols(), 3);
  if (s.rank > 0) dp = s.cod.solve(dq);

  DirectManipulationResult<Lattice> out{s.lattice, {}};
  for (size_t c = 0; c < s.columns.size(); ++c)
    for (const Eigen::Index r : s.columns[c])
      out.lattice.points.row(r) += dp.row(static_cast<Eigen::Index>(c));

  DirectManipulationReport& rep = out.report;
  rep.requested = static_cast<int>(n);
  rep.unknowns = static_cast<int>(s.columns.size());
  rep.rank = s.rank;
  rep.residual = (s.a * dp - dq).norm();
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d reached =
        deform_point(out.lattice, Eigen::Vector3d(s.points.row(i).transpose()));
    rep.achieved_max_error =
        std::max(rep.achieved_max_error, (reached - targets.row(i).transpose()).norm());
  }
  rep.displacement_norm = (out.lattice.points - s.lattice.points).norm();
  const double tolerance = s.options.relative_tolerance * s.size;
  rep.feasible = rep.achieved_max_error <= tolerance;

  const std::string counts = "rank " + std::to_string(rep.rank) + " for " + std::to_string(n) +
                             " point(s) and " + std::to_string(rep.unknowns) + " unknowns";
  rep.summary.final_residual = rep.achieved_max_error;
  rep.summary.termination = rep.feasible    ? Termination::Converged
                            : rep.rank == 0 ? Termination::Failed
                                            : Termination::NotConverged;
  if (rep.feasible) {
    rep.summary.message = "every selected point reaches its target (largest miss " +
                          format(rep.achieved_max_error, 3) + " mm, tolerance " +
                          format(tolerance, 3) + " mm); " + counts +
                          (rep.rank < rep.requested ? " (some requests repeat others)" : "");
  } else if (rep.rank == 0) {
    rep.summary.message =
        "no free control point acts on the selected points (those that do are all "
        "locked, or weigh below rank_tolerance): nothing moved, largest miss " +
        format(rep.achieved_max_error, 3) + " mm; unlock control points near the selected points";
  } else {
    rep.summary.message =
        "the request cannot be met (" + counts + "): least-squares compromise, residual " +
        format(rep.residual, 3) + " mm, largest miss " + format(rep.achieved_max_error, 3) +
        " mm above the tolerance " + format(tolerance, 3) +
        " mm; refine the lattice (more cells or a higher degree), unlock control points "
        "or drop conflicting requests";
  }
  return out;
}

template <class Lattice>
const Points3& DirectManipulator<Lattice>::images() const noexcept {
  return state_->images;
}

template <class Lattice>
int DirectManipulator<Lattice>::unknowns() const noexcept {
  return static_cast<int>(state_->columns.size());
}

template <class Lattice>
int DirectManipulator<Lattice>::rank() const noexcept {
  return state_->rank;
}

template class DirectManipulator<BSplineLattice>;
template class DirectManipulator<BezierLattice>;

// ---- one-off --------------------------------------------------------------------------------

namespace {

template <class Lattice>
DirectManipulationResult<Lattice> manipulate_impl(const Lattice& lattice,
                                                  std::span<const PointMove> moves,
                                                  const DirectManipulationOptions& options) {
  Points3 points(static_cast<Eigen::Index>(moves.size()), 3), targets(points.rows(), 3);
  for (size_t i = 0; i < moves.size(); ++i) {
    points.row(static_cast<Eigen::Index>(i)) = moves[i].point.transpose();
    targets.row(static_cast<Eigen::Index>(i)) = moves[i].target.transpose();
  }
  return DirectManipulator<Lattice>(lattice, points, options).move(targets);
}

}  // namespace

DirectManipulationResult<BSplineLattice> manipulate(const BSplineLattice& lattice,
                                                    std::span<const PointMove> moves,
                                                    const DirectManipulationOptions& options) {
  return manipulate_impl(lattice, moves, options);
}

DirectManipulationResult<BezierLattice> manipulate(const BezierLattice& lattice,
                                                   std::span<const PointMove> moves,
                                                   const DirectManipulationOptions& options) {
  return manipulate_impl(lattice, moves, options);
}

}  // namespace clay::deform
