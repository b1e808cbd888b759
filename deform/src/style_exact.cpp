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
#include "fairness.hpp"
#include "style_internal.hpp"

#include <clay/cancel.hpp>
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
#include <limits>
#include <optional>
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
// Dependent key points on nets of more free vertices than this are solved through the net's
// factorization (the dense null space would take nf^2 doubles: 20 GB at 50,000).
constexpr Eigen::Index dependent_dense_limit = 2048;
// The ridge added to the scaled energy's diagonal.
constexpr double energy_ridge = 1e-12;
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

}  // namespace

// Where the displacement may be non-zero, fixed in parameter space for every net the solve is
// refined to: the union of the supports of the vertices that are influenced and more than
// `fixed_rows` layers inside the region's edge on the *region net* (the parent with its spans
// over the region halved until the region's box covers at least region_spans of them in each
// direction). A vertex of any net is free when it is influenced and its support lies in this
// area. The spaces of displacements are then nested as the net is halved (a spline supported in
// the area is one on the finer net), so the solves are Galerkin approximations of one problem
// on one domain and converge; with free vertices chosen by layers on each net instead, the
// domain itself grew by a layer's width per halving and the shape changed by ~1/2 of its last
// change each time (the hood: 18 %, 7 %, 3 %).
struct FreeArea {
  // The region net, prepared for projection once (validated, kept across drags): the key
  // points are found on it at every update.
  std::shared_ptr<const surface::SurfaceProjector> net;
  InfluenceRegion region;      // the region on it (factors of its vertices)
  std::vector<double> bu, bv;  // breakpoints of the region net
  std::vector<int> sum;        // prefix sums of the cells in the area, (cu + 1) x (cv + 1)
  int cells_v = 0;

  int count(int a0, int a1, int b0, int b1) const {  // cells [a0, a1) x [b0, b1) in the area
    const auto at = [&](int a, int b) { return sum[static_cast<size_t>(a * (cells_v + 1) + b)]; };
    return at(a1, b1) - at(a0, b1) - at(a1, b0) + at(a0, b0);
  }
  // Cells of breakpoints `b` overlapping the open interval (lo, hi): [first, last).
  static std::pair<int, int> cells(const std::vector<double>& b, double lo, double hi) {
    const int first = static_cast<int>(std::upper_bound(b.begin(), b.end(), lo) - b.begin()) - 1;
    const int last = static_cast<int>(std::lower_bound(b.begin(), b.end(), hi) - b.begin());
    return {std::max(first, 0), std::min(last, static_cast<int>(b.size()) - 1)};
  }
  // True when the cells around (u, v) (both sides of a breakpoint it lies on) and their
  // neighbours lie in the area: a key point elsewhere cannot be met on any net, or only where the
  // displacement fades out towards the area's edge, by a net wound up around it. (Key points of
  // eq. 8 lie on rows, and a uniform cubic's rows are its knots.)
  bool holds(double u, double v) const {
    if (sum.empty()) return false;
    const double eu = 1e-9 * (bu.back() - bu.front()), ev = 1e-9 * (bv.back() - bv.front());
    auto [a0, a1] = cells(bu, u - eu, u + eu);
    auto [b0, b1] = cells(bv, v - ev, v + ev);
    a0 -= 1;
    b0 -= 1;
    a1 += 1;
    b1 += 1;
    const int cu = static_cast<int>(bu.size()) - 1, cv = static_cast<int>(bv.size()) - 1;
    if (a0 < 0 || b0 < 0 || a1 > cu || b1 > cv) return false;
    return count(a0, a1, b0, b1) == (a1 - a0) * (b1 - b0);
  }
  // True when the rectangle [u0, u1] x [v0, v1] lies in the area.
  bool contains(double u0, double u1, double v0, double v1) const {
    if (sum.empty()) return false;
    const auto [a0, a1] = cells(bu, u0, u1);
    const auto [b0, b1] = cells(bv, v0, v1);
    if (a1 <= a0 || b1 <= b0) return false;
    return count(a0, a1, b0, b1) == (a1 - a0) * (b1 - b0);
  }
};

// The free vertices of one net (knot vectors) and the fairness matrix over them.
struct NetCache {
  std::vector<double> knots_u, knots_v;  // the net it was built for
  std::vector<Eigen::Index> free_index;  // per vertex: its unknown, or -1 when fixed
  std::vector<Eigen::Index> free_rows;   // per unknown: its vertex
  Eigen::SparseMatrix<double> H;  // the fairness energy over the free vertices / scale + ridge
  double scale = 1;               // E_k(d) = scale * sum over x, y, z of d^T (H - ridge) d
  // H = P^T L D L^T P, factorized once per net: every drag on the net reuses it (only the
  // key-point rows B change), so a solve costs nk triangular solves instead of a KKT factorization.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> energy;
  bool factorized = false;
  // H^-1 itself on nets of up to dense_inverse_limit free vertices (at most 2 MB): a key-point
  // row has (p+1)(q+1) nonzeros, so H^-1 B^T is then that many columns of it per key point.
  Eigen::MatrixXd inverse;
};

namespace {

// Free vertices of `s` (influenced, their support in the free area) and the factorized fairness
// energy of order `order` of their displacements (fixed vertices have d = 0).
std::shared_ptr<const NetCache> build_cache(const BSplineSurface& s,
                                            const std::vector<std::uint8_t>& factors,
                                            const FreeArea& area, int order) {
  auto cache = std::make_shared<NetCache>();
  cache->knots_u = s.u.knots;
  cache->knots_v = s.v.knots;
  cache->free_index.assign(factors.size(), -1);
  const int p = s.u.degree, q = s.v.degree;
  for (int i = 0; i < s.count_u(); ++i)
    for (int j = 0; j < s.count_v(); ++j) {
      const size_t r = static_cast<size_t>(s.index(i, j));
      const auto& tu = s.u.knots;
      const auto& tv = s.v.knots;
      if (factors[r] == 0 ||
          !area.contains(tu[static_cast<size_t>(i)], tu[static_cast<size_t>(i + p + 1)],
                         tv[static_cast<size_t>(j)], tv[static_cast<size_t>(j + q + 1)]))
        continue;
      cache->free_index[r] = static_cast<Eigen::Index>(cache->free_rows.size());
      cache->free_rows.push_back(static_cast<Eigen::Index>(r));
    }
  const Eigen::Index nf = static_cast<Eigen::Index>(cache->free_rows.size());
  if (nf == 0) return cache;

  // The fairness energy's Galerkin matrix (fairness.hpp), scaled to a unit largest diagonal so
  // that the KKT system's blocks are of like size (the energy is reported unscaled).
  Eigen::SparseMatrix<double> H = fairness_matrix(s, cache->free_index, nf, order);
  double max_diag = 0;
  for (Eigen::Index c = 0; c < nf; ++c) max_diag = std::max(max_diag, H.coeff(c, c));
  if (!(max_diag > 0) || !std::isfinite(max_diag))
    throw Error(ErrorCategory::Internal, "style deformation: the fairness energy vanishes");
  H /= max_diag;
  cache->scale = max_diag;
  // A tiny ridge keeps H definite where the free vertices reach the border of the net.
  for (Eigen::Index c = 0; c < nf; ++c) H.coeffRef(c, c) += energy_ridge;
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

namespace {

// Parameter points over the region where net convergence compares shapes, and the parent there.
struct ShapeGrid {
  int n = 0;  // samples per direction over the region's box
  std::vector<Eigen::Vector2d> uv;
  std::vector<Eigen::Vector3d> parent;
};

template <class Inside>
ShapeGrid shape_grid(const BSplineSurface& parent, const InfluenceRegion& region, Inside&& inside) {
  constexpr int n = 81;
  ShapeGrid grid;
  grid.n = n;
  const Eigen::AlignedBox2d box = region_box(parent, region);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const Eigen::Vector2d uv =
          box.min() + Eigen::Vector2d(a, b).cwiseProduct(box.sizes()) / (n - 1);
      TraceSample t;
      t.u = uv.x();
      t.v = uv.y();
      if (!inside(t)) continue;
      grid.uv.push_back(uv);
      grid.parent.push_back(surface::evaluate(parent, uv.x(), uv.y()));
    }
  return grid;
}

// |S_new - S_old| at every grid point, and the figure: max |S_new - S_old| / max |S_new - parent|
// over the grid (0 where nothing moved).
struct ShapeChange {
  double relative = 0;
  double moved = 0;
  std::vector<double> at;  // per grid point, mm
};
ShapeChange shape_change(const ShapeGrid& grid, const BSplineSurface& old_shape,
                         const BSplineSurface& new_shape) {
  ShapeChange out;
  double change = 0;
  for (size_t k = 0; k < grid.uv.size(); ++k) {
    const Eigen::Vector3d a = surface::evaluate(old_shape, grid.uv[k].x(), grid.uv[k].y());
    const Eigen::Vector3d b = surface::evaluate(new_shape, grid.uv[k].x(), grid.uv[k].y());
    out.at.push_back((b - a).norm());
    change = std::max(change, out.at.back());
    out.moved = std::max(out.moved, (b - grid.parent[k]).norm());
  }
  out.relative = out.moved > 0 ? change / out.moved : 0.0;
  return out;
}

// The knots that halve the spans of `basis` within `reach` of a parameter in `marked` (and inside
// [lo, hi]): where the shape still changes, the net is refined; elsewhere it is left alone.
std::vector<double> local_halving_knots(const surface::BSplineBasis& basis,
                                        const std::vector<double>& marked, double reach, double lo,
                                        double hi) {
  std::vector<double> knots;
  const auto breaks = surface::breakpoints(basis);
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    if (!(breaks[k + 1] > lo && breaks[k] < hi)) continue;
    const bool near = std::any_of(marked.begin(), marked.end(), [&](double t) {
      return t + reach >= breaks[k] && t - reach <= breaks[k + 1];
    });
    if (near) knots.push_back(0.5 * (breaks[k] + breaks[k + 1]));
  }
  return knots;
}

}  // namespace

// What the exact mode keeps between drags: one NetCache per net it has solved on (the parent's
// and its refinements), never modified once shared.
struct ExactCache {
  std::shared_ptr<const FreeArea> area;
  std::vector<std::shared_ptr<const NetCache>> nets;
};

namespace {

// The region net's knot spans over the box in each direction at least this many (halving the
// parent's at most max_region_halvings times): the resolution of the free area's edge.
constexpr int region_spans = 32;
constexpr int max_region_halvings = 5;

// The exact mode holds the target's own ends too (where they lie in the region): the rows of eq. 8
// stop up to a row's spacing short of them, and that shortfall changed with every halving of the
// net, so the shape near the ends never settled (the hood: 4 % after five halvings, all of it
// past the crease's ends). A row key point within a quarter of the mean spacing of an end gives
// way to it (two nearly equal rows would make the system ill-conditioned).
template <class Inside>
void hold_target_ends(const BSplineSurface& s, const InfluenceRegion& region,
                      const std::vector<TraceSample>& trace, KeyDirection direction,
                      Inside&& inside, std::vector<KeyPoint>& points) {
  if (trace.size() < 2) return;
  const double span = trace.back().t - trace.front().t;
  const double spacing = span / static_cast<double>(std::max<size_t>(points.size(), 1));
  for (const TraceSample* end : {&trace.front(), &trace.back()}) {
    if (!inside(*end)) continue;
    std::erase_if(points, [&](const KeyPoint& k) {
      return std::abs(k.curve_parameter - end->t) < 0.25 * spacing;
    });
    KeyPoint k = make_key_point(s, region, end->point, end->t, end->u, end->v, direction);
    points.insert(end == &trace.front() ? points.begin() : points.end(), k);
  }
}

// The trace with 3 more samples between each two, uniform in the curve's parameter, each
// projected by Newton from the sample before it.
std::vector<TraceSample> densify(const surface::SurfaceProjector& projector,
                                 const BSplineCurve& target,
                                 const std::vector<TraceSample>& trace) {
  std::vector<TraceSample> fine;
  for (size_t k = 0; k < trace.size(); ++k) {
    fine.push_back(trace[k]);
    if (k + 1 == trace.size()) break;
    for (int j = 1; j < 4; ++j) {
      TraceSample x;
      x.t = trace[k].t + (trace[k + 1].t - trace[k].t) * j / 4;
      x.point = surface::evaluate(target, x.t);
      const auto p = project_from(projector, x.point, fine.back().u, fine.back().v);
      x.u = p.u;
      x.v = p.v;
      fine.push_back(x);
    }
  }
  return fine;
}

FreeArea make_free_area(const BSplineSurface& parent, const InfluenceRegion& region,
                        const Eigen::AlignedBox2d& box, int fixed_rows,
                        const surface::ProjectionOptions& projection) {
  BSplineSurface s = parent;
  for (int h = 0; h < max_region_halvings; ++h) {
    // One halving knot per span over the box: their count is the spans' count.
    const auto ku = halving_knots(s.u, box.min().x(), box.max().x());
    const auto kv = halving_knots(s.v, box.min().y(), box.max().y());
    const bool u = static_cast<int>(ku.size()) < region_spans;
    const bool v = static_cast<int>(kv.size()) < region_spans;
    if (!u && !v) break;
    if (u) s = surface::refine_knots_u(s, ku);
    if (v) s = surface::refine_knots_v(s, kv);
  }
  const auto factors = region_factors(s, region.polygon, region.target_trace, region.margin);
  const auto dist = distance_to_outside(s, factors);
  FreeArea area;
  area.region = region;
  area.region.count_u = s.count_u();
  area.region.count_v = s.count_v();
  area.region.factors = factors;
  area.bu = surface::breakpoints(s.u);
  area.bv = surface::breakpoints(s.v);
  const int cu = static_cast<int>(area.bu.size()) - 1, cv = static_cast<int>(area.bv.size()) - 1;
  area.cells_v = cv;
  std::vector<std::uint8_t> in(static_cast<size_t>(cu * cv), 0);
  const int p = s.u.degree, q = s.v.degree;
  for (int i = 0; i < s.count_u(); ++i)
    for (int j = 0; j < s.count_v(); ++j) {
      const size_t r = static_cast<size_t>(s.index(i, j));
      // The surface's own edges are held like the bound: they are where it meets its neighbours.
      const int to_edge = std::min({i, s.count_u() - 1 - i, j, s.count_v() - 1 - j}) + 1;
      if (factors[r] == 0 || std::min(dist[r], to_edge) <= fixed_rows) continue;
      const auto [a0, a1] = FreeArea::cells(area.bu, s.u.knots[static_cast<size_t>(i)],
                                            s.u.knots[static_cast<size_t>(i + p + 1)]);
      const auto [b0, b1] = FreeArea::cells(area.bv, s.v.knots[static_cast<size_t>(j)],
                                            s.v.knots[static_cast<size_t>(j + q + 1)]);
      for (int a = a0; a < a1; ++a)
        for (int b = b0; b < b1; ++b) in[static_cast<size_t>(a * cv + b)] = 1;
    }
  // Not the cells along the surface's own edges: a free vertex whose support reaches an edge
  // would move the edge itself (the bound of a sail drawn past its leech).
  for (int a = 0; a < cu; ++a)
    in[static_cast<size_t>(a * cv)] = in[static_cast<size_t>(a * cv + cv - 1)] = 0;
  for (int b = 0; b < cv; ++b)
    in[static_cast<size_t>(b)] = in[static_cast<size_t>((cu - 1) * cv + b)] = 0;
  // Only cells inside the region (corners and edge midpoints): a support whose Greville
  // neighbours all lie inside may still reach across a curved bound between them. Without a
  // bound, inside means between influenced vertices of the parent's net: the four whose Greville
  // points surround the sample have E = 1.
  const PolygonLocator bound(region.polygon, parameter_tolerance(parent));
  const auto xu = surface::greville_abscissae(parent.u), xv = surface::greville_abscissae(parent.v);
  auto inside = [&](double u, double v) {
    if (!region.polygon.empty()) return bound.inside({u, v});
    const int i = static_cast<int>(continuous_index(xu, u)),
              j = static_cast<int>(continuous_index(xv, v));
    for (int a = i; a <= std::min(i + 1, parent.count_u() - 1); ++a)
      for (int b = j; b <= std::min(j + 1, parent.count_v() - 1); ++b)
        if (!region.inside(a, b)) return false;
    return true;
  };
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b) {
      auto& cell = in[static_cast<size_t>(a * cv + b)];
      const double u0 = area.bu[static_cast<size_t>(a)], u1 = area.bu[static_cast<size_t>(a + 1)];
      const double v0 = area.bv[static_cast<size_t>(b)], v1 = area.bv[static_cast<size_t>(b + 1)];
      for (int x = 0; x <= 2 && cell != 0; ++x)
        for (int y = 0; y <= 2 && cell != 0; ++y)
          if (!inside(u0 + 0.5 * x * (u1 - u0), v0 + 0.5 * y * (v1 - v0))) cell = 0;
    }
  area.sum.assign(static_cast<size_t>((cu + 1) * (cv + 1)), 0);
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b)
      area.sum[static_cast<size_t>((a + 1) * (cv + 1) + b + 1)] =
          in[static_cast<size_t>(a * cv + b)] +
          area.sum[static_cast<size_t>(a * (cv + 1) + b + 1)] +
          area.sum[static_cast<size_t>((a + 1) * (cv + 1) + b)] -
          area.sum[static_cast<size_t>(a * (cv + 1) + b)];
  area.net = std::make_shared<const surface::SurfaceProjector>(std::move(s), projection);
  return area;
}

/// The key-point rows on net `s` (Han–De Amicis–Conti eq. 9): Σ_free R_ij(u_k, v_k) d_ij =
/// λ (K_k − P_k), one per influenced key point.
struct KeyPointSystem {
  std::vector<int> active;  // indices of the influenced key points
  Eigen::MatrixXd B;        // nk x nf: the free vertices' basis functions at the key points
  Eigen::MatrixXd rhs;      // nk x 3: λ (K_k − P_k)
};

KeyPointSystem key_point_system(const BSplineSurface& s, const std::vector<KeyPoint>& points,
                                const std::vector<Eigen::Index>& free_index, Eigen::Index nf,
                                double lambda) {
  KeyPointSystem out;
  for (size_t k = 0; k < points.size(); ++k)
    if (points[k].influenced) out.active.push_back(static_cast<int>(k));
  const Eigen::Index nk = static_cast<Eigen::Index>(out.active.size());
  out.B = Eigen::MatrixXd::Zero(nk, nf);
  out.rhs.resize(nk, 3);
  for (Eigen::Index k = 0; k < nk; ++k) {
    const KeyPoint& kp = points[static_cast<size_t>(out.active[static_cast<size_t>(k)])];
    for (const auto& [r, value] : basis_at(s, kp.u, kp.v))
      if (free_index[static_cast<size_t>(r)] >= 0)
        out.B(k, free_index[static_cast<size_t>(r)]) = value;
    out.rhs.row(k) = lambda * (kp.point - kp.foot).transpose();
  }
  return out;
}

/// H^-1 X for the factorization H = P^T L D L^T P and X with few columns (the key-point rows'
/// transposes, 30 to 60 on a styled panel): the right-hand sides are held row by row, so each
/// entry of L is read once for all of them (Eigen's solve sweeps L once per column, and L of a
/// refined net, 2 MB at 1631 free vertices, does not stay in cache between the sweeps), and the
/// forward sweep skips the rows still zero (a key point's row reaches (p+1)(q+1) vertices).
Eigen::MatrixXd solve_columns(const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& f,
                              const Eigen::MatrixXd& x) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Index n = x.rows(), m = x.cols();
  RowMajor z = f.permutationP() * x;
  const Eigen::SparseMatrix<double>& L = f.matrixL().nestedExpression();  // strictly lower
  double* const rows = z.data();
  for (Eigen::Index j = 0; j < n; ++j) {  // L y = P x, column by column of L
    const double* zj = rows + j * m;
    bool zero = true;
    for (Eigen::Index c = 0; c < m && zero; ++c) zero = zj[c] == 0;
    if (zero) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, j); it; ++it) {
      double* zi = rows + it.index() * m;
      const double l = it.value();
      for (Eigen::Index c = 0; c < m; ++c) zi[c] -= l * zj[c];
    }
  }
  const Eigen::VectorXd& d = f.vectorD();
  for (Eigen::Index i = 0; i < n; ++i) z.row(i) /= d[i];
  for (Eigen::Index j = n - 1; j >= 0; --j) {  // L^T w = D^-1 y: row j of L^T is column j of L
    double* zj = rows + j * m;
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, j); it; ++it) {
      const double* zi = rows + it.index() * m;
      const double l = it.value();
      for (Eigen::Index c = 0; c < m; ++c) zj[c] -= l * zi[c];
    }
  }
  return f.permutationPinv() * z;
}

/// Y = H^-1 B^T for the key-point rows B on `net`, its columns kept across the solves of one
/// style on the same net: a round of added key points appends rows to B, and the columns of the
/// rows already there are taken as they were. Emptied whenever the solve moves to another net.
struct RangeColumns {
  std::shared_ptr<const NetCache> net;  // the net B and Y are of
  Eigen::MatrixXd B, Y;
};

const Eigen::MatrixXd& energy_inverse_times(const NetCache& net, const Eigen::MatrixXd& B,
                                            RangeColumns& kept) {
  const Eigen::Index nk = B.rows(), nf = B.cols();
  Eigen::Index same = 0;  // leading rows of B equal to those of the last call on this net
  if (kept.net.get() == &net && kept.B.cols() == nf)
    while (same < std::min(nk, kept.B.rows()) && kept.B.row(same) == B.row(same)) ++same;
  Eigen::MatrixXd Y(nf, nk);
  if (same > 0) Y.leftCols(same) = kept.Y.leftCols(same);  // (an empty kept.Y has no rows)
  if (same < nk) {
    const Eigen::MatrixXd fresh = B.bottomRows(nk - same).transpose();
    if (net.inverse.size() > 0) {
      // A key point's row has (p+1)(q+1) nonzeros: its column of Y is as many columns of H^-1.
      Y.rightCols(nk - same).setZero();
      for (Eigen::Index k = 0; k < nk - same; ++k)
        for (Eigen::Index c = 0; c < nf; ++c)
          if (fresh(c, k) != 0) Y.col(same + k) += fresh(c, k) * net.inverse.col(c);
    } else {
      Y.rightCols(nk - same) = solve_columns(net.energy, fresh);
    }
  }
  kept.B = B;
  kept.Y = std::move(Y);
  return kept.Y;
}

/// The free vertices' displacements d (nf x 3) of least fairness energy that meet the key-point
/// rows B d = rhs (Han–De Amicis–Conti §4, the energy of eq. 10 under the constraints of eq. 9),
/// or, when the rows are dependent (rank < nk), the least-squares compromise of least energy.
/// `qr` is the rank-revealing QR of B^T that gave `rank`; `tol` the tolerance in mm.
/// `kept` holds H^-1 B^T's columns between the solves of one style (energy_inverse_times).
Eigen::MatrixXd constrained_minimum(const NetCache& net, const Eigen::MatrixXd& B,
                                    const Eigen::MatrixXd& rhs, int rank,
                                    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd>& qr,
                                    double tol, RangeColumns& kept) {
  // The energy minimum subject to the key points, when they are independent: d = H^-1 B^T μ with
  // (B H^-1 B^T) μ = r, else the KKT system (kkt_solve). Dependent key points:
  // d = d0 + Z y with d0 the minimal-norm least-squares solution of B d = r, Z a basis of null(B)
  // and y minimising the energy — the least-squares compromise of least energy.
  const Eigen::Index nk = B.rows(), nf = B.cols();
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(nf, 3);
  if (nk > 0 && nf > 0) {
    if (rank == nk) {
      // Range space first: Y = H^-1 B^T from the net's factorization, S = B Y (nk x nk, SPD),
      // S μ = r, d = Y μ, one step of refinement on the key-point residual. It is accepted
      // when it meets the key points to far below the tolerance; otherwise (S squares the
      // conditioning of nearly dependent rows) the KKT system decides.
      bool solved = false;
      if (net.factorized) {
        const Eigen::MatrixXd& Y = energy_inverse_times(net, B, kept);
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
          const double stationarity = (net.H * d - force).cwiseAbs().maxCoeff();
          solved = internal::all_finite(d) &&
                   (B * d - rhs).cwiseAbs().maxCoeff() <= range_space_accuracy * tol &&
                   stationarity <= range_space_stationarity * force.cwiseAbs().maxCoeff();
        }
      }
      if (!solved) d = kkt_solve(net.H, B, rhs);
    } else if (nf > dependent_dense_limit && net.factorized) {
      // Too many free vertices for the dense null space below (Q is nf x nf): the same
      // compromise as the limit of the penalty min d^T H d + |B d - r|^2 / ε, by the range
      // space with a ridge on the Schur complement, d = Y (B Y + ε I)^-1 r, Y = H^-1 B^T.
      const Eigen::MatrixXd& Y = energy_inverse_times(net, B, kept);
      Eigen::MatrixXd S = B * Y;
      const double ridge = 1e-10 * std::max(S.trace() / static_cast<double>(nk), 1e-300);
      S.diagonal().array() += ridge;
      d = Y * S.ldlt().solve(rhs);
    } else {
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(B);
      cod.setThreshold(1e-10);
      d = cod.solve(rhs);
      if (rank < nf) {
        const Eigen::MatrixXd Q = qr.householderQ();
        const Eigen::MatrixXd Z = Q.rightCols(nf - rank);
        const Eigen::MatrixXd HZ = net.H * Z;
        const Eigen::MatrixXd reduced = Z.transpose() * HZ;
        d -= Z * reduced.ldlt().solve(HZ.transpose() * d);
      }
    }
  }
  return d;
}

/// Adds key points where `result_surface` still misses the target by more than curve_tolerance:
/// at the local maxima of the miss along `fine` (the target's samples, 4 times as dense as the
/// trace), away from key points already there. Returns how many were added.
template <class InRegion>
size_t add_key_points_at_misses(const BSplineSurface& s, const BSplineSurface& result_surface,
                                const InfluenceRegion& reg, const std::vector<TraceSample>& fine,
                                KeyDirection direction, const FreeArea& area, InRegion&& in_region,
                                const StyleOptions& options, double size,
                                std::vector<KeyPoint>& points) {
  const double limit = options.curve_tolerance * size;
  std::vector<double> miss(fine.size(), 0.0);
  const surface::SurfaceProjector result(result_surface, options.projection);  // validated once
  for (size_t k = 0; k < fine.size(); ++k) {
    if (!in_region(fine[k]) || !area.holds(fine[k].u, fine[k].v)) continue;
    // The distance from the wanted point (λ scales the move as for key points) to the result;
    // the miss at the sample's own parameters bounds it from above and spares most
    // projections.
    const Eigen::Vector3d foot = surface::evaluate(s, fine[k].u, fine[k].v);
    const Eigen::Vector3d wanted = foot + options.lambda * (fine[k].point - foot);
    miss[k] = (surface::evaluate(result_surface, fine[k].u, fine[k].v) - wanted).norm();
    if (miss[k] > limit) miss[k] = project_from(result, wanted, fine[k].u, fine[k].v).distance;
  }
  size_t added = 0;
  for (size_t k = 0; k < fine.size(); ++k) {
    // Local maxima, with a relative slack so that a plateau of two equal misses (a symmetric
    // target) adds both samples, not whichever rounding favours.
    const double floor = miss[k] * (1 - 1e-6);
    const bool peak = miss[k] > limit && (k == 0 || floor >= miss[k - 1]) &&
                      (k + 1 == fine.size() || floor >= miss[k + 1]);
    if (!peak) continue;
    // Not next to a key point already there (nearly equal rows would make the system
    // ill-conditioned): at least half a sample step away along the curve.
    const double gap =
        0.5 * (fine.back().t - fine.front().t) / static_cast<double>(fine.size() - 1);
    bool crowded = false;
    for (const KeyPoint& p : points)
      crowded = crowded || std::abs(p.curve_parameter - fine[k].t) < gap;
    if (crowded) continue;
    points.push_back(
        make_key_point(s, reg, fine[k].point, fine[k].t, fine[k].u, fine[k].v, direction));
    ++added;
  }
  return added;
}

/// The report of the solve that is kept: the energy, the rank and degrees of freedom, the key
/// points that cannot be met, the measured figures, and the message saying what limited it.
template <class Net>
void finish_report(const BSplineSurface& parent, const InfluenceRegion& region,
                   const BSplineSurface& s, const InfluenceRegion& reg,
                   const BSplineSurface& result_surface, const Net& net, const Eigen::MatrixXd& d,
                   const KeyPointSystem& system, int rank, double amplification, double min_share,
                   const BSplineCurve& target, const std::vector<TraceSample>& trace,
                   const StyleOptions& options, double size, const std::vector<KeyPoint>& points,
                   StyleReport& report) {
  const Eigen::Index nk = system.B.rows(), nf = system.B.cols();
  const std::vector<int>& active = system.active;
  const Eigen::MatrixXd achieved = system.B * d - system.rhs;
  const double tol = options.relative_tolerance * size;
  report.key_points = points;
  // E_k(d) from the net's own matrix (fixed vertices have d = 0), without the ridge.
  report.fairness_energy =
      nf > 0 ? net.scale * ((d.transpose() * (net.H * d)).trace() - energy_ridge * d.squaredNorm())
             : 0.0;
  report.rank = rank;
  report.degrees_of_freedom = 3 * (static_cast<int>(nf) - rank);
  for (Eigen::Index k = 0; k < nk; ++k)
    if (achieved.row(k).norm() > tol)
      report.conflicting_key_points.push_back(active[static_cast<size_t>(k)]);
  measure(s, result_surface, reg.factors, reg, target, trace, options, report);
  // The edge of a region without a bound is that of the parent's influenced vertices (the
  // free area is made from them), not of those of the refined net, a band narrower by the
  // refinement.
  if (options.report_curves && region.polygon.empty())
    measure_boundary(parent, region.factors, region, s, result_surface, report);
  std::ostringstream msg;
  msg << to_string(report.constraint_class) << ", m = " << report.key_points.size()
      << " key points (" << nk << " influenced";
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
  if (options.curve_tolerance > 0 && report.target_curve_deviation > options.curve_tolerance * size)
    msg << "; the target curve is still missed by " << report.target_curve_deviation
        << " mm, more than "
        << "curve_tolerance x size = " << options.curve_tolerance * size
        << " mm (allow more max_key_point_rounds or max_refinements)";
  report.message = msg.str();
}
}  // namespace

StyleResult style_exact(const surface::SurfaceProjector& projector, const InfluenceRegion& region,
                        const BSplineCurve& target, const std::vector<TraceSample>& trace,
                        const StyleOptions& options, std::shared_ptr<const ExactCache>& cache) {
  const BSplineSurface& parent = projector.surface();
  const double size = model_size(parent);
  const double tol = options.relative_tolerance * size;
  const int order = options.continuity == BoundContinuity::G2 ? 3 : 2;
  const int fixed_rows = options.boundary_rows + (order - 2);
  if (parent.u.degree < order || parent.v.degree < order)
    throw Error(ErrorCategory::InvalidArgument,
                "style deformation (exact mode): the parent surface has degree (" +
                    std::to_string(parent.u.degree) + ", " + std::to_string(parent.v.degree) +
                    "), and continuity " + std::string(to_string(options.continuity)) +
                    " minimises derivatives of order " + std::to_string(order) +
                    ", which vanish inside its spans: elevate the parent to degree >= " +
                    std::to_string(order) + " in u and v (surface::elevate_degree)" +
                    (order == 3 ? ", or ask for G1" : ", or use the paper mode"));

  BSplineSurface s = parent;
  InfluenceRegion reg = region;
  StyleResult out{parent, parent, {}};
  StyleReport& report = out.report;

  // Every refinement halves the spans over the parent's region box, so the nets are nested.
  const Eigen::AlignedBox2d refine_box = region_box(parent, region);
  if (!cache || !cache->area) {
    auto fresh = std::make_shared<ExactCache>();
    if (cache) fresh->nets = cache->nets;
    fresh->area = std::make_shared<const FreeArea>(
        make_free_area(parent, region, refine_box, fixed_rows, options.projection));
    cache = std::move(fresh);
  }
  const std::shared_ptr<const FreeArea> area = cache->area;

  // The key points are those of eq. 8 on the region net, not on the net being solved: they are
  // the same on every net the solve is refined to, so the refined solves approximate one
  // problem (with the key points of each net, rows twice as dense at every halving, the shape
  // never settled near the target's ends). The target's ends are held too. Key points are added
  // where the result still misses the target curve.
  const KeyPoints keys =
      find_key_points(*area->net, area->region, target, trace, options.key_points_per_row);
  if (begin_report(keys, options, StyleMode::Exact, report)) {
    measure(parent, parent, region.factors, region, target, trace, options, report);
    return out;
  }
  std::vector<KeyPoint> points = keys.points;
  const PolygonLocator bound(region.polygon, parameter_tolerance(parent));
  auto in_region = [&](const TraceSample& t) {
    return region.polygon.empty() || bound.inside({t.u, t.v});
  };
  hold_target_ends(area->net->surface(), area->region, trace, keys.direction, in_region, points);
  // Key points where no free vertex of any net reaches (in the fixed band inside the bound) are
  // not influenced: they cannot be met (under-constrained targets cross that band).
  for (KeyPoint& k : points) k.influenced = k.influenced && area->holds(k.u, k.v);
  int refinements = 0, additions = 0;
  std::size_t accepted_points = points.size();  // key points before the last round of additions
  const std::size_t base_points = points.size();
  std::vector<TraceSample> fine;  // the trace 4 times as dense, made when first needed
  // Net convergence: the result on the previous (coarser) net, compared on a grid over the region.
  std::optional<BSplineSurface> previous;
  const ShapeGrid grid =
      options.net_convergence > 0 ? shape_grid(parent, region, in_region) : ShapeGrid{};
  report.net_change = std::numeric_limits<double>::quiet_NaN();
  double previous_change = 0;  // net_change of the halving before (best effort's stall test)
  double amplification = 0;
  RangeColumns range_columns;  // H^-1 B^T, kept between the solves on one net

  for (;;) {
    throw_if_cancelled("an exact style");
    std::shared_ptr<const NetCache> net;
    if (cache)
      for (const auto& n : cache->nets)
        if (n->knots_u == s.u.knots && n->knots_v == s.v.knots) net = n;
    if (!net) {
      net = build_cache(s, reg.factors, *area, order);
      auto grown = std::make_shared<ExactCache>();
      grown->area = area;
      grown->nets = cache->nets;
      if (grown->nets.size() >= 16) grown->nets.erase(grown->nets.begin());  // bounded memory
      grown->nets.push_back(net);
      cache = std::move(grown);
    }
    throw_if_cancelled("an exact style");  // a new net's factorization takes seconds on a fine net
    const auto& free_index = net->free_index;
    const auto& free_rows = net->free_rows;
    const Eigen::Index nf = static_cast<Eigen::Index>(free_rows.size());

    const KeyPointSystem system = key_point_system(s, points, free_index, nf, options.lambda);
    const Eigen::MatrixXd& B = system.B;
    const Eigen::MatrixXd& rhs = system.rhs;
    const Eigen::Index nk = B.rows();
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
    auto refine_at = [&](const std::vector<double>& ku, const std::vector<double>& kv) {
      s = surface::refine_knots_u(s, ku);
      s = surface::refine_knots_v(s, kv);
      report.knots_inserted += static_cast<int>(ku.size() + kv.size());
      ++refinements;
      reg.count_u = s.count_u();
      reg.count_v = s.count_v();
      reg.factors = region_factors(s, reg.polygon, reg.target_trace, reg.margin);
    };
    auto refine = [&] {
      const Eigen::AlignedBox2d& box = refine_box;
      refine_at(halving_knots(s.u, box.min().x(), box.max().x()),
                halving_knots(s.v, box.min().y(), box.max().y()));
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

    if (range_columns.net != net) range_columns = RangeColumns{net, {}, {}};
    const Eigen::MatrixXd d = constrained_minimum(*net, B, rhs, rank, qr, tol, range_columns);
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
      report.added_key_points = static_cast<int>(accepted_points - base_points);
      additions = options.max_key_point_rounds;  // no more rounds
      continue;
    }
    out.surface = s;
    out.refined_parent = s;
    for (Eigen::Index f = 0; f < nf; ++f)
      if (!d.row(f).isZero(0))
        out.surface.points.row(free_rows[static_cast<size_t>(f)]) += d.row(f);

    // Where the result still misses the target by more than curve_tolerance, add key points at
    // the local maxima of the miss along the target's samples (4 times as dense as the trace: the
    // dense measure of the report found misses between the trace's samples) and solve again.
    if (!missed && options.curve_tolerance > 0 && additions < options.max_key_point_rounds) {
      if (fine.empty()) fine = densify(projector, target, trace);
      const size_t added = add_key_points_at_misses(s, out.surface, reg, fine, keys.direction,
                                                    *area, in_region, options, size, points);
      if (added > 0) {
        accepted_points = points.size() - added;
        ++additions;
        report.added_key_points += static_cast<int>(added);
        continue;
      }
    }

    // The shape is the curves', not the net's: halve the net over the region and solve again
    // until one more halving moves the surface by less than net_convergence of its largest
    // displacement (the energy is a Galerkin discretization of one functional, so the results
    // converge as the net is refined).
    if (options.net_convergence > 0) {
      ShapeChange change;
      if (previous) {
        change = shape_change(grid, *previous, out.surface);
        report.net_change = change.relative;
      }
      const bool settled = previous && report.net_change <= options.net_convergence;
      // Best effort stops where a halving no longer shrinks the change by a fifth: the shape
      // does not converge (a target reaching the bound, which holds the net still there), and
      // each further round costs about four times the last.
      const bool stalled = options.net_convergence_best_effort && previous_change > 0 &&
                           report.net_change > 0.8 * previous_change;
      if (previous) previous_change = report.net_change;
      if (!settled && !stalled && refinements < options.max_refinements) {
        previous = out.surface;
        if (change.at.empty()) {
          refine();  // the first comparison needs a halving everywhere
        } else {
          // Halve the spans near where the last halving still moved the surface by more than
          // a quarter of net_convergence (the error concentrates at the free area's edge and
          // the target's ends); elsewhere one more halving moves it by less.
          const double limit = 0.25 * options.net_convergence * change.moved;
          std::vector<double> mu, mv;
          for (size_t k = 0; k < change.at.size(); ++k)
            if (change.at[k] > limit) {
              mu.push_back(grid.uv[k].x());
              mv.push_back(grid.uv[k].y());
            }
          const Eigen::AlignedBox2d& box = refine_box;
          const double du = box.sizes().x() / (grid.n - 1), dv = box.sizes().y() / (grid.n - 1);
          refine_at(local_halving_knots(s.u, mu, du, box.min().x(), box.max().x()),
                    local_halving_knots(s.v, mv, dv, box.min().y(), box.max().y()));
        }
        accepted_points = points.size();
        additions = 0;
        continue;
      }
    }

    finish_report(parent, region, s, reg, out.surface, *net, d, system, rank, amplification,
                  min_share, target, trace, options, size, points, report);
    return out;
  }
}

}  // namespace clay::deform::detail
