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
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <Eigen/Sparse>

#include <algorithm>
#include <deque>
#include <sstream>

namespace clay::deform::detail {

using surface::BSplineCurve;
using surface::BSplineSurface;

namespace {

// Below this share of a key point's basis weight on free vertices, the message says so (the
// displacement that meets it is amplified by up to 1 / share).
constexpr double min_free_share = 0.1;
// A solve that moves a free vertex more than this many times the farthest key point's distance
// meets its key points through a net wound up between them — a key point held mostly by fixed
// vertices, or rows nearly dependent though the rank test passes: the net is too coarse there,
// and is refined while allowed. Within this bound are the moves that a key point with a free
// share of min_free_share needs.
constexpr double max_amplification = 1 / min_free_share;
// The range-space solve is kept when it meets the key points to this fraction of the tolerance
// (else the KKT system is solved)...
constexpr double range_space_accuracy = 1e-3;
// ... and when H d = B^T μ holds to this fraction of |B^T μ| (rounding on the hood: ~1e-11).
constexpr double range_space_stationarity = 1e-8;
// Nets with up to this many free vertices keep H^-1 (dense, 2 MB at the limit).
constexpr Eigen::Index dense_inverse_limit = 512;

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

// Midpoints of the non-empty knot spans of `basis` that overlap [lo, hi].
std::vector<double> halving_knots(const surface::BSplineBasis& basis, double lo, double hi) {
  std::vector<double> knots;
  const auto breaks = surface::breakpoints(basis);
  for (size_t k = 0; k + 1 < breaks.size(); ++k)
    if (breaks[k + 1] > lo && breaks[k] < hi) knots.push_back(0.5 * (breaks[k] + breaks[k + 1]));
  return knots;
}

// The parameter box of the region: the bound polygon's, else that of the influenced vertices'
// Greville points widened by one Greville interval.
Eigen::AlignedBox2d region_box(const BSplineSurface& s, const InfluenceRegion& reg) {
  Eigen::AlignedBox2d box;
  if (!reg.polygon.empty()) {
    for (const auto& p : reg.polygon) box.extend(p);
    return box;
  }
  const auto xu = surface::greville_abscissae(s.u), xv = surface::greville_abscissae(s.v);
  for (int i = 0; i < s.count_u(); ++i)
    for (int j = 0; j < s.count_v(); ++j)
      if (reg.inside(i, j)) {
        const size_t a = static_cast<size_t>(i), b = static_cast<size_t>(j);
        box.extend(Eigen::Vector2d(xu[a > 0 ? a - 1 : a], xv[b > 0 ? b - 1 : b]));
        box.extend(Eigen::Vector2d(xu[std::min(a + 1, xu.size() - 1)],
                                   xv[std::min(b + 1, xv.size() - 1)]));
      }
  return box;
}

}  // namespace

// The free vertices of one net (knot vectors) and the fairness matrix over them.
struct NetCache {
  std::vector<double> knots_u, knots_v;  // the net it was built for
  std::vector<Eigen::Index> free_index;  // per vertex: its unknown, or -1 when fixed
  std::vector<Eigen::Index> free_rows;   // per unknown: its vertex
  Eigen::SparseMatrix<double> H;         // thin-plate energy L^T L + ridge, free vertices
  // H = P^T L D L^T P, factorized once per net: every drag on the net reuses it (only the
  // key-point rows B change), so a solve costs nk triangular solves instead of a KKT factorization.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> energy;
  bool factorized = false;
  // H^-1 itself on nets of up to dense_inverse_limit free vertices (at most 2 MB): a key-point
  // row has (p+1)(q+1) nonzeros, so H^-1 B^T is then that many columns of it per key point.
  Eigen::MatrixXd inverse;
};

namespace {

// Free vertices of `s` (influenced, more than boundary_rows layers inside the region's edge) and
// the factorized thin-plate fairness of their displacements (fixed vertices have d = 0).
std::shared_ptr<const NetCache> build_cache(const BSplineSurface& s,
                                            const std::vector<std::uint8_t>& factors,
                                            int boundary_rows) {
  auto cache = std::make_shared<NetCache>();
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
    for (const auto& [i, j, c] : terms)
      any = any || free_index[static_cast<size_t>(s.index(i, j))] >= 0;
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
  cache->H = std::move(H);
  cache->energy.compute(cache->H);
  cache->factorized = cache->energy.info() == Eigen::Success;
  if (cache->factorized && nf <= dense_inverse_limit)
    cache->inverse = cache->energy.solve(Eigen::MatrixXd::Identity(nf, nf));
  return cache;
}

// The energy minimum subject to B d = r by the KKT system [H B^T; B 0] [d; μ] = [0; r]: LU, dense
// for small systems (an interactive region, where it beats the sparse ordering analysis), sparse
// beyond (at 509 unknowns, a refined hood, a third of dense LU's time). It meets independent key
// points to rounding without the squared conditioning of the range-space solve.
Eigen::MatrixXd kkt_solve(const Eigen::SparseMatrix<double>& H, const Eigen::MatrixXd& B,
                          const Eigen::MatrixXd& rhs) {
  const Eigen::Index nf = H.rows(), nk = B.rows();
  std::vector<Eigen::Triplet<double>> kkt;
  for (Eigen::Index c = 0; c < nf; ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(H, c); it; ++it)
      kkt.emplace_back(it.row(), it.col(), it.value());
  for (Eigen::Index k = 0; k < nk; ++k)
    for (Eigen::Index c = 0; c < nf; ++c)
      if (B(k, c) != 0) {
        kkt.emplace_back(nf + k, c, B(k, c));
        kkt.emplace_back(c, nf + k, B(k, c));
      }
  Eigen::SparseMatrix<double> K(nf + nk, nf + nk);
  K.setFromTriplets(kkt.begin(), kkt.end());
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(nf + nk, 3);
  b.bottomRows(nk) = rhs;
  if (nf + nk <= 200)
    return Eigen::PartialPivLU<Eigen::MatrixXd>(Eigen::MatrixXd(K)).solve(b).topRows(nf);
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  lu.compute(K);
  if (lu.info() != Eigen::Success)
    throw Error(ErrorCategory::Internal,
                "style deformation: the key-point system could not be factorized");
  return Eigen::MatrixXd(lu.solve(b)).topRows(nf);
}

}  // namespace

// What the exact mode keeps between drags: one NetCache per net it has solved on (the parent's
// and its refinements), never modified once shared.
struct ExactCache {
  std::vector<std::shared_ptr<const NetCache>> nets;
};

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

  // The key points are those of the parent's net (eq. 8): refinement adds freedom, not
  // constraints. Key points are added where the result still misses the target curve.
  const KeyPoints keys =
      find_key_points(projector, region, target, trace, options.key_points_per_row);
  if (begin_report(keys, options, StyleMode::Exact, report)) {
    measure(parent, parent, region.factors, region, trace, options, report);
    return out;
  }
  std::vector<KeyPoint> points = keys.points;
  const PolygonLocator bound(region.polygon, parameter_tolerance(parent));
  auto in_region = [&](const TraceSample& t) {
    return region.polygon.empty() || bound.inside({t.u, t.v});
  };
  int refinements = 0, additions = 0;
  std::size_t accepted_points = points.size();  // key points before the last round of additions
  double amplification = 0;

  for (;;) {
    std::shared_ptr<const NetCache> net;
    if (cache)
      for (const auto& n : cache->nets)
        if (n->knots_u == s.u.knots && n->knots_v == s.v.knots) net = n;
    if (!net) {
      net = build_cache(s, reg.factors, options.boundary_rows);
      auto grown = std::make_shared<ExactCache>();
      if (cache) grown->nets = cache->nets;
      if (grown->nets.size() >= 16) grown->nets.erase(grown->nets.begin());  // bounded memory
      grown->nets.push_back(net);
      cache = std::move(grown);
    }
    const auto& free_index = net->free_index;
    const auto& free_rows = net->free_rows;
    const Eigen::Index nf = static_cast<Eigen::Index>(free_rows.size());

    std::vector<int> active;  // indices of the influenced key points
    for (size_t k = 0; k < points.size(); ++k)
      if (points[k].influenced) active.push_back(static_cast<int>(k));
    const Eigen::Index nk = static_cast<Eigen::Index>(active.size());
    // Key-point rows: sum_free R_ij(u_k, v_k) d_ij = λ (K_k - P_k).
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(nk, nf);
    Eigen::MatrixXd rhs(nk, 3);
    for (Eigen::Index k = 0; k < nk; ++k) {
      const KeyPoint& kp = points[static_cast<size_t>(active[static_cast<size_t>(k)])];
      for (const auto& [r, value] : basis_at(s, kp.u, kp.v))
        if (free_index[static_cast<size_t>(r)] >= 0)
          B(k, free_index[static_cast<size_t>(r)]) = value;
      rhs.row(k) = options.lambda * (kp.point - kp.foot).transpose();
    }
    // Rank of the key-point system from a rank-revealing QR of B^T = Q R P^T: the last nf - rank
    // columns of Q span the null space of B, the displacements that leave every key point alone.
    int rank = 0;
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;
    if (nk > 0 && nf > 0) {
      qr.setThreshold(1e-10);
      qr.compute(B.transpose());
      rank = static_cast<int>(qr.rank());
    }
    // The net is too coarse in the region for the key points: halve every knot span there (the
    // fixed edge layers get thinner, the free vertices more numerous). The region's box is
    // mirror-symmetric when the region is, and so is the refinement.
    auto refine = [&] {
      const Eigen::AlignedBox2d box = region_box(s, reg);
      const auto ku = halving_knots(s.u, box.min().x(), box.max().x());
      const auto kv = halving_knots(s.v, box.min().y(), box.max().y());
      s = surface::refine_knots_u(s, ku);
      s = surface::refine_knots_v(s, kv);
      report.knots_inserted += static_cast<int>(ku.size() + kv.size());
      ++refinements;
      reg.count_u = s.count_u();
      reg.count_v = s.count_v();
      reg.factors = region_factors(s, reg.polygon, reg.target_trace, reg.margin);
    };
    // A key point held mostly by fixed vertices (its free share Σ_free R_ij(u_k, v_k) is small)
    // is met only by moving the free ones by about distance / share: independent in rank, yet
    // amplified into a net metres away (seen on a filled sail, shares ~1e-4). The share is only
    // reported; what refines the net is the amplification the solve below actually shows.
    // No free vertex (a net too coarse for the region): every share is 0. B has no columns then,
    // and Eigen's row() of it would offset a null pointer (undefined behaviour, UBSan).
    double min_share = 1.0;
    if (nf == 0 && nk > 0) min_share = 0.0;
    if (nf > 0)
      for (Eigen::Index k = 0; k < nk; ++k) min_share = std::min(min_share, B.row(k).sum());
    if (rank < nk && refinements < options.max_refinements) {
      refine();
      continue;
    }

    // The energy minimum subject to the key points, when they are independent: d = H^-1 B^T μ with
    // (B H^-1 B^T) μ = r, else the KKT system (kkt_solve). Dependent key points:
    // d = d0 + Z y with d0 the minimal-norm least-squares solution of B d = r, Z a basis of null(B)
    // and y minimising the energy — the least-squares compromise of least energy.
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(nf, 3);
    if (nk > 0 && nf > 0) {
      if (rank == nk) {
        // Range space first: Y = H^-1 B^T from the net's factorization, S = B Y (nk x nk, SPD),
        // S μ = r, d = Y μ, one step of refinement on the key-point residual. It is accepted
        // when it meets the key points to far below the tolerance; otherwise (S squares the
        // conditioning of nearly dependent rows) the KKT system decides.
        bool solved = false;
        if (net->factorized) {
          Eigen::MatrixXd Y;
          if (net->inverse.size() > 0) {
            Y = Eigen::MatrixXd::Zero(nf, nk);
            for (Eigen::Index k = 0; k < nk; ++k)
              for (Eigen::Index c = 0; c < nf; ++c)
                if (B(k, c) != 0) Y.col(k) += B(k, c) * net->inverse.col(c);
          } else {
            Y = net->energy.solve(Eigen::MatrixXd(B.transpose()));
          }
          const Eigen::MatrixXd S = B * Y;
          const Eigen::LDLT<Eigen::MatrixXd> schur(S);
          if (schur.info() == Eigen::Success && schur.isPositive()) {
            Eigen::MatrixXd mu = schur.solve(rhs);
            mu += schur.solve(rhs - B * (Y * mu));
            d = Y * mu;
            // Both KKT conditions: the key points (B d = r) and stationarity (H d = B^T μ). The
            // first alone cannot see an inaccurate Y, since S was made from the same Y; the
            // second can (a nearly singular H, held definite only by its ridge where the free
            // vertices reach the net's border, or μ large along S's weak directions).
            const Eigen::MatrixXd force = B.transpose() * mu;
            const double stationarity = (net->H * d - force).cwiseAbs().maxCoeff();
            solved = internal::all_finite(d) &&
                     (B * d - rhs).cwiseAbs().maxCoeff() <= range_space_accuracy * tol &&
                     stationarity <= range_space_stationarity * force.cwiseAbs().maxCoeff();
          }
        }
        if (!solved) d = kkt_solve(net->H, B, rhs);
      } else {
        Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(B);
        cod.setThreshold(1e-10);
        d = cod.solve(rhs);
        if (rank < nf) {
          const Eigen::MatrixXd Q = qr.householderQ();
          const Eigen::MatrixXd Z = Q.rightCols(nf - rank);
          const Eigen::MatrixXd HZ = net->H * Z;
          const Eigen::MatrixXd reduced = Z.transpose() * HZ;
          d -= Z * reduced.ldlt().solve(HZ.transpose() * d);
        }
      }
    }
    // Key points independent but so nearly dependent that the solve misses them, or met only by
    // a wound-up net: a finer net. When the net may not be refined further and the last key points
    // added are what winds it up, they are taken back (the miss of the target curve is reported).
    const Eigen::MatrixXd achieved = B * d - rhs;
    const bool missed = nk > 0 && achieved.rowwise().norm().maxCoeff() > tol;
    const double farthest = nk > 0 ? rhs.rowwise().norm().maxCoeff() : 0.0;
    amplification = nf > 0 && farthest > 0 ? d.rowwise().norm().maxCoeff() / farthest : 0.0;
    const bool wound = amplification > max_amplification;
    if ((missed || wound) && refinements < options.max_refinements) {
      refine();
      continue;
    }
    if (wound && points.size() > accepted_points) {
      points.resize(accepted_points);
      report.added_key_points = static_cast<int>(accepted_points - keys.points.size());
      additions = options.max_key_point_rounds;  // no more rounds
      continue;
    }
    out.surface = s;
    out.refined_parent = s;
    for (Eigen::Index f = 0; f < nf; ++f)
      if (!d.row(f).isZero(0))
        out.surface.points.row(free_rows[static_cast<size_t>(f)]) += d.row(f);

    // Where the result still misses the target by more than curve_tolerance, add key points at
    // the local maxima of the miss along the target's samples and solve again.
    if (!missed && options.curve_tolerance > 0 && additions < options.max_key_point_rounds) {
      const double limit = options.curve_tolerance * size;
      std::vector<double> miss(trace.size(), 0.0);
      const surface::SurfaceProjector result(out.surface, options.projection);  // validated once
      for (size_t k = 0; k < trace.size(); ++k) {
        if (!in_region(trace[k])) continue;
        // The distance from the wanted point (λ scales the move as for key points) to the result;
        // the miss at the sample's own parameters bounds it from above and spares most
        // projections.
        const Eigen::Vector3d foot = surface::evaluate(s, trace[k].u, trace[k].v);
        const Eigen::Vector3d wanted = foot + options.lambda * (trace[k].point - foot);
        miss[k] = (surface::evaluate(out.surface, trace[k].u, trace[k].v) - wanted).norm();
        if (miss[k] > limit)
          miss[k] = project_from(result, wanted, trace[k].u, trace[k].v).distance;
      }
      size_t added = 0;
      for (size_t k = 0; k < trace.size(); ++k) {
        // Local maxima, with a relative slack so that a plateau of two equal misses (a symmetric
        // target) adds both samples, not whichever rounding favours.
        const double floor = miss[k] * (1 - 1e-6);
        const bool peak = miss[k] > limit && (k == 0 || floor >= miss[k - 1]) &&
                          (k + 1 == trace.size() || floor >= miss[k + 1]);
        if (!peak) continue;
        // Not next to a key point already there (nearly equal rows would make the system
        // ill-conditioned): at least half a sample step away along the curve.
        const double gap =
            0.5 * (trace.back().t - trace.front().t) / static_cast<double>(trace.size() - 1);
        bool crowded = false;
        for (const KeyPoint& p : points)
          crowded = crowded || std::abs(p.curve_parameter - trace[k].t) < gap;
        if (crowded) continue;
        points.push_back(make_key_point(s, reg, trace[k].point, trace[k].t, trace[k].u, trace[k].v,
                                        keys.direction));
        ++added;
      }
      if (added > 0) {
        accepted_points = points.size() - added;
        ++additions;
        report.added_key_points += static_cast<int>(added);
        continue;
      }
    }

    report.m = static_cast<int>(points.size());
    report.key_points = points;
    report.rank = rank;
    report.degrees_of_freedom = 3 * (static_cast<int>(nf) - rank);
    for (Eigen::Index k = 0; k < nk; ++k)
      if (achieved.row(k).norm() > tol)
        report.conflicting_key_points.push_back(active[static_cast<size_t>(k)]);
    measure(s, out.surface, reg.factors, reg, trace, options, report);
    std::ostringstream msg;
    msg << to_string(report.constraint_class) << ", m = " << report.m << " key points (" << nk
        << " influenced";
    if (report.added_key_points > 0)
      msg << ", " << report.added_key_points << " added where the target was missed";
    msg << "), " << nf << " free vertices, rank " << rank << ", " << report.degrees_of_freedom
        << " degrees of freedom left";
    if (report.knots_inserted > 0) msg << ", " << report.knots_inserted << " knots inserted";
    if (!report.conflicting_key_points.empty())
      msg << "; " << report.conflicting_key_points.size()
          << " key points cannot be met (the net is too coarse there: allow more max_refinements)";
    if (amplification > max_amplification)
      msg << "; the free vertices move up to " << amplification
          << " times the farthest key point's distance (allow more max_refinements)";
    if (min_share < min_free_share)
      msg << "; a key point is held mostly by fixed vertices (free share " << min_share
          << "): the free vertices move up to " << 1.0 / std::max(min_share, 1e-300)
          << " times its distance (allow more max_refinements, or a bound further from the target)";
    if (options.curve_tolerance > 0 &&
        report.target_curve_deviation > options.curve_tolerance * size)
      msg << "; the target curve is still missed by " << report.target_curve_deviation
          << " mm, more than "
          << "curve_tolerance x size = " << options.curve_tolerance * size
          << " mm (allow more max_key_point_rounds or max_refinements)";
    report.message = msg.str();
    return out;
  }
}

}  // namespace clay::deform::detail
