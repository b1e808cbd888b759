#include <clay/surface/knots.hpp>

#include <clay/error.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "net_rows.hpp"

namespace clay::surface {
namespace detail {

void insert_knot(Strip& strip, double t, int times) {
  for (int r = 0; r < times; ++r) {
    const BSplineBasis& b = strip.basis;
    const int p = b.degree;
    const int n = b.count();
    const int k = find_span(b, t);
    const auto& U = b.knots;
    Rows q(n + 1, strip.rows.cols());
    q.topRows(k - p + 1) = strip.rows.topRows(k - p + 1);
    for (int i = k - p + 1; i <= k; ++i) {
      // Boehm: Q_i = a_i P_i + (1 - a_i) P_{i-1}, a_i = (t - u_i) / (u_{i+p} - u_i)  (A5.1)
      const double a = (t - U[static_cast<size_t>(i)]) /
                       (U[static_cast<size_t>(i + p)] - U[static_cast<size_t>(i)]);
      q.row(i) = a * strip.rows.row(i) + (1.0 - a) * strip.rows.row(i - 1);
    }
    q.bottomRows(n - k) = strip.rows.bottomRows(n - k);
    strip.basis.knots.insert(strip.basis.knots.begin() + k + 1, t);
    strip.rows = std::move(q);
  }
}

void refine_knots(Strip& strip, std::vector<double> X) {
  if (X.empty()) return;
  // Knot refinement (The NURBS Book A5.4); n is the last control point index.
  const BSplineBasis& basis = strip.basis;
  const int p = basis.degree;
  const int n = basis.count() - 1;
  const int m = n + p + 1;
  const int r = static_cast<int>(X.size()) - 1;
  const std::vector<double>& U = basis.knots;
  const Rows& P = strip.rows;
  const int a = find_span(basis, X.front());
  const int b = find_span(basis, X.back()) + 1;
  Rows Q(n + r + 2, P.cols());
  std::vector<double> Ubar(static_cast<size_t>(m + r + 2));
  for (int j = 0; j <= a - p; ++j) Q.row(j) = P.row(j);
  for (int j = b - 1; j <= n; ++j) Q.row(j + r + 1) = P.row(j);
  for (int j = 0; j <= a; ++j) Ubar[static_cast<size_t>(j)] = U[static_cast<size_t>(j)];
  for (int j = b + p; j <= m; ++j) Ubar[static_cast<size_t>(j + r + 1)] = U[static_cast<size_t>(j)];
  int i = b + p - 1;
  int k = b + p + r;
  for (int j = r; j >= 0; --j) {
    const double x = X[static_cast<size_t>(j)];
    while (x <= U[static_cast<size_t>(i)] && i > a) {
      Q.row(k - p - 1) = P.row(i - p - 1);
      Ubar[static_cast<size_t>(k)] = U[static_cast<size_t>(i)];
      --k;
      --i;
    }
    Q.row(k - p - 1) = Q.row(k - p);
    for (int l = 1; l <= p; ++l) {
      const int ind = k - p + l;
      double alfa = Ubar[static_cast<size_t>(k + l)] - x;
      if (alfa == 0.0) {
        Q.row(ind - 1) = Q.row(ind);
      } else {
        // The book prints U[i-l+1] here; the correct left knot is U[i-p+l] (known erratum).
        alfa /= Ubar[static_cast<size_t>(k + l)] - U[static_cast<size_t>(i - p + l)];
        Q.row(ind - 1) = alfa * Q.row(ind - 1) + (1.0 - alfa) * Q.row(ind);
      }
    }
    Ubar[static_cast<size_t>(k)] = x;
    --k;
  }
  strip.basis.knots = std::move(Ubar);
  strip.rows = std::move(Q);
}

std::vector<double> bezier_refinement_knots(const BSplineBasis& basis) {
  std::vector<double> extra;
  for (double xi : breakpoints(basis)) {
    const int missing = basis.degree - multiplicity(basis, xi);
    for (int k = 0; k < missing; ++k) extra.push_back(xi);
  }
  return extra;
}

}  // namespace detail

namespace {

using detail::Direction;

std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

/// Checks that inserting `knots` keeps the basis valid; throws naming the knot otherwise.
std::vector<double> checked_knots(const BSplineBasis& basis, std::span<const double> knots,
                                  std::string_view what) {
  std::vector<double> sorted(knots.begin(), knots.end());
  std::sort(sorted.begin(), sorted.end());
  const auto [a, b] = basis.domain();
  for (size_t k = 0; k < sorted.size();) {
    const double t = sorted[k];
    if (!(t >= a && t <= b))
      throw Error(ErrorCategory::OutOfDomain, std::string(what) + ": knot " + number(t) +
                                                  " is outside the domain [" + number(a) + ", " +
                                                  number(b) + "]; insert knots inside the domain");
    size_t e = k;
    while (e < sorted.size() && sorted[e] == t) ++e;
    const int added = static_cast<int>(e - k);
    const bool outermost = (t == basis.knots.front() || t == basis.knots.back());
    const int limit = basis.degree + (outermost ? 1 : 0);
    const int now = multiplicity(basis, t);
    if (now + added > limit)
      throw Error(ErrorCategory::InvalidArgument,
                  std::string(what) + ": inserting knot " + number(t) + " " +
                      std::to_string(added) + " time(s) gives multiplicity " +
                      std::to_string(now + added) + ", above " + std::to_string(limit) +
                      " (degree " + std::to_string(basis.degree) + "); insert it at most " +
                      std::to_string(std::max(0, limit - now)) + " time(s)");
    k = e;
  }
  return sorted;
}

void check_times(int times, std::string_view what) {
  if (times < 0)
    throw Error(
        ErrorCategory::InvalidArgument,
        std::string(what) + ": times = " + std::to_string(times) + " is negative; give times >= 0");
}

BSplineSurface insert_in(const BSplineSurface& s, Direction d, double t, int times,
                         const char* what) {
  validate(s);
  check_times(times, what);
  const std::vector<double> request(static_cast<size_t>(times), t);
  checked_knots(d == Direction::U ? s.u : s.v, request, what);
  return detail::apply_in_direction(
      s, d, [&](detail::Strip& strip) { detail::insert_knot(strip, t, times); });
}

BSplineSurface refine_in(const BSplineSurface& s, Direction d, std::span<const double> knots,
                         const char* what) {
  validate(s);
  auto sorted = checked_knots(d == Direction::U ? s.u : s.v, knots, what);
  return detail::apply_in_direction(
      s, d, [&](detail::Strip& strip) { detail::refine_knots(strip, std::move(sorted)); });
}

/// Rows k-p..k of the Bézier-refined strip for each span, with the span's clamped basis.
std::vector<detail::Strip> bezier_strips(const detail::Strip& refined) {
  const BSplineBasis& b = refined.basis;
  const int p = b.degree;
  const auto breaks = breakpoints(b);
  std::vector<detail::Strip> out;
  for (size_t s = 0; s + 1 < breaks.size(); ++s) {
    const int k = find_span(b, breaks[s]);  // u_k = breaks[s] < u_{k+1}
    detail::Strip seg;
    seg.basis.degree = p;
    seg.basis.knots.assign(static_cast<size_t>(p + 1), breaks[s]);
    seg.basis.knots.insert(seg.basis.knots.end(), static_cast<size_t>(p + 1), breaks[s + 1]);
    seg.rows = refined.rows.middleRows(k - p, p + 1);
    seg.polynomial = refined.polynomial;
    out.push_back(std::move(seg));
  }
  return out;
}

}  // namespace

BSplineCurve insert_knot(const BSplineCurve& curve, double t, int times) {
  validate(curve);
  check_times(times, "insert_knot");
  checked_knots(curve.basis, std::vector<double>(static_cast<size_t>(times), t), "insert_knot");
  detail::Strip strip = detail::curve_strip(curve);
  detail::insert_knot(strip, t, times);
  return detail::curve_from_strip(std::move(strip));
}

BSplineSurface insert_knot_u(const BSplineSurface& surface, double u, int times) {
  return insert_in(surface, Direction::U, u, times, "insert_knot_u");
}

BSplineSurface insert_knot_v(const BSplineSurface& surface, double v, int times) {
  return insert_in(surface, Direction::V, v, times, "insert_knot_v");
}

BSplineSurface restricted(const BSplineSurface& surface, double u0, double u1, double v0,
                          double v1) {
  validate(surface);
  auto check = [](const BSplineBasis& b, double lo, double hi, const char* name) {
    const auto [a, c] = b.domain();
    if (!(lo >= a && hi <= c && lo < hi))
      throw Error(ErrorCategory::InvalidArgument,
                  std::string("restricted: the ") + name + " range [" + std::to_string(lo) + ", " +
                      std::to_string(hi) + "] is not a non-empty part of the domain [" +
                      std::to_string(a) + ", " + std::to_string(c) + "]");
    if (!is_clamped(b))
      throw Error(
          ErrorCategory::InvalidArgument,
          std::string("restricted: the ") + name +
              " basis is not clamped; clamp it first (its ends of multiplicity degree + 1)");
  };
  check(surface.u, u0, u1, "u");
  check(surface.v, v0, v1, "v");
  BSplineSurface s = surface;
  // Each cut to multiplicity degree (the ends are clamped already).
  for (const double u : {u0, u1}) {
    const int have = multiplicity(s.u, u);
    if (have < s.u.degree) s = insert_knot_u(s, u, s.u.degree - have);
  }
  for (const double v : {v0, v1}) {
    const int have = multiplicity(s.v, v);
    if (have < s.v.degree) s = insert_knot_v(s, v, s.v.degree - have);
  }
  // The kept knots: lo once more, the last `degree` copies of lo .. the first `degree` of hi, hi
  // once more; the control points from one before the first kept copy of lo.
  struct Cut {
    BSplineBasis basis;
    int first = 0, count = 0;
  };
  auto cut = [](const BSplineBasis& b, double lo, double hi) {
    const int p = b.degree;
    const auto& k = b.knots;
    const int last_lo = static_cast<int>(std::upper_bound(k.begin(), k.end(), lo) - k.begin()) - 1;
    const int first_hi = static_cast<int>(std::lower_bound(k.begin(), k.end(), hi) - k.begin());
    const int start = last_lo - p + 1;
    Cut c;
    c.basis.degree = p;
    c.basis.knots.push_back(lo);
    c.basis.knots.insert(c.basis.knots.end(), k.begin() + start, k.begin() + first_hi + p);
    c.basis.knots.push_back(hi);
    c.first = start - 1;
    c.count = first_hi - start + 1;
    return c;
  };
  const Cut cu = cut(s.u, u0, u1), cv = cut(s.v, v0, v1);
  Points3 points(static_cast<Eigen::Index>(cu.count) * cv.count, 3);
  Eigen::VectorXd weights(points.rows());
  for (int i = 0; i < cu.count; ++i)
    for (int j = 0; j < cv.count; ++j) {
      const Eigen::Index to = static_cast<Eigen::Index>(i) * cv.count + j;
      const Eigen::Index from = s.index(cu.first + i, cv.first + j);
      points.row(to) = s.points.row(from);
      weights(to) = s.weights(from);
    }
  return make_surface(cu.basis, cv.basis, std::move(points), std::move(weights));
}

BSplineCurve refine_knots(const BSplineCurve& curve, std::span<const double> knots) {
  validate(curve);
  auto sorted = checked_knots(curve.basis, knots, "refine_knots");
  detail::Strip strip = detail::curve_strip(curve);
  detail::refine_knots(strip, std::move(sorted));
  return detail::curve_from_strip(std::move(strip));
}

BSplineSurface refine_knots_u(const BSplineSurface& surface, std::span<const double> knots) {
  return refine_in(surface, Direction::U, knots, "refine_knots_u");
}

BSplineSurface refine_knots_v(const BSplineSurface& surface, std::span<const double> knots) {
  return refine_in(surface, Direction::V, knots, "refine_knots_v");
}

std::vector<BSplineCurve> extract_bezier(const BSplineCurve& curve) {
  validate(curve);
  detail::Strip strip = detail::curve_strip(curve);
  detail::refine_knots(strip, detail::bezier_refinement_knots(strip.basis));
  std::vector<BSplineCurve> out;
  for (auto& seg : bezier_strips(strip)) out.push_back(detail::curve_from_strip(std::move(seg)));
  return out;
}

std::vector<SpanExtraction> bezier_extraction(const BSplineBasis& basis) {
  validate(basis, "bezier_extraction basis");
  // The same refinement as extract_bezier, applied to the identity: row r of a span's strip is
  // then Bézier point r as a combination of the original control points.
  const int n = basis.count(), p = basis.degree;
  detail::Strip strip{basis, detail::Rows::Identity(n, n), false};
  detail::refine_knots(strip, detail::bezier_refinement_knots(strip.basis));
  const std::vector<double> breaks = breakpoints(basis);
  const std::vector<detail::Strip> spans = bezier_strips(strip);
  std::vector<SpanExtraction> out(spans.size());
  for (size_t s = 0; s < spans.size(); ++s) {
    SpanExtraction& e = out[s];
    e.a = breaks[s];
    e.b = breaks[s + 1];
    e.first = find_span(basis, e.a) - p;
    e.matrix = spans[s].rows.middleCols(e.first, p + 1);
  }
  return out;
}

BezierPatches extract_bezier(const BSplineSurface& surface) {
  validate(surface);
  BezierPatches out;
  out.breaks_u = breakpoints(surface.u);
  out.breaks_v = breakpoints(surface.v);
  // Refine both directions to Bézier form, then cut u-strips and each of those into v-strips.
  BSplineSurface refined = detail::apply_in_direction(surface, Direction::U, [](detail::Strip& s) {
    detail::refine_knots(s, detail::bezier_refinement_knots(s.basis));
  });
  refined = detail::apply_in_direction(refined, Direction::V, [](detail::Strip& s) {
    detail::refine_knots(s, detail::bezier_refinement_knots(s.basis));
  });
  const auto u_strips = bezier_strips(detail::surface_strip(refined, Direction::U));
  for (const auto& us : u_strips) {
    const BSplineSurface band = detail::surface_from_strip(us, refined.v, Direction::U);
    for (auto& vs : bezier_strips(detail::surface_strip(band, Direction::V)))
      out.patches.push_back(detail::surface_from_strip(std::move(vs), band.u, Direction::V));
  }
  return out;
}

}  // namespace clay::surface
