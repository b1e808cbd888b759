#pragma once
// Quadrature over a face's trimmed domain, shared by the volume (volume.cpp) and the mass
// properties with their gradients (mass_properties.cpp): Gauss–Legendre rules, the adaptive rule
// with its budget, knot breaks, a pcurve's crossings of knot lines, and the reference point and
// scale of the divergence-theorem fields. Private to clay_brep.
#include <clay/brep/model.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace clay::brep::detail {

/// The n-point Gauss–Legendre rule, n in [1, 64], computed once.
const internal::GaussRule& rule(int n);

/// The integral of f over [a, b] by n-point Gauss–Legendre (exact for degree 2n - 1).
template <class F>
double gauss(int n, double a, double b, F&& f) {
  const auto& r = rule(n);
  double sum = 0;
  for (std::size_t g = 0; g < r.nodes.size(); ++g)
    sum += r.weights[g] * f(0.5 * (a + b) + 0.5 * (b - a) * r.nodes[g]);
  return 0.5 * (b - a) * sum;
}

/// What one face's adaptive integration may spend, and whether it converged. A 7 KB IGES file
/// with one weight of 1e6 ran the unbounded recursion for ever: once the halved tolerance fell
/// below rounding, every branch descended to the depth cap, 2^40 times (issue #36).
struct Budget {
  long intervals = 0;  // subdivisions still allowed on this face
  bool converged = true;
};

/// Adaptive: accepts [a, b] when the 16- and 10-point rules agree to `tol` (absolute; both exact
/// to degree 19, so agreement means the integrand is resolved), or to the rounding of the rule
/// itself (32 ulps of ∫|f| over the interval: a tolerance below that can never be met), else
/// halves the interval. Past the depth cap or the budget the interval is accepted unconverged.
template <class F>
double adaptive(double a, double b, F&& f, double tol, Budget& budget, int depth = 0) {
  const auto& r = rule(16);
  double fine = 0, magnitude = 0;
  for (std::size_t g = 0; g < r.nodes.size(); ++g) {
    const double y = r.weights[g] * f(0.5 * (a + b) + 0.5 * (b - a) * r.nodes[g]);
    fine += y;
    magnitude += std::abs(y);
  }
  fine *= 0.5 * (b - a);
  magnitude *= 0.5 * std::abs(b - a);
  const double gap = std::abs(fine - gauss(10, a, b, f));
  if (!std::isfinite(fine)) {
    budget.converged = false;
    return fine;
  }
  if (gap <= tol || gap <= 32 * std::numeric_limits<double>::epsilon() * magnitude) return fine;
  if (depth >= 40 || --budget.intervals < 0) {
    budget.converged = false;
    return fine;
  }
  const double m = 0.5 * (a + b);
  return adaptive(a, m, f, 0.5 * tol, budget, depth + 1) +
         adaptive(m, b, f, 0.5 * tol, budget, depth + 1);
}

/// A quadrature node of a face's trimmed domain: ∬_D f du dv ≈ Σ w f(u, v).
struct Node {
  double u, v, w;
};

/// detail::adaptive on a vector of integrals at once (V a fixed-size Eigen vector): [a, b] is
/// accepted when the 16- and 10-point rules agree to tol (per entry) or to their own rounding, else
/// halved. f(x, rec) gives the integrand at x and appends the nodes it used (weights per unit of x)
/// to rec when rec is not null; the nodes of an accepted interval's 16-point rule are appended to
/// `record`, weighted by the rule. `gaps`, when given, gathers each accepted interval's
/// max(|16-point − 10-point|, rounding): the a posteriori error bound of the coarser rule (the sum
/// returned is the finer one's), as QUADPACK's estimates.
template <class V, class F>
V adaptive_vector(double a, double b, F&& f, const V& tol, Budget& budget,
                  std::vector<Node>& record, V* gaps = nullptr, int depth = 0) {
  const auto& r16 = rule(16);
  const auto& r10 = rule(10);
  const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
  V fine = V::Zero(), magnitude = V::Zero(), coarse = V::Zero();
  std::vector<Node> mine;
  for (std::size_t g = 0; g < r16.nodes.size(); ++g) {
    const std::size_t first = mine.size();
    const V y = r16.weights[g] * f(mid + half * r16.nodes[g], &mine);
    for (std::size_t k = first; k < mine.size(); ++k) mine[k].w *= r16.weights[g] * half;
    fine += y;
    magnitude += y.cwiseAbs();
  }
  for (std::size_t g = 0; g < r10.nodes.size(); ++g)
    coarse += r10.weights[g] * f(mid + half * r10.nodes[g], nullptr);
  fine *= half;
  coarse *= half;
  magnitude *= std::abs(half);
  const V gap = (fine - coarse).cwiseAbs();
  const V rounding = 32 * std::numeric_limits<double>::epsilon() * magnitude;
  bool resolved = fine.allFinite();
  for (int k = 0; k < V::RowsAtCompileTime && resolved; ++k)
    resolved = gap[k] <= tol[k] || gap[k] <= rounding[k];
  if (!fine.allFinite() || (!resolved && (depth >= 40 || --budget.intervals < 0))) {
    budget.converged = false;
    resolved = true;
  }
  if (resolved) {
    record.insert(record.end(), mine.begin(), mine.end());
    if (gaps) *gaps += gap.cwiseMax(rounding);
    return fine;
  }
  return adaptive_vector(a, mid, f, V(tol / 2), budget, record, gaps, depth + 1) +
         adaptive_vector(mid, b, f, V(tol / 2), budget, record, gaps, depth + 1);
}

/// The distinct knots of a basis strictly inside (a, b), with a and b around them.
std::vector<double> breaks(const surface::BSplineBasis& basis, double a, double b);

/// `pieces` (a pcurve's parameters, increasing) with the parameters added where the pcurve
/// crosses a knot of the surface's v basis. The loop integrand z (x_u y_v − x_v y_u) v'(t) is
/// only as smooth as the surface in v: at a C0 knot line (Alias's fillets carry triple knots in a
/// cubic v) it jumps, and an adaptive rule halving the tolerance with the interval can never meet
/// it there (issue #39: Alias's k1 key was refused). Crossings are bracketed by 32 samples per
/// piece and bisected to rounding; a pcurve that only touches a knot line keeps a kink, not a
/// jump.
std::vector<double> with_knot_crossings(const surface::BSplineCurve& pcurve,
                                        const std::vector<double>& pieces,
                                        const surface::BSplineBasis& v_basis, double t_lo,
                                        double t_hi);

/// A face's budget: 200,000 subdivisions and 1,000 more per knot span (the real files of
/// tests/data/cad need at most about 42,000 on a face; a weight of 1e6 takes all of them, about
/// 3 s).
long face_budget(const surface::BSplineSurface& s);

/// The cube of the diagonal of the model's control points: the scale of volume tolerances.
double size_cubed(const Model& m);

/// A surface along u at a fixed v: the homogeneous isocurve at v and its v derivative, made once
/// for the control rows [lo, hi] uses, so each point sums p + 1 of them instead of (p + 1)(q + 1)
/// control points with both bases (surface::derivatives' own sums, in its order: the same
/// numbers). The volume integration spent three quarters of reading a real file in the full sums.
class Isocurve {
 public:
  /// The isocurve of `s` at v (clamped to the domain) for u in [lo, hi].
  Isocurve(const surface::BSplineSurface& s, double v, double lo, double hi);

  /// A point of the isocurve: the surface's point and first derivatives, the weight function W
  /// and its derivatives, the u span and the u basis (N_i at 0..p, N_i' at p + 1..2p + 1).
  struct Point {
    Eigen::Vector3d point, du, dv;
    double weight = 1, weight_u = 0, weight_v = 0;
    int span = 0;
    std::array<double, 2 * (surface::max_kernel_degree + 1)> basis{};
  };
  /// The point at u in [lo, hi] (clamped to the domain).
  void at(double u, Point& out) const;
  /// The point and its first derivatives only.
  void at(double u, Eigen::Vector3d& point, Eigen::Vector3d& du, Eigen::Vector3d& dv) const;

 private:
  const surface::BSplineSurface& s_;
  int row0_ = 0;
  std::vector<Eigen::Vector4d> rows_;  // per control row: the isocurve's point, its v derivative
};

/// The derivative of a face integral Σ_nodes w F(X, X_u, X_v) (N integrals at once) with respect
/// to the face's control points, weights held: P_k -> P_k + e moves a node's term by
/// R_k e·a + R_k,u e·b + R_k,v e·c, where `terms(at, w, a, b, c)` gives the rows a, b, c (N x 3,
/// the node's weight w included) at the node's point `at`. With R_k = w_k N_i N_j / W that is
/// w_k [N_j (N_i A + N_i' B) + N_j' N_i C], A = (a − (W_u b + W_v c) / W) / W, B = b / W,
/// C = c / W. The nodes of one inner integral share v, so N_j(v) too: the sums over i are made per
/// control row along the line, then spread over j once per line ((p + 1) work per node, not
/// (p + 1)(q + 1): NX 9's B-spline sphere under a (2, 2, 2) lattice, 117 -> 26 s). Nodes must come
/// grouped by v, as the inner integrals record them. Returns one n x 3 matrix per integral.
template <int N, class Terms>
std::array<Eigen::MatrixX3d, N> control_point_gradients(const surface::BSplineSurface& s,
                                                        const std::vector<Node>& nodes,
                                                        Terms&& terms) {
  using Block = Eigen::Matrix<double, N, 3>;
  std::array<Eigen::MatrixX3d, N> out;
  for (auto& g : out) g = Eigen::MatrixX3d::Zero(s.points.rows(), 3);
  const int p = s.u.degree, q = s.v.degree;
  std::vector<Block> along(static_cast<std::size_t>(s.count_u()), Block::Zero());
  std::vector<Block> across(static_cast<std::size_t>(s.count_u()), Block::Zero());
  std::array<double, 2 * (surface::max_kernel_degree + 1)> nv{};
  Isocurve::Point at;
  const double u0 = s.u.domain().first, u1 = s.u.domain().second;
  for (std::size_t first = 0; first < nodes.size();) {
    const double v = nodes[first].v;
    std::size_t last = first;
    double lo = nodes[first].u, hi = lo;
    for (; last < nodes.size() && nodes[last].v == v; ++last) {
      lo = std::min(lo, nodes[last].u);
      hi = std::max(hi, nodes[last].u);
    }
    const Isocurve iso(s, v, std::clamp(lo, u0, u1), std::clamp(hi, u0, u1));
    int row_lo = s.count_u(), row_hi = -1;
    for (std::size_t k = first; k < last; ++k) {
      iso.at(nodes[k].u, at);
      Block a, b, c;
      terms(at, nodes[k].w, a, b, c);
      const double weight = at.weight;
      const Block big_a = (a - (at.weight_u * b + at.weight_v * c) / weight) / weight;
      const Block big_b = b / weight, big_c = c / weight;
      for (int i = 0; i <= p; ++i) {
        const int row = at.span - p + i;
        const auto r2 = static_cast<std::size_t>(row);
        const double ni = at.basis[static_cast<std::size_t>(i)];
        const double di = at.basis[static_cast<std::size_t>(p + 1 + i)];
        along[r2] += ni * big_a + di * big_b;
        across[r2] += ni * big_c;
        row_lo = std::min(row_lo, row);
        row_hi = std::max(row_hi, row);
      }
    }
    const double vc = std::clamp(v, s.v.domain().first, s.v.domain().second);
    const int sv = surface::find_span(s.v, vc);
    surface::basis_derivatives(s.v, sv, vc, 1, nv);
    for (int row = row_lo; row <= row_hi; ++row) {
      const auto r2 = static_cast<std::size_t>(row);
      for (int j = 0; j <= q; ++j) {
        const Eigen::Index k = s.index(row, sv - q + j);
        const Block g = s.weights[k] * (nv[static_cast<std::size_t>(j)] * along[r2] +
                                        nv[static_cast<std::size_t>(q + 1 + j)] * across[r2]);
        for (int m = 0; m < N; ++m) out[static_cast<std::size_t>(m)].row(k) += g.row(m);
      }
      along[r2].setZero();
      across[r2].setZero();
    }
    first = last;
  }
  return out;
}

/// The points whose mean is body_centre: the vertices the bodies' faces' edges end at (each
/// once), or, when there are none, every control point of the bodies' faces (`faces`).
struct CentrePoints {
  std::vector<int> vertices;
  std::vector<int> faces;
};
CentrePoints centre_points(const Model& m, const std::vector<int>& bodies);

/// The centre of the field (x − c) / 3 for the bodies `bodies` (indices into m.bodies): the mean of
/// the vertices its faces' edges end at (each once), else of its faces' control points (a body of
/// untrimmed closed faces). Any c gives the same volume on a watertight shell; on a real file's
/// shell with gaps (up to its edge tolerances) the figure is the flux through the faces only, and a
/// c that moves with the model keeps it covariant: an affine map x -> A x + b maps the vertices'
/// mean to A c + b, so it multiplies the figure by det A exactly. The field (0, 0, z) of the first
/// version was not: NX 9's gappy bracket, stretched, was 6.5e-5 off det A x V (issue #39). Near the
/// body, c also keeps the gaps' lever arm short.
Eigen::Vector3d body_centre(const Model& m, const std::vector<int>& bodies);

}  // namespace clay::brep::detail
