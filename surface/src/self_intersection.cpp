// Self-intersection of a curve: Bézier pieces with convex-hull bounds, a bounding-volume tree in
// curve order with monotone runs pruned, chord-pair candidates, Newton on |C(s) - C(t)|^2.
#include <clay/surface/self_intersection.hpp>

#include <clay/error.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <clay/surface/detail/builder_tools.hpp>
#include "homogeneous.hpp"
namespace clay::surface {
namespace {

using detail::Homogeneous;

constexpr double degree = std::numbers::pi / 180.0;
/// A piece is final when its control polygon's edges lie within this angle of one axis.
constexpr double piece_cone = 15.0 * degree;
/// A run of pieces whose edges lie within this angle of one axis advances monotonically along it:
/// two of its points s apart along the curve are at least cos(80°) s ≈ 0.17 s apart in space,
/// more than the tolerance once s exceeds the arc threshold (100 tolerances).
constexpr double monotone_cone = 80.0 * degree;
constexpr double invalid_cone = std::numbers::pi;
/// Pieces of a candidate pair are halved until their edges lie within this angle of their axis.
constexpr double flat_cone = 2.0 * degree;

/// A cone of directions: unit axis and half-angle (radians); `empty` when it holds no direction
/// (a piece collapsed to a point), half = invalid_cone when no cone below 90 degrees is known.
struct Cone {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  double half = invalid_cone;
  bool empty = false;
};

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Cone merge(const Cone& a, const Cone& b) {
  if (a.empty) return b;
  if (b.empty) return a;
  Cone out;
  if (a.half >= std::numbers::pi / 2 || b.half >= std::numbers::pi / 2) return out;
  const Eigen::Vector3d sum = a.axis + b.axis;
  const double norm = sum.norm();
  if (!(norm > 1e-9)) return out;
  out.axis = sum / norm;
  out.half =
      std::max(angle_between(out.axis, a.axis) + a.half, angle_between(out.axis, b.axis) + b.half);
  return out;
}

/// One Bézier piece of the curve: its parameter range, end points (on the curve), the box of its
/// control points, the largest distance from a control point to the chord (which bounds the
/// distance from the piece to its chord: convex hull, weights > 0), its control polygon's length
/// (an upper bound of its arc length), the cone of its control polygon's edges (which holds every
/// tangent direction of the piece: a rational Bézier derivative is a positive combination of
/// forward differences of the control points).
struct Piece {
  double t0 = 0, t1 = 0;
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), p1 = Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  double chord_error = 0;
  double polygon = 0;
  double chord = 0;
  double arc = 0;  // arc length estimate (2 chord + (p - 1) polygon) / (p + 1) (Gravesen 1997)
  Cone cone;
  Homogeneous h;       // its control points, for further subdivision
  size_t segment = 0;  // index of the Bézier segment it comes from
};

Points3 cartesian(const Homogeneous& h) {
  Points3 p(h.rows(), 3);
  for (Eigen::Index i = 0; i < h.rows(); ++i) p.row(i) = h.row(i).head<3>() / h(i, 3);
  return p;
}

double distance_to_segment(const Eigen::Vector3d& x, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b) {
  const Eigen::Vector3d d = b - a;
  const double dd = d.squaredNorm();
  const double f = dd > 0 ? std::clamp((x - a).dot(d) / dd, 0.0, 1.0) : 0.0;
  return (a + f * d - x).norm();
}

Piece make_piece(const Homogeneous& h, double t0, double t1, size_t segment) {
  const Points3 p = cartesian(h);
  const Eigen::Index last = p.rows() - 1;
  Piece piece;
  piece.t0 = t0;
  piece.t1 = t1;
  piece.p0 = p.row(0).transpose();
  piece.p1 = p.row(last).transpose();
  piece.h = h;
  piece.segment = segment;
  piece.lo = p.colwise().minCoeff().transpose();
  piece.hi = p.colwise().maxCoeff().transpose();
  piece.chord = (piece.p1 - piece.p0).norm();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> edges;
  for (Eigen::Index i = 0; i <= last; ++i) {
    const Eigen::Vector3d x = p.row(i).transpose();
    piece.chord_error = std::max(piece.chord_error, distance_to_segment(x, piece.p0, piece.p1));
    if (i == 0) continue;
    const Eigen::Vector3d e = x - p.row(i - 1).transpose();
    const double length = e.norm();
    piece.polygon += length;
    if (length > 0) {
      edges.push_back(e / length);
      sum += e / length;
    }
  }
  const double p_degree = static_cast<double>(last);
  piece.arc = (2.0 * piece.chord + (p_degree - 1.0) * piece.polygon) / (p_degree + 1.0);
  if (edges.empty()) {
    piece.cone.empty = true;
    piece.cone.half = 0;
  } else if (sum.norm() > 1e-9) {
    piece.cone.axis = sum.normalized();
    piece.cone.half = 0;
    for (const Eigen::Vector3d& e : edges)
      piece.cone.half = std::max(piece.cone.half, angle_between(piece.cone.axis, e));
  }
  return piece;
}

/// De Casteljau split of a Bézier segment (homogeneous rows) at its middle.
void split(const Homogeneous& h, Homogeneous& left, Homogeneous& right) {
  const Eigen::Index n = h.rows();
  Homogeneous work = h;
  left.resize(n, 4);
  right.resize(n, 4);
  left.row(0) = work.row(0);
  right.row(n - 1) = work.row(n - 1);
  for (Eigen::Index level = 1; level < n; ++level) {
    for (Eigen::Index i = 0; i < n - level; ++i)
      work.row(i) = 0.5 * (work.row(i) + work.row(i + 1));
    left.row(level) = work.row(0);
    right.row(n - 1 - level) = work.row(n - 1 - level);
  }
}

/// Pieces of one Bézier segment on [t0, t1], subdivided until each piece's edges lie within
/// piece_cone of its axis or its control polygon is shorter than `short_piece` (such a piece
/// cannot meet itself at points min_arc apart).
void subdivide(const Homogeneous& h, double t0, double t1, size_t segment, double short_piece,
               int depth, std::vector<Piece>& out) {
  Piece piece = make_piece(h, t0, t1, segment);
  if (piece.cone.half <= piece_cone || piece.polygon <= short_piece || depth >= 48) {
    out.push_back(piece);
    return;
  }
  Homogeneous left, right;
  split(h, left, right);
  const double mid = 0.5 * (t0 + t1);
  subdivide(left, t0, mid, segment, short_piece, depth + 1, out);
  subdivide(right, mid, t1, segment, short_piece, depth + 1, out);
}

/// A node of the bounding-volume tree over pieces [first, last) in curve order.
struct Node {
  int first = 0, last = 0;
  int left = -1, right = -1;  // children, -1 for a leaf (one piece)
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  Cone cone;
  bool leaf() const { return left < 0; }
};

/// Minimum over a, b in [0, 1] of |w + a u - b v| subject to lo <= k0 + kb b - ka a <= hi (the
/// arc length between the two chord points stays in the admissible band). `found` is false when
/// no (a, b) is admissible.
struct ChordMinimum {
  bool found = false;
  double a = 0, b = 0, distance = INFINITY;
  bool on_band = false;  // the minimum lies on the edge of the arc-length band
};

ChordMinimum chord_minimum(const Eigen::Vector3d& w, const Eigen::Vector3d& u,
                           const Eigen::Vector3d& v, double k0, double ka, double kb, double lo,
                           double hi) {
  // Constraints n . (a, b) <= c, each row normalized.
  struct Row {
    Eigen::Vector2d n;
    double c;
  };
  std::array<Row, 6> rows = {Row{{-1, 0}, 0}, Row{{1, 0}, 1}, Row{{0, -1}, 0}, Row{{0, 1}, 1}};
  size_t count = 4;
  auto add = [&](Eigen::Vector2d n, double c) {
    const double norm = n.norm();
    if (norm > 0)
      rows[count++] = {n / norm, c / norm};
    else if (c < 0)
      rows[count++] = {{0, 0}, -1};  // infeasible
  };
  add({ka, -kb}, k0 - lo);  // k0 + kb b - ka a >= lo
  if (std::isfinite(hi)) add({-ka, kb}, hi - k0);
  constexpr double eps = 1e-12;
  auto feasible = [&](const Eigen::Vector2d& x) {
    for (size_t i = 0; i < count; ++i)
      if (rows[i].n.dot(x) > rows[i].c + eps) return false;
    return true;
  };
  ChordMinimum best;
  auto consider = [&](const Eigen::Vector2d& x, bool band) {
    const double d = (w + x[0] * u - x[1] * v).norm();
    if (d < best.distance) best = {true, x[0], x[1], d, band};
  };
  const double uu = u.dot(u), vv = v.dot(v), uv = u.dot(v);
  const double det = uu * vv - uv * uv;
  if (det > 1e-12 * uu * vv && det > 0) {
    const Eigen::Vector2d x((uv * w.dot(v) - vv * w.dot(u)) / det,
                            (uu * w.dot(v) - uv * w.dot(u)) / det);
    if (feasible(x)) consider(x, false);
  }
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector2d n = rows[i].n;
    if (n.squaredNorm() == 0) continue;
    const Eigen::Vector2d x0 = n * rows[i].c, d(-n[1], n[0]);
    double tlo = -INFINITY, thi = INFINITY;
    bool empty = false;
    for (size_t j = 0; j < count && !empty; ++j) {
      if (j == i) continue;
      const double nd = rows[j].n.dot(d), slack = rows[j].c - rows[j].n.dot(x0);
      if (std::abs(nd) < 1e-15) {
        if (slack < -eps) empty = true;
      } else if (nd > 0) {
        thi = std::min(thi, slack / nd);
      } else {
        tlo = std::max(tlo, slack / nd);
      }
    }
    if (empty || !(tlo <= thi + eps) || !std::isfinite(tlo) || !std::isfinite(thi)) continue;
    const Eigen::Vector3d m = w + x0[0] * u - x0[1] * v, g = d[0] * u - d[1] * v;
    const double gg = g.dot(g);
    const double tau = std::clamp(gg > 0 ? -m.dot(g) / gg : tlo, tlo, std::max(tlo, thi));
    consider(x0 + tau * d, i >= 4);
  }
  return best;
}

/// Bound-constrained Newton on f(s, t) = |A(s) - B(t)|^2 / 2 from (s, t), s in [s0, s1] and t in
/// [t0, t1] (the two pieces: a start far from the minimum cannot wander off to the diagonal or to
/// another crossing), with a backtracking line search (Levenberg damping where the Hessian is not
/// positive definite). A and B are the pieces' Bézier segments, so that derivatives at a piece's
/// end are its own even where the curve has a corner there.
void refine(const BSplineCurve& ca, const BSplineCurve& cb, double s0, double s1, double t0,
            double t1, double& s, double& t) {
  auto f = [&](double x, double y) {
    return 0.5 * (evaluate(ca, x) - evaluate(cb, y)).squaredNorm();
  };
  double value = f(s, t);
  for (int iteration = 0; iteration < 50 && value > 0; ++iteration) {
    const CurveDerivatives ds = derivatives(ca, s, 2), dt = derivatives(cb, t, 2);
    const Eigen::Vector3d r = ds.point - dt.point;
    Eigen::Vector2d g(r.dot(ds.d1), -r.dot(dt.d1));
    Eigen::Matrix2d H;
    H << ds.d1.dot(ds.d1) + r.dot(ds.d2), -ds.d1.dot(dt.d1), -ds.d1.dot(dt.d1),
        dt.d1.dot(dt.d1) - r.dot(dt.d2);
    // Variables at a bound with the gradient pushing outwards stay there.
    const bool fix_s = (s <= s0 && g[0] > 0) || (s >= s1 && g[0] < 0);
    const bool fix_t = (t <= t0 && g[1] > 0) || (t >= t1 && g[1] < 0);
    if (fix_s) g[0] = 0, H.row(0).setZero(), H.col(0).setZero(), H(0, 0) = 1;
    if (fix_t) g[1] = 0, H.row(1).setZero(), H.col(1).setZero(), H(1, 1) = 1;
    if (g.squaredNorm() == 0) break;
    const double scale = std::max(std::abs(H(0, 0)) + std::abs(H(1, 1)), 1e-300);
    Eigen::Vector2d step;
    for (double damping = 0;; damping = damping == 0 ? 1e-9 * scale : 10 * damping) {
      const Eigen::Matrix2d M = H + damping * Eigen::Matrix2d::Identity();
      const Eigen::LLT<Eigen::Matrix2d> llt(M);
      if (llt.info() == Eigen::Success && M.determinant() > 0) {
        step = -llt.solve(g);
        break;
      }
      if (damping > 1e6 * scale) {
        step = -g / scale;
        break;
      }
    }
    bool improved = false;
    for (double alpha = 1.0; alpha > 1e-12; alpha *= 0.5) {
      const double ns = std::clamp(s + alpha * step[0], s0, s1),
                   nt = std::clamp(t + alpha * step[1], t0, t1);
      const double next = f(ns, nt);
      if (next < value) {
        const bool small = std::abs(ns - s) + std::abs(nt - t) <= 1e-15 * (s1 - s0 + t1 - t0);
        s = ns, t = nt, value = next;
        improved = !small;
        break;
      }
    }
    if (!improved) break;
  }
}

class Search {
 public:
  Search(const BSplineCurve& curve, double tolerance)
      : curve_(clamp(curve)), tol_(tolerance), min_arc_(self_intersection_arc_factor * tolerance) {
    segments_ = extract_bezier(curve_);
    for (size_t k = 0; k < segments_.size(); ++k) {
      const BSplineCurve& segment = segments_[k];
      const auto [t0, t1] = segment.basis.domain();
      subdivide(detail::to_homogeneous(segment.points, segment.weights), t0, t1, k, 0.5 * min_arc_,
                0, pieces_);
    }
    const size_t n = pieces_.size();
    polygon_.assign(n + 1, 0.0);
    arc_.assign(n + 1, 0.0);
    for (size_t k = 0; k < n; ++k) {
      polygon_[k + 1] = polygon_[k] + pieces_[k].polygon;
      arc_[k + 1] = arc_[k] + pieces_[k].arc;
    }
    closed_ = (pieces_.front().p0 - pieces_.back().p1).norm() <= tol_;
    nodes_.reserve(2 * n);
    build(0, static_cast<int>(n));
  }

  std::optional<CurveSelfIntersection> run() {
    if (polygon_.back() < min_arc_) return std::nullopt;  // too short to meet itself
    self(0);
    return best_;
  }

 private:
  int build(int first, int last) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.push_back({});
    Node node;
    node.first = first;
    node.last = last;
    if (last - first == 1) {
      const Piece& p = pieces_[static_cast<size_t>(first)];
      node.lo = p.lo;
      node.hi = p.hi;
      node.cone = p.cone;
    } else {
      const int mid = first + (last - first) / 2;
      node.left = build(first, mid);
      node.right = build(mid, last);
      const Node& l = nodes_[static_cast<size_t>(node.left)];
      const Node& r = nodes_[static_cast<size_t>(node.right)];
      node.lo = l.lo.cwiseMin(r.lo);
      node.hi = l.hi.cwiseMax(r.hi);
      node.cone = merge(l.cone, r.cone);
    }
    nodes_[static_cast<size_t>(index)] = node;
    return index;
  }

  double polygon_length(const Node& n) const {
    return polygon_[static_cast<size_t>(n.last)] - polygon_[static_cast<size_t>(n.first)];
  }

  bool monotone(const Cone& c) const { return c.empty || c.half < monotone_cone; }

  void self(int index) {
    const Node& n = nodes_[static_cast<size_t>(index)];
    if (n.leaf() || monotone(n.cone) || polygon_length(n) < min_arc_) return;
    // Earlier pieces first, so that the first intersection found has a small t0 and prunes the
    // rest.
    self(n.left);
    pair(n.left, n.right);
    self(n.right);
  }

  /// Pieces of node ia (earlier along the curve) against those of node ib.
  void pair(int ia, int ib) {
    const Node& A = nodes_[static_cast<size_t>(ia)];
    const Node& B = nodes_[static_cast<size_t>(ib)];
    // Only an intersection with a smaller t0 than the one found can replace it.
    if (best_ && pieces_[static_cast<size_t>(A.first)].t0 > best_->t0) return;
    // Boxes apart by more than the tolerance: no pair of points within it.
    if (((A.lo - B.hi).array() > tol_).any() || ((B.lo - A.hi).array() > tol_).any()) return;
    // Every pair of points nearer than min_arc along the curve (the shorter way when closed).
    const double total = polygon_.back();
    double farthest =
        polygon_[static_cast<size_t>(B.last)] - polygon_[static_cast<size_t>(A.first)];
    if (closed_)
      farthest = std::min(farthest, total - polygon_[static_cast<size_t>(B.first)] +
                                        polygon_[static_cast<size_t>(A.last)]);
    if (farthest < min_arc_) return;
    // Neighbours (also across the seam of a closed curve) that together advance monotonically.
    const bool adjacent = A.last == B.first ||
                          (closed_ && A.first == 0 && B.last == static_cast<int>(pieces_.size()));
    if (adjacent && monotone(merge(A.cone, B.cone))) return;
    if (A.leaf() && B.leaf()) {
      candidate(A.first, B.first);
      return;
    }
    const bool split_a = !A.leaf() && (B.leaf() || polygon_length(A) >= polygon_length(B));
    if (split_a) {
      pair(A.left, ib);
      pair(A.right, ib);
    } else {
      pair(ia, B.left);
      pair(ia, B.right);
    }
  }

  /// Arc length from the curve start to the point at t: the pieces' arc estimates, and within its
  /// piece the estimate scaled by the distance from the piece's start along its chord.
  double arc_at(double t, const Eigen::Vector3d& point) const {
    const auto it = std::upper_bound(pieces_.begin(), pieces_.end(), t,
                                     [](double x, const Piece& p) { return x < p.t0; });
    const size_t k = it == pieces_.begin() ? 0 : static_cast<size_t>(it - pieces_.begin()) - 1;
    const Piece& p = pieces_[k];
    const double along =
        p.chord > 0 ? std::clamp((point - p.p0).dot(p.p1 - p.p0) / (p.chord * p.chord), 0.0, 1.0)
                    : 0.0;
    return arc_[k] + along * p.arc;
  }

  void candidate(int ka, int kb) {
    budget_ = 4096;
    const size_t a = static_cast<size_t>(ka), b = static_cast<size_t>(kb);
    narrow(pieces_[a], arc_[a], arc_[a + 1], pieces_[b], arc_[b], arc_[b + 1], 0);
  }

  /// Piece A, at arc lengths [a0, a1] from the curve start, against the later piece B at [b0, b1].
  /// (The arc positions of a piece's halves split its own interval, so that the ends of pieces
  /// keep one position at every level and the band test stays exact where two pieces meet.)
  void narrow(const Piece& A, double a0, double a1, const Piece& B, double b0, double b1,
              int depth) {
    if (best_ && A.t0 > best_->t0) return;
    if (((A.lo - B.hi).array() > tol_).any() || ((B.lo - A.hi).array() > tol_).any()) return;
    // Chord points a, b in [0, 1]; the arc between them, ~ b0 + b (b1 - b0) - a0 - a (a1 - a0),
    // kept in the admissible band with a 10% margin: where the chords converge (a curve running
    // back along itself at a small angle) the nearest admissible points sit on the band's edge,
    // and the Newton iteration from there slides down to the trivial diagonal; the start itself
    // must then pass the test.
    const double lo = 1.1 * min_arc_;
    const double hi = closed_ ? arc_.back() - 1.1 * min_arc_ : INFINITY;
    const ChordMinimum m =
        chord_minimum(A.p0 - B.p0, A.p1 - A.p0, B.p1 - B.p0, b0 - a0, a1 - a0, b1 - b0, lo, hi);
    if (!m.found || m.distance > tol_ + A.chord_error + B.chord_error) return;
    // Curved pieces may meet where their chords do not (or not where they do): halve the more
    // curved one and look again, until both are nearly straight, where the chords' nearest points
    // are a sound start for Newton's method. Where those lie on the edge of the arc-length band
    // (the pieces meet at a sharp V near the trivial diagonal) a crossing of the two may still hide
    // beside it: halve the longer piece too. A budget per pair of pieces bounds the work where the
    // answer stays close (strands running side by side at about the tolerance).
    const bool curved = std::max(A.cone.half, B.cone.half) > flat_cone &&
                        std::max(A.polygon, B.polygon) > 1e-2 * tol_;
    if (depth < 48 && budget_ > 0 && (curved || m.on_band)) {
      --budget_;
      const bool split_a = curved ? A.cone.half >= B.cone.half : A.polygon >= B.polygon;
      const Piece& big = split_a ? A : B;
      Homogeneous left, right;
      split(big.h, left, right);
      const double mid = 0.5 * (big.t0 + big.t1);
      const Piece first = make_piece(left, big.t0, mid, big.segment);
      const Piece second = make_piece(right, mid, big.t1, big.segment);
      const double total = first.arc + second.arc;
      const double f = total > 0 ? first.arc / total : 0.5;
      if (split_a) {
        const double m0 = a0 + f * (a1 - a0);
        narrow(first, a0, m0, B, b0, b1, depth + 1);
        narrow(second, m0, a1, B, b0, b1, depth + 1);
      } else {
        const double m0 = b0 + f * (b1 - b0);
        narrow(A, a0, a1, first, b0, m0, depth + 1);
        narrow(A, a0, a1, second, m0, b1, depth + 1);
      }
      return;
    }
    const double s0 = A.t0 + m.a * (A.t1 - A.t0), t0 = B.t0 + m.b * (B.t1 - B.t0);
    double s = s0, t = t0;
    const BSplineCurve& ca = segments_[A.segment];
    const BSplineCurve& cb = segments_[B.segment];
    refine(ca, cb, A.t0, A.t1, B.t0, B.t1, s, t);
    if (!accept(ca, cb, s, t)) accept(ca, cb, s0, t0);
  }

  /// Arc length of the curve over [s, t] inside the domain (8-point Gauss–Legendre on every piece
  /// the interval meets).
  double arc_length(double s, double t) const {
    double sum = 0;
    const auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s,
                                     [](double x, const Piece& p) { return x < p.t0; });
    for (size_t k = it == pieces_.begin() ? 0 : static_cast<size_t>(it - pieces_.begin()) - 1;
         k < pieces_.size() && pieces_[k].t0 < t; ++k) {
      const double a = std::max(s, pieces_[k].t0), b = std::min(t, pieces_[k].t1);
      if (b > a)
        sum += internal::gauss_legendre_8(a, b, [&](double x) {
          return derivatives(segments_[pieces_[k].segment], x, 1).d1.norm();
        });
    }
    return sum;
  }

  /// Arc length between s < t (the shorter way round on a closed curve): estimated from the
  /// pieces, integrated where the estimate is near the threshold.
  double separation(double s, const Eigen::Vector3d& ps, double t,
                    const Eigen::Vector3d& pt) const {
    const double d = arc_at(t, pt) - arc_at(s, ps);
    const bool around = closed_ && arc_.back() - d < d;
    const double estimate = around ? arc_.back() - d : d;
    if (estimate > 4 * min_arc_) return estimate;
    const double first = pieces_.front().t0, last = pieces_.back().t1;
    return around ? arc_length(t, last) + arc_length(first, s) : arc_length(s, t);
  }

  /// Records (s, t) if the points are within the tolerance and far enough apart along the curve;
  /// A and B are the Bézier segments holding s and t.
  bool accept(const BSplineCurve& ca, const BSplineCurve& cb, double s, double t) {
    const CurveDerivatives ds = derivatives(ca, s, 1), dt = derivatives(cb, t, 1);
    const double distance = (ds.point - dt.point).norm();
    if (!(distance <= tol_)) return false;
    const double arc = separation(s, ds.point, t, dt.point);
    if (!(arc >= min_arc_)) return false;
    if (best_ && (best_->t0 < s || (best_->t0 == s && best_->t1 <= t))) return true;
    CurveSelfIntersection found;
    found.t0 = s;
    found.t1 = t;
    found.distance = distance;
    found.point = 0.5 * (ds.point + dt.point);
    found.angle_degrees =
        (ds.d1.norm() > 0 && dt.d1.norm() > 0) ? angle_between(ds.d1, dt.d1) / degree : 0.0;
    found.arc_length = arc;
    best_ = found;
    return true;
  }

  BSplineCurve curve_;
  double tol_, min_arc_;
  bool closed_ = false;
  std::vector<BSplineCurve> segments_;  // Bézier segments of curve_
  std::vector<Piece> pieces_;
  std::vector<double> polygon_, arc_;  // cumulative control-polygon lengths and arc estimates
  std::vector<Node> nodes_;
  std::optional<CurveSelfIntersection> best_;
  int budget_ = 0;  // subdivisions left for the current pair of pieces
};

}  // namespace

std::optional<CurveSelfIntersection> find_self_intersection(const BSplineCurve& curve,
                                                            double tolerance) {
  if (!(tolerance > 0.0 && std::isfinite(tolerance)))
    throw Error(ErrorCategory::InvalidArgument, "find_self_intersection: tolerance is " +
                                                    detail::short_number(tolerance) +
                                                    " mm; it must be positive and finite");
  validate(curve, "curve");
  return Search(curve, tolerance).run();
}

}  // namespace clay::surface
