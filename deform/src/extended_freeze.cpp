// Freezing points in an extended lattice (Coquillart 1990 §3.3): chunk location by k-DOP of the
// control points (a superset of their convex hull), Newton's method with the pseudo-inverse and
// subdivision; and the evaluation of Coquillart eq. (1) at the frozen (u, v, w).
#include <clay/deform/extended_lattice.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/parallel.hpp>

#include <Eigen/Dense>  // determinant, LU, JacobiSVD

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <sstream>
#include <utility>

#include "extended_internal.hpp"
#include "messages.hpp"

namespace clay::deform {

namespace {

using Vec3 = Eigen::Vector3d;
using detail::format;
using internal::all_finite;
using Ctrl = std::array<Vec3, chunk_control_points>;

constexpr std::size_t min_freeze_points_per_thread = 1024;
constexpr std::size_t min_evaluate_points_per_thread = 16384;

// ---- cubic Bernstein polynomials --------------------------------------------------------------

/// B_i(t) and B_i'(t), i = 0..3.
inline void bernstein(double t, double b[4], double d[4]) {
  const double s = 1 - t;
  b[0] = s * s * s;
  b[1] = 3 * t * s * s;
  b[2] = 3 * t * t * s;
  b[3] = t * t * t;
  d[0] = -3 * s * s;
  d[1] = 3 * s * s - 6 * t * s;
  d[2] = 6 * t * s - 3 * t * t;
  d[3] = 3 * t * t;
}

/// L(q) and its Jacobian (columns dL/du, dL/dv, dL/dw) for control points P (Coquillart eq. (1)).
void evaluate_with_jacobian(const Ctrl& P, const Vec3& q, Vec3& F, Eigen::Matrix3d& J) {
  double bu[4], du[4], bv[4], dv[4], bw[4], dw[4];
  bernstein(q[0], bu, du);
  bernstein(q[1], bv, dv);
  bernstein(q[2], bw, dw);
  F.setZero();
  J.setZero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      Vec3 s = Vec3::Zero(), sw = Vec3::Zero();  // sums over k of B_k(w) P and B_k'(w) P
      for (int k = 0; k < 4; ++k) {
        const Vec3& p = P[static_cast<size_t>((i * 4 + j) * 4 + k)];
        s += bw[k] * p;
        sw += dw[k] * p;
      }
      F += (bu[i] * bv[j]) * s;
      J.col(0) += (du[i] * bv[j]) * s;
      J.col(1) += (bu[i] * dv[j]) * s;
      J.col(2) += (bu[i] * bv[j]) * sw;
    }
}

/// Halves control points along direction `dir` (0 = u, 1 = v, 2 = w) by de Casteljau at 1/2,
/// keeping the lower (upper = false) or upper half.
Ctrl halve(const Ctrl& in, int dir, bool upper) {
  Ctrl out;
  const int stride = dir == 0 ? 16 : dir == 1 ? 4 : 1;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      // The other two indices, in the order of the remaining directions.
      int base;
      if (dir == 0)
        base = a * 4 + b;
      else if (dir == 1)
        base = a * 16 + b;
      else
        base = a * 16 + b * 4;
      const Vec3 p0 = in[static_cast<size_t>(base)], p1 = in[static_cast<size_t>(base + stride)],
                 p2 = in[static_cast<size_t>(base + 2 * stride)],
                 p3 = in[static_cast<size_t>(base + 3 * stride)];
      const Vec3 q01 = 0.5 * (p0 + p1), q12 = 0.5 * (p1 + p2), q23 = 0.5 * (p2 + p3);
      const Vec3 r0 = 0.5 * (q01 + q12), r1 = 0.5 * (q12 + q23);
      const Vec3 m = 0.5 * (r0 + r1);
      const std::array<Vec3, 4> half =
          upper ? std::array<Vec3, 4>{m, r1, q23, p3} : std::array<Vec3, 4>{p0, q01, r0, m};
      for (int r = 0; r < 4; ++r)
        out[static_cast<size_t>(base + r * stride)] = half[static_cast<size_t>(r)];
    }
  return out;
}

// ---- k-DOP: slabs of the control points in fixed and chunk-specific directions ------------------

constexpr int fixed_directions = 13;
constexpr int max_directions = fixed_directions + 3;

const std::array<Vec3, fixed_directions>& dop_directions() {
  static const std::array<Vec3, fixed_directions> d = [] {
    std::array<Vec3, fixed_directions> r = {
        Vec3(1, 0, 0),  Vec3(0, 1, 0),  Vec3(0, 0, 1), Vec3(1, 1, 0),  Vec3(1, -1, 0),
        Vec3(1, 0, 1),  Vec3(1, 0, -1), Vec3(0, 1, 1), Vec3(0, 1, -1), Vec3(1, 1, 1),
        Vec3(1, 1, -1), Vec3(1, -1, 1), Vec3(-1, 1, 1)};
    for (auto& v : r) v.normalize();
    return r;
  }();
  return d;
}

/// A k-DOP: the intersection of slabs lo[d] <= dir[d] . x <= hi[d]. It contains the convex hull
/// of the points it was made from, hence (Bézier convex hull property) the chunk they control.
struct Dop {
  std::array<Vec3, max_directions> dir;
  std::array<double, max_directions> lo{}, hi{};
  int count = 0;

  bool contains(const Vec3& x) const noexcept {
    for (int d = 0; d < count; ++d) {
      const double v = dir[static_cast<size_t>(d)].dot(x);
      if (!(v >= lo[static_cast<size_t>(d)] && v <= hi[static_cast<size_t>(d)])) return false;
    }
    return true;
  }
};

Dop make_dop(const Ctrl& P, double margin) {
  Dop dop;
  for (const Vec3& d : dop_directions()) dop.dir[static_cast<size_t>(dop.count++)] = d;
  // The chunk's own face normals from its mean edge vectors (any direction keeps the k-DOP a
  // superset of the hull; these make it tight for skewed chunks).
  Vec3 e[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      e[0] += P[static_cast<size_t>(48 + a * 4 + b)] - P[static_cast<size_t>(a * 4 + b)];
      e[1] += P[static_cast<size_t>(a * 16 + 12 + b)] - P[static_cast<size_t>(a * 16 + b)];
      e[2] += P[static_cast<size_t>(a * 16 + b * 4 + 3)] - P[static_cast<size_t>(a * 16 + b * 4)];
    }
  for (int d = 0; d < 3; ++d) {
    const Vec3 n = e[(d + 1) % 3].cross(e[(d + 2) % 3]);
    const double len = n.norm();
    if (len > 1e-9 * e[(d + 1) % 3].norm() * e[(d + 2) % 3].norm() && std::isfinite(len))
      dop.dir[static_cast<size_t>(dop.count++)] = n / len;
  }
  for (int d = 0; d < dop.count; ++d) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec3& p : P) {
      const double v = dop.dir[static_cast<size_t>(d)].dot(p);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    dop.lo[static_cast<size_t>(d)] = lo - margin;
    dop.hi[static_cast<size_t>(d)] = hi + margin;
  }
  return dop;
}

// ---- prepared chunks and the candidate grid
// -------------------------------------------------------

struct ChunkData {
  Ctrl ctrl;      // rest control points relative to `centre`
  Vec3 centre;    // centre of the control points' bounding box
  Vec3 lo, hi;    // bounding box of the control points with the margin (absolute)
  double size;    // bounding box diagonal (mm)
  double margin;  // hull tests accept points this close to the hull (mm)
  Dop dop;
};

struct Grid {
  Vec3 lo = Vec3::Zero(), inverse_cell = Vec3::Zero();
  std::array<int, 3> n{1, 1, 1};
  std::vector<int> start;  // CSR: chunks of cell c are items[start[c] .. start[c + 1])
  std::vector<int> items;

  /// Cell of x, or -1 outside the grid.
  int cell(const Vec3& x) const noexcept {
    int c = 0;
    for (int d = 0; d < 3; ++d) {
      const int nd = n[static_cast<size_t>(d)];
      const double f = (x[d] - lo[d]) * inverse_cell[d];
      if (!(f >= 0 && f <= nd)) return -1;  // NaN too
      c = c * nd + std::min(static_cast<int>(f), nd - 1);
    }
    return c;
  }
};

struct Prepared {
  std::vector<ChunkData> chunks;
  Grid grid;
};

Prepared prepare(const ExtendedLattice& lattice, const FreezeOptions& options) {
  Prepared prep;
  prep.chunks.resize(lattice.chunks.size());
  Vec3 all_lo = Vec3::Constant(std::numeric_limits<double>::infinity()), all_hi = -all_lo;
  for (size_t c = 0; c < lattice.chunks.size(); ++c) {
    ChunkData& cd = prep.chunks[c];
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int r = 0; r < chunk_control_points; ++r) {
      const Vec3 p = lattice.rest.row(lattice.chunks[c][static_cast<size_t>(r)]).transpose();
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    cd.centre = 0.5 * (lo + hi);
    cd.size = (hi - lo).norm();
    cd.margin = (8 * options.parameter_tolerance + 1e-12) * cd.size;
    cd.lo = lo - Vec3::Constant(cd.margin);
    cd.hi = hi + Vec3::Constant(cd.margin);
    for (int r = 0; r < chunk_control_points; ++r)
      cd.ctrl[static_cast<size_t>(r)] =
          lattice.rest.row(lattice.chunks[c][static_cast<size_t>(r)]).transpose() - cd.centre;
    cd.dop = make_dop(cd.ctrl, cd.margin);
    all_lo = all_lo.cwiseMin(cd.lo);
    all_hi = all_hi.cwiseMax(cd.hi);
  }
  // A uniform grid of about (2 cbrt(chunks))^3 cells over the lattice's bounding box.
  Grid& g = prep.grid;
  const Vec3 extent = all_hi - all_lo;
  const double largest = extent.maxCoeff();
  const double k = std::ceil(2 * std::cbrt(static_cast<double>(lattice.chunks.size())));
  g.lo = all_lo;
  for (int d = 0; d < 3; ++d) {
    g.n[static_cast<size_t>(d)] =
        std::clamp(static_cast<int>(std::ceil(k * extent[d] / largest)), 1, 64);
    g.inverse_cell[d] = g.n[static_cast<size_t>(d)] / extent[d];
  }
  const int cells = g.n[0] * g.n[1] * g.n[2];
  std::vector<std::vector<int>> lists(static_cast<size_t>(cells));
  for (size_t c = 0; c < prep.chunks.size(); ++c) {
    std::array<int, 3> a{}, b{};
    for (int d = 0; d < 3; ++d) {
      const int n = g.n[static_cast<size_t>(d)];
      a[static_cast<size_t>(d)] = std::clamp(
          static_cast<int>((prep.chunks[c].lo[d] - g.lo[d]) * g.inverse_cell[d]), 0, n - 1);
      b[static_cast<size_t>(d)] = std::clamp(
          static_cast<int>((prep.chunks[c].hi[d] - g.lo[d]) * g.inverse_cell[d]), 0, n - 1);
    }
    for (int x = a[0]; x <= b[0]; ++x)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int z = a[2]; z <= b[2]; ++z)
          lists[static_cast<size_t>((x * g.n[1] + y) * g.n[2] + z)].push_back(static_cast<int>(c));
  }
  g.start.assign(static_cast<size_t>(cells) + 1, 0);
  for (int c = 0; c < cells; ++c)
    g.start[static_cast<size_t>(c) + 1] =
        g.start[static_cast<size_t>(c)] + static_cast<int>(lists[static_cast<size_t>(c)].size());
  g.items.reserve(static_cast<size_t>(g.start.back()));
  for (const auto& l : lists) g.items.insert(g.items.end(), l.begin(), l.end());
  return prep;
}

// ---- Newton's method (Coquillart §3.3)
// ---------------------------------------------------------------

struct Counters {
  Eigen::Index inside = 0, outside = 0, unresolved = 0, subdivided = 0, splits = 0, pseudo = 0;
  long long iterations = 0;
  double worst_residual = 0, worst_initial = 0;
};

struct NewtonRun {
  bool converged = false;
  Vec3 q = Vec3::Zero();
  double residual = 0, initial = 0;
};

/// Solves L(q) = x (x relative to the chunk centre) from `q`: Newton steps with the inverse
/// Jacobian, or the Moore–Penrose pseudo-inverse where the Jacobian is (nearly) singular (Lukács,
/// as Coquillart §3.3 proposes). Fails on divergence (q leaves [-1, 2]^3), on a stall of
/// pseudo-inverse steps, or at the iteration limit.
NewtonRun newton(const ChunkData& cd, const Vec3& x, Vec3 q, const FreezeOptions& o,
                 Counters& count) {
  NewtonRun run;
  const double tol = o.newton_tolerance * cd.size;
  const double cutoff = std::max(o.pseudo_inverse_threshold, 1e-15);
  Vec3 F;
  Eigen::Matrix3d J;
  // The Newton step -J^-1 r, or -J+ r when J is (nearly) singular; false when J = 0.
  auto step_of = [&](const Vec3& r, Vec3& step, bool& pseudo) {
    const double scale = std::max({J.col(0).norm(), J.col(1).norm(), J.col(2).norm()});
    if (!(scale > 0)) return false;  // the map is locally constant: nothing to follow
    pseudo = !(std::abs(J.determinant()) > o.pseudo_inverse_threshold * scale * scale * scale);
    if (!pseudo) {
      step = J.partialPivLu().solve(-r);
      return true;
    }
    // Moore–Penrose: J+ = V diag(1 / sigma_i) U^T over the singular values above cutoff x the
    // largest; the others (the collapsed directions) take no step.
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(J, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Vec3 sigma = svd.singularValues();
    Vec3 c = svd.matrixU().transpose() * (-r);
    for (int d = 0; d < 3; ++d) c[d] = sigma[d] > cutoff * sigma[0] ? c[d] / sigma[d] : 0.0;
    step = svd.matrixV() * c;
    ++count.pseudo;
    return true;
  };
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    evaluate_with_jacobian(cd.ctrl, q, F, J);
    const Vec3 r = F - x;
    const double rn = r.norm();
    if (it == 0) run.initial = rn;
    run.q = q;
    run.residual = rn;
    if (!std::isfinite(rn)) return run;
    Vec3 step;
    bool pseudo = false;
    if (rn <= tol) {
      run.converged = true;
      // One more step takes a quadratically converging run from just below the tolerance down
      // to rounding (kept only when it helps), so the rest shape reproduces x to ~1e-15.
      if (rn > 1e-3 * tol && step_of(r, step, pseudo)) {
        ++count.iterations;
        const Vec3 polished = q + step;
        Eigen::Matrix3d unused;
        evaluate_with_jacobian(cd.ctrl, polished, F, unused);
        const double pn = (F - x).norm();
        if (pn < rn) {
          run.q = polished;
          run.residual = pn;
        }
      }
      return run;
    }
    if (it == o.max_iterations) return run;
    ++count.iterations;
    if (!step_of(r, step, pseudo)) return run;
    if (pseudo && rn >= 0.999 * previous)
      return run;  // the pseudo-inverse cannot reduce it further
    previous = rn;
    q += step;
    for (int d = 0; d < 3; ++d)
      if (!(q[d] >= -1.0 && q[d] <= 2.0)) return run;  // diverging (or NaN)
  }
}

bool in_unit_cube(const Vec3& q, double tol) {
  for (int d = 0; d < 3; ++d)
    if (!(q[d] >= -tol && q[d] <= 1 + tol)) return false;
  return true;
}

enum class Outcome { inside, outside, unresolved };

/// Splits `ctrl` (the control points of the sub-chunk [lo, lo + width]^3 of cd) into eight and
/// runs Newton from the centre of each child whose k-DOP holds x, recursively.
Outcome subdivide(const ChunkData& cd, const Ctrl& ctrl, const Vec3& lo, double width, int depth,
                  const Vec3& x, const FreezeOptions& o, Counters& count, NewtonRun& found) {
  ++count.splits;
  bool unresolved = false;
  const double half = 0.5 * width;
  for (int a = 0; a < 2; ++a) {
    const Ctrl ca = halve(ctrl, 0, a == 1);
    for (int b = 0; b < 2; ++b) {
      const Ctrl cb = halve(ca, 1, b == 1);
      for (int c = 0; c < 2; ++c) {
        const Ctrl child = halve(cb, 2, c == 1);
        if (!make_dop(child, cd.margin).contains(x)) continue;
        const Vec3 child_lo = lo + half * Vec3(a, b, c);
        // Newton on the whole chunk from the child's centre: the same iterates as on the
        // reparametrised child (Newton is affine invariant), and any root in [0, 1]^3 counts.
        const NewtonRun run = newton(cd, x, child_lo + Vec3::Constant(0.5 * half), o, count);
        if (run.converged) {
          if (in_unit_cube(run.q, o.parameter_tolerance)) {
            found = run;
            return Outcome::inside;
          }
          continue;
        }
        if (depth >= o.max_subdivision_depth) {
          unresolved = true;
          continue;
        }
        const Outcome inner = subdivide(cd, child, child_lo, half, depth + 1, x, o, count, found);
        if (inner == Outcome::inside) return inner;
        if (inner == Outcome::unresolved) unresolved = true;
      }
    }
  }
  return unresolved ? Outcome::unresolved : Outcome::outside;
}

/// Coquillart §3.3 for one point: candidates by the grid and the k-DOP, Newton from
/// (0.5, 0.5, 0.5), then subdivision of the chunks where Newton failed.
FrozenPoint locate(const Prepared& prep, const Vec3& x, const FreezeOptions& o, Counters& count) {
  FrozenPoint out;
  const int cell = prep.grid.cell(x);
  if (cell < 0) {
    ++count.outside;
    return out;
  }
  int failed[64];
  int failures = 0;
  bool overflow = false;
  auto accept = [&](int chunk, const NewtonRun& run) {
    out.chunk = chunk;
    out.uvw = run.q;
    ++count.inside;
    count.worst_residual = std::max(count.worst_residual, run.residual);
    count.worst_initial = std::max(count.worst_initial, run.initial);
  };
  for (int i = prep.grid.start[static_cast<size_t>(cell)];
       i < prep.grid.start[static_cast<size_t>(cell) + 1]; ++i) {
    const int c = prep.grid.items[static_cast<size_t>(i)];
    const ChunkData& cd = prep.chunks[static_cast<size_t>(c)];
    if (!((x.array() >= cd.lo.array()).all() && (x.array() <= cd.hi.array()).all())) continue;
    const Vec3 xr = x - cd.centre;
    if (!cd.dop.contains(xr)) continue;
    const NewtonRun run = newton(cd, xr, Vec3::Constant(0.5), o, count);
    if (run.converged) {
      if (in_unit_cube(run.q, o.parameter_tolerance)) {
        accept(c, run);
        return out;
      }
      continue;  // the root lies outside this chunk
    }
    if (failures < 64)
      failed[failures++] = c;
    else
      overflow = true;
  }
  bool unresolved = overflow;
  for (int f = 0; f < failures; ++f) {
    const ChunkData& cd = prep.chunks[static_cast<size_t>(failed[f])];
    NewtonRun found;
    const Outcome r = o.max_subdivision_depth > 0 ? subdivide(cd, cd.ctrl, Vec3::Zero(), 1.0, 1,
                                                              x - cd.centre, o, count, found)
                                                  : Outcome::unresolved;
    if (r == Outcome::inside) {
      accept(failed[f], found);
      ++count.subdivided;
      return out;
    }
    if (r == Outcome::unresolved) unresolved = true;
  }
  if (unresolved) {
    out.chunk = unresolved_chunk;
    ++count.unresolved;
  } else {
    ++count.outside;
  }
  return out;
}

/// Runs work(begin, end, part) on `threads` contiguous ranges of [0, n), on `executor`.
template <class Work>
void parallel(std::size_t n, std::size_t threads, const Executor& executor, Work&& work) {
  internal::run_parts(threads, executor, [&](std::size_t part) {
    work(n * part / threads, n * (part + 1) / threads, part);
  });
}

}  // namespace

Eigen::Vector3d chunk_point(const Points3& control, const Chunk& chunk,
                            const Eigen::Vector3d& uvw) {
  // Coquillart eq. (1).
  double bu[4], du[4], bv[4], dv[4], bw[4], dw[4];
  bernstein(uvw[0], bu, du);
  bernstein(uvw[1], bv, dv);
  bernstein(uvw[2], bw, dw);
  Vec3 x = Vec3::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      Vec3 s = Vec3::Zero();
      for (int k = 0; k < 4; ++k)
        s += bw[k] * control.row(chunk[static_cast<size_t>((i * 4 + j) * 4 + k)]).transpose();
      x += (bu[i] * bv[j]) * s;
    }
  return x;
}

// ---- freezing and deformation
// ----------------------------------------------------------------------------

std::vector<std::string> FreezeOptions::problems() const {
  std::vector<std::string> out;
  auto bad = [&out](const std::string& field, const std::string& value, const std::string& rule) {
    out.push_back(field + " = " + value + " breaks the rule " + rule);
  };
  if (!(newton_tolerance > 0 && newton_tolerance <= 1e-3))
    bad("FreezeOptions::newton_tolerance", format(newton_tolerance),
        "0 < newton_tolerance <= 1e-3 (relative to the chunk size)");
  if (!(parameter_tolerance >= 0 && parameter_tolerance <= 1e-3))
    bad("FreezeOptions::parameter_tolerance", format(parameter_tolerance),
        "0 <= parameter_tolerance <= 1e-3");
  if (!(pseudo_inverse_threshold >= 0 && pseudo_inverse_threshold <= 1e-3))
    bad("FreezeOptions::pseudo_inverse_threshold", format(pseudo_inverse_threshold),
        "0 <= pseudo_inverse_threshold <= 1e-3");
  if (max_iterations < 1 || max_iterations > 1000)
    bad("FreezeOptions::max_iterations", std::to_string(max_iterations),
        "1 <= max_iterations <= 1000");
  if (max_subdivision_depth < 0 || max_subdivision_depth > 10)
    bad("FreezeOptions::max_subdivision_depth", std::to_string(max_subdivision_depth),
        "0 <= max_subdivision_depth <= 10");
  if (threads < 0 || threads > 1024)
    bad("FreezeOptions::threads", std::to_string(threads),
        "0 <= threads <= 1024 (0 = one per hardware thread)");
  return out;
}

void FreezeOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string FreezeReport::brief() const {
  char buffer[320];
  std::snprintf(buffer, sizeof buffer,
                "frozen %lld points: %lld inside, %lld outside, %lld unresolved; %lld found after "
                "subdivision (%lld splits), %lld pseudo-inverse steps, %d Newton iterations, worst "
                "residual %.3g mm",
                static_cast<long long>(inside + outside + unresolved),
                static_cast<long long>(inside), static_cast<long long>(outside),
                static_cast<long long>(unresolved), static_cast<long long>(subdivided),
                static_cast<long long>(splits), static_cast<long long>(pseudo_inverse_steps),
                summary.iterations, summary.final_residual);
  return buffer;
}

FrozenPoints freeze(const ExtendedLattice& lattice, const Points3& points,
                    const FreezeOptions& options) {
  options.validate();
  validate(lattice);
  for (Eigen::Index r = 0; r < points.rows(); ++r)
    if (!all_finite(points.row(r)))
      throw Error(ErrorCategory::InvalidGeometry,
                  "freeze: point row " + std::to_string(r) + " is not finite " +
                      format(Vec3(points.row(r).transpose())) + "; give finite coordinates");
  const Prepared prep = prepare(lattice, options);
  FrozenPoints out;
  const std::size_t n = static_cast<std::size_t>(points.rows());
  out.points.resize(n);
  out.positions = points;
  out.control_points = lattice.rest.rows();
  out.chunks = lattice.chunks.size();
  const std::size_t threads =
      internal::part_count(options.threads, n, min_freeze_points_per_thread);
  std::vector<Counters> counts(threads);
  parallel(n, threads, options.executor, [&](std::size_t b, std::size_t e, std::size_t part) {
    for (std::size_t i = b; i < e; ++i)
      out.points[i] =
          locate(prep, points.row(static_cast<Eigen::Index>(i)).transpose(), options, counts[part]);
  });
  Counters total;
  for (const Counters& c : counts) {
    total.inside += c.inside;
    total.outside += c.outside;
    total.unresolved += c.unresolved;
    total.subdivided += c.subdivided;
    total.splits += c.splits;
    total.pseudo += c.pseudo;
    total.iterations += c.iterations;
    total.worst_residual = std::max(total.worst_residual, c.worst_residual);
    total.worst_initial = std::max(total.worst_initial, c.worst_initial);
  }
  FreezeReport& s = out.report;
  s.inside = total.inside;
  s.outside = total.outside;
  s.unresolved = total.unresolved;
  s.subdivided = total.subdivided;
  s.splits = total.splits;
  s.pseudo_inverse_steps = total.pseudo;
  s.summary.termination =
      total.unresolved == 0 ? Termination::Converged : Termination::NotConverged;
  s.summary.iterations =
      static_cast<int>(std::min<long long>(total.iterations, std::numeric_limits<int>::max()));
  s.summary.initial_residual = total.worst_initial;
  s.summary.final_residual = total.worst_residual;
  s.summary.message = s.brief();
  if (total.unresolved > 0)
    s.summary.message +=
        "; unresolved points are left unchanged: raise max_iterations or "
        "max_subdivision_depth, or untangle the lattice";
  return out;
}

Points3 evaluate(const ExtendedLattice& lattice, const FrozenPoints& frozen,
                 const DeformOptions& options) {
  options.validate();
  validate(lattice);
  if (lattice.rest.rows() != frozen.control_points || lattice.chunks.size() != frozen.chunks ||
      static_cast<Eigen::Index>(frozen.points.size()) != frozen.positions.rows())
    throw Error(ErrorCategory::InvalidArgument,
                "evaluate: the points were frozen on a lattice of " +
                    std::to_string(frozen.control_points) + " control points and " +
                    std::to_string(frozen.chunks) + " chunks, this one has " +
                    std::to_string(lattice.rest.rows()) + " and " +
                    std::to_string(lattice.chunks.size()) + " (" +
                    std::to_string(frozen.points.size()) + " frozen points, " +
                    std::to_string(frozen.positions.rows()) +
                    " positions); only moving control points keeps a freeze valid: freeze again");
  const std::size_t n = frozen.points.size();
  Points3 out(static_cast<Eigen::Index>(n), 3);
  const std::size_t threads =
      internal::part_count(options.threads, n, min_evaluate_points_per_thread);
  parallel(n, threads, options.executor, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t i = b; i < e; ++i) {
      const FrozenPoint& f = frozen.points[i];
      const auto r = static_cast<Eigen::Index>(i);
      if (f.chunk >= 0 && static_cast<std::size_t>(f.chunk) < lattice.chunks.size())
        out.row(r) =
            chunk_point(lattice.points, lattice.chunks[static_cast<std::size_t>(f.chunk)], f.uvw)
                .transpose();
      else
        out.row(r) = frozen.positions.row(r);
    }
  });
  return out;
}

Eigen::Vector3d deform_point(const ExtendedLattice& lattice, const Eigen::Vector3d& x) {
  FreezeOptions o;
  o.threads = 1;
  const Points3 p = x.transpose();
  return evaluate(lattice, freeze(lattice, p, o), DeformOptions{1}).row(0).transpose();
}

namespace detail {

std::function<Eigen::Vector3d(const Eigen::Vector3d&)> prepared_point_map(
    const ExtendedLattice& lattice) {
  validate(lattice);
  FreezeOptions o;  // as deform_point: default options, one thread
  o.threads = 1;
  auto data =
      std::make_shared<const std::pair<ExtendedLattice, Prepared>>(lattice, prepare(lattice, o));
  return [data, o](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    if (!internal::all_finite(x))
      throw Error(ErrorCategory::InvalidGeometry,
                  "freeze: point row 0 is not finite " + format(x) + "; give finite coordinates");
    Counters count;
    const FrozenPoint f = locate(data->second, x, o, count);
    if (f.chunk < 0) return x;
    return chunk_point(data->first.points, data->first.chunks[static_cast<std::size_t>(f.chunk)],
                       f.uvw);
  };
}

}  // namespace detail

Points3 deform_points(const ExtendedLattice& lattice, const Points3& points,
                      const DeformOptions& options) {
  options.validate();
  FreezeOptions o;
  o.threads = options.threads;
  return evaluate(lattice, freeze(lattice, points, o), options);
}
}  // namespace clay::deform
