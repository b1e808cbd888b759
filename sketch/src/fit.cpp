#include <clay/sketch/fit.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/degree_elevation.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "fit_engine.hpp"
#include "stroke_fitting.hpp"
#include "stroke_points.hpp"

namespace clay::sketch {

std::vector<std::string> FitOptions::problems() const {
  std::vector<std::string> out;
  auto bad = [&out](const std::string& field, double value, const std::string& rule) {
    std::ostringstream s;
    s << "FitOptions::" << field << " = " << value << " " << rule;
    out.push_back(s.str());
  };
  if (!(std::isfinite(tolerance_mm) && tolerance_mm > 0.0))
    bad("tolerance_mm", tolerance_mm, "must be a positive distance in mm");
  if (degree < 2 || degree > 9) bad("degree", degree, "must be in [2, 9]");
  if (!(std::isfinite(fairness) && fairness >= 0.0))
    bad("fairness", fairness, "must be finite and >= 0");
  if (fairness_reductions < 0) bad("fairness_reductions", fairness_reductions, "must be >= 0");
  if (max_control_points < 2 * degree)
    bad("max_control_points", max_control_points,
        "must be >= 2 * degree (" + std::to_string(2 * degree) + ")");
  if (max_iterations < 1) bad("max_iterations", max_iterations, "must be >= 1");
  if (!(std::isfinite(corner_angle) && corner_angle > 0.0 && corner_angle <= 180.0))
    bad("corner_angle", corner_angle, "must be in (0, 180] degrees (180 never splits)");
  if (!(std::isfinite(corner_window) && corner_window >= 0.0))
    bad("corner_window", corner_window,
        "must be finite and >= 0 mm (0: 10 x tolerance, at least 3 point spacings)");
  if (!(std::isfinite(closing_ratio) && closing_ratio >= 0.0 && closing_ratio <= 0.5))
    bad("closing_ratio", closing_ratio, "must be in [0, 0.5] (0 never closes)");
  if (end_samples < 1) bad("end_samples", end_samples, "must be >= 1 (1: the drawn end point)");
  return out;
}

void FitOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

namespace detail {

Points3 prepared_points(const Stroke& stroke, bool drop_duplicates, double& plane_offset) {
  validate(stroke, "stroke", drop_duplicates);
  plane_offset = 0.0;
  if (stroke.plane)
    for (Eigen::Index i = 0; i < stroke.points.rows(); ++i)
      plane_offset = std::max(
          plane_offset, std::abs(signed_distance(*stroke.plane, stroke.points.row(i).transpose())));
  Points3 w = working_points(stroke);
  if (!drop_duplicates) return w;
  const double eps = duplicate_distance(w);
  Points3 kept(w.rows(), 3);
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < w.rows(); ++i) {
    if (n > 0 && (w.row(i) - kept.row(n - 1)).norm() <= eps) continue;
    kept.row(n++) = w.row(i);
  }
  kept.conservativeResize(n, 3);
  if (n < 2)
    throw Error(ErrorCategory::InvalidGeometry,
                "stroke: has a single distinct point once repeated points are dropped; draw a "
                "stroke that moves");
  return kept;
}

Eigen::Vector3d end_anchor(const Points3& pts, bool at_start, int samples, double limit) {
  const Eigen::Index n = pts.rows();
  const Eigen::Index k = std::min<Eigen::Index>(samples, n / 4);
  const Eigen::Vector3d raw = pts.row(at_start ? 0 : n - 1).transpose();
  // The end value of a least-squares polynomial of degree d on k samples has about (d + 1)^2 / k
  // times the variance of one sample: cubic from 24 samples, quadratic from 12, else the point.
  const int d = k >= 24 ? 3 : k >= 12 ? 2 : 0;
  if (d == 0) return raw;
  Eigen::MatrixXd a(k, d + 1);
  Eigen::MatrixXd b(k, 3);
  const double c = 0.5 * double(k - 1);
  for (Eigen::Index j = 0; j < k; ++j) {
    const double x = (double(j) - c) / c;  // centred index in [-1, 1], the end at -1
    double power = 1.0;
    for (int e = 0; e <= d; ++e, power *= x) a(j, e) = power;
    b.row(j) = pts.row(at_start ? j : n - 1 - j);
  }
  const Eigen::MatrixXd coef = a.colPivHouseholderQr().solve(b);
  Eigen::Vector3d est = Eigen::Vector3d::Zero();
  for (int e = 0; e <= d; ++e) est += (e % 2 ? -1.0 : 1.0) * coef.row(e).transpose();
  Eigen::Vector3d offset = est - raw;
  const double len = offset.norm();
  if (!std::isfinite(len)) return raw;
  if (len > limit) offset *= limit / len;
  return raw + offset;
}

namespace {

/// Points smoothed by three passes of [1 2 1] / 4 (ends kept when open) and their arc lengths.
struct Smoothed {
  Points3 points;
  std::vector<double> s;  ///< arc length at each point
  double length = 0;      ///< total (with the closing chord when closed)
};

Smoothed smooth(const Points3& pts, bool closed) {
  const Eigen::Index n = pts.rows();
  Smoothed out;
  out.points = smoothed(pts, closed);
  out.s.assign(static_cast<size_t>(n), 0.0);
  for (Eigen::Index i = 1; i < n; ++i)
    out.s[static_cast<size_t>(i)] =
        out.s[static_cast<size_t>(i - 1)] + (out.points.row(i) - out.points.row(i - 1)).norm();
  out.length = out.s.back() + (closed ? (out.points.row(0) - out.points.row(n - 1)).norm() : 0.0);
  return out;
}

/// Point of the smoothed polyline at arc length `at` (wrapping when closed).
Eigen::Vector3d at_length(const Smoothed& sm, double at, bool closed) {
  const Eigen::Index n = sm.points.rows();
  if (closed) {
    at = std::fmod(at, sm.length);
    if (at < 0) at += sm.length;
    if (at >= sm.s.back()) {  // on the closing chord
      const double gap = sm.length - sm.s.back();
      const double f = gap > 0 ? (at - sm.s.back()) / gap : 0.0;
      return ((1 - f) * sm.points.row(n - 1) + f * sm.points.row(0)).transpose();
    }
  }
  at = std::clamp(at, 0.0, sm.s.back());
  const auto it = std::upper_bound(sm.s.begin(), sm.s.end(), at);
  const Eigen::Index j = std::clamp<Eigen::Index>(it - sm.s.begin(), 1, n - 1);
  const double s0 = sm.s[static_cast<size_t>(j - 1)], s1 = sm.s[static_cast<size_t>(j)];
  const double f = s1 > s0 ? (at - s0) / (s1 - s0) : 0.0;
  return ((1 - f) * sm.points.row(j - 1) + f * sm.points.row(j)).transpose();
}

struct Line {
  Eigen::Vector3d point, direction;
  bool ok = false;
};

Line fit_line(const Points3& pts, const std::vector<Eigen::Index>& idx) {
  Line line;
  if (idx.size() < 2) return line;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (auto i : idx) c += pts.row(i).transpose();
  c /= double(idx.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (auto i : idx) {
    const Eigen::Vector3d d = pts.row(i).transpose() - c;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  line.point = c;
  line.direction = es.eigenvectors().col(2).normalized();
  line.ok = internal::all_finite(line.direction);
  return line;
}

}  // namespace

std::vector<Corner> find_corners(const Points3& pts, bool closed, double angle_degrees,
                                 double window) {
  std::vector<Corner> corners;
  const Eigen::Index n = pts.rows();
  if (angle_degrees >= 180.0 || n < 5) return corners;
  const Smoothed sm = smooth(pts, closed);
  const double r = std::min(window, sm.length / 6.0);
  if (!(r > 0.0)) return corners;
  std::vector<double> turn(static_cast<size_t>(n), 0.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double si = sm.s[static_cast<size_t>(i)];
    if (!closed && (si - r < 0.0 || si + r > sm.s.back())) continue;
    const Eigen::Vector3d here = sm.points.row(i).transpose();
    const Eigen::Vector3d u = here - at_length(sm, si - r, closed);
    const Eigen::Vector3d v = at_length(sm, si + r, closed) - here;
    const double nu = u.norm(), nv = v.norm();
    if (!(nu > 0 && nv > 0)) continue;
    turn[static_cast<size_t>(i)] =
        std::acos(std::clamp(u.dot(v) / (nu * nv), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  }
  // Strongest turns first; a corner suppresses candidates within the window.
  std::vector<Eigen::Index> order(static_cast<size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) order[static_cast<size_t>(i)] = i;
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    return turn[static_cast<size_t>(a)] > turn[static_cast<size_t>(b)];
  });
  auto arc_gap = [&](Eigen::Index a, Eigen::Index b) {
    const double d = std::abs(sm.s[static_cast<size_t>(a)] - sm.s[static_cast<size_t>(b)]);
    return closed ? std::min(d, sm.length - d) : d;
  };
  std::vector<Eigen::Index> picked;
  for (Eigen::Index i : order) {
    if (!(turn[static_cast<size_t>(i)] > angle_degrees)) break;
    bool near = false;
    for (Eigen::Index j : picked) near = near || arc_gap(i, j) < 2.0 * r;
    if (!near) picked.push_back(i);
  }
  // Refine each: legs fitted as lines outside a guard band, split where the points change leg,
  // the corner where the legs meet.
  for (Eigen::Index c : picked) {
    const double sc = sm.s[static_cast<size_t>(c)];
    // The legs reach 3 windows, but only half way to another corner or an end of the stroke.
    double reach = 3.0 * r;
    for (Eigen::Index other : picked)
      if (other != c) reach = std::min(reach, 0.5 * arc_gap(c, other));
    if (!closed) reach = std::min({reach, 0.5 * sc, 0.5 * (sm.s.back() - sc)});
    reach = std::max(reach, r);
    std::vector<Eigen::Index> around, leg1, leg2;  // `around` in drawing order through c
    for (Eigen::Index k = -n; k <= n; ++k) {
      Eigen::Index i = c + k;
      if (closed)
        i = ((i % n) + n) % n;
      else if (i < 0 || i >= n)
        continue;
      if (k < -n / 2 || k > n / 2) continue;
      double d = sm.s[static_cast<size_t>(i)] - sc;
      if (closed) {
        if (k < 0 && d > 0) d -= sm.length;
        if (k > 0 && d < 0) d += sm.length;
      }
      if (std::abs(d) > reach) continue;
      if (d <= -0.25 * r) leg1.push_back(i);
      if (d >= 0.25 * r) leg2.push_back(i);
      if (std::abs(d) <= r) around.push_back(i);
    }
    Corner corner;
    corner.split = c;
    corner.anchor = pts.row(c).transpose();
    const Line l1 = fit_line(pts, leg1), l2 = fit_line(pts, leg2);
    if (l1.ok && l2.ok) {
      // Closest points of the two lines: the corner.
      const Eigen::Vector3d w0 = l1.point - l2.point;
      const double b = l1.direction.dot(l2.direction);
      const double den = 1.0 - b * b;
      if (den > 0.01) {
        const double d = l1.direction.dot(w0), e = l2.direction.dot(w0);
        const double s1 = (b * e - d) / den, s2 = (e - b * d) / den;
        const Eigen::Vector3d meet =
            0.5 * (l1.point + s1 * l1.direction + l2.point + s2 * l2.direction);
        if ((meet - pts.row(c).transpose()).norm() <= r) corner.anchor = meet;
      }
      // Split where the points change leg: each leg is the half-line from its points to the
      // corner, so a point just past the corner belongs to the leg it lies on.
      auto ray_distance2 = [&](const Line& l, const Eigen::Vector3d& q) {
        // The half-line from the corner through the leg's points.
        Eigen::Vector3d dir = l.direction;
        if ((l.point - corner.anchor).dot(dir) < 0) dir = -dir;
        const double along = std::max(0.0, (q - corner.anchor).dot(dir));
        return (q - corner.anchor - along * dir).squaredNorm();
      };
      double best = std::numeric_limits<double>::infinity();
      for (size_t s = 0; s + 1 < around.size(); ++s) {
        double cost = 0;
        for (size_t j = 0; j < around.size(); ++j)
          cost += ray_distance2(j <= s ? l1 : l2, pts.row(around[j]).transpose());
        if (cost < best) {
          best = cost;
          corner.split = around[s];
        }
      }
    }
    corners.push_back(corner);
  }
  std::sort(corners.begin(), corners.end(),
            [](const Corner& a, const Corner& b) { return a.split < b.split; });
  // Every curve keeps at least one point: refined splits must stay distinct.
  corners.erase(std::unique(corners.begin(), corners.end(),
                            [](const Corner& a, const Corner& b) { return a.split == b.split; }),
                corners.end());
  return corners;
}

std::vector<double> anchored_parameters(const Eigen::Vector3d& a, const Points3& pts,
                                        const Eigen::Vector3d& b) {
  Points3 poly(pts.rows() + 2, 3);
  poly.row(0) = a.transpose();
  poly.middleRows(1, pts.rows()) = pts;
  poly.row(pts.rows() + 1) = b.transpose();
  std::vector<double> t = chord_parameters(poly, false);
  return std::vector<double>(t.begin() + 1, t.end() - 1);
}

PieceProblem piece_problem(const FitOptions& o) {
  PieceProblem pr;
  pr.degree = o.degree;
  pr.tolerance_mm = o.tolerance_mm;
  pr.fairness = o.fairness;
  pr.fairness_reductions = o.fairness_reductions;
  pr.max_control_points = o.max_control_points;
  pr.max_iterations = o.max_iterations;
  return pr;
}

}  // namespace detail

namespace {

using detail::Corner;
using detail::EndKind;
using detail::PieceProblem;
using detail::PieceResult;

FittedCurve report(const PieceResult& r, surface::BSplineCurve curve, bool closed,
                   Eigen::Index first, Eigen::Index last) {
  FittedCurve f;
  f.curve = std::move(curve);
  f.closed = closed;
  f.first_point = first;
  f.last_point = last;
  f.max_deviation_mm = r.max_deviation;
  f.rms_deviation_mm = r.rms_deviation;
  f.control_points = static_cast<int>(f.curve.points.rows());
  f.iterations = r.iterations;
  f.fairness = r.fairness;
  f.noise = r.noise;
  f.summary = r.summary;
  return f;
}

surface::BSplineCurve to_world_curve(surface::BSplineCurve c,
                                     const std::optional<SketchPlane>& plane) {
  if (!plane) return c;
  for (Eigen::Index i = 0; i < c.points.rows(); ++i)
    c.points.row(i) = to_world(*plane, Eigen::Vector2d(c.points(i, 0), c.points(i, 1))).transpose();
  return c;
}

}  // namespace

StrokeFit fit_stroke(const Stroke& stroke, const FitOptions& options) {
  options.validate();
  StrokeFit out;
  const Points3 pts = detail::prepared_points(stroke, options.drop_duplicates, out.plane_offset);
  const Eigen::Index n = pts.rows();
  double total = 0;
  for (Eigen::Index i = 1; i < n; ++i) total += (pts.row(i) - pts.row(i - 1)).norm();
  const double gap = (pts.row(n - 1) - pts.row(0)).norm();
  const bool closed = n >= 2 * options.degree + 2 && gap <= options.closing_ratio * total;
  // Turning is measured on the stroke smoothed point by point, which rounds a corner off over a
  // few points: a window shorter than that rounding misses corners of sparse strokes (a fast hand
  // gives a few mm between pointer events), so the default window is also 3 spacings long.
  double window = options.corner_window;
  if (!(window > 0)) {
    std::vector<double> spacing;
    for (Eigen::Index i = 1; i < n; ++i) spacing.push_back((pts.row(i) - pts.row(i - 1)).norm());
    std::nth_element(spacing.begin(),
                     spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2),
                     spacing.end());
    const double median = spacing.empty() ? 0.0 : spacing[spacing.size() / 2];
    window = std::max(10.0 * options.tolerance_mm, 3.0 * median);
  }
  std::vector<Corner> corners = detail::find_corners(pts, closed, options.corner_angle, window);
  const bool plane = stroke.plane.has_value();
  for (auto& c : corners)
    if (plane) c.anchor.z() = 0.0;

  auto fit_open = [&](const Eigen::Vector3d& a, const std::vector<Eigen::Index>& idx,
                      const Eigen::Vector3d& b) {
    PieceProblem pr = detail::piece_problem(options);
    pr.data.resize(static_cast<Eigen::Index>(idx.size()), 3);
    for (size_t k = 0; k < idx.size(); ++k)
      pr.data.row(static_cast<Eigen::Index>(k)) = pts.row(idx[k]);
    pr.params = detail::anchored_parameters(a, pr.data, b);
    pr.start.kind = EndKind::Point;
    pr.start.point = a;
    pr.end.kind = EndKind::Point;
    pr.end.point = b;
    PieceResult r = detail::fit_piece(pr);
    if (plane) r.curve.points.col(2).setZero();
    return report(r, to_world_curve(r.curve, stroke.plane), false, idx.front(), idx.back());
  };
  auto range = [&](Eigen::Index from, Eigen::Index to) {  // inclusive, wrapping
    std::vector<Eigen::Index> idx;
    for (Eigen::Index i = from;; i = (i + 1) % n) {
      idx.push_back(i);
      if (i == to) break;
    }
    return idx;
  };

  if (closed && corners.empty()) {
    PieceProblem pr = detail::piece_problem(options);
    pr.data = pts;
    pr.periodic = true;
    pr.params = detail::chord_parameters(pts, true);
    PieceResult r = detail::fit_piece(pr);
    surface::BSplineCurve c = r.curve;
    if (c.points.rows() > 0) {
      c = surface::clamp(c);
      if (plane) c.points.col(2).setZero();
      c.points.row(c.points.rows() - 1) = c.points.row(0);
    }
    out.curves.push_back(report(r, to_world_curve(c, stroke.plane), true, 0, n - 1));
    out.closed = true;
  } else if (closed) {
    const size_t k = corners.size();
    for (size_t j = 0; j < k; ++j) {
      const Corner& from = corners[j];
      const Corner& to = corners[(j + 1) % k];
      out.curves.push_back(fit_open(from.anchor, range((from.split + 1) % n, to.split), to.anchor));
    }
    out.closed = true;
  } else {
    // The ends move at most three noise deviations (and the tolerance) from the drawn points.
    const double limit = std::min(options.tolerance_mm, 3.0 * detail::noise_level(pts, false));
    // Each end is estimated from its own curve's points only (never across a corner).
    const Eigen::Index head = corners.empty() ? n : corners.front().split + 1;
    const Eigen::Index tail = corners.empty() ? n : n - corners.back().split - 1;
    const Eigen::Vector3d a =
        detail::end_anchor(pts.topRows(head), true, options.end_samples, limit);
    const Eigen::Vector3d b =
        detail::end_anchor(pts.bottomRows(tail), false, options.end_samples, limit);
    Eigen::Vector3d from = a;
    Eigen::Index first = 0;
    for (const Corner& c : corners) {
      out.curves.push_back(fit_open(from, range(first, c.split), c.anchor));
      from = c.anchor;
      first = c.split + 1;
    }
    out.curves.push_back(fit_open(from, range(first, n - 1), b));
  }
  for (const Corner& c : corners) out.corners.push_back(c.split);

  // Aggregate report.
  Summary& s = out.summary;
  s.termination = Termination::Converged;
  for (const auto& c : out.curves) {
    out.max_deviation_mm = std::max(out.max_deviation_mm, c.max_deviation_mm);
    s.iterations += c.iterations;
    s.initial_residual = std::max(s.initial_residual, c.summary.initial_residual);
    if (c.summary.termination == Termination::Failed)
      s.termination = Termination::Failed;
    else if (c.summary.termination == Termination::NotConverged &&
             s.termination == Termination::Converged)
      s.termination = Termination::NotConverged;
  }
  s.final_residual = out.max_deviation_mm;
  std::ostringstream m;
  m.precision(3);
  m << out.curves.size() << (out.curves.size() == 1 ? " curve" : " curves") << ", "
    << corners.size() << (corners.size() == 1 ? " corner" : " corners") << ", "
    << (out.closed ? "closed" : "open") << "; max deviation " << out.max_deviation_mm
    << " mm for tolerance " << options.tolerance_mm << " mm";
  if (s.termination != Termination::Converged) m << " (see the curves' summaries)";
  s.message = m.str();
  return out;
}

std::string StrokeFit::brief() const {
  int points = 0;
  for (const FittedCurve& c : curves) points += c.control_points;
  std::ostringstream m;
  m.precision(3);
  m << curves.size() << (curves.size() == 1 ? " curve" : " curves")
    << (closed ? " (closed)" : " (open)") << ", " << corners.size()
    << (corners.size() == 1 ? " corner" : " corners") << ", " << points
    << " control points, max deviation " << max_deviation_mm << " mm, plane offset " << plane_offset
    << " mm; " << (summary.converged() ? "converged" : "not converged: " + summary.message);
  return m.str();
}

}  // namespace clay::sketch
