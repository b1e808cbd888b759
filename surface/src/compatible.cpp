// Compatible curves (one degree, one knot vector) for skinning and filling, with the slivers of
// the knot union merged: two curves fitted independently put knots at 0.50057 and 0.50089, the
// union then has a span 1/3,000 of its neighbours, and a surface built on it creases where a
// later refinement crowds knots into that span (issue #21).
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/skin.hpp>
#include <clay/tolerance.hpp>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include <clay/surface/detail/builder_tools.hpp>
#include "curve_fit.hpp"
#include "homogeneous.hpp"

namespace clay::surface {
namespace {

using detail::normalized;

std::string num(double x) { return detail::short_number(x); }

std::string curve_label(const std::vector<std::string>& names, size_t k) {
  return k < names.size() ? names[k] : "curve #" + std::to_string(k);
}

/// Every curve clamped, on [0, 1] and at the highest degree of all.
std::vector<BSplineCurve> common_degree(const std::vector<BSplineCurve>& curves,
                                        const std::vector<std::string>& names) {
  if (curves.empty())
    throw Error(ErrorCategory::InvalidArgument,
                "make_compatible: no curves given; give at least one");
  std::vector<BSplineCurve> out;
  int degree = 1;
  for (size_t k = 0; k < curves.size(); ++k) {
    validate(curves[k], curve_label(names, k));
    out.push_back(normalized(curves[k]));
    degree = std::max(degree, curves[k].basis.degree);
  }
  for (BSplineCurve& c : out)
    if (c.basis.degree < degree) c = elevate_degree(c, degree - c.basis.degree);
  return out;
}

/// The curves refined to the union of their knot vectors (values within 1e-12 are one).
std::vector<BSplineCurve> refined_to_union(std::vector<BSplineCurve> out,
                                           const std::vector<BSplineCurve>& inputs,
                                           const std::vector<std::string>& names) {
  struct Knot {
    double value;
    size_t curve;
  };
  std::vector<Knot> all;
  for (size_t k = 0; k < out.size(); ++k)
    for (double t : out[k].basis.knots)
      if (t > 0.0 && t < 1.0) all.push_back({t, k});
  std::sort(all.begin(), all.end(), [](const Knot& a, const Knot& b) { return a.value < b.value; });
  std::vector<std::vector<double>> snapped(out.size());
  std::vector<std::vector<double>> missing(out.size());
  for (size_t i = 0; i < all.size();) {
    const double representative = all[i].value;
    size_t e = i;
    std::vector<int> mult(out.size(), 0);
    while (e < all.size() && all[e].value - representative <= tolerance::knot_relative) {
      ++mult[all[e].curve];
      ++e;
    }
    const int target = *std::max_element(mult.begin(), mult.end());
    for (size_t k = 0; k < out.size(); ++k)
      for (int r = mult[k]; r < target; ++r) missing[k].push_back(representative);
    for (size_t j = i; j < e; ++j) snapped[all[j].curve].push_back(representative);
    i = e;
  }
  for (size_t k = 0; k < out.size(); ++k) {
    // Snap this curve's interior knots to their cluster's value (a change of at most 1e-12).
    size_t next = 0;
    for (double& t : out[k].basis.knots)
      if (t > 0.0 && t < 1.0) t = snapped[k][next++];
    validate(out[k], curve_label(names, k));
    if (!missing[k].empty()) out[k] = refine_knots(out[k], missing[k]);
    if (!inputs[k].is_rational()) out[k].weights.setOnes();
  }
  for (size_t k = 1; k < out.size(); ++k)
    if (out[k].basis.knots != out[0].basis.knots)
      throw Error(ErrorCategory::Internal,
                  "make_compatible: " + curve_label(names, k) +
                      " did not reach the common knot vector (please report this input)");
  return out;
}

// ---- sliver merging ----------------------------------------------------------------------------

/// A breakpoint of the union and the curves that have it (every curve has the ends 0 and 1).
struct Break {
  double value = 0;
  std::vector<int> owners;
};

bool has_knot(const BSplineCurve& c, double x) {
  if (x <= 0.0 || x >= 1.0) return true;
  for (double t : c.basis.knots)
    if (std::abs(t - x) <= tolerance::knot_relative) return true;
  return false;
}

std::vector<Break> union_breaks(const std::vector<BSplineCurve>& curves) {
  std::vector<std::pair<double, int>> all;
  for (size_t k = 0; k < curves.size(); ++k)
    for (double t : curves[k].basis.knots)
      if (t > 0.0 && t < 1.0) all.emplace_back(t, static_cast<int>(k));
  std::sort(all.begin(), all.end());
  std::vector<int> everyone(curves.size());
  for (size_t k = 0; k < curves.size(); ++k) everyone[k] = static_cast<int>(k);
  std::vector<Break> out{{0.0, everyone}};
  for (size_t i = 0; i < all.size();) {
    Break b{all[i].first, {}};
    for (; i < all.size() && all[i].first - b.value <= tolerance::knot_relative; ++i)
      if (std::find(b.owners.begin(), b.owners.end(), all[i].second) == b.owners.end())
        b.owners.push_back(all[i].second);
    out.push_back(std::move(b));
  }
  out.push_back({1.0, everyone});
  return out;
}

/// Span lengths' ratio to the longer neighbour, for spans [x_i, x_{i+1}] of sorted breakpoints.
std::vector<double> span_ratios(const std::vector<double>& x) {
  std::vector<double> ratio(x.size() - 1, 1.0);
  for (size_t i = 0; i + 1 < x.size(); ++i) {
    double neighbour = 0;
    if (i > 0) neighbour = std::max(neighbour, x[i] - x[i - 1]);
    if (i + 2 < x.size()) neighbour = std::max(neighbour, x[i + 2] - x[i + 1]);
    if (neighbour > 0) ratio[i] = (x[i + 1] - x[i]) / neighbour;
  }
  return ratio;
}

/// The C2 quintic step 6s^5 - 15s^4 + 10s^3: 0 at 0, 1 at 1, first and second derivatives 0 at
/// both; its slope is at most 15/8.
double quintic_step(double s) { return s * s * s * (10.0 + s * (-15.0 + 6.0 * s)); }

/// phi(t) = t + (from - to) h(t): the identity outside [lo, hi], `to` mapped to `from`.
double reparametrize(const KnotMerge& m, double t) {
  if (!m.reparametrized || t <= m.lo || t >= m.hi) return t;
  const double s = t < m.to ? (t - m.lo) / (m.to - m.lo) : (m.hi - t) / (m.hi - m.to);
  return t + (m.from - m.to) * quintic_step(s);
}

Eigen::Vector4d homogeneous_at(const BSplineCurve& c, double t) {
  const int p = c.basis.degree;
  const int span = find_span(c.basis, std::clamp(t, 0.0, 1.0));
  double values[max_kernel_degree + 1];
  basis_functions(c.basis, span, std::clamp(t, 0.0, 1.0), std::span<double>(values, p + 1));
  Eigen::Vector4d h = Eigen::Vector4d::Zero();
  for (int j = 0; j <= p; ++j) {
    const Eigen::Index i = span - p + j;
    const double w = c.weights[i];
    h.head<3>() += values[j] * w * c.points.row(i).transpose();
    h[3] += values[j] * w;
  }
  return h;
}

std::vector<double> merged_breaks(const BSplineBasis& a, const BSplineBasis& b) {
  std::vector<double> x = breakpoints(a);
  const std::vector<double> y = breakpoints(b);
  x.insert(x.end(), y.begin(), y.end());
  std::sort(x.begin(), x.end());
  x.erase(std::unique(x.begin(), x.end()), x.end());
  return x;
}

/// The least-squares fit of old(phi(t)) on `basis` at Chebyshev–Lobatto parameters, 2 (p + 1)
/// per span of both bases, end points kept; its largest deviation from old(phi(t)) at 16
/// samples per span. A rational fit whose weights are not all positive fails (deviation inf).
struct Fit {
  BSplineCurve curve;
  double deviation = INFINITY;
};
Fit fit_on(const BSplineCurve& old, const BSplineBasis& basis, const KnotMerge& m) {
  const int p = basis.degree;
  const int n = basis.count();
  const bool rational = old.is_rational();
  const int dims = rational ? 4 : 3;
  const std::vector<double> breaks = merged_breaks(old.basis, basis);
  // Ends kept: the homogeneous points of the old curve at 0 and 1 (phi fixes both).
  const Eigen::MatrixXd net =
      detail::fit_with_ends(basis, detail::lobatto_parameters(breaks, 2 * (p + 1)), [&](double t) {
        return Eigen::RowVectorXd(homogeneous_at(old, reparametrize(m, t)).head(dims).transpose());
      });
  Fit out;
  out.curve.basis = basis;
  if (rational) {
    if (!(net.col(3).minCoeff() > 0)) return out;
    detail::Homogeneous h = net;
    detail::from_homogeneous(h, out.curve.points, out.curve.weights);
  } else {
    out.curve.points = net;
    out.curve.weights = Eigen::VectorXd::Ones(n);
  }
  out.deviation = 0;
  for (size_t s = 0; s + 1 < breaks.size(); ++s)
    for (int k = 0; k <= 16; ++k) {
      const double u = breaks[s] + (breaks[s + 1] - breaks[s]) * k / 16.0;
      out.deviation = std::max(
          out.deviation, (evaluate(out.curve, u) - evaluate(old, reparametrize(m, u))).norm());
    }
  return out;
}

/// One way to merge a sliver: knot `from` moved onto `to` in every curve that has it.
struct Attempt {
  bool ok = true;
  double cost = 0;                  // largest deviation of a moved curve
  std::vector<BSplineCurve> moved;  // one per merge
  std::vector<KnotMerge> merges;
  int failing = -1;  // the curve that could not move within its budget
  double failing_deviation = 0;
};

Attempt try_merge(const std::vector<BSplineCurve>& curves, const Break& from, double to,
                  const std::vector<double>& used, double tolerance,
                  const std::vector<double>& union_values, double min_span_ratio) {
  Attempt out;
  for (int k : from.owners) {
    const BSplineCurve& c = curves[static_cast<size_t>(k)];
    const double budget = tolerance - used[static_cast<size_t>(k)];
    KnotMerge m;
    m.curve = k;
    m.from = from.value;
    m.to = to;
    m.removed = has_knot(c, to);
    BSplineBasis basis = c.basis;
    std::vector<double> kept;
    for (double t : basis.knots)
      if (std::abs(t - from.value) > tolerance::knot_relative)
        kept.push_back(t);
      else if (!m.removed)
        kept.push_back(to);
    basis.knots = kept;
    std::sort(basis.knots.begin(), basis.knots.end());
    if (basis.count() <= basis.degree) {  // nothing left to fit: the curve needs this knot
      out.ok = false;
      out.failing = k;
      out.failing_deviation = INFINITY;
      return out;
    }
    Fit fit = fit_on(c, basis, m);
    if (!(fit.deviation <= budget) && !m.removed) {
      // The knot carries shape: move the curve's own break onto `to` by reparametrizing
      // between its neighbouring knots, where phi stays monotone.
      const std::vector<double> own = breakpoints(c.basis);
      KnotMerge r = m;
      r.reparametrized = true;
      r.lo = 0.0, r.hi = 1.0;
      for (double x : own) {
        if (x < from.value - tolerance::knot_relative) r.lo = x;
        if (x > from.value + tolerance::knot_relative) {
          r.hi = x;
          break;
        }
      }
      const double room = std::min(r.to - r.lo, r.hi - r.to);
      if (std::abs(r.from - r.to) * 15.0 / 8.0 < 0.5 * room) {
        // The fit of old(phi(t)) misses by about |from - to| |C'| times the relative error of a
        // degree-p fit of the quintic step on a span (a few %): halve the two spans (up to 3
        // times, 14 knots) while no new knot makes a sliver of the union.
        for (int level = 0; level <= 3 && !(fit.deviation <= budget); ++level) {
          BSplineBasis refined = basis;
          std::vector<double> added;
          const int parts = 1 << level;
          // The union without `from`: a new knot near one of its values takes that value (no new
          // breakpoint); the others must not make a sliver with their neighbours.
          std::vector<double> y;
          for (double v : union_values)
            if (std::abs(v - r.from) > tolerance::knot_relative) y.push_back(v);
          std::vector<double> fresh;
          for (const auto& [a, b] : {std::pair{r.lo, r.to}, std::pair{r.to, r.hi}})
            for (int j = 1; j < parts; ++j) {
              const double step = (b - a) / parts, t = a + step * j;
              const auto near = std::min_element(y.begin(), y.end(), [&](double p, double q) {
                return std::abs(p - t) < std::abs(q - t);
              });
              if (std::abs(*near - t) < 0.25 * step && *near > r.lo && *near < r.hi &&
                  *near != r.to)
                added.push_back(*near);
              else
                added.push_back(t), fresh.push_back(t);
            }
          if (!fresh.empty()) {
            y.insert(y.end(), fresh.begin(), fresh.end());
            std::sort(y.begin(), y.end());
            const std::vector<double> ratio = span_ratios(y);
            bool sliver = false;
            for (size_t i = 0; i < ratio.size(); ++i)
              if (ratio[i] < min_span_ratio && (std::count(fresh.begin(), fresh.end(), y[i]) ||
                                                std::count(fresh.begin(), fresh.end(), y[i + 1])))
                sliver = true;
            if (sliver) break;
          }
          std::sort(added.begin(), added.end());
          added.erase(std::unique(added.begin(), added.end()), added.end());
          refined.knots.insert(refined.knots.end(), added.begin(), added.end());
          std::sort(refined.knots.begin(), refined.knots.end());
          Fit moved = fit_on(c, refined, r);
          if (moved.deviation < fit.deviation) {
            fit = std::move(moved);
            m = r;
            m.knots_added = static_cast<int>(added.size());
          }
        }
      }
    }
    m.deviation_mm = fit.deviation;
    if (!(fit.deviation <= budget)) {
      out.ok = false;
      out.failing = k;
      out.failing_deviation = fit.deviation;
      return out;
    }
    out.cost = std::max(out.cost, fit.deviation);
    out.moved.push_back(std::move(fit.curve));
    out.merges.push_back(m);
  }
  return out;
}

}  // namespace

std::vector<std::string> KnotMergeOptions::problems() const {
  std::vector<std::string> out;
  if (!(min_span_ratio >= 0.0 && min_span_ratio < 0.5))
    out.push_back("KnotMergeOptions::min_span_ratio is " + num(min_span_ratio) +
                  "; it must be in [0, 0.5) (0 keeps every span)");
  if (!(tolerance_mm > 0.0 && std::isfinite(tolerance_mm)))
    out.push_back("KnotMergeOptions::tolerance_mm is " + num(tolerance_mm) +
                  "; it must be > 0 and finite");
  return out;
}

void KnotMergeOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::vector<BSplineCurve> make_compatible(const std::vector<BSplineCurve>& curves) {
  return refined_to_union(common_degree(curves, {}), curves, {});
}

CompatibleCurves make_compatible(const std::vector<BSplineCurve>& curves,
                                 const KnotMergeOptions& options,
                                 const std::vector<std::string>& names) {
  options.validate();
  CompatibleCurves out;
  std::vector<BSplineCurve> work = common_degree(curves, names);
  std::vector<double> used(work.size(), 0.0);
  // Each merge takes one breakpoint out of the union, so this ends.
  while (options.min_span_ratio > 0) {
    const std::vector<Break> breaks = union_breaks(work);
    std::vector<double> x;
    for (const Break& b : breaks) x.push_back(b.value);
    const std::vector<double> ratio = span_ratios(x);
    const auto worst = std::min_element(ratio.begin(), ratio.end());
    if (*worst >= options.min_span_ratio) break;
    const size_t i = static_cast<size_t>(worst - ratio.begin());
    const Break& left = breaks[i];
    const Break& right = breaks[i + 1];
    Attempt best;
    best.ok = false;
    std::vector<Attempt> tried;
    if (i + 1 + 1 < breaks.size())  // the right knot is interior: move it left
      tried.push_back(try_merge(work, right, left.value, used, options.tolerance_mm, x,
                                options.min_span_ratio));
    if (i > 0)
      tried.push_back(try_merge(work, left, right.value, used, options.tolerance_mm, x,
                                options.min_span_ratio));
    for (Attempt& a : tried)
      if (a.ok && (!best.ok || a.cost < best.cost)) best = std::move(a);
    if (!best.ok) {
      const Break& who = left.value > 0 ? left : right;
      const Attempt* least = nullptr;
      for (const Attempt& a : tried)
        if (!least || a.failing_deviation < least->failing_deviation) least = &a;
      throw Error(ErrorCategory::InvalidGeometry,
                  "make_compatible: the knots " + num(left.value) + " and " + num(right.value) +
                      " (of " + curve_label(names, static_cast<size_t>(who.owners.front())) +
                      (right.owners.front() != who.owners.front()
                           ? " and " + curve_label(names, static_cast<size_t>(right.owners.front()))
                           : std::string()) +
                      ") make a span " + num(*worst) + " of its neighbour's length, below " +
                      num(options.min_span_ratio) + "; merging them would move " +
                      (least && least->failing >= 0
                           ? curve_label(names, static_cast<size_t>(least->failing)) + " by " +
                                 num(least->failing_deviation) + " mm"
                           : std::string("a curve")) +
                      ", more than the tolerance " + num(options.tolerance_mm) +
                      " mm: raise the merge tolerance, or keep the sliver with min_span_ratio 0");
    }
    for (size_t j = 0; j < best.merges.size(); ++j) {
      const auto k = static_cast<size_t>(best.merges[j].curve);
      work[k] = std::move(best.moved[j]);
      used[k] += best.merges[j].deviation_mm;
      out.merges.push_back(best.merges[j]);
    }
  }
  for (double u : used) out.max_deviation_mm = std::max(out.max_deviation_mm, u);
  out.curves = refined_to_union(std::move(work), curves, names);
  return out;
}

double input_parameter(const CompatibleCurves& result, int curve, double t) {
  for (auto m = result.merges.rbegin(); m != result.merges.rend(); ++m)
    if (m->curve == curve) t = reparametrize(*m, t);
  return t;
}

double smallest_span_ratio(const BSplineBasis& basis) {
  const std::vector<double> ratio = span_ratios(breakpoints(basis));
  return *std::min_element(ratio.begin(), ratio.end());
}

}  // namespace clay::surface
