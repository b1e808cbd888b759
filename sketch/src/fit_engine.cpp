#include "fit_engine.hpp"

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>

#include "curve_tools.hpp"

namespace clay::sketch::detail {
namespace {

using surface::BSplineBasis;
using surface::BSplineCurve;
using surface::Points3;

constexpr int max_width = surface::max_kernel_degree + 1;

/// Knot vector over the breakpoints 0 = b_0 < ... < b_m = 1: clamped, or periodically extended
/// (b_{j+m} = b_j + 1) so that the last `degree` control points repeat the first ones.
BSplineBasis make_basis(const std::vector<double>& breaks, int p, bool periodic) {
  BSplineBasis basis;
  basis.degree = p;
  const int m = static_cast<int>(breaks.size()) - 1;
  if (!periodic) {
    basis.knots.assign(static_cast<size_t>(p + 1), 0.0);
    for (int j = 1; j < m; ++j) basis.knots.push_back(breaks[static_cast<size_t>(j)]);
    basis.knots.insert(basis.knots.end(), static_cast<size_t>(p + 1), 1.0);
    return basis;
  }
  for (int j = -p; j <= m + p; ++j) {
    if (j < 0)
      basis.knots.push_back(breaks[static_cast<size_t>(j + m)] - 1.0);
    else if (j > m)
      basis.knots.push_back(breaks[static_cast<size_t>(j - m)] + 1.0);
    else
      basis.knots.push_back(breaks[static_cast<size_t>(j)]);
  }
  return basis;
}

/// Control point i = constant + sum of variable * direction (an affine map of the unknowns).
struct PointMap {
  struct Term {
    int variable;
    Eigen::Vector3d direction;
  };
  std::vector<Eigen::Vector3d> constant;
  std::vector<std::vector<Term>> terms;
  int variables = 0;
};

/// How an end is written in the unknowns: the fixed tangent length alpha (when known) of a
/// constrained end.
struct EndSetup {
  EndCondition condition;
  double alpha = 0;  ///< fixed |P1 - P0| along the tangent (Curvature ends, or a retry)
  bool alpha_fixed = false;
  bool curvature = false;  ///< write the curvature condition (needs alpha_fixed)
};

int fixed_count(const EndCondition& e) {
  switch (e.kind) {
    case EndKind::Point:
      return 1;
    case EndKind::Tangent:
      return 2;
    case EndKind::Curvature:
      return 3;
  }
  return 0;
}

/// First and second derivative coefficients of the basis functions at a domain end: row 1 and 2
/// of A2.3 at t = 0 (span p) or t = 1 (span n - 1).
std::array<double, 3 * max_width> end_derivatives(const BSplineBasis& basis, bool at_start) {
  std::array<double, 3 * max_width> nd{};
  const int span = at_start ? basis.degree : basis.count() - 1;
  surface::basis_derivatives(basis, span, at_start ? 0.0 : 1.0, 2, nd);
  return nd;
}

PointMap build_map(const BSplineBasis& basis, bool periodic, const EndSetup& s, const EndSetup& e) {
  const int p = basis.degree;
  const int n = basis.count();
  PointMap map;
  map.constant.assign(static_cast<size_t>(n), Eigen::Vector3d::Zero());
  map.terms.assign(static_cast<size_t>(n), {});
  auto free_point = [&](int i) {
    for (int c = 0; c < 3; ++c)
      map.terms[static_cast<size_t>(i)].push_back({map.variables + c, Eigen::Vector3d::Unit(c)});
    map.variables += 3;
  };
  if (periodic) {
    const int m = n - p;
    for (int i = 0; i < m; ++i) free_point(i);
    for (int i = m; i < n; ++i)
      map.terms[static_cast<size_t>(i)] = map.terms[static_cast<size_t>(i - m)];
    return map;
  }
  const int fs = fixed_count(s.condition);
  const int fe = fixed_count(e.condition);
  // Start: P0 (= A), P1 (= A + alpha T), P2 (curvature: affine in beta along T).
  const auto ds = end_derivatives(basis, true);
  const auto de = end_derivatives(basis, false);
  auto constrain = [&](const EndSetup& end, bool at_start) {
    const EndCondition& c = end.condition;
    const int i0 = at_start ? 0 : n - 1;
    const int i1 = at_start ? 1 : n - 2;
    const int i2 = at_start ? 2 : n - 3;
    const double sign =
        at_start ? 1.0 : -1.0;  // P1 = A + alpha T at the start, B - alpha T at the end
    map.constant[static_cast<size_t>(i0)] = c.point;
    if (c.kind == EndKind::Point) return;
    if (!end.alpha_fixed) {
      map.constant[static_cast<size_t>(i1)] = c.point;
      map.terms[static_cast<size_t>(i1)].push_back({map.variables++, sign * c.tangent});
      if (c.kind == EndKind::Curvature) free_point(i2);  // first pass of G2: P2 free
      return;
    }
    const Eigen::Vector3d p1 = c.point + sign * end.alpha * c.tangent;
    map.constant[static_cast<size_t>(i1)] = p1;
    if (!end.curvature) {
      if (c.kind == EndKind::Curvature) free_point(i2);
      return;
    }
    // C'  = d1[a] (P1 - P0) in the direction of travel; C'' = sum d2[j] P_j = beta T + mu^2 kappa.
    const auto& nd = at_start ? ds : de;
    const int w = p + 1;
    const int j0 = at_start ? 0 : p, j1 = at_start ? 1 : p - 1, j2 = at_start ? 2 : p - 2;
    const double mu = std::abs(nd[static_cast<size_t>(w + j1)]) * end.alpha;
    const double d20 = nd[static_cast<size_t>(2 * w + j0)];
    const double d21 = nd[static_cast<size_t>(2 * w + j1)];
    const double d22 = nd[static_cast<size_t>(2 * w + j2)];
    map.constant[static_cast<size_t>(i2)] =
        (mu * mu * c.curvature - d20 * c.point - d21 * p1) / d22;
    map.terms[static_cast<size_t>(i2)].push_back({map.variables++, c.tangent / d22});
  };
  constrain(s, true);
  for (int i = fs; i < n - fe; ++i) free_point(i);
  constrain(e, false);
  return map;
}

/// Banded normal matrix H (n x n, half bandwidth p) and right-hand sides b (n x 3) of the data
/// term plus lambda times the bending matrix K_ij = int N_i'' N_j'' dt.
struct Normal {
  Eigen::MatrixXd band;  ///< band(i, d) = H(i, i + d - p)
  Eigen::MatrixXd rhs;   ///< n x 3
  int p = 0;
  double at(int i, int j) const { return band(i, j - i + p); }
};

Normal assemble(const BSplineBasis& basis, const Points3& data, const std::vector<double>& t,
                double lambda, const internal::GaussRule& rule) {
  const int p = basis.degree;
  const int n = basis.count();
  Normal h;
  h.p = p;
  h.band = Eigen::MatrixXd::Zero(n, 2 * p + 1);
  h.rhs = Eigen::MatrixXd::Zero(n, 3);
  std::array<double, 3 * max_width> nd{};
  for (Eigen::Index k = 0; k < data.rows(); ++k) {
    const double tk = t[static_cast<size_t>(k)];
    const int span = surface::find_span(basis, tk);
    surface::basis_functions(basis, span, tk, nd);
    for (int a = 0; a <= p; ++a) {
      const int i = span - p + a;
      const double wa = nd[static_cast<size_t>(a)];
      h.rhs.row(i) += wa * data.row(k);
      for (int b = 0; b <= p; ++b)
        h.band(i, span - p + b - i + p) += wa * nd[static_cast<size_t>(b)];
    }
  }
  // Bending energy, exact: N_i'' N_j'' has degree 2p - 4 on a span, the rule has p >= p - 1 nodes.
  const auto breaks = surface::breakpoints(basis);
  for (size_t s = 0; s + 1 < breaks.size(); ++s) {
    const double lo = breaks[s], hi = breaks[s + 1];
    const double half = 0.5 * (hi - lo);
    for (size_t g = 0; g < rule.nodes.size(); ++g) {
      const double x = lo + half * (rule.nodes[g] + 1.0);
      const int span = surface::find_span(basis, x);
      surface::basis_derivatives(basis, span, x, 2, nd);
      const double* d2 = nd.data() + 2 * (p + 1);
      for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= p; ++b)
          h.band(span - p + a, b - a + p) += lambda * half * rule.weights[g] * d2[a] * d2[b];
    }
  }
  return h;
}

struct Solved {
  Points3 points;
  Eigen::VectorXd x;
  bool ok = false;
};

Solved solve(const Normal& h, const PointMap& map) {
  const int n = static_cast<int>(map.constant.size());
  const int p = h.p;
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(map.variables);
  for (int i = 0; i < n; ++i) {
    const auto& ti = map.terms[static_cast<size_t>(i)];
    Eigen::Vector3d r = h.rhs.row(i).transpose();
    for (int j = std::max(0, i - p); j <= std::min(n - 1, i + p); ++j) {
      const double hij = h.at(i, j);
      if (hij == 0.0) continue;
      r -= hij * map.constant[static_cast<size_t>(j)];
      for (const auto& a : ti)
        for (const auto& b : map.terms[static_cast<size_t>(j)]) {
          const double v = hij * a.direction.dot(b.direction);
          if (v != 0.0) entries.emplace_back(a.variable, b.variable, v);
        }
    }
    for (const auto& a : ti) rhs[a.variable] += a.direction.dot(r);
  }
  Eigen::SparseMatrix<double> m(map.variables, map.variables);
  m.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(m);
  Solved out;
  if (ldlt.info() != Eigen::Success) return out;
  out.x = ldlt.solve(rhs);
  if (ldlt.info() != Eigen::Success || !internal::all_finite(out.x)) return out;
  out.points.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d q = map.constant[static_cast<size_t>(i)];
    for (const auto& a : map.terms[static_cast<size_t>(i)]) q += out.x[a.variable] * a.direction;
    out.points.row(i) = q.transpose();
  }
  out.ok = true;
  return out;
}

/// Index of the tangent-length variable of an end in the first (alpha free) pass, or -1.
int alpha_variable(const PointMap& map, int point) {
  const auto& t = map.terms[static_cast<size_t>(point)];
  return t.size() == 1 ? t.front().variable : -1;
}

/// Solves for the control points under the end conditions. G1/G2 ends: a tangent length
/// alpha <= 0 would turn back (a cusp), so it is held at a small positive value; G2 takes alpha
/// from a first (G1) solution and then solves for the curvature term, which is linear once alpha
/// is known.
std::optional<Points3> solve_ends(const Normal& h, const BSplineBasis& basis, bool periodic,
                                  const PieceProblem& pr, Eigen::Index count) {
  EndSetup s{pr.start}, e{pr.end};
  PointMap map = build_map(basis, periodic, s, e);
  Solved sol = solve(h, map);
  if (!sol.ok) return std::nullopt;
  if (periodic) return sol.points;
  const int n = basis.count();
  const int p = basis.degree;
  auto constrained = [](const EndCondition& c) {
    return c.kind == EndKind::Tangent || c.kind == EndKind::Curvature;
  };
  const int vs = constrained(s.condition) ? alpha_variable(map, 1) : -1;
  const int ve = constrained(e.condition) ? alpha_variable(map, n - 2) : -1;
  // A control leg is about (domain / spans / p) x |C'|; |C'| is about the data's size.
  const double size =
      count > 1 ? (pr.data.colwise().maxCoeff() - pr.data.colwise().minCoeff()).norm() : 1.0;
  const double floor = 0.1 * std::max(size, 1e-9) / (p * std::max(1, n - p));
  bool again = false;
  auto settle = [&](EndSetup& end, int variable) {
    if (variable < 0) return;
    const double a = sol.x[variable];
    if (a >= floor && end.condition.kind != EndKind::Curvature) return;
    end.alpha = std::max(a, floor);
    end.alpha_fixed = true;
    end.curvature = end.condition.kind == EndKind::Curvature;
    again = true;
  };
  settle(s, vs);
  settle(e, ve);
  if (!again) return sol.points;
  sol = solve(h, build_map(basis, periodic, s, e));
  if (!sol.ok) return std::nullopt;
  return sol.points;
}

}  // namespace

double noise_level(const Points3& pts, bool closed) {
  // Residuals of the 7-point cubic Savitzky–Golay smoother, weights (-2 3 6 7 6 3 -2) / 21: for
  // white noise of sigma per coordinate each residual coordinate has variance (2/3) sigma^2, and
  // the median of |r| (a chi variable with 3 degrees of freedom) is 1.538 sqrt(2/3) sigma. The
  // median keeps corners and a few wild points from counting as noise.
  static constexpr double w[7] = {-2, 3, 6, 7, 6, 3, -2};
  const Eigen::Index n = pts.rows();
  if (n < 7) return 0.0;
  std::vector<double> r;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!closed && (i < 3 || i + 3 >= n)) continue;
    Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
    for (int j = -3; j <= 3; ++j) s += w[j + 3] * pts.row(((i + j) % n + n) % n);
    r.push_back((pts.row(i) - s / 21.0).norm());
  }
  if (r.empty()) return 0.0;
  const auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  return *mid / (1.538 * std::sqrt(2.0 / 3.0));
}

Points3 smoothed(const Points3& points, bool closed) {
  const Eigen::Index n = points.rows();
  Points3 s = points;
  for (int pass = 0; pass < 3 && n >= 3; ++pass) {
    Points3 next = s;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!closed && (i == 0 || i == n - 1)) continue;
      next.row(i) = 0.25 * (s.row((i + n - 1) % n) + 2.0 * s.row(i) + s.row((i + 1) % n));
    }
    s = next;
  }
  return s;
}

std::vector<double> chord_parameters(const Points3& points, bool closed) {
  const Eigen::Index n = points.rows();
  const Points3 s = smoothed(points, closed);
  std::vector<double> t(static_cast<size_t>(n), 0.0);
  double total = 0.0;
  for (Eigen::Index i = 1; i < n; ++i) {
    total += (s.row(i) - s.row(i - 1)).norm();
    t[static_cast<size_t>(i)] = total;
  }
  if (closed) total += (s.row(0) - s.row(n - 1)).norm();
  if (!(total > 0.0)) {
    // Smoothing collapsed the chords (tiny strokes): fall back to uniform parameters.
    for (Eigen::Index i = 0; i < n; ++i)
      t[static_cast<size_t>(i)] = closed ? double(i) / double(n) : double(i) / double(n - 1);
    return t;
  }
  for (double& v : t) v /= total;
  if (!closed) t.back() = 1.0;
  return t;
}

PieceResult fit_piece(const PieceProblem& pr) {
  const int p = pr.degree;
  const Eigen::Index count = pr.data.rows();
  const bool periodic = pr.periodic;
  PieceResult out;
  out.params = pr.params;
  const internal::GaussRule rule = internal::gauss_legendre(p);
  double alpha = pr.fairness;
  int reductions = 0;

  // Initial knots: the fewest spans the end conditions allow, breakpoints at data quantiles.
  const int fixed = periodic ? 0 : fixed_count(pr.start) + fixed_count(pr.end);
  const int first_count = periodic ? 2 * p : std::max(p + 1, fixed);
  const int first_spans = first_count - p;
  std::vector<double> breaks{0.0};
  {
    std::vector<double> sorted = out.params;
    std::sort(sorted.begin(), sorted.end());
    for (int j = 1; j < first_spans; ++j) {
      double q =
          sorted[static_cast<size_t>(std::min<Eigen::Index>(count - 1, count * j / first_spans))];
      if (!(q > breaks.back() + 1e-9 && q < 1.0 - 1e-9)) q = double(j) / first_spans;
      breaks.push_back(q);
    }
    breaks.push_back(1.0);
    std::sort(breaks.begin(), breaks.end());
  }
  const int max_points = std::max(pr.max_control_points, first_count);
  // A noisy stroke is judged on its residuals averaged over 2 * window + 1 neighbours: noise
  // averages out, a misfit does not. Averaged pure noise stays below about 1.5 sigma for a few
  // hundred points (3.4 sigma / 3 in the plane normal to the curve).
  out.noise = noise_level(pr.data, periodic);
  const bool noisy = out.noise > pr.tolerance_mm / 8.0;
  const int window = noisy ? 4 : 0;
  const double limit = noisy ? std::max(0.5 * pr.tolerance_mm, 1.5 * out.noise) : pr.tolerance_mm;

  BSplineCurve curve;
  Eigen::VectorXd dist = Eigen::VectorXd::Zero(count);
  bool converged = false;
  std::string why = "iteration limit reached";
  int it = 0;
  for (; it < pr.max_iterations; ++it) {
    const BSplineBasis basis = make_basis(breaks, p, periodic);
    const double lambda = alpha * static_cast<double>(count);
    // Solve, then move every parameter to its foot point (Hoschek's parameter correction); a few
    // rounds per knot vector.
    for (int round = 0; round < 4; ++round) {
      const Normal h = assemble(basis, pr.data, out.params, lambda, rule);
      std::optional<Points3> solved = solve_ends(h, basis, periodic, pr, count);
      if (!solved) {
        out.summary.termination = Termination::Failed;
        out.summary.message = "the least-squares system is singular";
        out.iterations = it + 1;
        return out;
      }
      curve.basis = basis;
      curve.points = std::move(*solved);
      curve.weights = Eigen::VectorXd::Ones(curve.points.rows());
      double moved = 0;
      for (Eigen::Index k = 0; k < count; ++k) {
        double& tk = out.params[static_cast<size_t>(k)];
        const double tn =
            surface::project_normal(curve, pr.data.row(k).transpose(), tk, periodic).t;
        moved = std::max(moved, periodic ? std::min(std::abs(tn - tk), 1.0 - std::abs(tn - tk))
                                         : std::abs(tn - tk));
        tk = tn;
      }
      if (moved < 1e-9) break;
    }
    // Residuals at the foot points and their moving average (the systematic part).
    Points3 res(count, 3);
    for (Eigen::Index k = 0; k < count; ++k) {
      res.row(k) =
          pr.data.row(k) - surface::evaluate(curve, out.params[static_cast<size_t>(k)]).transpose();
      dist[k] = res.row(k).norm();
    }
    Eigen::VectorXd score = dist;
    if (window > 0)
      for (Eigen::Index k = 0; k < count; ++k) {
        Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
        int used = 0;
        for (Eigen::Index j = k - window; j <= k + window; ++j) {
          if (!periodic && (j < 0 || j >= count)) continue;
          sum += res.row(((j % count) + count) % count);
          ++used;
        }
        score[k] = sum.norm() / used;
      }
    const double worst = dist.maxCoeff();
    if (it == 0) out.summary.initial_residual = worst;
    if (worst <= pr.tolerance_mm) {
      converged = true;
      why = "tolerance met";
      ++it;
      break;
    }
    if (noisy && score.maxCoeff() <= limit) {
      // The curve follows the stroke; what is left is noise, which a fair curve does not chase.
      converged = true;
      const auto beyond = (dist.array() > pr.tolerance_mm).count();
      std::ostringstream m;
      m.precision(3);
      m << "tolerance met by the deviation averaged over " << 2 * window + 1
        << " neighbouring points; " << beyond << (beyond == 1 ? " point lies" : " points lie")
        << " farther by the stroke's noise (about " << out.noise << " mm per coordinate)";
      why = m.str();
      ++it;
      break;
    }
    // Knot refinement (Piegl–Tiller): a knot in the span with the largest error, at the median
    // parameter of its points so that both halves keep data.
    const int m = static_cast<int>(breaks.size()) - 1;
    std::vector<double> span_score(static_cast<size_t>(m), -1.0);
    std::vector<std::vector<double>> span_params(static_cast<size_t>(m));
    for (Eigen::Index k = 0; k < count; ++k) {
      const double tk = out.params[static_cast<size_t>(k)];
      int j =
          static_cast<int>(std::upper_bound(breaks.begin(), breaks.end(), tk) - breaks.begin()) - 1;
      j = std::clamp(j, 0, m - 1);
      span_score[static_cast<size_t>(j)] = std::max(span_score[static_cast<size_t>(j)], score[k]);
      span_params[static_cast<size_t>(j)].push_back(tk);
    }
    int best = -1;
    for (int j = 0; j < m; ++j) {
      if (span_params[static_cast<size_t>(j)].size() < 2) continue;  // nothing to split
      if (best < 0 || span_score[static_cast<size_t>(j)] > span_score[static_cast<size_t>(best)])
        best = j;
    }
    const int n_now = m + (periodic ? 0 : p);
    bool refined = false;
    if (best >= 0 && span_score[static_cast<size_t>(best)] > limit && n_now < max_points) {
      auto& ts = span_params[static_cast<size_t>(best)];
      std::sort(ts.begin(), ts.end());
      const double knot = 0.5 * (ts[ts.size() / 2 - 1] + ts[ts.size() / 2]);
      const double lo = breaks[static_cast<size_t>(best)],
                   hi = breaks[static_cast<size_t>(best + 1)];
      const double gap = 1e-6 * (hi - lo) + 1e-12;
      if (knot > lo + gap && knot < hi - gap) {
        breaks.insert(breaks.begin() + best + 1, knot);
        refined = true;
      }
    }
    if (!refined) {
      // The data allow no more knots here (or the limit is reached): what keeps the curve from the
      // points is the fairness term, so it is relaxed.
      if (reductions < pr.fairness_reductions && alpha > 0.0) {
        alpha *= 0.1;
        ++reductions;
        continue;
      }
      why = n_now >= max_points ? "control point limit reached" : "no span left to refine";
      ++it;
      break;
    }
  }
  out.curve = curve;
  out.distances = dist;
  out.max_deviation = dist.maxCoeff();
  out.rms_deviation = std::sqrt(dist.squaredNorm() / double(count));
  out.fairness = alpha;
  out.iterations = it;
  std::ostringstream msg;
  msg.precision(3);
  msg << why << " (" << curve.points.rows() << " control points, max deviation "
      << out.max_deviation << " mm for tolerance " << pr.tolerance_mm << " mm, fairness " << alpha
      << ")";
  out.summary.message = msg.str();
  out.summary.iterations = it;
  out.summary.final_residual = out.max_deviation;
  out.summary.termination = converged ? Termination::Converged : Termination::NotConverged;
  return out;
}

}  // namespace clay::sketch::detail
