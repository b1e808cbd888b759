// Certified refit of a deformed surface (issue #7 item 4): least-squares B-spline fit of D(S(u, v))
// refined span by span, and per cell a bound of |fit − D∘S| from a dense sample plus a Taylor
// remainder whose derivatives are bounded by convex hulls of difference nets (fit, S) and by
// bounds of D' and D'' over the cell's hull. See refit.hpp and docs/deform.md.
//
// Note for the lead: the other certificate, comparing control nets after splitting and
// degree elevation to a common basis, needs the exact Bézier composition (compose.hpp, written in
// parallel); it is not used here. This file has no Bernstein-product routine of its own.
#include <clay/cancel.hpp>
#include <clay/deform/refit.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "certifier.hpp"
#include "extended_internal.hpp"
#include "fit_samples.hpp"
#include "messages.hpp"
#include "refit_edges.hpp"
#include "seal.hpp"

namespace clay::deform {

// The light form's samples and collocation (fit_samples.hpp), shared with light_map.cpp.
namespace detail {

std::vector<double> fit_parameters(const surface::BSplineBasis& basis, int intervals) {
  const std::vector<double> breaks = surface::breakpoints(basis);
  std::vector<double> t;
  for (std::size_t s = 0; s + 1 < breaks.size(); ++s) {
    const double a = breaks[s], b = breaks[s + 1];
    for (int k = 0; k < intervals; ++k)
      t.push_back(a + (b - a) * 0.5 * (1 - std::cos(std::numbers::pi * k / intervals)));
  }
  t.push_back(breaks.back());
  return t;
}

Eigen::MatrixXd collocation(const surface::BSplineBasis& basis, const std::vector<double>& t) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(t.size()), basis.count());
  std::vector<double> values(static_cast<std::size_t>(basis.degree + 1));
  for (std::size_t r = 0; r < t.size(); ++r) {
    const int span = surface::find_span(basis, t[r]);
    surface::basis_functions(basis, span, t[r], values);
    for (int k = 0; k <= basis.degree; ++k)
      a(static_cast<Eigen::Index>(r), span - basis.degree + k) =
          values[static_cast<std::size_t>(k)];
  }
  return a;
}

}  // namespace detail

namespace {

using surface::BSplineBasis;
using surface::BSplineSurface;

constexpr double infinity = std::numeric_limits<double>::infinity();

using detail::format;

std::string short_format(double v) { return internal::with_digits(v, 3); }

using detail::Bounds;
using detail::Certifier;
using detail::certifier;
using detail::collocation;
using detail::fit_parameters;
using detail::HullInfo;
using detail::Plane;

// ---- surfaces: bases, fit, derivative bounds of Bézier patches --------------------------------

/// The largest jump of the third derivative across u = t (fixed_u) or v = t of `s`, over 9
/// parameters of the other direction: one-sided differences of the second derivative, exact up
/// to O(delta) inside each polynomial piece.
double third_derivative_jump(const BSplineSurface& s, bool along_u, double t, double delta) {
  const auto [a, b] = along_u ? s.v.domain() : s.u.domain();
  double jump = 0;
  for (double w : surface::linspace(a, b, 9)) {
    auto second = [&](double x) {
      const surface::SurfaceDerivatives d =
          along_u ? surface::derivatives(s, x, w, 2) : surface::derivatives(s, w, x, 2);
      return Eigen::Vector3d(along_u ? d.duu : d.dvv);
    };
    const Eigen::Vector3d here = second(t);
    const Eigen::Vector3d right = (second(t + delta) - here) / delta;
    const Eigen::Vector3d left = (here - second(t - delta)) / delta;
    jump = std::max(jump, (right - left).norm());
  }
  return jump;
}

/// The fit's basis in one direction: the original's breakpoints, degree p_fit, and at each
/// interior breakpoint the multiplicity that keeps the original's continuity C^(p − m) there
/// (at least 1, at most p_fit). Without keep_breakpoints, a breakpoint as smooth as the fit's own
/// joins (C^(p_fit - 1) or smoother) is left out, except, for a cubic fit, a C2 join whose jump J
/// of the third derivative a cubic without a knot there would feel: J h^3 above a tenth of the
/// tolerance, h the shorter of its neighbouring spans (a loft's joins between few sections stay;
/// the simple knots a style refinement or an exact composition piles up go, and the refinement
/// adds knots only where the tolerance needs them).
BSplineBasis initial_basis(const BSplineSurface& surface, bool along_u, int degree,
                           bool keep_breakpoints, double tolerance) {
  const BSplineBasis& original = along_u ? surface.u : surface.v;
  const std::vector<double> breaks = surface::breakpoints(original);
  BSplineBasis b;
  b.degree = degree;
  b.knots.assign(static_cast<std::size_t>(degree + 1), breaks.front());
  for (std::size_t k = 1; k + 1 < breaks.size(); ++k) {
    const int continuity = original.degree - surface::multiplicity(original, breaks[k]);
    if (!keep_breakpoints && continuity >= degree) continue;  // smoother than a fit's join
    if (!keep_breakpoints && continuity == degree - 1) {
      if (degree != 3) continue;
      const double h = std::min(breaks[k] - breaks[k - 1], breaks[k + 1] - breaks[k]);
      const double jump = third_derivative_jump(surface, along_u, breaks[k], 1e-4 * h);
      if (!(jump * h * h * h > 0.1 * tolerance)) continue;
    }
    const int m = std::clamp(degree - continuity, 1, degree);
    b.knots.insert(b.knots.end(), static_cast<std::size_t>(m), breaks[k]);
  }
  b.knots.insert(b.knots.end(), static_cast<std::size_t>(degree + 1), breaks.back());
  return b;
}

/// A uniform start (RefitOptions::initial_count) with the original's creases and C1 joins added,
/// at the multiplicity that keeps them: a rational conic's joins (a cylinder's quarters) are only
/// C1 in its parameter, and a quintic without knots there would need dense knots around them to
/// follow the first derivatives a matched curve asks for.
BSplineBasis with_rough_breaks(BSplineBasis uniform, const BSplineBasis& original) {
  const std::vector<double> breaks = surface::breakpoints(original);
  const double width = original.domain().second - original.domain().first;
  for (std::size_t k = 1; k + 1 < breaks.size(); ++k) {
    const int continuity = original.degree - surface::multiplicity(original, breaks[k]);
    if (continuity > 1) continue;
    const int want = std::clamp(uniform.degree - continuity, 1, uniform.degree);
    // a uniform knot within 1e-12 of the domain counts as the same knot
    const auto near = [&](double t) { return std::abs(t - breaks[k]) <= 1e-12 * width; };
    const int have =
        static_cast<int>(std::count_if(uniform.knots.begin(), uniform.knots.end(), near));
    for (int m = have; m < want; ++m) uniform.knots.push_back(breaks[k]);
    std::sort(uniform.knots.begin(), uniform.knots.end());
  }
  return uniform;
}

/// Tensor-product least squares: the net C minimising Σ |Σ N_i(u_r) N_j(v_s) C_ij − F_rs|^2 is
/// C = A_u^+ F A_v^+T per coordinate (the problem separates).
BSplineSurface least_squares(const BSplineBasis& bu, const BSplineBasis& bv,
                             const std::vector<double>& us, const std::vector<double>& vs,
                             const Points3& values) {
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qu(collocation(bu, us));
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qv(collocation(bv, vs));
  const auto mu = static_cast<Eigen::Index>(us.size()), mv = static_cast<Eigen::Index>(vs.size());
  Points3 net(static_cast<Eigen::Index>(bu.count()) * bv.count(), 3);
  for (int c = 0; c < 3; ++c) {
    Eigen::MatrixXd f(mu, mv);
    for (Eigen::Index i = 0; i < mu; ++i)
      for (Eigen::Index j = 0; j < mv; ++j) f(i, j) = values(i * mv + j, c);
    const Eigen::MatrixXd x = qu.solve(f);                          // count_u x mv
    const Eigen::MatrixXd y = qv.solve(x.transpose()).transpose();  // count_u x count_v
    for (Eigen::Index i = 0; i < y.rows(); ++i)
      for (Eigen::Index j = 0; j < y.cols(); ++j) net(i * y.cols() + j, c) = y(i, j);
  }
  return surface::make_surface(bu, bv, std::move(net));
}

/// Bounds of |S_u|, |S_uu|, |S_v|, |S_vv| over a (rational) Bézier patch, from the hodograph nets
/// of the homogeneous form (convex hull) and the quotient rule: with c the mean control point,
/// A = Σ B w (P − c), W = Σ B w, S − c = A / W,
///   S_u = (A_u − (S − c) W_u) / W,  S_uu = (A_uu − 2 S_u W_u − (S − c) W_uu) / W,
/// |S − c| <= max|P − c| and W >= min w (convex hull, positive weights).
struct PatchBounds {
  double d1u = 0, d2u = 0, d1v = 0, d2v = 0;
};
PatchBounds patch_bounds(const BSplineSurface& patch) {
  const int p = patch.u.degree, q = patch.v.degree;
  const double du = patch.u.knots.back() - patch.u.knots.front();
  const double dv = patch.v.knots.back() - patch.v.knots.front();
  const Eigen::Vector3d c = patch.points.colwise().mean().transpose();
  double radius = 0, w_min = infinity;
  for (Eigen::Index r = 0; r < patch.points.rows(); ++r) {
    radius = std::max(radius, (patch.points.row(r).transpose() - c).norm());
    w_min = std::min(w_min, patch.weights(r));
  }
  auto h = [&](int i, int j) -> Eigen::Vector4d {
    const Eigen::Index r = patch.index(i, j);
    const double w = patch.weights(r);
    Eigen::Vector4d out;
    out << w * (patch.points.row(r).transpose() - c), w;
    return out;
  };
  // first / second differences along one direction: max norms of the vector and weight parts
  auto differences = [&](bool along_u, double& a1, double& w1, double& a2, double& w2) {
    const int n = along_u ? p : q;
    const int other = along_u ? q : p;
    a1 = w1 = a2 = w2 = 0;
    for (int o = 0; o <= other; ++o)
      for (int k = 0; k <= n; ++k) {
        auto at = [&](int s) { return along_u ? h(s, o) : h(o, s); };
        if (k + 1 <= n) {
          const Eigen::Vector4d d = at(k + 1) - at(k);
          a1 = std::max(a1, d.head<3>().norm()), w1 = std::max(w1, std::abs(d(3)));
        }
        if (k + 2 <= n) {
          const Eigen::Vector4d d = at(k + 2) - 2 * at(k + 1) + at(k);
          a2 = std::max(a2, d.head<3>().norm()), w2 = std::max(w2, std::abs(d(3)));
        }
      }
    const double span = along_u ? du : dv;
    a1 *= n / span, w1 *= n / span;
    a2 *= n * (n - 1) / (span * span), w2 *= n * (n - 1) / (span * span);
  };
  PatchBounds b;
  double a1, w1, a2, w2;
  differences(true, a1, w1, a2, w2);
  b.d1u = (a1 + radius * w1) / w_min;
  b.d2u = (a2 + 2 * b.d1u * w1 + radius * w2) / w_min;
  differences(false, a1, w1, a2, w2);
  b.d1v = (a1 + radius * w1) / w_min;
  b.d2v = (a2 + 2 * b.d1v * w1 + radius * w2) / w_min;
  return b;
}

/// Distinct values of `refined` not in `original` (both sorted).
std::vector<double> added_breaks(const std::vector<double>& refined,
                                 const std::vector<double>& original) {
  std::vector<double> out;
  std::set_difference(refined.begin(), refined.end(), original.begin(), original.end(),
                      std::back_inserter(out));
  return out;
}

Eigen::Vector3d deformed(const Certifier& d, const Eigen::Vector3d& x) {
  const Eigen::Vector3d y = d.map(x);
  if (!internal::all_finite(y))
    throw Error(ErrorCategory::InvalidArgument,
                "refit_deformed: the " + d.name + " maps (" + format(x.x()) + ", " + format(x.y()) +
                    ", " + format(x.z()) +
                    ") to a non-finite point; use a deformation defined on the whole surface");
  return y;
}

// ---- the certificate ------------------------------------------------------------------------

struct CellResult {
  double sampled = 0;
  double bound = infinity;
  bool lipschitz = false;
  std::vector<Plane> planes;
};

struct Certificate {
  std::vector<CellResult> cells;  // (iu, iv) at iu * cells_v + iv
  int cells_u = 0, cells_v = 0;
  std::vector<int> span_u, span_v;  // the fit's non-empty span holding each cell
  int spans_u = 0, spans_v = 0;     // the fit's non-empty spans
  double sampled = 0, bound = 0;
  long samples = 0;
  bool certified = true;
};

/// Every cell of `fit` (pair of its non-empty spans): sampled deviation on a uniform grid of at
/// least `base` intervals per direction, and (when the certifier has bounds) the bound
/// max|e(grid)| + remainder + rounding allowance.
Certificate certify(const BSplineSurface& original, const BSplineSurface& fit, const Certifier& d,
                    int base, double budget, double rounding) {
  // Cells: the union of both surfaces' breakpoints, each refined to it (the same surfaces), so
  // both are one polynomial per cell. The fit's breakpoints hold the original's unless it was
  // started from fewer (RefitOptions::keep_breakpoints); its cells are then split.
  const std::vector<double> fit_u = surface::breakpoints(fit.u),
                            fit_v = surface::breakpoints(fit.v);
  const std::vector<double> original_u = surface::breakpoints(original.u),
                            original_v = surface::breakpoints(original.v);
  BSplineSurface refined = original, refined_fit = fit;
  if (const auto a = added_breaks(fit_u, original_u); !a.empty())
    refined = surface::refine_knots_u(refined, a);
  if (const auto a = added_breaks(fit_v, original_v); !a.empty())
    refined = surface::refine_knots_v(refined, a);
  if (const auto a = added_breaks(original_u, fit_u); !a.empty())
    refined_fit = surface::refine_knots_u(refined_fit, a);
  if (const auto a = added_breaks(original_v, fit_v); !a.empty())
    refined_fit = surface::refine_knots_v(refined_fit, a);
  const surface::BezierPatches fit_patches = surface::extract_bezier(refined_fit);
  const surface::BezierPatches s_patches = surface::extract_bezier(refined);
  if (s_patches.count_u() != fit_patches.count_u() || s_patches.count_v() != fit_patches.count_v())
    throw Error(ErrorCategory::Internal,
                "refit_deformed: the fit's and the surface's cells differ");

  const int cap = std::max(base, 64);
  Certificate out;
  out.cells_u = fit_patches.count_u(), out.cells_v = fit_patches.count_v();
  auto spans_of = [](const std::vector<double>& cells, const std::vector<double>& spans) {
    std::vector<int> owner;
    for (std::size_t k = 0; k + 1 < cells.size(); ++k)
      owner.push_back(static_cast<int>(
          std::upper_bound(spans.begin(), spans.end(), 0.5 * (cells[k] + cells[k + 1])) -
          spans.begin() - 1));
    return owner;
  };
  out.span_u = spans_of(fit_patches.breaks_u, fit_u);
  out.span_v = spans_of(fit_patches.breaks_v, fit_v);
  out.spans_u = static_cast<int>(fit_u.size()) - 1;
  out.spans_v = static_cast<int>(fit_v.size()) - 1;
  out.certified = static_cast<bool>(d.info);
  for (int iu = 0; iu < out.cells_u; ++iu)
    for (int iv = 0; iv < out.cells_v; ++iv) {
      const std::size_t index = static_cast<std::size_t>(iu * out.cells_v + iv);
      const BSplineSurface& sp = s_patches.patches[index];
      const BSplineSurface& fp = fit_patches.patches[index];
      const double du = fit_patches.breaks_u[static_cast<std::size_t>(iu + 1)] -
                        fit_patches.breaks_u[static_cast<std::size_t>(iu)];
      const double dv = fit_patches.breaks_v[static_cast<std::size_t>(iv + 1)] -
                        fit_patches.breaks_v[static_cast<std::size_t>(iv)];
      CellResult cell;
      int nu = base, nv = base;
      // the remainder as a function of the grid, chosen below
      std::function<double(int, int)> remainder;
      if (d.info) {
        const HullInfo info = d.info(sp.points);
        cell.planes = info.planes;
        const PatchBounds s = patch_bounds(sp), f = patch_bounds(fp);
        const double l1 = info.bounds.first, l2 = info.bounds.second;
        auto grid = [&](double need) {
          return static_cast<int>(
              std::clamp(std::ceil(need), static_cast<double>(base), static_cast<double>(cap)));
        };
        if (std::isfinite(l2)) {
          // Taylor: |e − I e| <= (h_u^2 / 8) sup|e_uu| + (h_v^2 / 8) sup|e_vv|
          const double euu = f.d2u + l2 * s.d1u * s.d1u + l1 * s.d2u;
          const double evv = f.d2v + l2 * s.d1v * s.d1v + l1 * s.d2v;
          nu = grid(du * std::sqrt(euu / (4 * budget)));
          nv = grid(dv * std::sqrt(evv / (4 * budget)));
          remainder = [=](int a, int b) {
            const double hu = du / a, hv = dv / b;
            return hu * hu / 8 * euu + hv * hv / 8 * evv;
          };
        } else if (std::isfinite(l1)) {
          // Lipschitz: |e(x) − e(nearest node)| <= (h_u / 2) sup|e_u| + (h_v / 2) sup|e_v|
          cell.lipschitz = true;
          const double eu = f.d1u + l1 * s.d1u, ev = f.d1v + l1 * s.d1v;
          nu = grid(du * eu / budget);
          nv = grid(dv * ev / budget);
          remainder = [=](int a, int b) { return du / a / 2 * eu + dv / b / 2 * ev; };
        } else {
          out.certified = false;
        }
      }
      const std::vector<double> us =
          surface::linspace(sp.u.knots.front(), sp.u.knots.back(), nu + 1);
      const std::vector<double> vs =
          surface::linspace(sp.v.knots.front(), sp.v.knots.back(), nv + 1);
      const Points3 s_values = surface::evaluate_grid(sp, us, vs);
      const Points3 f_values = surface::evaluate_grid(fp, us, vs);
      for (Eigen::Index r = 0; r < s_values.rows(); ++r) {
        const Eigen::Vector3d target = deformed(d, s_values.row(r).transpose());
        cell.sampled = std::max(cell.sampled, (f_values.row(r).transpose() - target).norm());
      }
      out.samples += s_values.rows();
      if (remainder) cell.bound = cell.sampled + remainder(nu, nv) + rounding;
      out.sampled = std::max(out.sampled, cell.sampled);
      out.bound = std::max(out.bound, cell.bound);
      out.cells.push_back(std::move(cell));
    }
  if (!out.certified) out.bound = infinity;
  return out;
}

/// The basis with a knot added at the middle of every marked non-empty span.
/// Keeps the marks of at most `room` spans, those with the worst cells; true when any mark is
/// left.
bool keep_worst(std::vector<char>& marked, const std::vector<double>& worst, int room) {
  std::vector<std::size_t> spans;
  for (std::size_t s = 0; s < marked.size(); ++s)
    if (marked[s]) spans.push_back(s);
  const std::size_t keep = static_cast<std::size_t>(std::max(room, 0));
  if (spans.size() > keep) {
    std::stable_sort(spans.begin(), spans.end(),
                     [&](std::size_t a, std::size_t b) { return worst[a] > worst[b]; });
    for (std::size_t k = keep; k < spans.size(); ++k) marked[spans[k]] = 0;
  }
  return std::min(spans.size(), keep) > 0;
}

/// The basis with `interior` simple interior knots placed so that each span carries an
/// equal share of the error (de Boor's equidistribution, "A Practical Guide to Splines" ch. XII):
/// a degree-p fit's error on a span of length h is about (h rho)^(p + 1), so span s of the old
/// basis, with error e_s, holds mass e_s^(1 / (p + 1)) spread evenly over it; the new breaks cut
/// the running mass into equal parts. A floor of a tenth of the mean mass keeps every region some
/// knots. `error` has one entry per non-empty span.
BSplineBasis equidistributed(const BSplineBasis& basis, const std::vector<double>& error,
                             std::size_t interior) {
  const std::vector<double> breaks = surface::breakpoints(basis);
  const std::size_t spans = breaks.size() - 1;
  std::vector<double> mass(spans);
  double mean = 0;
  for (std::size_t s = 0; s < spans; ++s)
    mean += mass[s] = std::pow(std::max(error[s], 0.0), 1.0 / (basis.degree + 1));
  mean /= static_cast<double>(spans);
  double total = 0;
  for (double& m : mass) total += m = std::max(m, 0.1 * mean);
  BSplineBasis out;
  out.degree = basis.degree;
  out.knots.assign(static_cast<std::size_t>(basis.degree + 1), breaks.front());
  double below = 0;  // mass of the spans before s
  std::size_t s = 0;
  for (std::size_t k = 1; k <= interior; ++k) {
    const double at = total * static_cast<double>(k) / static_cast<double>(interior + 1);
    while (s + 1 < spans && below + mass[s] < at) below += mass[s++];
    const double f = mass[s] > 0 ? std::clamp((at - below) / mass[s], 0.0, 1.0) : 0.5;
    out.knots.push_back(breaks[s] + f * (breaks[s + 1] - breaks[s]));
  }
  out.knots.insert(out.knots.end(), static_cast<std::size_t>(basis.degree + 1), breaks.back());
  return out;
}

BSplineBasis split_spans(const BSplineBasis& basis, const std::vector<char>& marked) {
  const std::vector<double> breaks = surface::breakpoints(basis);
  BSplineBasis out = basis;
  for (std::size_t s = 0; s < marked.size(); ++s)
    if (marked[s]) out.knots.push_back(0.5 * (breaks[s] + breaks[s + 1]));
  std::sort(out.knots.begin(), out.knots.end());
  return out;
}

RefitResult refit(const BSplineSurface& surface, const Certifier& d, const RefitOptions& options) {
  options.validate();
  surface::validate(surface, "refit_deformed surface");
  const int p = options.degree;
  const int intervals = p + 1;  // fit parameters per span, per direction
  const int base = 4 * intervals;

  // size: the deformed surface sampled 8 x 8 per span
  const std::vector<double> su = surface::span_samples(surface.u, 8);
  const std::vector<double> sv = surface::span_samples(surface.v, 8);
  Points3 sample = surface::evaluate_grid(surface, su, sv);
  for (Eigen::Index r = 0; r < sample.rows(); ++r)
    sample.row(r) = deformed(d, sample.row(r).transpose()).transpose();
  const double size = (sample.colwise().maxCoeff() - sample.colwise().minCoeff()).norm();
  const double magnitude = sample.cwiseAbs().maxCoeff();
  const bool relative = options.relative_tolerance > 0;
  if (relative && !(size > 0))
    throw Error(ErrorCategory::InvalidGeometry,
                "refit_deformed: the deformed surface has zero size (" + format(size) +
                    " mm), so a relative tolerance is zero; give the tolerance in mm "
                    "(RefitOptions::tolerance_mm, relative_tolerance = 0)");
  const double tolerance = relative ? options.relative_tolerance * size : options.tolerance_mm;
  const double rounding = 1e-12 * (size + magnitude);
  const double budget = options.certificate_share * tolerance;

  RefitResult result;
  RefitReport& report = result.report;
  report.tolerance_mm = tolerance;
  report.size = size;
  report.degree_u = report.degree_v = p;
  const bool fixed = options.count_u > 0;
  const bool matching = !options.matched_curves.empty();
  // A fixed net, or an adaptive one from a uniform start (initial_count) or from the original's
  // breakpoints.
  const int uniform_u = fixed ? options.count_u : options.initial_count;
  const int uniform_v = fixed ? options.count_v : options.initial_count;
  BSplineBasis bu = uniform_u > 0
                        ? surface::clamped_uniform_basis(p, uniform_u, surface.u.domain().first,
                                                         surface.u.domain().second)
                        : initial_basis(surface, true, p, options.keep_breakpoints, tolerance),
               bv = uniform_v > 0
                        ? surface::clamped_uniform_basis(p, uniform_v, surface.v.domain().first,
                                                         surface.v.domain().second)
                        : initial_basis(surface, false, p, options.keep_breakpoints, tolerance);
  if (!fixed && uniform_u > 0) bu = with_rough_breaks(std::move(bu), surface.u);
  if (!fixed && uniform_v > 0) bv = with_rough_breaks(std::move(bv), surface.v);
  const std::size_t initial_u = bu.knots.size(), initial_v = bv.knots.size();
  // a closed side's seam: the fit keeps the source's own continuity across it (refit_edges.hpp)
  const detail::SeamTies ties =
      matching ? detail::seam_ties(surface, detail::closed_sides(surface)) : detail::SeamTies{};
  std::string limit;
  RefitResult best;  // the best fit that missed, kept when moving knots did worse
  double best_measure = infinity;
  int relocations = 0, moves_u = 0, moves_v = 0;
  std::vector<double> best_error_u, best_error_v;  // the best fit's error per span
  for (int iteration = 1;; ++iteration) {
    throw_if_cancelled("a certified refit");
    const std::vector<double> us = fit_parameters(bu, intervals),
                              vs = fit_parameters(bv, intervals);
    Points3 values = surface::evaluate_grid(surface, us, vs);
    for (Eigen::Index r = 0; r < values.rows(); ++r)
      values.row(r) = deformed(d, values.row(r).transpose()).transpose();
    // Along matched curves (a model face's edges) D∘S's position and derivatives are weighted
    // rows too: 1e4 times a grid sample's weight, so the fit follows them as closely as its
    // knots allow; the spans are then split until they are within their figures.
    std::vector<detail::EdgeSample> edge;
    if (matching) {
      const auto spans = [](const BSplineBasis& b) {
        return static_cast<int>(surface::breakpoints(b).size()) - 1;
      };
      const int per_curve = std::min(4000, 4 * intervals * (spans(bu) + spans(bv)) + 32);
      edge = detail::edge_samples(
          surface, options.matched_curves, [&](const Eigen::Vector3d& x) { return deformed(d, x); },
          size, per_curve, options.matched_curvature > 0);
      detail::mark_seams(edge, per_curve, surface, ties);
      result.surface = detail::least_squares_matching(
          bu, bv, us, vs, values, edge, 100.0, options.matched_gap_mm, options.matched_angle_deg,
          options.matched_curvature, size, ties);
    } else {
      result.surface = least_squares(bu, bv, us, vs, values);
    }
    detail::keep_closed_and_collapsed(surface, result.surface,
                                      [&](const Eigen::Vector3d& x) { return deformed(d, x); });
    const Certificate cert = certify(surface, result.surface, d, base, budget, rounding);

    report.summary.iterations = iteration;
    report.certified = cert.certified;
    report.sampled_max = cert.sampled;
    report.certified_bound_mm = cert.certified ? cert.bound : infinity;
    report.samples = cert.samples;
    report.knots_added_u = static_cast<int>(bu.knots.size() - initial_u);
    report.knots_added_v = static_cast<int>(bv.knots.size() - initial_v);
    report.lipschitz_cells = 0;
    report.crossings.clear();
    std::vector<char> mark_u(static_cast<std::size_t>(cert.spans_u), 0);
    std::vector<char> mark_v(static_cast<std::size_t>(cert.spans_v), 0);
    // the worst cell of each span row and column that misses (which to split first under a
    // cap), and of every one (where to move knots once the cap is reached)
    std::vector<double> worst_u(mark_u.size(), 0.0), worst_v(mark_v.size(), 0.0);
    std::vector<double> error_u(mark_u.size(), 0.0), error_v(mark_v.size(), 0.0);
    for (int iu = 0; iu < cert.cells_u; ++iu)
      for (int iv = 0; iv < cert.cells_v; ++iv) {
        const CellResult& c = cert.cells[static_cast<std::size_t>(iu * cert.cells_v + iv)];
        const int span_u = cert.span_u[static_cast<std::size_t>(iu)];
        const int span_v = cert.span_v[static_cast<std::size_t>(iv)];
        if (c.lipschitz) ++report.lipschitz_cells;
        for (const Plane& pl : c.planes)
          report.crossings.push_back(
              {span_u, span_v, pl.step, pl.axis, pl.value, c.sampled, c.bound});
        const double measure = cert.certified ? c.bound : c.sampled;
        error_u[static_cast<std::size_t>(span_u)] =
            std::max(error_u[static_cast<std::size_t>(span_u)], measure);
        error_v[static_cast<std::size_t>(span_v)] =
            std::max(error_v[static_cast<std::size_t>(span_v)], measure);
        if (measure > tolerance) {
          mark_u[static_cast<std::size_t>(span_u)] = mark_v[static_cast<std::size_t>(span_v)] = 1;
          double& wu = worst_u[static_cast<std::size_t>(span_u)];
          double& wv = worst_v[static_cast<std::size_t>(span_v)];
          wu = std::max(wu, measure), wv = std::max(wv, measure);
        }
      }
    // The matched curves' figures, as a share of their allowance: spans holding a sample that
    // misses are split (their worst counted as that share of the tolerance).
    double edge_share = 0;
    if (matching) {
      const std::vector<detail::EdgeMiss> misses = detail::edge_misses(result.surface, edge);
      const std::vector<double> breaks_u = surface::breakpoints(bu),
                                breaks_v = surface::breakpoints(bv);
      auto span_of = [](const std::vector<double>& breaks, double t) {
        const auto k = std::upper_bound(breaks.begin(), breaks.end(), t) - breaks.begin() - 1;
        return static_cast<std::size_t>(
            std::clamp<std::ptrdiff_t>(k, 0, static_cast<std::ptrdiff_t>(breaks.size()) - 2));
      };
      const double min_width_u = (breaks_u.back() - breaks_u.front()) /
                                 (2.0 * options.max_count_per_direction),
                   min_width_v = (breaks_v.back() - breaks_v.front()) /
                                 (2.0 * options.max_count_per_direction);
      report.matched_gap_mm = report.matched_angle_deg = 0;
      report.matched_samples = static_cast<long>(edge.size());
      for (std::size_t k = 0; k < edge.size(); ++k) {
        // A tied seam meets only its own face, continuous across by the tie: its distance from
        // D∘S is the certified bound's, not a neighbour's gap.
        if (edge[k].seam) continue;
        // a sharp edge's angle is not continuity: its position only
        const double angle = edge[k].order >= 1 ? misses[k].angle_deg : 0.0;
        report.matched_gap_mm = std::max(report.matched_gap_mm, misses[k].gap_mm);
        report.matched_angle_deg = std::max(report.matched_angle_deg, angle);
        const double share =
            std::max(misses[k].gap_mm / options.matched_gap_mm, angle / options.matched_angle_deg);
        edge_share = std::max(edge_share, share);
        if (share <= 1) continue;
        const std::size_t iu = span_of(breaks_u, edge[k].u), iv = span_of(breaks_v, edge[k].v);
        // The span along the curve is split; the one across only while it is (relative to its
        // domain) the wider of the two, and never below its share of a net twice the cap: a
        // torus's edge missing for want of control points along it halved the span across it
        // at every round, down to 1e-4 of its domain, until the least squares lost every digit.
        const double width_u = (breaks_u[iu + 1] - breaks_u[iu]) / (breaks_u.back() - breaks_u[0]);
        const double width_v = (breaks_v[iv + 1] - breaks_v[iv]) / (breaks_v.back() - breaks_v[0]);
        const bool along_u = edge[k].along_u >= edge[k].along_v;
        if ((along_u || width_u > width_v) && breaks_u[iu + 1] - breaks_u[iu] >= min_width_u)
          mark_u[iu] = 1;
        if ((!along_u || width_v > width_u) && breaks_v[iv + 1] - breaks_v[iv] >= min_width_v)
          mark_v[iv] = 1;
        worst_u[iu] = std::max(worst_u[iu], share * tolerance);
        worst_v[iv] = std::max(worst_v[iv], share * tolerance);
        error_u[iu] = std::max(error_u[iu], share * tolerance);
        error_v[iv] = std::max(error_v[iv], share * tolerance);
      }
    }
    const double measure = cert.certified ? cert.bound : cert.sampled;
    if (iteration == 1) report.summary.initial_residual = measure;
    report.summary.final_residual = measure;
    if (measure <= tolerance && edge_share <= 1) {
      report.summary.termination = Termination::Converged;
      break;
    }
    // the fit kept when the limits are reached: the least miss of the tolerance and the figures
    const double miss = std::max(measure, edge_share * tolerance);
    if (miss < best_measure) {
      best_measure = miss, best = result;
      best_error_u = error_u, best_error_v = error_v;
    }
    if (fixed) {
      limit = "the fixed net of " + std::to_string(options.count_u) + " x " +
              std::to_string(options.count_v) + " control points (count_u, count_v)";
      break;
    }
    if (iteration >= options.max_iterations) {
      limit = "iteration limit " + std::to_string(options.max_iterations) + " reached";
      break;
    }
    // The least squares are dense per direction ((degree + 1) rows per span x count columns), so
    // one long direction costs count^2 memory even within max_control_points: a twist of 1e6
    // degrees grew one direction to 10,000 and took 4.4 GB (issue #18). Near the cap, the spans
    // with the worst cells are split first, as many as it leaves room for (a class-A net of at
    // most 32 control points per direction puts its knots where the error is).
    // Both directions are trimmed, so neither call may be short-circuited away.
    const bool missed_u = std::find(mark_u.begin(), mark_u.end(), 1) != mark_u.end();
    const bool missed_v = std::find(mark_v.begin(), mark_v.end(), 1) != mark_v.end();
    const bool room_u = keep_worst(mark_u, worst_u, options.max_count_per_direction - bu.count());
    const bool room_v = keep_worst(mark_v, worst_v, options.max_count_per_direction - bv.count());
    const bool room = room_u || room_v;
    BSplineBasis nu = split_spans(bu, mark_u), nv = split_spans(bv, mark_v);
    const bool stuck_u = missed_u && !room_u, stuck_v = missed_v && !room_v;
    if ((stuck_u || stuck_v) && options.initial_count > 0 && relocations < 6) {
      // A direction at its cap with spans that miss: its knots move instead, so that each span
      // carries an equal share of the error (kept only when it does better), while the other
      // direction is split as usual (waiting for both to reach the cap spent a class-A torus's
      // rounds on splitting the direction that did not need it).
      ++relocations;
      // As many control points as before: the simple knots moved, the rough breaks' kept. A
      // direction's first move follows the last fit's error (a bump's sheet at a cap of 16:
      // 0.74 mm halved, 0.020 moved, 0.40 spread evenly); its second spreads them evenly (an
      // error e ~ h^(p+1) on every span): halving leaves spans of two widths at the cap, and a
      // wide span's error may show where narrow ones meet a break, which following the error
      // crowds further (a class-A torus missed 3.6 times at 32 halved, 4.6 moved by the error,
      // 0.95 spread evenly). Later moves follow the best fit's error so far (the last fit's
      // drifted: each move's error, noisier, pushed the next further off).
      auto moved = [&](const BSplineBasis& b, const std::vector<double>& last_error,
                       const BSplineBasis& best_basis, const std::vector<double>& best_error,
                       const BSplineBasis& original, int& moves) {
        const int move = moves++;
        const bool even = move == 1, last = move == 0 || best_error.empty();
        const BSplineBasis& from = even || last ? b : best_basis;
        std::vector<double> error = last ? last_error : best_error;
        if (even) {
          const std::vector<double> breaks = surface::breakpoints(b);
          error.assign(breaks.size() - 1, 0.0);
          for (std::size_t s = 0; s + 1 < breaks.size(); ++s)
            error[s] = std::pow(breaks[s + 1] - breaks[s], b.degree + 1);
        }
        BSplineBasis bare;
        bare.degree = b.degree;
        bare.knots.assign(static_cast<std::size_t>(2 * (b.degree + 1)), original.domain().first);
        std::fill(bare.knots.begin() + b.degree + 1, bare.knots.end(), original.domain().second);
        const std::size_t rough =
            with_rough_breaks(bare, original).knots.size() - bare.knots.size();
        const std::size_t interior = b.knots.size() - bare.knots.size();
        return with_rough_breaks(
            equidistributed(from, error, interior > rough ? interior - rough : 0), original);
      };
      const BSplineBasis next_u =
          stuck_u ? moved(bu, error_u, best.surface.u, best_error_u, surface.u, moves_u)
                  : std::move(nu);
      const BSplineBasis next_v =
          stuck_v ? moved(bv, error_v, best.surface.v, best_error_v, surface.v, moves_v)
                  : std::move(nv);
      // the same knots again (the best did not change): nothing left to try
      if (next_u.knots != bu.knots || next_v.knots != bv.knots) {
        bu = next_u, bv = next_v;
        continue;
      }
      limit = "control point limit per direction " +
              std::to_string(options.max_count_per_direction) + " reached (net " +
              std::to_string(bu.count()) + " x " + std::to_string(bv.count()) + ")";
      break;
    }
    if (!room || std::max(nu.count(), nv.count()) > options.max_count_per_direction) {
      limit = "control point limit per direction " +
              std::to_string(options.max_count_per_direction) + " reached (" +
              (room ? "next net " : "net ") + std::to_string(nu.count()) + " x " +
              std::to_string(nv.count()) + ")";
      break;
    }
    if (static_cast<long>(nu.count()) * nv.count() > options.max_control_points) {
      limit = "control point limit " + std::to_string(options.max_control_points) +
              " reached (next net " + std::to_string(nu.count()) + " x " +
              std::to_string(nv.count()) + ")";
      break;
    }
    bu = std::move(nu), bv = std::move(nv);
  }
  if (report.summary.termination != Termination::Converged &&
      std::max(report.summary.final_residual,
               matching ? tolerance * std::max(report.matched_gap_mm / options.matched_gap_mm,
                                               report.matched_angle_deg / options.matched_angle_deg)
                        : 0.0) > best_measure) {
    const Summary summary = report.summary;
    result = std::move(best);
    report.summary = summary;
    report.summary.final_residual =
        result.report.certified ? result.report.certified_bound_mm : result.report.sampled_max;
  }

  std::string message;
  if (report.summary.termination == Termination::Converged) {
    message = report.certified ? "certified bound " + short_format(report.certified_bound_mm) +
                                     " mm within the tolerance " + short_format(tolerance) + " mm"
                               : "sampled maximum " + short_format(report.sampled_max) +
                                     " mm within the tolerance " + short_format(tolerance) +
                                     " mm, not certified";
  } else {
    report.summary.termination = Termination::NotConverged;
    const double reached = report.certified ? report.certified_bound_mm : report.sampled_max;
    const std::string what =
        (report.certified ? "certified bound " : "sampled maximum ") + short_format(reached);
    if (reached <= tolerance)  // only the matched curves miss
      message = limit + ": " + what + " mm within the tolerance " + short_format(tolerance) +
                " mm, but the matched curves miss their figures; give more control points or "
                "relax the figures";
    else
      message = limit + ": " + what + " mm above the tolerance " + short_format(tolerance) +
                (fixed ? " mm; give more control points (count_u, count_v), a larger tolerance "
                         "or a higher degree"
                       : " mm; raise the limits, the tolerance or the degree");
  }
  if (matching) {
    message += "; matched curves: gap " + short_format(report.matched_gap_mm) + " mm (" +
               short_format(options.matched_gap_mm) + " allowed), normal angle " +
               short_format(report.matched_angle_deg) + " deg (" +
               short_format(options.matched_angle_deg) + " allowed) at " +
               std::to_string(report.matched_samples) + " samples";
  }
  if (!report.certified) {
    message += "; not certified: ";
    message += d.info ? "the deformation's derivatives are unbounded in some cell" : d.why_not;
  }
  if (report.lipschitz_cells > 0)
    message += "; " + std::to_string(report.lipschitz_cells) +
               " cells cross a plane where the deformation is only C0 (first-derivative bound)";
  if (!report.crossings.empty())
    message += "; " + std::to_string(report.crossings.size()) +
               " lattice plane crossings by cells of the fit (see crossings)";
  report.summary.message = message;
  return result;
}

}  // namespace

std::vector<std::string> RefitOptions::problems() const {
  std::vector<std::string> out;
  auto fail = [&out](const std::string& what) { out.push_back("RefitOptions::" + what); };
  if (degree < 1 || degree > 25)
    fail("degree = " + std::to_string(degree) +
         ": must be in [1, 25] (the exchange degree limit); 3 is usual");
  // Exactly one of the two: a tolerance whose unit the caller did not choose is refused.
  for (const auto& [name, value] :
       {std::pair{"relative_tolerance", relative_tolerance}, {"tolerance_mm", tolerance_mm}})
    if (!(std::isfinite(value) && value >= 0))
      fail(std::string(name) + " = " + internal::shortest(value) + ": must be finite and >= 0");
  if ((relative_tolerance > 0) == (tolerance_mm > 0))
    fail("relative_tolerance = " + internal::shortest(relative_tolerance) +
         " and tolerance_mm = " + internal::shortest(tolerance_mm) +
         ": exactly one must be > 0 (e.g. relative_tolerance = 1e-4, a fraction of the size, or "
         "tolerance_mm = 0.01 with relative_tolerance = 0)");
  if (max_iterations < 1)
    fail("max_iterations = " + std::to_string(max_iterations) + ": must be >= 1");
  if (max_control_points < (degree + 1) * (degree + 1))
    fail("max_control_points = " + std::to_string(max_control_points) +
         ": must be >= (degree + 1)^2 = " + std::to_string((degree + 1) * (degree + 1)));
  if (max_count_per_direction < degree + 1)
    fail("max_count_per_direction = " + std::to_string(max_count_per_direction) +
         ": must be >= degree + 1 = " + std::to_string(degree + 1));
  if (initial_count != 0 && (initial_count < degree + 1 || initial_count > max_count_per_direction))
    fail("initial_count = " + std::to_string(initial_count) +
         " breaks the rule 0, or degree + 1 (" + std::to_string(degree + 1) +
         ") <= initial_count <= max_count_per_direction (" +
         std::to_string(max_count_per_direction) + ")");
  if ((count_u > 0) != (count_v > 0) || count_u < 0 || count_v < 0)
    fail("count_u = " + std::to_string(count_u) + ", count_v = " + std::to_string(count_v) +
         ": give both (a fixed net) or neither (0, adaptive)");
  else if (count_u > 0 && (std::min(count_u, count_v) < degree + 1 ||
                           std::max(count_u, count_v) > max_count_per_direction))
    fail("count_u = " + std::to_string(count_u) + ", count_v = " + std::to_string(count_v) +
         ": each must be in [degree + 1, max_count_per_direction] = [" +
         std::to_string(degree + 1) + ", " + std::to_string(max_count_per_direction) + "]");
  if (!(certificate_share > 0 && certificate_share < 1))
    fail("certificate_share = " + format(certificate_share) + ": must be in (0, 1), e.g. 0.1");
  if (!(matched_curvature >= 0 && matched_curvature < 1))
    fail("matched_curvature = " + format(matched_curvature) +
         ": must be in [0, 1), a fraction of the normal curvature (0.002; 0: no curvature rows)");
  if (!matched_curves.empty()) {
    if (!(matched_gap_mm > 0 && std::isfinite(matched_gap_mm)) ||
        !(matched_angle_deg > 0 && matched_angle_deg < 90))
      fail("matched_gap_mm = " + format(matched_gap_mm) +
           ", matched_angle_deg = " + format(matched_angle_deg) +
           ": with matched_curves both must be given, a gap > 0 mm and an angle in (0, 90) deg "
           "(class A: 0.0005 mm and 0.008 deg per face)");
    for (std::size_t k = 0; k < matched_curves.size(); ++k) {
      const MatchedCurve& c = matched_curves[k];
      const std::string name = "matched_curves[" + std::to_string(k) + "]";
      for (const std::string& problem : surface::problems(c.pcurve, name + ".pcurve"))
        fail(problem);
      const auto [a, b] = c.pcurve.basis.domain();
      if (!(std::isfinite(c.t0) && std::isfinite(c.t1) && c.t0 < c.t1 && c.t0 >= a && c.t1 <= b))
        fail(name + ": t0 = " + format(c.t0) + ", t1 = " + format(c.t1) +
             ": must be finite, t0 < t1, within the pcurve's domain [" + format(a) + ", " +
             format(b) + "]");
    }
  }
  return out;
}

void RefitOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string RefitReport::brief() const {
  char buffer[256];
  if (certified) {
    std::snprintf(buffer, sizeof buffer, "certified %.3g mm %s %.3g mm (sampled %.3g mm)",
                  certified_bound_mm, certified_bound_mm <= tolerance_mm ? "<=" : ">", tolerance_mm,
                  sampled_max);
  } else {
    std::snprintf(buffer, sizeof buffer, "not certified, sampled %.3g mm %s %.3g mm", sampled_max,
                  sampled_max <= tolerance_mm ? "<=" : ">", tolerance_mm);
  }
  std::string line = buffer;
  std::snprintf(buffer, sizeof buffer,
                ", %d + %d knots added, %d iterations, %zu knot-plane crossings", knots_added_u,
                knots_added_v, summary.iterations, crossings.size());
  return line + buffer;
}

namespace {

// Every deformation kind: validated, then fitted and certified by its certifier.
template <class D>
RefitResult refit_validated(const BSplineSurface& surface, const D& deformation,
                            const RefitOptions& options) {
  validate(deformation);
  return refit(surface, certifier(deformation), options);
}

}  // namespace

RefitResult refit_surface(const BSplineSurface& surface, const RefitOptions& options) {
  // The identity: |D'| = 1, D'' = 0 everywhere, so the certificate's Taylor remainder holds.
  Certifier identity{"identity map",
                     [](const Eigen::Vector3d& x) { return x; },
                     [](const Points3&) {
                       HullInfo info;
                       info.bounds = {1.0, 0.0};
                       return info;
                     },
                     {}};
  return refit(surface, identity, options);
}

RefitResult refit_deformed(const SpaceMap& map, const BSplineSurface& surface,
                           const RefitOptions& options) {
  if (const auto* point_map = std::get_if<PointMap>(&map)) {
    if (!*point_map)
      throw Error(ErrorCategory::InvalidArgument,
                  "refit_deformed: the point map is empty; pass a callable Eigen::Vector3d -> "
                  "Eigen::Vector3d");
    return refit(surface,
                 {"point map", *point_map, {}, "nothing is known of a point map's derivatives"},
                 options);
  }
  if (const auto* stack = std::get_if<DeformationStack>(&map))
    return refit_validated(surface, *stack, options);
  return std::visit(
      [&](const auto& deformation) { return refit_validated(surface, deformation, options); },
      std::get<Deformation>(map));
}

}  // namespace clay::deform
