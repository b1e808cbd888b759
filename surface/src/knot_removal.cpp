// Knot removal (The NURBS Book A5.8), on strips of homogeneous control points, so one routine
// serves curves and both directions of a surface. Moved here from the exact composition, which
// joins Bézier patches with full-multiplicity knots and then removes every knot it can.
#include <clay/surface/knots.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "net_rows.hpp"

namespace clay::surface {
namespace detail {
namespace {

/// Largest norm of the 4-wide homogeneous blocks of a strip row (one control point of the other
/// direction each).
double block_norm(const Eigen::Ref<const Eigen::RowVectorXd>& row) {
  double worst = 0;
  for (Eigen::Index c = 0; c + 3 < row.size(); c += 4)
    worst = std::max(worst, row.segment<4>(c).norm());
  return worst;
}

/// Removes the knot at index r (its last occurrence, multiplicity s) once, when the control
/// points allow it within `tolerance` (A5.8, one removal). Returns the gap (>= 0) when removed,
/// -1 when not (the strip is then unchanged).
double remove_knot_once(Strip& strip, int r, int s, double tolerance) {
  const int p = strip.basis.degree;
  const std::vector<double>& U = strip.basis.knots;
  const double u = U[static_cast<size_t>(r)];
  const int first = r - p, last = r - s, off = first - 1;
  const Rows& P = strip.rows;
  Rows t(last - off + 2, P.cols());
  auto alpha = [&](int i) {
    return (u - U[static_cast<size_t>(i)]) /
           (U[static_cast<size_t>(i + p + 1)] - U[static_cast<size_t>(i)]);
  };
  t.row(0) = P.row(off);
  t.row(last + 1 - off) = P.row(last + 1);
  int i = first, j = last, ii = 1, jj = last - off;
  while (j - i > 0) {  // the new points from both ends towards the middle
    const double ai = alpha(i), aj = alpha(j);
    t.row(ii) = (P.row(i) - (1 - ai) * t.row(ii - 1)) / ai;
    t.row(jj) = (P.row(j) - aj * t.row(jj + 1)) / (1 - aj);
    ++i, ++ii, --j, --jj;
  }
  double gap;
  if (j - i < 0) {
    gap = block_norm(t.row(ii - 1) - t.row(jj + 1));
  } else {
    const double ai = alpha(i);
    gap = block_norm(P.row(i) - (ai * t.row(ii + 1) + (1 - ai) * t.row(ii - 1)));
  }
  if (!(gap <= tolerance)) return -1;
  // The gap is a homogeneous norm, so a removal can meet it and still leave a weight at zero or
  // below: an I-DEAS cone whose apex row carries weights unlike its base row gave a weight of
  // -1e-17 after composition, which made the surface invalid. Such a removal is refused.
  if (!strip.polynomial) {
    double largest = 0;
    for (Eigen::Index r0 = off; r0 <= last + 1; ++r0)
      for (Eigen::Index c = 3; c < P.cols(); c += 4) largest = std::max(largest, P(r0, c));
    for (int a = first, b = last; b - a > 0; ++a, --b)  // the rows the removal writes
      for (Eigen::Index c = 3; c < t.cols(); c += 4)
        if (!(t(a - off, c) > 1e-12 * largest) || !(t(b - off, c) > 1e-12 * largest)) return -1;
  }
  i = first, j = last;
  while (j - i > 0) {
    strip.rows.row(i) = t.row(i - off);
    strip.rows.row(j) = t.row(j - off);
    ++i, --j;
  }
  // The control point that disappears: the rows below it move up one, in place (rows are
  // contiguous, row-major), and the last row goes. A fresh copy of the whole net per removal made
  // knot removal 5x slower on compose_exact's nets.
  const Eigen::Index out = (2 * r - s - p) / 2, rows = strip.rows.rows(), cols = strip.rows.cols();
  double* data = strip.rows.data();
  std::memmove(data + out * cols, data + (out + 1) * cols,
               static_cast<std::size_t>((rows - 1 - out) * cols) * sizeof(double));
  strip.rows.conservativeResize(rows - 1, cols);
  strip.basis.knots.erase(strip.basis.knots.begin() + r);
  return gap;
}

}  // namespace

int remove_knots(Strip& strip, double tolerance) {
  int removed = 0;
  const double first = strip.basis.knots.front(), last = strip.basis.knots.back();
  std::vector<double> values;  // the distinct interior knot values
  for (double k : strip.basis.knots)
    if (k != first && k != last && (values.empty() || values.back() != k)) values.push_back(k);
  for (double value : values) {
    // Repeated removals of one value compound: their gaps share the one tolerance.
    double spent = 0;
    for (;;) {
      auto& K = strip.basis.knots;
      const auto hi = std::upper_bound(K.begin(), K.end(), value);
      const auto lo = std::lower_bound(K.begin(), K.end(), value);
      const int s = static_cast<int>(hi - lo);
      if (s == 0) break;
      const double gap =
          remove_knot_once(strip, static_cast<int>(hi - K.begin()) - 1, s, tolerance - spent);
      if (gap < 0) break;
      spent += gap;
      ++removed;
    }
  }
  return removed;
}

}  // namespace detail

namespace {

void check_tolerance(double tolerance_mm, const char* who) {
  if (!(std::isfinite(tolerance_mm) && tolerance_mm >= 0))
    throw Error(ErrorCategory::InvalidArgument,
                std::string(who) + ": tolerance_mm = " + std::to_string(tolerance_mm) +
                    " must be finite and >= 0 (in model units; 1e-12 of the model size removes "
                    "the knots whose removal is exact up to rounding)");
}

SurfaceKnotRemoval remove_in(const BSplineSurface& surface, detail::Direction d,
                             double tolerance_mm, const char* who) {
  validate(surface);
  check_tolerance(tolerance_mm, who);
  SurfaceKnotRemoval out;
  out.surface = detail::apply_in_direction(
      surface, d, [&](detail::Strip& s) { out.removed = detail::remove_knots(s, tolerance_mm); });
  return out;
}

}  // namespace

CurveKnotRemoval remove_knots(const BSplineCurve& curve, double tolerance_mm) {
  validate(curve);
  check_tolerance(tolerance_mm, "remove_knots");
  detail::Strip strip = detail::curve_strip(curve);
  CurveKnotRemoval out;
  out.removed = detail::remove_knots(strip, tolerance_mm);
  out.curve = detail::curve_from_strip(std::move(strip));
  return out;
}

SurfaceKnotRemoval remove_knots(const BSplineSurface& surface, double tolerance_mm) {
  validate(surface);
  check_tolerance(tolerance_mm, "remove_knots");
  // One homogeneous net for both directions: the u strip is regrouped into the v strip directly,
  // without the surface in between (its division by w, a second validate and a second
  // conversion). compose_exact calls this on every result, and the copies of two separate
  // remove_knots_u/_v calls cost it as much time as the removal itself (docs/perf/compose.md).
  detail::Strip in_u = detail::surface_strip(surface, detail::Direction::U);
  SurfaceKnotRemoval out;
  out.removed = detail::remove_knots(in_u, tolerance_mm);
  const Eigen::Index nu = in_u.rows.rows(), nv = in_u.rows.cols() / 4;
  detail::Strip in_v{surface.v, detail::Rows(nv, 4 * nu), in_u.polynomial};
  for (Eigen::Index i = 0; i < nu; ++i)
    for (Eigen::Index j = 0; j < nv; ++j)
      in_v.rows.block<1, 4>(j, 4 * i) = in_u.rows.block<1, 4>(i, 4 * j);
  in_u.rows.resize(0, 0);
  out.removed += detail::remove_knots(in_v, tolerance_mm);
  out.surface = detail::surface_from_strip(std::move(in_v), in_u.basis, detail::Direction::V);
  return out;
}

SurfaceKnotRemoval remove_knots_u(const BSplineSurface& surface, double tolerance_mm) {
  return remove_in(surface, detail::Direction::U, tolerance_mm, "remove_knots_u");
}

SurfaceKnotRemoval remove_knots_v(const BSplineSurface& surface, double tolerance_mm) {
  return remove_in(surface, detail::Direction::V, tolerance_mm, "remove_knots_v");
}

}  // namespace clay::surface
