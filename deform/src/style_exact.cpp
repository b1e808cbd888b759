// Style deformation, exact target mode (beyond Han–De Amicis–Conti): the displacements d of the
// free control vertices minimise a thin-plate fairness energy of the displacement net,
//   min  sum |d_{i-1,j} - 2 d_ij + d_{i+1,j}|^2 + 2 |d_{i+1,j+1} - d_{i+1,j} - d_{i,j+1} + d_ij|^2
//        + |d_{i,j-1} - 2 d_ij + d_{i,j+1}|^2      (fixed vertices have d = 0)
//   subject to  S'(u_k, v_k) = P_k + λ (K_k - P_k)  for every influenced key point k,
// which is linear in d (S' = S + sum R_ij d_ij with the rational basis R_ij). With H the energy's
// matrix and B the key-point rows: d = H^-1 B^T (B H^-1 B^T)^+ r, the minimal-energy solution, or
// the least-squares compromise where the key points conflict. The vertices outside the bound and
// the `boundary_rows` layers inside its edge are fixed, so the surface near the bound curve is
// untouched. Where the key-point system is rank deficient (the net is too coarse there), the knot
// spans holding key points are halved (exact knot insertion) and the solve is repeated.
#include "style_internal.hpp"

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include <algorithm>
#include <deque>
#include <set>
#include <sstream>

namespace clay::deform::detail {

using surface::BSplineCurve;
using surface::BSplineSurface;

namespace {

// Chebyshev distance (in vertices) from every vertex to the nearest vertex with E = 0; vertices
// of a region covering the whole net get INT_MAX.
std::vector<int> distance_to_outside(const BSplineSurface& s, const std::vector<std::uint8_t>& e) {
  const int nu = s.count_u(), nv = s.count_v();
  std::vector<int> dist(e.size(), std::numeric_limits<int>::max());
  std::deque<std::pair<int, int>> queue;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      if (e[static_cast<size_t>(s.index(i, j))] == 0) {
        dist[static_cast<size_t>(s.index(i, j))] = 0;
        queue.emplace_back(i, j);
      }
  while (!queue.empty()) {
    const auto [i, j] = queue.front();
    queue.pop_front();
    const int d = dist[static_cast<size_t>(s.index(i, j))];
    for (int a = std::max(0, i - 1); a <= std::min(nu - 1, i + 1); ++a)
      for (int b = std::max(0, j - 1); b <= std::min(nv - 1, j + 1); ++b) {
        int& db = dist[static_cast<size_t>(s.index(a, b))];
        if (db > d + 1) {
          db = d + 1;
          queue.emplace_back(a, b);
        }
      }
  }
  return dist;
}

// The rational basis functions R_ij(u, v) of the surface that are non-zero at (u, v), as
// (vertex row, value) pairs.
std::vector<std::pair<Eigen::Index, double>> basis_at(const BSplineSurface& s, double u, double v) {
  const int p = s.u.degree, q = s.v.degree;
  const int ku = surface::find_span(s.u, u), kv = surface::find_span(s.v, v);
  std::vector<double> nu(static_cast<size_t>(p + 1)), nv(static_cast<size_t>(q + 1));
  surface::basis_functions(s.u, ku, u, nu);
  surface::basis_functions(s.v, kv, v, nv);
  std::vector<std::pair<Eigen::Index, double>> out;
  double w = 0;
  for (int a = 0; a <= p; ++a)
    for (int b = 0; b <= q; ++b) {
      const Eigen::Index r = s.index(ku - p + a, kv - q + b);
      const double value = nu[static_cast<size_t>(a)] * nv[static_cast<size_t>(b)] * s.weights[r];
      w += value;
      out.emplace_back(r, value);
    }
  for (auto& [r, value] : out) value /= w;
  return out;
}

// Midpoints of the knot spans of `basis` that hold one of `params` (each span once); a parameter
// on a knot (within 1e-12 of the domain) counts for the spans on both sides, so mirror-symmetric
// key points refine mirror-symmetrically.
std::vector<double> halving_knots(const surface::BSplineBasis& basis, const std::vector<double>& params) {
  const auto [a, b] = basis.domain();
  const double eps = 1e-12 * (b - a);
  std::set<int> spans;
  for (double t : params) {
    spans.insert(surface::find_span(basis, std::max(a, t - eps)));
    spans.insert(surface::find_span(basis, std::min(b, t + eps)));
  }
  std::vector<double> knots;
  for (int k : spans)
    knots.push_back(0.5 * (basis.knots[static_cast<size_t>(k)] + basis.knots[static_cast<size_t>(k + 1)]));
  return knots;
}

}  // namespace

// The fairness factorization of one net (knot vectors) and its free vertices.
struct ExactCache {
  std::vector<double> knots_u, knots_v;     // the net it was built for
  std::vector<Eigen::Index> free_index;     // per vertex: its unknown, or -1 when fixed
  std::vector<Eigen::Index> free_rows;      // per unknown: its vertex
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;  // of H = L^T L + ridge
};

namespace {

// Free vertices of `s` (influenced, more than boundary_rows layers inside the region's edge) and
// the factorized thin-plate fairness of their displacements (fixed vertices have d = 0).
std::shared_ptr<const ExactCache> build_cache(const BSplineSurface& s, const std::vector<std::uint8_t>& factors,
                                              int boundary_rows) {
  auto cache = std::make_shared<ExactCache>();
  cache->knots_u = s.u.knots;
  cache->knots_v = s.v.knots;
  const auto dist = distance_to_outside(s, factors);
  cache->free_index.assign(factors.size(), -1);
  for (size_t r = 0; r < factors.size(); ++r)
    if (factors[r] != 0 && dist[r] > boundary_rows) {
      cache->free_index[r] = static_cast<Eigen::Index>(cache->free_rows.size());
      cache->free_rows.push_back(static_cast<Eigen::Index>(r));
    }
  const Eigen::Index nf = static_cast<Eigen::Index>(cache->free_rows.size());
  if (nf == 0) return cache;

  std::vector<Eigen::Triplet<double>> stencil;
  Eigen::Index stencil_rows = 0;
  const int nu = s.count_u(), nv = s.count_v();
  const auto& free_index = cache->free_index;
  auto add_stencil = [&](std::initializer_list<std::tuple<int, int, double>> terms) {
    bool any = false;
    for (const auto& [i, j, c] : terms) any = any || free_index[static_cast<size_t>(s.index(i, j))] >= 0;
    if (!any) return;
    for (const auto& [i, j, c] : terms) {
      const Eigen::Index f = free_index[static_cast<size_t>(s.index(i, j))];
      if (f >= 0) stencil.emplace_back(stencil_rows, f, c);
    }
    ++stencil_rows;
  };
  const double twist = std::sqrt(2.0);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      if (i > 0 && i + 1 < nu) add_stencil({{i - 1, j, 1.0}, {i, j, -2.0}, {i + 1, j, 1.0}});
      if (j > 0 && j + 1 < nv) add_stencil({{i, j - 1, 1.0}, {i, j, -2.0}, {i, j + 1, 1.0}});
      if (i + 1 < nu && j + 1 < nv)
        add_stencil({{i, j, twist}, {i + 1, j, -twist}, {i, j + 1, -twist}, {i + 1, j + 1, twist}});
    }
  Eigen::SparseMatrix<double> L(stencil_rows, nf);
  L.setFromTriplets(stencil.begin(), stencil.end());
  Eigen::SparseMatrix<double> H = L.transpose() * L;
  double max_diag = 0;
  for (Eigen::Index c = 0; c < nf; ++c) max_diag = std::max(max_diag, H.coeff(c, c));
  // A tiny ridge keeps H definite where the free vertices reach the border of the net.
  for (Eigen::Index c = 0; c < nf; ++c) H.coeffRef(c, c) += 1e-12 * std::max(max_diag, 1.0);
  cache->ldlt.compute(H);
  if (cache->ldlt.info() != Eigen::Success)
    throw Error(ErrorCategory::Internal, "style deformation: the fairness matrix is not positive definite");
  return cache;
}

}  // namespace

StyleResult style_exact(const surface::SurfaceProjector& projector, const InfluenceRegion& region,
                        const BSplineCurve& target, const std::vector<TraceSample>& trace,
                        const StyleOptions& options, std::shared_ptr<const ExactCache>& cache) {
  const BSplineSurface& parent = projector.surface();
  const double size = model_size(parent);
  const double tol = options.tolerance * size;

  BSplineSurface s = parent;
  InfluenceRegion reg = region;
  StyleResult out{parent, parent, {}};
  StyleReport& report = out.report;
  report.mode = StyleMode::exact;

  // The key points are those of the parent's net (eq. 8): refinement adds freedom, not constraints.
  const KeyPoints keys = find_key_points(projector, region, target, trace, options.key_points_per_row);
  report.constraint_class = keys.constraint_class;
  report.direction = keys.direction;
  report.m = static_cast<int>(keys.points.size());
  report.key_points = keys.points;
  if (keys.constraint_class == ConstraintClass::over_constrained || options.lambda == 0) {
    report.message = keys.constraint_class == ConstraintClass::over_constrained
                         ? "over-constrained: the target curve lies outside the bound; the surface is unchanged"
                         : "lambda = 0: the surface is unchanged";
    measure(parent, parent, region.factors, region, trace, options, report);
    return out;
  }
  std::vector<const KeyPoint*> active;
  std::vector<int> active_index;  // index in keys.points
  for (size_t k = 0; k < keys.points.size(); ++k)
    if (keys.points[k].influenced) {
      active.push_back(&keys.points[k]);
      active_index.push_back(static_cast<int>(k));
    }
  const Eigen::Index nk = static_cast<Eigen::Index>(active.size());
  Eigen::MatrixXd rhs(nk, 3);
  for (Eigen::Index k = 0; k < nk; ++k)
    rhs.row(k) = options.lambda * (active[static_cast<size_t>(k)]->point - active[static_cast<size_t>(k)]->foot).transpose();

  for (int round = 0;; ++round) {
    if (!cache || cache->knots_u != s.u.knots || cache->knots_v != s.v.knots)
      cache = build_cache(s, reg.factors, options.boundary_rows);
    const auto& free_index = cache->free_index;
    const auto& free_rows = cache->free_rows;
    const Eigen::Index nf = static_cast<Eigen::Index>(free_rows.size());

    // Key-point rows: sum_free R_ij(u_k, v_k) d_ij = λ (K_k - P_k).
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(nk, nf);
    for (Eigen::Index k = 0; k < nk; ++k)
      for (const auto& [r, value] : basis_at(s, active[static_cast<size_t>(k)]->u, active[static_cast<size_t>(k)]->v))
        if (free_index[static_cast<size_t>(r)] >= 0) B(k, free_index[static_cast<size_t>(r)]) = value;
    int rank = 0;
    if (nk > 0 && nf > 0) {
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(B.transpose());
      qr.setThreshold(1e-10);
      rank = static_cast<int>(qr.rank());
    }
    if (rank < nk && round < options.max_refinements) {
      // The net is too coarse where the key points are: halve the knot spans that hold them.
      std::vector<double> us, vs;
      for (const KeyPoint* k : active) {
        us.push_back(k->u);
        vs.push_back(k->v);
      }
      const auto ku = halving_knots(s.u, us), kv = halving_knots(s.v, vs);
      s = surface::refine_knots_u(s, ku);
      s = surface::refine_knots_v(s, kv);
      report.knots_inserted += static_cast<int>(ku.size() + kv.size());
      reg.count_u = s.count_u();
      reg.count_v = s.count_v();
      reg.factors = region_factors(s, reg.polygon, reg.target_trace, reg.margin);
      continue;
    }

    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(nf, 3);
    if (nk > 0 && nf > 0) {
      const Eigen::MatrixXd Y = cache->ldlt.solve(Eigen::MatrixXd(B.transpose()));  // H^-1 B^T
      const Eigen::MatrixXd M = B * Y;
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(M);
      cod.setThreshold(1e-12);
      d = Y * cod.solve(rhs);
    }
    out.surface = s;
    out.refined_parent = s;
    for (Eigen::Index f = 0; f < nf; ++f)
      if (!d.row(f).isZero(0)) out.surface.points.row(free_rows[static_cast<size_t>(f)]) += d.row(f);

    report.rank = rank;
    report.degrees_of_freedom = 3 * (static_cast<int>(nf) - rank);
    const Eigen::MatrixXd achieved = B * d - rhs;
    for (Eigen::Index k = 0; k < nk; ++k)
      if (achieved.row(k).norm() > tol) report.conflicting_key_points.push_back(active_index[static_cast<size_t>(k)]);
    measure(s, out.surface, reg.factors, reg, trace, options, report);
    std::ostringstream msg;
    msg << to_string(report.constraint_class) << ", m = " << report.m << " key points ("
        << nk << " influenced), " << nf << " free vertices, rank " << rank << ", "
        << report.degrees_of_freedom << " degrees of freedom left";
    if (report.knots_inserted > 0) msg << ", " << report.knots_inserted << " knots inserted";
    if (!report.conflicting_key_points.empty())
      msg << "; " << report.conflicting_key_points.size()
          << " key points cannot be met (the net is too coarse there: allow more max_refinements)";
    report.message = msg.str();
    return out;
  }
}

}  // namespace clay::deform::detail
