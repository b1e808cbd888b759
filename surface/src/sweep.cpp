// Sweep: a profile along a path with rotation-minimizing frames (Wang et al. 2008), the copies
// interpolated across v (The NURBS Book §10.3).
#include <clay/surface/skin.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/tolerance.hpp>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <clay/surface/detail/builder_tools.hpp>
#include "section_interpolation.hpp"

namespace clay::surface {
namespace {

using detail::averaged_basis;
using detail::interpolate_sections;
using detail::model_size;
using detail::normalized;
using detail::polygon_length;

std::string num(double x) { return detail::short_number(x); }

// ---- Sweep: rotation-minimizing frames on a fine table of the path ----

/// The path sampled finely: points, unit tangents, rotation-minimizing normals r (double
/// reflection, Wang et al. 2008, Algorithm 1) and cumulative arc length. Frames and arc lengths
/// between entries come from one more reflection / quadrature step from the entry before.
class PathTable {
 public:
  PathTable(const BSplineCurve& path, double size) : path_(path) {
    const std::vector<double> bp = breakpoints(path.basis);
    const int spans = static_cast<int>(bp.size()) - 1;
    const int steps = std::max(8, (512 + spans - 1) / spans);
    for (int k = 0; k < spans; ++k) {
      const std::vector<double> ts =
          linspace(bp[static_cast<size_t>(k)], bp[static_cast<size_t>(k + 1)], steps + 1);
      for (size_t i = k == 0 ? 0 : 1; i < ts.size(); ++i) t_.push_back(ts[i]);
    }
    const double domain = bp.back() - bp.front();
    for (double t : t_) {
      const CurveDerivatives d = derivatives(path, t, 2);
      const double speed = d.d1.norm();
      if (!(speed * domain > 1e-12 * size))
        throw Error(ErrorCategory::InvalidGeometry,
                    "sweep: path has a zero tangent at t = " + num(t) +
                        " (a cusp or a collapsed span); remove the repeated control points there");
      x_.push_back(d.point);
      tangent_.push_back(d.d1 / speed);
      // dT/ds = kappa n: the part of C'' normal to the tangent over the squared speed.
      curvature_.push_back((d.d2 - d.d2.dot(tangent_.back()) * tangent_.back()) / (speed * speed));
    }
    // Any unit vector normal to the first tangent: the sweep does not depend on the choice.
    const Eigen::Vector3d& t0 = tangent_.front();
    Eigen::Index axis;
    t0.cwiseAbs().minCoeff(&axis);
    r_.push_back(t0.cross(Eigen::Vector3d::Unit(axis)).normalized());
    s_.push_back(0.0);
    for (size_t j = 1; j < t_.size(); ++j) {
      r_.push_back(reflect(x_[j - 1], tangent_[j - 1], r_[j - 1], x_[j], tangent_[j]));
      s_.push_back(s_[j - 1] + arc(t_[j - 1], t_[j]));
    }
  }

  double length() const { return s_.back(); }
  double first() const { return t_.front(); }
  double last() const { return t_.back(); }

  /// Entries of the table: parameter, point and curvature vector kappa n (right-sided at knots).
  size_t entries() const { return t_.size(); }
  double parameter_of(size_t j) const { return t_[j]; }
  const Eigen::Vector3d& point_of(size_t j) const { return x_[j]; }
  const Eigen::Vector3d& curvature_of(size_t j) const { return curvature_[j]; }

  /// Arc length from the path start to t.
  double arc_length(double t) const {
    const size_t j = entry(t);
    return s_[j] + arc(t_[j], t);
  }

  /// The parameter t at arc length s in [0, length()] (Newton with bisection safeguard).
  double parameter(double s) const {
    if (s <= 0.0) return t_.front();
    if (s >= s_.back()) return t_.back();
    const size_t j =
        static_cast<size_t>(std::upper_bound(s_.begin(), s_.end(), s) - s_.begin()) - 1;
    double lo = t_[j], hi = t_[j + 1];
    double t = lo + (hi - lo) * (s - s_[j]) / (s_[j + 1] - s_[j]);
    for (int it = 0; it < 60; ++it) {
      const double f = s_[j] + arc(t_[j], t) - s;
      if (std::abs(f) <= 1e-15 * s_.back()) break;
      if (f > 0)
        hi = t;
      else
        lo = t;
      double next = t - f / derivatives(path_, t, 1).d1.norm();
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (next == t) break;
      t = next;
    }
    return t;
  }

  /// Position, unit tangent and rotation-minimizing normal at t.
  void frame(double t, Eigen::Vector3d& x, Eigen::Vector3d& tangent, Eigen::Vector3d& r) const {
    const size_t j = entry(t);
    if (t == t_[j]) {
      x = x_[j];
      tangent = tangent_[j];
      r = r_[j];
      return;
    }
    const CurveDerivatives d = derivatives(path_, t, 1);
    x = d.point;
    tangent = d.d1.normalized();
    r = reflect(x_[j], tangent_[j], r_[j], x, tangent);
  }

 private:
  /// Double reflection (Wang et al. 2008, Algorithm 1): the normal at (x1, t1) from (x0, t0, r0).
  static Eigen::Vector3d reflect(const Eigen::Vector3d& x0, const Eigen::Vector3d& t0,
                                 const Eigen::Vector3d& r0, const Eigen::Vector3d& x1,
                                 const Eigen::Vector3d& t1) {
    Eigen::Vector3d rl = r0, tl = t0;
    const Eigen::Vector3d v1 = x1 - x0;
    const double c1 = v1.squaredNorm();
    if (c1 > 0) {
      rl = r0 - (2.0 / c1) * v1.dot(r0) * v1;
      tl = t0 - (2.0 / c1) * v1.dot(t0) * v1;
    }
    const Eigen::Vector3d v2 = t1 - tl;
    const double c2 = v2.squaredNorm();
    Eigen::Vector3d r1 = c2 > 0 ? Eigen::Vector3d(rl - (2.0 / c2) * v2.dot(rl) * v2) : rl;
    // Keep r exactly normal to the tangent and of unit length (rounding only).
    r1 -= r1.dot(t1) * t1;
    return r1.normalized();
  }

  size_t entry(double t) const {
    const auto it = std::upper_bound(t_.begin(), t_.end(), t);
    if (it == t_.begin()) return 0;
    return std::min(static_cast<size_t>(it - t_.begin()) - 1, t_.size() - 1);
  }

  double arc(double a, double b) const {
    if (b <= a) return 0.0;
    return internal::gauss_legendre_8(a, b,
                                      [&](double t) { return derivatives(path_, t, 1).d1.norm(); });
  }

  const BSplineCurve& path_;
  std::vector<double> t_, s_;
  std::vector<Eigen::Vector3d> x_, tangent_, r_, curvature_;
};

/// The rigid motions of the sweep: start frame to frame at t, with the twist.
class SweepMotion {
 public:
  SweepMotion(const PathTable& table, double twist_radians) : table_(table), twist_(twist_radians) {
    Eigen::Vector3d t0, r0;
    table_.frame(table_.first(), x0_, t0, r0);
    f0_ = frame_matrix(t0, r0, 0.0);
  }

  /// The profile moved to path parameter t (control points moved, weights kept: exact).
  BSplineCurve moved(const BSplineCurve& profile, double t) const {
    Eigen::Vector3d x;
    const Eigen::Matrix3d m = rotation(t, x);
    BSplineCurve c = profile;
    for (Eigen::Index i = 0; i < c.points.rows(); ++i)
      c.points.row(i) = (x + m * (profile.points.row(i).transpose() - x0_)).transpose();
    return c;
  }

  /// Points moved to path parameter t.
  Points3 moved(const Points3& points, double t) const {
    Eigen::Vector3d x;
    const Eigen::Matrix3d m = rotation(t, x);
    Points3 out(points.rows(), 3);
    for (Eigen::Index i = 0; i < points.rows(); ++i)
      out.row(i) = (x + m * (points.row(i).transpose() - x0_)).transpose();
    return out;
  }

 private:
  static Eigen::Matrix3d frame_matrix(const Eigen::Vector3d& t, const Eigen::Vector3d& r,
                                      double angle) {
    const Eigen::Vector3d s = t.cross(r);
    const Eigen::Vector3d rt = std::cos(angle) * r + std::sin(angle) * s;
    Eigen::Matrix3d f;
    f.col(0) = t;
    f.col(1) = rt;
    f.col(2) = t.cross(rt);
    return f;
  }

  Eigen::Matrix3d rotation(double t, Eigen::Vector3d& x) const {
    Eigen::Vector3d tangent, r;
    table_.frame(t, x, tangent, r);
    const double angle = twist_ == 0.0 ? 0.0 : twist_ * table_.arc_length(t) / table_.length();
    return frame_matrix(tangent, r, angle) * f0_.transpose();
  }

  const PathTable& table_;
  double twist_;
  Eigen::Vector3d x0_;
  Eigen::Matrix3d f0_;
};

/// Where the sweep folds through itself. With rotation-minimizing frames, a profile point at
/// offset q from the path point moves with dS/ds = T (1 - kappa n . q) + (terms normal to T): where
/// kappa n . q reaches 1 the profile stretches to the path's centre of curvature and beyond it the
/// surface runs backwards, through itself. Throws when the largest kappa n . q over the path
/// table and dense profile samples reaches 1 - 1e-3 (the sampling's margin), naming the path
/// parameter, the radius of curvature and how far the profile reaches toward the centre.
void check_fold(const PathTable& table, const SweepMotion& motion, const BSplineCurve& profile) {
  const Points3 samples = evaluate_many(profile, span_samples(profile.basis, 16));
  double worst = 0;
  size_t worst_entry = 0;
  for (size_t j = 0; j < table.entries(); ++j) {
    const Eigen::Vector3d& k = table.curvature_of(j);
    if (k.squaredNorm() == 0.0) continue;
    const Points3 moved = motion.moved(samples, table.parameter_of(j));
    for (Eigen::Index i = 0; i < moved.rows(); ++i) {
      const double reach = k.dot(moved.row(i).transpose() - table.point_of(j));
      if (reach > worst) worst = reach, worst_entry = j;
    }
  }
  if (worst < 1.0 - 1e-3) return;
  const double kappa = table.curvature_of(worst_entry).norm();
  const std::string radius = num(1.0 / kappa), reach = num(worst / kappa);
  throw Error(ErrorCategory::InvalidGeometry,
              "sweep: the swept surface would fold through itself near path t = " +
                  num(table.parameter_of(worst_entry)) +
                  ": the path's radius of curvature there is " + radius +
                  " mm but the profile reaches " + reach +
                  " mm from the path toward the centre of curvature; use a smaller profile "
                  "(reaching less than " +
                  radius +
                  " mm toward the centre) or a gentler path "
                  "(radius of curvature above " +
                  reach + " mm there)");
}

/// True when every control point of the path lies on the chord from its first to its last one and
/// they advance monotonically along it: the path is a straight segment traversed once.
bool is_straight(const BSplineCurve& path, double size) {
  const Eigen::Vector3d a = path.points.row(0).transpose();
  const Eigen::Vector3d d = path.points.row(path.points.rows() - 1).transpose() - a;
  const double length = d.norm();
  if (!(length > 0)) return false;
  const Eigen::Vector3d e = d / length;
  double along = 0;
  for (Eigen::Index i = 0; i < path.points.rows(); ++i) {
    const Eigen::Vector3d p = path.points.row(i).transpose() - a;
    if ((p - p.dot(e) * e).norm() > 1e-13 * size) return false;
    if (p.dot(e) < along) return false;
    along = p.dot(e);
  }
  return true;
}

void check_corners(const BSplineCurve& path, double tolerance) {
  const std::vector<BSplineCurve> segments = extract_bezier(path);
  for (size_t k = 0; k + 1 < segments.size(); ++k) {
    const double t = segments[k].basis.domain().second;
    const Eigen::Vector3d a = derivatives(segments[k], t, 1).d1;
    const Eigen::Vector3d b =
        derivatives(segments[k + 1], segments[k + 1].basis.domain().first, 1).d1;
    if (!(a.norm() > 0 && b.norm() > 0))
      throw Error(ErrorCategory::InvalidGeometry,
                  "sweep: path has a zero tangent at its knot t = " + num(t) +
                      "; remove the repeated control points there");
    const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
    if (angle > tolerance)
      throw Error(ErrorCategory::InvalidGeometry,
                  "sweep: path has a corner at t = " + num(t) + " (its tangent turns by " +
                      num(angle * 180.0 / std::numbers::pi) +
                      " degrees); split the path there and sweep each part");
  }
}

/// A path knot where the sweep is less smooth than a cubic across the sections: the moved profile
/// is C^0 in arc length where the path's curvature jumps (multiplicity 3 in v) and C^1 where only
/// its derivative does (multiplicity 2), as at the knots of a C2 cubic path.
struct Join {
  double t = 0;
  int multiplicity = 3;
};

/// Curvature vector dT/ds of a segment at t, and its arc-length derivative by a one-sided
/// second-order difference into the segment (direction +1 or -1).
std::pair<Eigen::Vector3d, Eigen::Vector3d> curvature(const BSplineCurve& segment, double t,
                                                      double direction) {
  auto k = [&](double x) {
    const CurveDerivatives d = derivatives(segment, x, 2);
    const double speed = d.d1.norm();
    const Eigen::Vector3d tangent = d.d1 / speed;
    return Eigen::Vector3d((d.d2 - d.d2.dot(tangent) * tangent) / (speed * speed));
  };
  const auto [a, b] = segment.basis.domain();
  const double h = 1e-3 * (b - a) * direction;
  const Eigen::Vector3d k0 = k(t), k1 = k(t + h), k2 = k(t + 2 * h);
  const double speed = derivatives(segment, t, 1).d1.norm();
  return {k0, (-3.0 * k0 + 4.0 * k1 - k2) / (2.0 * h * speed)};
}

std::vector<Join> sweep_joins(const BSplineCurve& path, double size) {
  std::vector<Join> joins;
  const std::vector<BSplineCurve> segments = extract_bezier(path);
  for (size_t k = 0; k + 1 < segments.size(); ++k) {
    const double t = segments[k].basis.domain().second;
    const auto [kl, dkl] = curvature(segments[k], t, -1.0);
    const auto [kr, dkr] = curvature(segments[k + 1], t, +1.0);
    if ((kl - kr).norm() * size > 1e-9)
      joins.push_back({t, 3});
    else if ((dkl - dkr).norm() * size * size > 1e-4)
      joins.push_back({t, 2});
  }
  return joins;
}

/// `total` section intervals spread over the pieces in proportion to their arc length, at least 3
/// each when there is room (else all in the first entry: the caller then ignores the joins).
void distribute_intervals(int total, const std::vector<double>& sigma,
                          std::vector<int>& intervals) {
  const size_t pieces = intervals.size();
  if (total < 3 * static_cast<int>(pieces)) {
    std::fill(intervals.begin(), intervals.end(), 0);
    intervals[0] = total;
    return;
  }
  int used = 0;
  for (size_t k = 0; k < pieces; ++k) {
    intervals[k] = std::max(3, static_cast<int>(std::floor(total * (sigma[k + 1] - sigma[k]))));
    used += intervals[k];
  }
  // Take or give the difference where the pieces are largest.
  while (used != total) {
    size_t pick = 0;
    for (size_t k = 1; k < pieces; ++k)
      if ((used > total) ? intervals[k] > intervals[pick]
                         : (sigma[k + 1] - sigma[k]) / intervals[k] >
                               (sigma[pick + 1] - sigma[pick]) / intervals[pick])
        pick = k;
    intervals[pick] += used > total ? -1 : 1;
    used += used > total ? -1 : 1;
  }
}

/// Cubic knots for sections at sites v split into pieces (piece k starts at site piece_start[k]):
/// knots by averaging inside each piece, and at a join the site repeated `multiplicity` times
/// (3: C0, 2: C1 plus one extra knot at the next site to keep one basis function per section).
BSplineBasis joined_basis(const std::vector<double>& v, const std::vector<int>& piece_start,
                          const std::vector<int>& multiplicity) {
  BSplineBasis basis;
  basis.degree = 3;
  basis.knots.assign(4, 0.0);
  const size_t pieces = piece_start.size();
  for (size_t k = 0; k < pieces; ++k) {
    const int first = piece_start[k];
    const int last = k + 1 < pieces ? piece_start[k + 1] : static_cast<int>(v.size()) - 1;
    if (k > 0) {
      const double at = v[static_cast<size_t>(first)];
      basis.knots.insert(basis.knots.end(), 2, at);
      basis.knots.push_back(multiplicity[k] == 3 ? at : v[static_cast<size_t>(first + 1)]);
    }
    for (int i = first + 1; i + 2 <= last - 1; ++i)
      basis.knots.push_back((v[static_cast<size_t>(i)] + v[static_cast<size_t>(i + 1)] +
                             v[static_cast<size_t>(i + 2)]) /
                            3.0);
  }
  basis.knots.insert(basis.knots.end(), 4, 1.0);
  return basis;
}

}  // namespace

std::vector<std::string> SweepOptions::problems() const {
  std::vector<std::string> out;
  if (!std::isfinite(twist_degrees))
    out.push_back("SweepOptions::twist_degrees is " + num(twist_degrees) + "; it must be finite");
  if (sections != 0 && sections < 2)
    out.push_back("SweepOptions::sections is " + std::to_string(sections) +
                  "; it must be 0 (adaptive) or >= 2");
  if (!(relative_tolerance > 0.0 && relative_tolerance <= 1e-1))
    out.push_back("SweepOptions::relative_tolerance is " + num(relative_tolerance) +
                  "; it must be in (0, 1e-1]");
  if (max_sections < 2)
    out.push_back("SweepOptions::max_sections is " + std::to_string(max_sections) +
                  "; it must be >= 2");
  return out;
}

void SweepOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

BuiltSurface sweep(const BSplineCurve& profile, const BSplineCurve& path,
                   const SweepOptions& options) {
  options.validate();
  validate(profile, "sweep profile");
  validate(path, "sweep path");
  const double size = model_size({&profile, &path});
  const double exact_tol = tolerance::exact_relative * size;
  if (!(polygon_length(profile) > exact_tol))
    throw Error(ErrorCategory::InvalidGeometry,
                "sweep: profile is degenerate: its control polygon is " +
                    num(polygon_length(profile)) + " mm long (tolerance " + num(exact_tol) +
                    " mm); give a curve, not a point");
  if (!(polygon_length(path) > exact_tol))
    throw Error(ErrorCategory::InvalidGeometry,
                "sweep: path has zero length (its control polygon is " + num(polygon_length(path)) +
                    " mm long, tolerance " + num(exact_tol) + " mm); give a path that moves");
  detail::reject_self_intersection(profile, exact_tol, "sweep: profile",
                                   "the swept surface would intersect itself: give a profile that "
                                   "does not cross or touch itself");
  detail::reject_self_intersection(path, exact_tol, "sweep: path",
                                   "the swept surface would intersect itself: move the path apart "
                                   "there, or split it and sweep each part");
  const BSplineCurve shape = clamp(profile);
  const BSplineCurve track = clamp(path);
  check_corners(track, options.relative_tolerance);
  const PathTable table(track, size);
  if (!(table.length() > exact_tol))
    throw Error(
        ErrorCategory::InvalidGeometry,
        "sweep: path has zero length (" + num(table.length()) + " mm); give a path that moves");
  const double twist = options.twist_degrees * std::numbers::pi / 180.0;
  const SweepMotion motion(table, twist);
  check_fold(table, motion, shape);

  // Samples of the profile for the deviation check.
  const int profile_spans = static_cast<int>(breakpoints(shape.basis).size()) - 1;
  const auto [ua, ub] = shape.basis.domain();
  const std::vector<double> us = linspace(ua, ub, std::max(17, 4 * profile_spans + 1));
  const Points3 profile_samples = evaluate_many(shape, us);

  // Largest distance between S(u, v) and the moved profile at 1/4, 1/2, 3/4 of every interval
  // between sites; `per_interval` gets the largest of each interval.
  std::vector<double> per_interval;
  auto deviation = [&](const BSplineSurface& s, const std::vector<double>& sites, int& samples) {
    std::vector<double> vs;
    for (size_t k = 0; k + 1 < sites.size(); ++k)
      for (double f : {0.25, 0.5, 0.75}) vs.push_back(sites[k] + f * (sites[k + 1] - sites[k]));
    const Points3 grid = evaluate_grid(s, us, vs);
    per_interval.assign(sites.size() - 1, 0.0);
    for (size_t j = 0; j < vs.size(); ++j) {
      const Points3 expected =
          motion.moved(profile_samples, table.parameter(vs[j] * table.length()));
      double& worst = per_interval[j / 3];
      for (size_t i = 0; i < us.size(); ++i)
        worst = std::max(worst, (grid.row(static_cast<Eigen::Index>(i * vs.size() + j)) -
                                 expected.row(static_cast<Eigen::Index>(i)))
                                    .norm());
    }
    samples = static_cast<int>(vs.size() * us.size());
    return *std::max_element(per_interval.begin(), per_interval.end());
  };

  BuiltSurface built;
  if (twist == 0.0 && is_straight(track, size)) {
    // The exact extrusion: the profile and its copy translated to the path end, degree 1 across.
    BSplineCurve end = shape;
    const Eigen::RowVector3d d = track.points.row(track.points.rows() - 1) - track.points.row(0);
    end.points.rowwise() += d;
    built.surface = interpolate_sections({shape, end}, {0.0, 1.0}, 1);
    int samples = 0;
    const double worst = deviation(built.surface, linspace(0.0, 1.0, 9), samples);
    built.report = describe(built.surface, "sweep along a straight path (exact extrusion)");
    built.report.exact = true;
    built.report.max_deviation_mm = worst;
    built.report.samples = samples;
    return built;
  }

  // Pieces of the path between joins (path knots where the sweep is less smooth than the cubic
  // across the sections would be), each with its number of section intervals.
  const std::vector<Join> joins = sweep_joins(track, size);
  std::vector<double> piece_t = {table.first()}, piece_sigma = {0.0};
  std::vector<int> piece_mult = {0};
  for (const Join& j : joins) {
    piece_t.push_back(j.t);
    piece_sigma.push_back(table.arc_length(j.t) / table.length());
    piece_mult.push_back(j.multiplicity);
  }
  piece_t.push_back(table.last());
  piece_sigma.push_back(1.0);
  const size_t pieces = piece_t.size() - 1;
  const std::vector<double> path_breaks = breakpoints(track.basis);
  std::vector<int> intervals(pieces);
  if (options.sections > 0) {
    distribute_intervals(options.sections - 1, piece_sigma, intervals);
  } else {
    for (size_t k = 0; k < pieces; ++k) {
      // 4 per path knot span inside the piece, at least 4.
      int spans = 0;
      for (size_t b = 0; b + 1 < path_breaks.size(); ++b) {
        const double mid = 0.5 * (path_breaks[b] + path_breaks[b + 1]);
        if (mid > piece_t[k] && mid < piece_t[k + 1]) ++spans;
      }
      intervals[k] = 4 * std::max(1, spans);
    }
  }
  int initial = 0;
  for (int m : intervals) initial += m;
  if (initial + 1 > options.max_sections)
    distribute_intervals(options.max_sections - 1, piece_sigma, intervals);
  const double target = options.relative_tolerance * size;
  double worst = 0;
  int samples = 0;
  int count = 0;
  while (true) {
    int total = 0;
    for (int m : intervals) total += m;
    const bool use_joins = pieces > 1 && *std::min_element(intervals.begin(), intervals.end()) >= 3;
    // Without joins: one piece over the whole path.
    const std::vector<double> pt =
        use_joins ? piece_t : std::vector<double>{table.first(), table.last()};
    const std::vector<double> ps = use_joins ? piece_sigma : std::vector<double>{0.0, 1.0};
    const std::vector<int> pm = use_joins ? intervals : std::vector<int>{total};
    std::vector<BSplineCurve> copies;
    std::vector<double> v;
    std::vector<int> piece_start;  // index in v of each piece's first site
    for (size_t k = 0; k + 1 < pt.size(); ++k) {
      piece_start.push_back(static_cast<int>(v.size()));
      for (int i = 0; i < pm[k]; ++i) {
        const double sigma = ps[k] + (ps[k + 1] - ps[k]) * i / pm[k];
        v.push_back(sigma);
        if (k == 0 && i == 0)
          copies.push_back(shape);  // the start frame maps the profile to itself, exactly
        else
          copies.push_back(
              motion.moved(shape, i == 0 ? pt[k] : table.parameter(sigma * table.length())));
      }
    }
    v.push_back(1.0);
    copies.push_back(motion.moved(shape, table.last()));
    count = static_cast<int>(v.size());
    const BSplineBasis basis_v = use_joins ? joined_basis(v, piece_start, piece_mult)
                                           : averaged_basis(v, std::min(3, count - 1));
    built.surface = interpolate_sections(copies, v, basis_v);
    worst = deviation(built.surface, v, samples);
    if (options.sections > 0 || worst <= target || count >= options.max_sections) break;
    // Double the intervals of the pieces that miss the tolerance (all of them without joins).
    int grown = 0;
    for (size_t k = 0; k < pieces; ++k) {
      bool miss = !use_joins;
      for (int i = 0; use_joins && i < intervals[k]; ++i)
        miss = miss || per_interval[static_cast<size_t>(piece_start[k] + i)] > target;
      if (miss) intervals[k] *= 2;
      grown += intervals[k];
    }
    if (grown + 1 > options.max_sections)
      distribute_intervals(options.max_sections - 1, piece_sigma, intervals);
  }
  // A sweep that misses its tolerance is a failure, not a result (DESIGN.md): a twist of 1e300
  // degrees used to come back as a wild surface whose export then ran for minutes (issue #18).
  if (options.sections == 0 && worst > target)
    throw Error(
        ErrorCategory::InvalidArgument,
        "sweep: the deviation " + num(worst) + " mm is still above the tolerance " + num(target) +
            " mm with " + std::to_string(count) +
            " sections, the most SweepOptions::max_sections = " +
            std::to_string(options.max_sections) +
            " allows; loosen SweepOptions::relative_tolerance, reduce SweepOptions::twist_degrees "
            "or smooth the path");
  const std::string method =
      "sweep with rotation-minimizing frames, " + std::to_string(count) + " sections";
  built.report = describe(built.surface, method);
  built.report.exact = false;
  built.report.max_deviation_mm = worst;
  built.report.samples = samples;
  return built;
}

}  // namespace clay::surface
