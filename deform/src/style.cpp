// Style deformation, paper mode and the shared pieces: influence factors (Han–De Amicis–Conti
// eq. 2), key points (eqs. 3, 8), forces (eqs. 4-7, 9), relaxation (eqs. 10-11) and smoothing
// (eqs. 12-13), and the quality figures of every result.
#include <clay/deform/style.hpp>

#include "style_internal.hpp"

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace clay::deform {

using surface::BSplineCurve;
using surface::BSplineSurface;
using surface::Points3;

std::string_view to_string(ConstraintClass c) noexcept {
  switch (c) {
    case ConstraintClass::OverConstrained:
      return "over-constrained";
    case ConstraintClass::UnderConstrained:
      return "under-constrained";
    case ConstraintClass::WellConstrained:
      return "well-constrained";
  }
  return "?";
}

std::string_view to_string(BoundContinuity c) noexcept {
  return c == BoundContinuity::G2 ? "G2" : "G1";
}

std::vector<std::string> StyleOptions::problems() const {
  std::vector<std::string> out;
  auto fail = [&out](const std::string& what) { out.push_back("style options: " + what); };
  if (!(lambda >= 0 && lambda <= 1))
    fail("lambda = " + std::to_string(lambda) + " must lie in [0, 1] (Han et al. eq. 9)");
  if (curve_samples != 0 && curve_samples < 8)
    fail("curve_samples = " + std::to_string(curve_samples) + " must be 0 (automatic) or >= 8");
  if (bound_samples < 8) fail("bound_samples = " + std::to_string(bound_samples) + " must be >= 8");
  if (key_points_per_row < 1)
    fail("key_points_per_row = " + std::to_string(key_points_per_row) + " must be >= 1");
  if (boundary_rows < 0 || boundary_rows > 4)
    fail("boundary_rows = " + std::to_string(boundary_rows) + " must lie in [0, 4]");
  if (!(relative_tolerance > 0 && relative_tolerance <= 1e-3))
    fail("relative_tolerance = " + std::to_string(relative_tolerance) +
         " must lie in (0, 1e-3] (relative to the model size)");
  if (max_refinements < 0 || max_refinements > 10)
    fail("max_refinements = " + std::to_string(max_refinements) +
         " must lie in [0, 10] (each round halves the spans over the region)");
  if (!(net_convergence >= 0 && net_convergence <= 0.5))
    fail("net_convergence = " + std::to_string(net_convergence) +
         " must lie in [0, 0.5] (a fraction of the largest displacement; 0 = no such rounds)");
  if (continuity != BoundContinuity::G1 && continuity != BoundContinuity::G2)
    fail("continuity = " + std::to_string(static_cast<int>(continuity)) + " must be G1 or G2");
  if (!(curve_tolerance >= 0 && curve_tolerance <= 1e-1))
    fail("curve_tolerance = " + std::to_string(curve_tolerance) +
         " must lie in [0, 0.1] (relative to the model size; 0 = key points only)");
  if (max_key_point_rounds < 0)
    fail("max_key_point_rounds = " + std::to_string(max_key_point_rounds) + " must be >= 0");
  internal::append(out, projection.problems());
  return out;
}

void StyleOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

int InfluenceRegion::inside_count() const noexcept {
  return static_cast<int>(std::count(factors.begin(), factors.end(), std::uint8_t{1}));
}

namespace detail {

std::vector<TraceSample> trace_on_surface(const surface::SurfaceProjector& projector,
                                          const BSplineCurve& curve, int count,
                                          const std::vector<Eigen::Vector2d>* warm) {
  const auto [a, b] = curve.basis.domain();
  const auto ts = surface::linspace(a, b, count);
  std::vector<TraceSample> out(ts.size());
  const bool have_warm = warm && warm->size() == ts.size();
  for (size_t k = 0; k < ts.size(); ++k) {
    TraceSample& s = out[k];
    s.t = ts[k];
    s.point = surface::evaluate(curve, s.t);
    surface::SurfaceProjection p;
    if (k == 0 && !have_warm) {
      p = projector.closest_point(s.point);
    } else {
      // Newton from the previous sample, or from the same sample of the previous drag position.
      const Eigen::Vector2d start =
          have_warm ? (*warm)[k] : Eigen::Vector2d(out[k - 1].u, out[k - 1].v);
      p = projector.project_normal(s.point, start.x(), start.y());
      if (!p.summary.converged()) p = projector.closest_point(s.point);
    }
    s.u = p.u;
    s.v = p.v;
  }
  return out;
}

PolygonLocator::PolygonLocator(const std::vector<Eigen::Vector2d>& polygon,
                               double on_edge_tolerance)
    : polygon_(&polygon), tolerance_(on_edge_tolerance) {
  if (polygon.empty()) return;
  y_lo_ = 1e300;
  double y_hi = -1e300;
  for (const auto& p : polygon) {
    y_lo_ = std::min(y_lo_, p.y());
    y_hi = std::max(y_hi, p.y());
  }
  y_lo_ -= tolerance_;
  y_hi += tolerance_;
  const int bins = std::max(1, static_cast<int>(polygon.size() / 4));
  inverse_height_ = bins / std::max(y_hi - y_lo_, 1e-300);
  bins_.resize(static_cast<size_t>(bins));
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const double a = polygon[i].y(), b = polygon[(i + 1) % n].y();
    const int first = bin_of(std::min(a, b) - tolerance_),
              last = bin_of(std::max(a, b) + tolerance_);
    for (int k = first; k <= last; ++k)
      bins_[static_cast<size_t>(k)].push_back(static_cast<int>(i));
  }
}

int PolygonLocator::bin_of(double y) const noexcept {
  const double f = (y - y_lo_) * inverse_height_;
  const int last = static_cast<int>(bins_.size()) - 1;
  if (!(f > 0)) return 0;
  return f >= last ? last : static_cast<int>(f);
}

bool PolygonLocator::inside(const Eigen::Vector2d& p) const {
  if (bins_.empty() || p.y() < y_lo_ ||
      p.y() > y_lo_ + static_cast<double>(bins_.size()) / inverse_height_)
    return false;
  // Winding number: only edges whose y-range holds p.y can cross the ray, and those are in p's
  // bin; so are the edges p can lie on.
  const auto& poly = *polygon_;
  const size_t n = poly.size();
  int winding = 0;
  for (int i : bins_[static_cast<size_t>(bin_of(p.y()))]) {
    const Eigen::Vector2d& a = poly[static_cast<size_t>(i)];
    const Eigen::Vector2d& b = poly[(static_cast<size_t>(i) + 1) % n];
    if (p.x() >= std::min(a.x(), b.x()) - tolerance_ &&
        p.x() <= std::max(a.x(), b.x()) + tolerance_) {
      const Eigen::Vector2d ab = b - a;
      const double len2 = ab.squaredNorm();
      const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
      if ((a + s * ab - p).norm() <= tolerance_) return true;
    }
    const double side = (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    if (a.y() <= p.y()) {
      if (b.y() > p.y() && side > 0) ++winding;
    } else if (b.y() <= p.y() && side < 0) {
      --winding;
    }
  }
  return winding != 0;
}

int target_samples(const BSplineCurve& target, const StyleOptions& options) {
  if (options.curve_samples > 0) return options.curve_samples;
  const int spans = static_cast<int>(surface::breakpoints(target.basis).size()) - 1;
  return std::clamp(16 * spans, 32, 4096);
}

surface::SurfaceProjection project_from(const surface::SurfaceProjector& projector,
                                        const Eigen::Vector3d& x, double u, double v) {
  auto p = projector.project_normal(x, u, v);
  if (!p.summary.converged()) p = projector.closest_point(x);
  return p;
}

double parameter_tolerance(const BSplineSurface& s) {
  const auto [u0, u1] = s.u.domain();
  const auto [v0, v1] = s.v.domain();
  return 1e-12 * std::max(u1 - u0, v1 - v0);
}

std::vector<std::uint8_t> region_factors(const BSplineSurface& surface,
                                         const std::vector<Eigen::Vector2d>& polygon,
                                         const std::vector<Eigen::Vector2d>& trace, int margin) {
  const int nu = surface.count_u(), nv = surface.count_v();
  std::vector<std::uint8_t> e(static_cast<size_t>(nu) * static_cast<size_t>(nv), 0);
  if (!polygon.empty()) {
    // Han et al. eq. 2: E = 1 where φ(u_j, v_j) <= 0, at the Greville point of the vertex.
    const auto xu = surface::greville_abscissae(surface.u);
    const auto xv = surface::greville_abscissae(surface.v);
    const PolygonLocator locator(polygon, parameter_tolerance(surface));
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j)
        e[static_cast<size_t>(surface.index(i, j))] =
            locator.inside({xu[static_cast<size_t>(i)], xv[static_cast<size_t>(j)]}) ? 1 : 0;
    return e;
  }
  // §5: the vertices whose basis functions support a point of the projected target, widened by
  // `margin` layers.
  const int p = surface.u.degree, q = surface.v.degree;
  for (const Eigen::Vector2d& uv : trace) {
    const int ku = surface::find_span(surface.u, uv.x());
    const int kv = surface::find_span(surface.v, uv.y());
    for (int i = std::max(0, ku - p - margin); i <= std::min(nu - 1, ku + margin); ++i)
      for (int j = std::max(0, kv - q - margin); j <= std::min(nv - 1, kv + margin); ++j)
        e[static_cast<size_t>(surface.index(i, j))] = 1;
  }
  return e;
}

double model_size(const BSplineSurface& surface) {
  const auto [lo, hi] = surface::control_box(surface);
  return (hi - lo).norm();
}

double continuous_index(const std::vector<double>& xi, double x) {
  if (x <= xi.front()) return 0;
  if (x >= xi.back()) return static_cast<double>(xi.size() - 1);
  const auto it = std::upper_bound(xi.begin(), xi.end(), x);
  const size_t i = static_cast<size_t>(it - xi.begin()) - 1;
  return static_cast<double>(i) + (x - xi[i]) / (xi[i + 1] - xi[i]);
}

namespace {

// Unit normal where the surface is regular, else the zero vector (a pole: no normal to move along).
Eigen::Vector3d normal_or_zero(const BSplineSurface& s, double u, double v) {
  const auto d = surface::derivatives(s, u, v, 1);
  const Eigen::Vector3d n = d.du.cross(d.dv);
  const double len = n.norm();
  if (!(len > 1e-300 * d.du.norm() * d.dv.norm()) || len == 0) return Eigen::Vector3d::Zero();
  return n / len;
}

// Mean curvature H = (E N - 2 F M + G L) / (2 (E G - F^2)) (The NURBS Book's fundamental forms;
// sign along S_u x S_v); NaN where the surface is degenerate.
double mean_curvature(const BSplineSurface& s, double u, double v) {
  const auto d = surface::derivatives(s, u, v, 2);
  const Eigen::Vector3d cross = d.du.cross(d.dv);
  const double E = d.du.dot(d.du), F = d.du.dot(d.dv), G = d.dv.dot(d.dv);
  const double det = E * G - F * F;
  if (!(cross.norm() > 1e-12 * std::sqrt(E * G)) || !(det > 0))
    return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d normal = cross.normalized();
  const double L = d.duu.dot(normal), M = d.duv.dot(normal), N = d.dvv.dot(normal);
  return (E * N - 2 * F * M + G * L) / (2 * det);
}

// Turning points of a sequence: local extrema between swings of at least `swing` each way (a
// hysteresis, so that rounding does not count); its ends are not turns.
int turns(const std::vector<double>& values, double swing) {
  if (values.size() < 3) return 0;
  int dir = 0, count = 0;
  double lo = values.front(), hi = lo, extreme = lo;
  for (const double x : values) {
    if (dir == 0) {
      lo = std::min(lo, x);
      hi = std::max(hi, x);
      if (x - lo >= swing)
        dir = 1, extreme = x;
      else if (hi - x >= swing)
        dir = -1, extreme = x;
    } else if (dir * (x - extreme) > 0) {
      extreme = x;
    } else if (dir * (extreme - x) >= swing) {
      ++count;
      dir = -dir;
      extreme = x;
    }
  }
  return count;
}

// Whether a sample lies in the region: inside the bound polygon, or anywhere when the region was
// made from the target itself.
class RegionTest {
 public:
  RegionTest(const InfluenceRegion& region, const BSplineSurface& s)
      : bounded_(!region.polygon.empty()), locator_(region.polygon, parameter_tolerance(s)) {}
  bool operator()(double u, double v) const { return !bounded_ || locator_.inside({u, v}); }

 private:
  bool bounded_;
  PolygonLocator locator_;
};

}  // namespace

KeyPoint make_key_point(const BSplineSurface& s, const InfluenceRegion& region,
                        const Eigen::Vector3d& point, double t, double u, double v,
                        KeyDirection direction) {
  KeyPoint k;
  k.curve_parameter = t;
  k.point = point;
  k.u = u;
  k.v = v;
  k.foot = surface::evaluate(s, u, v);
  k.normal = normal_or_zero(s, u, v);
  k.distance = (k.point - k.foot).dot(k.normal);
  const double gu = continuous_index(surface::greville_abscissae(s.u), u);
  const double gv = continuous_index(surface::greville_abscissae(s.v), v);
  k.row = static_cast<int>(std::lround(direction == KeyDirection::U ? gu : gv));
  k.influenced =
      region.inside(static_cast<int>(std::lround(gu)), static_cast<int>(std::lround(gv)));
  return k;
}

bool begin_report(const KeyPoints& keys, const StyleOptions& options, StyleMode mode,
                  StyleReport& report) {
  report.mode = mode;
  report.constraint_class = keys.constraint_class;
  report.direction = keys.direction;
  report.key_points = keys.points;
  if (keys.constraint_class == ConstraintClass::OverConstrained) {
    report.message =
        "over-constrained: the target curve lies outside the bound; the surface is unchanged";
    return true;
  }
  if (options.lambda == 0) {
    report.message = "lambda = 0: the surface is unchanged";
    return true;
  }
  return false;
}

KeyPoints find_key_points(const surface::SurfaceProjector& projector, const InfluenceRegion& region,
                          const BSplineCurve& target, const std::vector<TraceSample>& trace,
                          int per_row) {
  const BSplineSurface& s = projector.surface();
  KeyPoints out;
  const auto xu = surface::greville_abscissae(s.u);
  const auto xv = surface::greville_abscissae(s.v);

  // Han et al. eq. 8: the direction is the one in which the target covers more rows of the net.
  double gu_lo = 1e300, gu_hi = -1e300, gv_lo = 1e300, gv_hi = -1e300;
  int inside = 0;
  const RegionTest sample_inside(region, s);
  for (const TraceSample& t : trace) {
    const double gu = continuous_index(xu, t.u), gv = continuous_index(xv, t.v);
    gu_lo = std::min(gu_lo, gu);
    gu_hi = std::max(gu_hi, gu);
    gv_lo = std::min(gv_lo, gv);
    gv_hi = std::max(gv_hi, gv);
    inside += sample_inside(t.u, t.v) ? 1 : 0;
  }
  out.direction = (gu_hi - gu_lo >= gv_hi - gv_lo) ? KeyDirection::U : KeyDirection::V;
  out.constraint_class = inside == 0 ? ConstraintClass::OverConstrained
                         : inside == static_cast<int>(trace.size())
                             ? ConstraintClass::WellConstrained
                             : ConstraintClass::UnderConstrained;
  const bool along_u = out.direction == KeyDirection::U;
  const std::vector<double>& along = along_u ? xu : xv;
  auto coord = [&](double u, double v) { return along_u ? u : v; };
  double lo = 1e300, hi = -1e300;
  for (const TraceSample& t : trace) {
    lo = std::min(lo, coord(t.u, t.v));
    hi = std::max(hi, coord(t.u, t.v));
  }

  // The parameter values to cross: the Greville abscissae (rows of the net) in the covered range,
  // each row interval subdivided per_row times.
  std::vector<double> values;
  for (size_t r = 0; r < along.size(); ++r) {
    for (int j = 0; j < per_row; ++j) {
      if (j > 0 && r + 1 == along.size()) break;
      const double c = j == 0 ? along[r] : along[r] + (along[r + 1] - along[r]) * j / per_row;
      if (c >= lo && c <= hi) values.push_back(c);
    }
  }

  const auto [d0, d1] = along_u ? s.u.domain() : s.v.domain();
  const double ftol = 1e-13 * (d1 - d0);
  auto make_key = [&](double t, double u, double v) {
    return make_key_point(s, region, surface::evaluate(target, t), t, u, v, out.direction);
  };

  for (double c : values) {
    // The first sample interval whose projection crosses c.
    size_t k = 0;
    for (; k + 1 < trace.size(); ++k) {
      const double a = coord(trace[k].u, trace[k].v) - c,
                   b = coord(trace[k + 1].u, trace[k + 1].v) - c;
      if ((a <= 0 && b >= 0) || (a >= 0 && b <= 0)) break;
    }
    if (k + 1 >= trace.size()) continue;  // cannot happen for c in [lo, hi]; kept for safety
    double ta = trace[k].t, tb = trace[k + 1].t;
    double fa = coord(trace[k].u, trace[k].v) - c, fb = coord(trace[k + 1].u, trace[k + 1].v) - c;
    if (fa == 0) {
      out.points.push_back(make_key(ta, trace[k].u, trace[k].v));
      continue;
    }
    if (fb == 0) {
      out.points.push_back(make_key(tb, trace[k + 1].u, trace[k + 1].v));
      continue;
    }
    // Illinois regula falsi on f(t) = coordinate of the foot point of C(t) - c.
    double u = trace[k].u, v = trace[k].v, t = ta;
    int side = 0;
    for (int it = 0; it < 100; ++it) {
      t = (fa * tb - fb * ta) / (fa - fb);
      const auto p = project_from(projector, surface::evaluate(target, t), u, v);
      u = p.u;
      v = p.v;
      const double f = coord(u, v) - c;
      if (std::abs(f) <= ftol) break;
      if ((f > 0) == (fb > 0)) {
        tb = t;
        fb = f;
        if (side == -1) fa /= 2;
        side = -1;
      } else {
        ta = t;
        fa = f;
        if (side == +1) fb /= 2;
        side = +1;
      }
      if (tb == ta) break;
    }
    // Land exactly on the row where the root is that close (the row is what eq. 8 counts).
    if (along_u)
      u = std::abs(u - c) <= ftol ? c : u;
    else
      v = std::abs(v - c) <= ftol ? c : v;
    out.points.push_back(make_key(t, u, v));
  }
  if (out.points.empty()) {
    // The target crosses no row: one key point at its middle (m = 1 rather than eq. 8's 0).
    const TraceSample& mid = trace[trace.size() / 2];
    out.points.push_back(make_key(mid.t, mid.u, mid.v));
  }
  return out;
}

// The parameter box of the region: the bound polygon's, else that of the influenced vertices'
// Greville points widened by one Greville interval.
Eigen::AlignedBox2d region_box(const BSplineSurface& s, const InfluenceRegion& reg) {
  Eigen::AlignedBox2d box;
  if (!reg.polygon.empty()) {
    for (const auto& p : reg.polygon) box.extend(p);
    return box;
  }
  const auto xu = surface::greville_abscissae(s.u), xv = surface::greville_abscissae(s.v);
  for (int i = 0; i < s.count_u(); ++i)
    for (int j = 0; j < s.count_v(); ++j)
      if (reg.inside(i, j)) {
        const size_t a = static_cast<size_t>(i), b = static_cast<size_t>(j);
        box.extend(Eigen::Vector2d(xu[a > 0 ? a - 1 : a], xv[b > 0 ? b - 1 : b]));
        box.extend(Eigen::Vector2d(xu[std::min(a + 1, xu.size() - 1)],
                                   xv[std::min(b + 1, xv.size() - 1)]));
      }
  return box;
}

void measure(const BSplineSurface& parent, const BSplineSurface& result,
             const std::vector<std::uint8_t>& factors, const InfluenceRegion& region,
             const BSplineCurve& target, const std::vector<TraceSample>& samples,
             const StyleOptions& options, StyleReport& report) {
  report.model_size = model_size(parent);
  report.locality = 0;
  report.moved_vertices = 0;
  report.max_displacement = 0;
  for (Eigen::Index r = 0; r < parent.points.rows(); ++r) {
    const double d = (result.points.row(r) - parent.points.row(r)).norm();
    if (d > 0) ++report.moved_vertices;
    report.max_displacement = std::max(report.max_displacement, d);
    if (factors[static_cast<size_t>(r)] == 0) report.locality = std::max(report.locality, d);
  }
  report.influenced_vertices =
      static_cast<int>(std::count(factors.begin(), factors.end(), std::uint8_t{1}));

  report.target_deviation = 0;
  const surface::SurfaceProjector projector(result, options.projection);  // validated once
  for (const KeyPoint& k : report.key_points) {
    if (!k.influenced) continue;
    const auto p = project_from(projector, k.point, k.u, k.v);
    report.target_deviation = std::max(report.target_deviation, p.distance);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  report.target_curve_deviation = nan;
  report.target_curve_distance = nan;
  report.mean_curvature_min = nan;
  report.mean_curvature_max = nan;
  report.curvature_waves = -1;
  report.boundary_position_jump = nan;
  report.boundary_tangent_angle = nan;
  if (!options.report_curves) return;
  const RegionTest inside(region, parent);

  // The target curve against the result, independently of the trace and its Newton continuation:
  // 4 times as many samples, each foot found by a global closest point on the parent (is it in
  // the region? where does λ put the wanted point?) and on the result (the distance).
  if (!samples.empty()) {
    const surface::SurfaceProjector on_parent(parent, options.projection);
    const int n = 4 * (static_cast<int>(samples.size()) - 1) + 1;
    const double t0 = samples.front().t, t1 = samples.back().t;
    double worst = -1;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d c = surface::evaluate(target, t0 + (t1 - t0) * k / (n - 1));
      const auto foot = on_parent.closest_point(c);
      if (!inside(foot.u, foot.v)) continue;
      const Eigen::Vector3d wanted = foot.point + options.lambda * (c - foot.point);
      worst = std::max(worst, projector.closest_point(wanted).distance);
    }
    if (worst >= 0) report.target_curve_distance = worst;
  }

  // Mean curvature H = (E N - 2 F M + G L) / (2 (E G - F^2)) of the result on a 41 x 41 grid over
  // the region's box, at the points inside the region; and its change from the parent's, whose
  // waves along the grid's lines are the rings Zebra shows (curvature_waves).
  {
    constexpr int n = 41;
    const Eigen::AlignedBox2d box = region_box(parent, region);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    Eigen::MatrixXd change = Eigen::MatrixXd::Constant(n, n, nan);  // ΔH, NaN outside
    double largest_change = 0;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const Eigen::Vector2d uv =
            box.min() + Eigen::Vector2d(a, b).cwiseProduct(box.sizes()) / (n - 1);
        if (!inside(uv.x(), uv.y())) continue;
        const double h = mean_curvature(result, uv.x(), uv.y());
        if (std::isnan(h)) continue;  // degenerate
        lo = std::min(lo, h);
        hi = std::max(hi, h);
        const double h0 = mean_curvature(parent, uv.x(), uv.y());
        if (std::isnan(h0)) continue;
        change(a, b) = h - h0;
        largest_change = std::max(largest_change, std::abs(h - h0));
      }
    if (lo <= hi) {
      report.mean_curvature_min = lo;
      report.mean_curvature_max = hi;
    }
    report.curvature_waves = deform::grid_waves(change, 0.1 * largest_change);
  }
  report.target_curve_deviation = samples.empty() ? nan : 0.0;
  for (const TraceSample& t : samples) {
    if (!inside(t.u, t.v)) continue;
    const auto p = project_from(projector, t.point, t.u, t.v);
    report.target_curve_deviation = std::max(report.target_curve_deviation, p.distance);
  }

  measure_boundary(parent, factors, region, parent, result, report);
}

void measure_boundary(const BSplineSurface& net, const std::vector<std::uint8_t>& factors,
                      const InfluenceRegion& region, const BSplineSurface& parent,
                      const BSplineSurface& result, StyleReport& report) {
  // The region edge: the bound polygon, or (region from the target) the midpoints between each
  // influenced vertex's Greville point and those of its non-influenced neighbours.
  std::vector<Eigen::Vector2d> edge = region.polygon;
  if (edge.empty()) {
    const auto xu = surface::greville_abscissae(net.u);
    const auto xv = surface::greville_abscissae(net.v);
    const int nu = net.count_u(), nv = net.count_v();
    auto e = [&](int i, int j) { return factors[static_cast<size_t>(net.index(i, j))] != 0; };
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        if (!e(i, j)) continue;
        const Eigen::Vector2d g(xu[static_cast<size_t>(i)], xv[static_cast<size_t>(j)]);
        const int di[] = {-1, 1, 0, 0}, dj[] = {0, 0, -1, 1};
        for (int n = 0; n < 4; ++n) {
          const int a = i + di[n], b = j + dj[n];
          if (a < 0 || b < 0 || a >= nu || b >= nv || e(a, b)) continue;
          edge.push_back(
              0.5 * (g + Eigen::Vector2d(xu[static_cast<size_t>(a)], xv[static_cast<size_t>(b)])));
        }
      }
  }
  report.boundary_position_jump = 0;
  report.boundary_tangent_angle = 0;
  for (const Eigen::Vector2d& uv : edge) {
    const Eigen::Vector3d a = surface::evaluate(parent, uv.x(), uv.y());
    const Eigen::Vector3d b = surface::evaluate(result, uv.x(), uv.y());
    report.boundary_position_jump = std::max(report.boundary_position_jump, (b - a).norm());
    const Eigen::Vector3d na = normal_or_zero(parent, uv.x(), uv.y());
    const Eigen::Vector3d nb = normal_or_zero(result, uv.x(), uv.y());
    if (na.isZero() || nb.isZero()) continue;
    const double angle =
        std::atan2(na.cross(nb).norm(), na.dot(nb)) * (180.0 / 3.14159265358979323846);
    report.boundary_tangent_angle = std::max(report.boundary_tangent_angle, angle);
  }
}

}  // namespace detail

namespace {

void check_region(const BSplineSurface& parent, const InfluenceRegion& region) {
  if (region.count_u != parent.count_u() || region.count_v != parent.count_v() ||
      region.factors.size() != static_cast<size_t>(parent.points.rows()))
    throw Error(ErrorCategory::InvalidArgument,
                "style deformation: the influence region was made for a " +
                    std::to_string(region.count_u) + " x " + std::to_string(region.count_v) +
                    " control net, the parent surface has " + std::to_string(parent.count_u()) +
                    " x " + std::to_string(parent.count_v()) +
                    ": compute influence_factors on this surface");
}

// Where the projection of the bound polygon crosses itself: indices of two non-adjacent edges.
std::optional<std::pair<size_t, size_t>> polygon_crossing(
    const std::vector<Eigen::Vector2d>& poly) {
  const size_t n = poly.size();
  auto orient = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  };
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[(i + 1) % n];
    const Eigen::Vector2d lo_ab = a.cwiseMin(b), hi_ab = a.cwiseMax(b);
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      const Eigen::Vector2d& c = poly[j];
      const Eigen::Vector2d& d = poly[(j + 1) % n];
      if ((c.cwiseMax(d).array() < lo_ab.array()).any() ||
          (c.cwiseMin(d).array() > hi_ab.array()).any())
        continue;
      const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a),
                   o4 = orient(c, d, b);
      if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
        return std::make_pair(i, j);
    }
  }
  return std::nullopt;
}

void check_inputs(const BSplineSurface& parent, const BSplineCurve& curve, const char* curve_name,
                  const StyleOptions& options) {
  options.validate();
  surface::validate(parent, "parent surface");
  surface::validate(curve, curve_name);
}

}  // namespace

InfluenceRegion influence_factors(const BSplineSurface& parent, const BSplineCurve& bound,
                                  const StyleOptions& options) {
  check_inputs(parent, bound, "bound curve", options);
  const auto [a, b] = bound.basis.domain();
  const Eigen::Vector3d first = surface::evaluate(bound, a), last = surface::evaluate(bound, b);
  const double size =
      (bound.points.colwise().maxCoeff() - bound.points.colwise().minCoeff()).norm();
  if (!((first - last).norm() <= 1e-7 * size)) {
    std::ostringstream msg;
    msg << "bound curve: its ends are " << (first - last).norm()
        << " mm apart; a bound curve must be closed (make its last point equal its first)";
    throw Error(ErrorCategory::InvalidGeometry, msg.str());
  }
  const surface::SurfaceProjector projector(parent, options.projection);
  const auto trace = detail::trace_on_surface(projector, bound, options.bound_samples, nullptr);
  InfluenceRegion region;
  region.count_u = parent.count_u();
  region.count_v = parent.count_v();
  for (size_t k = 0; k + 1 < trace.size(); ++k)  // the last sample repeats the first
    region.polygon.emplace_back(trace[k].u, trace[k].v);
  if (const auto crossing = polygon_crossing(region.polygon)) {
    const auto& s = trace[crossing->first];
    const auto& r = trace[crossing->second];
    std::ostringstream msg;
    msg << "bound curve: its projection onto the parent surface crosses itself between curve "
           "parameters "
        << s.t << " and " << r.t << " (near surface parameters (" << s.u << ", " << s.v
        << ")); draw a simple closed curve on the surface";
    throw Error(ErrorCategory::InvalidGeometry, msg.str());
  }
  region.factors = detail::region_factors(parent, region.polygon, {}, 0);
  return region;
}

InfluenceRegion influence_from_target(const BSplineSurface& parent, const BSplineCurve& target,
                                      const StyleOptions& options) {
  check_inputs(parent, target, "target curve", options);
  const surface::SurfaceProjector projector(parent, options.projection);
  const auto trace =
      detail::trace_on_surface(projector, target, detail::target_samples(target, options), nullptr);
  std::vector<Eigen::Vector2d> uv;
  uv.reserve(trace.size());
  for (const auto& t : trace) uv.emplace_back(t.u, t.v);
  InfluenceRegion region;
  region.count_u = parent.count_u();
  region.count_v = parent.count_v();
  region.margin = options.boundary_rows;
  region.factors = detail::region_factors(parent, {}, uv, region.margin);
  region.target_trace = std::move(uv);
  return region;
}

KeyPoints key_points(const BSplineSurface& parent, const InfluenceRegion& region,
                     const BSplineCurve& target, const StyleOptions& options) {
  check_inputs(parent, target, "target curve", options);
  check_region(parent, region);
  const surface::SurfaceProjector projector(parent, options.projection);
  const auto trace =
      detail::trace_on_surface(projector, target, detail::target_samples(target, options), nullptr);
  return detail::find_key_points(projector, region, target, trace, 1);
}

StyleEditor::StyleEditor(BSplineSurface parent, InfluenceRegion region, const StyleOptions& options)
    : projector_((options.validate(), std::move(parent)), options.projection),
      region_(std::move(region)),
      options_(options) {
  check_region(projector_.surface(), region_);
}

Summary judge_style(const StyleReport& report, const StyleOptions& options) {
  Summary s;
  s.iterations = 1;
  double farthest = 0;
  for (const KeyPoint& k : report.key_points)
    if (k.influenced) farthest = std::max(farthest, std::abs(k.distance));
  s.initial_residual = farthest;
  s.final_residual = report.target_deviation;
  std::ostringstream m;
  m.precision(4);
  if (report.constraint_class == ConstraintClass::OverConstrained) {
    s.termination = Termination::Failed;
    s.message =
        "the target curve lies outside the bound, so no control vertex may move and the surface is "
        "unchanged: draw the target curve (at least partly) inside the bound, or the bound around "
        "it";
    return s;
  }
  s.termination = Termination::Converged;
  if (options.lambda == 0) {
    s.message = "lambda = 0: unchanged, as asked";
    return s;
  }
  // A control vertex may move more than the surface point it shapes (a B-spline basis value is
  // below 1), but not ten times the farthest key point's distance: beyond that the net folds.
  constexpr double fold_factor = 10;
  if (farthest > 0 && report.max_displacement > fold_factor * farthest) {
    s.termination = Termination::NotConverged;
    m << "a control vertex moves " << report.max_displacement << " mm for a target at most "
      << farthest << " mm from the surface (" << report.max_displacement / farthest
      << " times; at most 10 times is accepted): the surface folds. Move the bound further from "
         "the target or "
         "the target closer to the surface";
    if (report.mode == StyleMode::Exact) m << ", or allow more max_refinements";
    s.message = m.str();
    return s;
  }
  if (report.mode == StyleMode::Exact) {
    const double size = report.model_size;
    if (!report.conflicting_key_points.empty()) {
      s.termination = Termination::NotConverged;
      m << report.conflicting_key_points.size() << " key points cannot be met (missed by up to "
        << report.target_deviation
        << " mm, more than relative_tolerance x size = " << options.relative_tolerance * size
        << " mm): the control net is too coarse there; allow more max_refinements";
    } else if (report.target_deviation > options.relative_tolerance * size) {
      s.termination = Termination::NotConverged;
      m << "a key point is missed by " << report.target_deviation
        << " mm, more than relative_tolerance x size = " << options.relative_tolerance * size
        << " mm; allow more max_refinements";
    } else if (const double miss = std::max(
                   std::isfinite(report.target_curve_deviation) ? report.target_curve_deviation
                                                                : 0.0,
                   std::isfinite(report.target_curve_distance) ? report.target_curve_distance
                                                               : 0.0);
               options.curve_tolerance > 0 && miss > options.curve_tolerance * size) {
      s.termination = Termination::NotConverged;
      m << "the target curve is missed by " << miss
        << " mm, more than curve_tolerance x size = " << options.curve_tolerance * size
        << " mm; allow more max_key_point_rounds or max_refinements, or a larger curve_tolerance";
    } else if (options.net_convergence > 0 && !options.net_convergence_best_effort &&
               !(report.net_change <= options.net_convergence)) {
      s.termination = Termination::NotConverged;
      if (std::isnan(report.net_change))
        m << "the net could not be halved to check that the shape has converged";
      else
        m << "the shape still changes by " << 100 * report.net_change
          << " % of its largest displacement when the net is halved, more than net_convergence = "
          << 100 * options.net_convergence << " %";
      m << "; allow more max_refinements, or a larger net_convergence";
    }
    s.message = m.str();
  }
  if (s.converged())
    s.message = report.mode == StyleMode::Exact ? "the key points and the target curve are met"
                                                : "the target is approximated (paper mode)";
  return s;
}

StyleResult StyleEditor::update(const BSplineCurve& target) {
  surface::validate(target, "target curve");
  const auto trace = detail::trace_on_surface(projector_, target,
                                              detail::target_samples(target, options_), &warm_);
  StyleResult out = options_.mode == StyleMode::Exact
                        ? detail::style_exact(projector_, region_, target, trace, options_, exact_)
                        : detail::style_paper(projector_, region_, target, trace, options_);
  out.report.summary = judge_style(out.report, options_);
  warm_.resize(trace.size());
  for (size_t k = 0; k < trace.size(); ++k) warm_[k] = {trace[k].u, trace[k].v};
  return out;
}

namespace detail {

StyleResult style_paper(const surface::SurfaceProjector& projector, const InfluenceRegion& region,
                        const BSplineCurve& target, const std::vector<TraceSample>& trace,
                        const StyleOptions& options) {
  const BSplineSurface& parent = projector.surface();
  KeyPoints keys = find_key_points(projector, region, target, trace, 1);
  StyleResult out{parent, parent, {}};
  StyleReport& report = out.report;
  report.fairness_energy = std::numeric_limits<double>::quiet_NaN();  // exact mode only
  if (begin_report(keys, options, StyleMode::Paper, report)) {
    detail::measure(parent, out.surface, region.factors, region, target, trace, options, report);
    return out;
  }

  // Rows of the net in the key direction (vertices (row, col) for direction u, (col, row) for v).
  const bool along_u = keys.direction == KeyDirection::U;
  const int rows = along_u ? parent.count_u() : parent.count_v();
  const int cols = along_u ? parent.count_v() : parent.count_u();
  auto vertex = [&](int row, int col) {
    return along_u ? parent.index(row, col) : parent.index(col, row);
  };
  auto E = [&](int row, int col) {
    return region.factors[static_cast<size_t>(vertex(row, col))] != 0;
  };
  const auto xi_cols = surface::greville_abscissae(along_u ? parent.v : parent.u);

  Points3 delta = Points3::Zero(parent.points.rows(), 3);
  // Distributes the force f along control-net row `row`, its peak at continuous column g:
  // eqs. 12-13 (smoothing) spread it symmetrically with a linear fall-off to zero at the first
  // vertex outside the bound on each side; without smoothing eqs. 4-5 give it to the two
  // neighbouring vertices by area (here: length) weights.
  auto spread = [&](int row, double g, const Eigen::RowVector3d& f, double factor) {
    if (options.smoothing) {
      int c0 = static_cast<int>(std::lround(g));
      if (!E(row, c0)) {
        const int alt = (g > c0) ? c0 + 1 : c0 - 1;
        if (alt < 0 || alt >= cols || !E(row, alt)) return;
        c0 = alt;
      }
      int lo = c0, hi = c0;
      while (lo >= 0 && E(row, lo)) --lo;
      while (hi < cols && E(row, hi)) ++hi;
      const double glo = lo, ghi = hi;
      if (!(g > glo && g < ghi)) return;
      for (int c = lo + 1; c < hi; ++c) {
        const double w = c <= g ? (c - glo) / (g - glo) : (ghi - c) / (ghi - g);
        delta.row(vertex(row, c)) += factor * w * f;
      }
    } else {
      const int c0 = std::min(static_cast<int>(std::floor(g)), cols - 1);
      const double frac = g - c0;
      if (E(row, c0)) delta.row(vertex(row, c0)) += factor * (1 - frac) * f;
      if (c0 + 1 < cols && frac > 0 && E(row, c0 + 1))
        delta.row(vertex(row, c0 + 1)) += factor * frac * f;
    }
  };
  auto peak = [&](const KeyPoint& k) {
    return detail::continuous_index(xi_cols, along_u ? k.v : k.u);
  };

  // Eqs. 3, 5, 9: f_i = λ E(Q_j) D(K_i) along the normal at the projection.
  const KeyPoint* first = nullptr;
  const KeyPoint* last = nullptr;
  for (const KeyPoint& k : keys.points) {
    if (!k.influenced) continue;
    spread(k.row, peak(k), options.lambda * k.distance * k.normal.transpose(), 1.0);
    if (!first) first = &k;
    last = &k;
  }
  // Eqs. 10-11: beyond the end key points the end forces fall off linearly to zero at the rows
  // just outside the region's extent.
  if (options.relaxation && first) {
    int min_row = rows, max_row = -1;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        if (E(r, c)) {
          min_row = std::min(min_row, r);
          max_row = std::max(max_row, r);
        }
    const KeyPoint* lo_key = first->row <= last->row ? first : last;
    const KeyPoint* hi_key = first->row <= last->row ? last : first;
    const int below = min_row - 1, above = max_row + 1;
    for (int r = below + 1; r < lo_key->row; ++r)
      spread(r, peak(*lo_key), options.lambda * lo_key->distance * lo_key->normal.transpose(),
             static_cast<double>(r - below) / (lo_key->row - below));
    for (int r = hi_key->row + 1; r < above; ++r)
      spread(r, peak(*hi_key), options.lambda * hi_key->distance * hi_key->normal.transpose(),
             static_cast<double>(above - r) / (above - hi_key->row));
  }
  // Write only influenced vertices that move, so every other vertex stays bit-identical.
  for (Eigen::Index r = 0; r < delta.rows(); ++r)
    if (region.factors[static_cast<size_t>(r)] != 0 && !delta.row(r).isZero(0))
      out.surface.points.row(r) += delta.row(r);

  detail::measure(parent, out.surface, region.factors, region, target, trace, options, report);
  std::ostringstream msg;
  msg << to_string(report.constraint_class) << ", m = " << report.key_points.size()
      << " key points along " << (along_u ? "u" : "v") << ", " << report.moved_vertices << " of "
      << report.influenced_vertices << " influenced vertices moved";
  report.message = msg.str();
  return out;
}

}  // namespace detail

StyleResult style_deform(const BSplineSurface& parent, const InfluenceRegion& region,
                         const BSplineCurve& target, const StyleOptions& options) {
  check_inputs(parent, target, "target curve", options);
  return StyleEditor(parent, region, options).update(target);
}

StyleResult style_deform(const BSplineSurface& parent, const BSplineCurve& bound,
                         const BSplineCurve& target, const StyleOptions& options) {
  return style_deform(parent, influence_factors(parent, bound, options), target, options);
}

StyleResult style_deform(const BSplineSurface& parent, const BSplineCurve& target,
                         const StyleOptions& options) {
  return style_deform(parent, influence_from_target(parent, target, options), target, options);
}

std::string StyleReport::brief() const {
  std::ostringstream text;
  text.precision(3);
  text << summary.brief() << "; " << to_string(constraint_class) << ", " << key_points.size()
       << " key points, " << moved_vertices << " vertices moved (largest " << max_displacement
       << " mm), target deviation " << target_deviation << " mm";
  return text.str();
}

int grid_waves(const Eigen::MatrixXd& grid, double swing) {
  if (!(swing > 0)) return 0;
  int most = 0;
  std::vector<double> run;
  auto line = [&](auto at, Eigen::Index length) {
    run.clear();
    for (Eigen::Index k = 0; k <= length; ++k) {
      const double x = k < length ? at(k) : std::numeric_limits<double>::quiet_NaN();
      if (!std::isnan(x)) {
        run.push_back(x);
        continue;
      }
      most = std::max(most, detail::turns(run, swing));
      run.clear();
    }
  };
  for (Eigen::Index a = 0; a < grid.rows(); ++a)
    line([&](Eigen::Index k) { return grid(a, k); }, grid.cols());
  for (Eigen::Index b = 0; b < grid.cols(); ++b)
    line([&](Eigen::Index k) { return grid(k, b); }, grid.rows());
  return most;
}

}  // namespace clay::deform
