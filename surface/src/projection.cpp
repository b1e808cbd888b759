#include <clay/surface/projection.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <numeric>
#include <string>

namespace clay::surface {

std::vector<std::string> ProjectionOptions::problems() const {
  std::vector<std::string> out;
  auto bad = [&out](const std::string& field, const std::string& rule) {
    out.push_back("ProjectionOptions::" + field + " " + rule);
  };
  if (max_iterations < 1)
    bad("max_iterations", "= " + std::to_string(max_iterations) + " must be >= 1");
  if (!(parametric_tolerance > 0.0 && parametric_tolerance < 1.0))
    bad("parametric_tolerance", "= " + std::to_string(parametric_tolerance) + " must be in (0, 1)");
  if (!(cosine_tolerance > 0.0 && cosine_tolerance < 1.0))
    bad("cosine_tolerance", "= " + std::to_string(cosine_tolerance) + " must be in (0, 1)");
  if (samples_per_span < 1)
    bad("samples_per_span", "= " + std::to_string(samples_per_span) + " must be >= 1");
  if (starts < 1) bad("starts", "= " + std::to_string(starts) + " must be >= 1");
  return out;
}

void ProjectionOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

namespace {

void check_point(const Eigen::Vector3d& p) {
  if (!internal::all_finite(p))
    throw Error(
        ErrorCategory::InvalidGeometry,
        "projection: the point to project has a non-finite coordinate; give a finite point");
}

/// Diagonal of the control box: the scale of "P is on S" in newton().
double net_size(const BSplineSurface& s) {
  return (s.points.colwise().maxCoeff() - s.points.colwise().minCoeff()).norm();
}

/// Newton from (u0, v0) on a valid surface (checked by the callers); `size` = net_size(s).
SurfaceProjection newton(const BSplineSurface& s, double size, const Eigen::Vector3d& target,
                         double u0, double v0, const ProjectionOptions& o) {
  const auto [ua, ub] = s.u.domain();
  const auto [va, vb] = s.v.domain();
  const double lo[2] = {ua, va}, hi[2] = {ub, vb};
  const double step_tol[2] = {o.parametric_tolerance * (ub - ua),
                              o.parametric_tolerance * (vb - va)};
  double x[2] = {u0, v0};
  SurfaceProjection out;
  SurfaceDerivatives d = derivatives(s, x[0], x[1], 2);
  double f = (d.point - target).squaredNorm();
  out.summary.initial_residual = std::sqrt(f);
  const double scale = size + target.norm();
  out.summary.termination = Termination::NotConverged;
  out.summary.message = "iteration limit reached";
  int it = 0;
  bool active[2] = {false, false};
  for (; it < o.max_iterations; ++it) {
    const Eigen::Vector3d r = d.point - target;
    const Eigen::Vector3d su = d.du, sv = d.dv;
    const Eigen::Vector2d g(su.dot(r), sv.dot(r));
    Eigen::Matrix2d H;
    H << su.dot(su) + d.duu.dot(r), su.dot(sv) + d.duv.dot(r), su.dot(sv) + d.duv.dot(r),
        sv.dot(sv) + d.dvv.dot(r);
    // Active bounds: at a domain edge with the descent direction pointing outside.
    for (int k = 0; k < 2; ++k)
      active[k] = (x[k] <= lo[k] && g[k] > 0.0) || (x[k] >= hi[k] && g[k] < 0.0);
    // Stationary for every free coordinate: S - P is normal to S_u (resp. S_v), or P is on S.
    const double rn = r.norm();
    bool stationary = rn <= 1e-15 * scale;
    if (!stationary) {
      stationary = true;
      const Eigen::Vector3d* tangents[2] = {&su, &sv};
      for (int k = 0; k < 2; ++k) {
        if (active[k]) continue;
        const double tn = tangents[k]->norm();
        if (tn == 0.0) continue;  // degenerate direction (a pole): nothing to move
        if (std::abs(g[k]) > o.cosine_tolerance * tn * rn) stationary = false;
      }
    }
    if (stationary) {
      out.summary.termination = Termination::Converged;
      out.summary.message = "foot point found";
      break;
    }
    // Newton step on the free coordinates; Gauss–Newton matrix when the Hessian is not positive.
    Eigen::Vector2d step = Eigen::Vector2d::Zero();
    Eigen::Matrix2d G;
    G << su.dot(su), su.dot(sv), su.dot(sv), sv.dot(sv);
    // A direction whose tangent vanishes (a collapsed edge, a pole) cannot move the point at first
    // order: it is held for this step and Newton runs on the other one.
    const double tangent_floor = 1e-24 * (G(0, 0) + G(1, 1));
    const bool held[2] = {active[0] || !(G(0, 0) > tangent_floor),
                          active[1] || !(G(1, 1) > tangent_floor)};
    auto solve_free = [&](const Eigen::Matrix2d& M) -> bool {
      if (!held[0] && !held[1]) {
        if (!(M(0, 0) > 0.0 && M.determinant() > 0.0)) return false;
        step = -M.ldlt().solve(g);
        return internal::all_finite(step);
      }
      bool moved = false;
      for (int k = 0; k < 2; ++k) {
        if (held[k]) continue;
        if (!(M(k, k) > 0.0)) return false;
        step[k] = -g[k] / M(k, k);
        moved = true;
      }
      return moved;
    };
    step.setZero();
    if (!solve_free(H)) {
      step.setZero();
      if (!solve_free(G)) {
        out.summary.termination = Termination::Failed;
        out.summary.message = "degenerate surface derivatives at the current point";
        break;
      }
    }
    // Backtracking line search within the domain box.
    double t = 1.0, xn[2] = {x[0], x[1]};
    double fn = f;
    SurfaceDerivatives dn;
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls) {
      for (int k = 0; k < 2; ++k) xn[k] = std::clamp(x[k] + t * step[k], lo[k], hi[k]);
      dn = derivatives(s, xn[0], xn[1], 2);
      fn = (dn.point - target).squaredNorm();
      // Near the foot point f changes at rounding level: accept that noise, or Newton stalls.
      if (fn <= f * (1.0 + 1e-13)) {
        accepted = true;
        break;
      }
      t *= 0.5;
    }
    const bool tiny =
        std::abs(xn[0] - x[0]) <= step_tol[0] && std::abs(xn[1] - x[1]) <= step_tol[1];
    if (!accepted || tiny) {
      if (accepted) {
        x[0] = xn[0];
        x[1] = xn[1];
        d = dn;
        f = fn;
      }
      out.summary.termination = Termination::Converged;
      out.summary.message = "parameter step below tolerance";
      ++it;
      break;
    }
    x[0] = xn[0];
    x[1] = xn[1];
    d = dn;
    f = fn;
  }
  out.u = x[0];
  out.v = x[1];
  out.point = d.point;
  out.distance = std::sqrt(f);
  out.on_boundary = active[0] || active[1];
  out.summary.iterations = it;
  out.summary.final_residual = out.distance;
  return out;
}

}  // namespace

SurfaceProjection project_normal(const BSplineSurface& surface, const Eigen::Vector3d& point,
                                 double u0, double v0, const ProjectionOptions& options) {
  options.validate();
  validate(surface);
  check_point(point);
  find_span(surface.u, u0);  // throws OutOfDomain with the value and the domain
  find_span(surface.v, v0);
  return newton(surface, net_size(surface), point, u0, v0, options);
}

SurfaceProjection closest_point(const BSplineSurface& surface, const Eigen::Vector3d& point,
                                const ProjectionOptions& options) {
  return SurfaceProjector(surface, options).closest_point(point);
}

// The start grid of closest_point: parameters and points, row iu * vs.size() + iv. Built under a
// mutex, published by `ready` (not std::call_once: in GCC 12's libstdc++ a call_once whose
// function throws leaves the flag deadlocked, GCC PR 66146).
struct SurfaceProjector::StartGrid {
  std::mutex mutex;
  std::atomic<bool> ready{false};
  std::vector<double> us, vs;
  Points3 points;
};

SurfaceProjector::SurfaceProjector(BSplineSurface surface, const ProjectionOptions& options)
    : surface_(std::move(surface)), options_(options), grid_(std::make_shared<StartGrid>()) {
  options_.validate();
  validate(surface_);
  size_ = net_size(surface_);
}

const SurfaceProjector::StartGrid& SurfaceProjector::start_grid() const {
  if (!grid_)
    throw Error(ErrorCategory::InvalidArgument,
                "SurfaceProjector: used after being moved from; assign a projector to it first");
  StartGrid& g = *grid_;
  if (!g.ready.load(std::memory_order_acquire)) {
    const std::lock_guard<std::mutex> lock(g.mutex);
    if (!g.ready.load(std::memory_order_relaxed)) {
      // Built aside, then moved in: a throw (bad_alloc) leaves the grid empty and unpublished.
      std::vector<double> us = span_samples(surface_.u, options_.samples_per_span);
      std::vector<double> vs = span_samples(surface_.v, options_.samples_per_span);
      Points3 points = evaluate_grid(surface_, us, vs);
      g.us = std::move(us);
      g.vs = std::move(vs);
      g.points = std::move(points);
      g.ready.store(true, std::memory_order_release);
    }
  }
  return g;
}

SurfaceProjection SurfaceProjector::project_normal(const Eigen::Vector3d& point, double u0,
                                                   double v0) const {
  check_point(point);
  find_span(surface_.u, u0);  // throws OutOfDomain with the value and the domain
  find_span(surface_.v, v0);
  return newton(surface_, size_, point, u0, v0, options_);
}

SurfaceProjection SurfaceProjector::closest_point(const Eigen::Vector3d& point) const {
  check_point(point);
  const StartGrid& grid = start_grid();
  // Newton from the `starts` grid samples nearest to the point; the nearest result wins.
  const size_t starts =
      std::min(static_cast<size_t>(grid.points.rows()), static_cast<size_t>(options_.starts));
  std::vector<std::pair<double, Eigen::Index>> best_samples;  // (squared distance, row), sorted
  best_samples.reserve(starts + 1);
  for (Eigen::Index r = 0; r < grid.points.rows(); ++r) {
    const double d2 = (grid.points.row(r) - point.transpose()).squaredNorm();
    if (best_samples.size() == starts && d2 >= best_samples.back().first) continue;
    const auto at =
        std::upper_bound(best_samples.begin(), best_samples.end(), std::make_pair(d2, r));
    best_samples.insert(at, {d2, r});
    if (best_samples.size() > starts) best_samples.pop_back();
  }
  SurfaceProjection best;
  bool have = false;
  for (const auto& [d2, r] : best_samples) {
    const double u0 = grid.us[static_cast<size_t>(r) / grid.vs.size()];
    const double v0 = grid.vs[static_cast<size_t>(r) % grid.vs.size()];
    SurfaceProjection candidate = newton(surface_, size_, point, u0, v0, options_);
    if (!have || candidate.distance < best.distance) {
      best = std::move(candidate);
      have = true;
    }
  }
  return best;
}

// ---- curves (moved from the sketch module, where oversketch and stroke fitting used them) ---

namespace {

/// Newton from t0 without the input checks (closest_point runs it from several starts).
double curve_foot(const BSplineCurve& curve, const Eigen::Vector3d& q, double t0, bool periodic) {
  // Not a structured binding: the lambda captures a and b, which Clang 14 refuses for bindings.
  const auto domain = curve.basis.domain();
  const double a = domain.first, b = domain.second;
  const double period = b - a;
  auto fold = [&](double t) {
    if (periodic) {
      t = a + std::fmod(t - a, period);
      if (t < a) t += period;
      return t >= b ? a : t;
    }
    return std::clamp(t, a, b);
  };
  double t = fold(t0);
  CurveDerivatives d = derivatives(curve, t, 2);
  double f = (d.point - q).squaredNorm();
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector3d r = d.point - q;
    const double tt = d.d1.squaredNorm();
    if (!(tt > 0.0)) break;
    const double g = r.dot(d.d1);
    double h = tt + r.dot(d.d2);
    if (!(h > 0.1 * tt)) h = tt;  // Gauss–Newton where the Hessian is not safely positive
    double step = std::clamp(-g / h, -0.25 * period, 0.25 * period);
    bool accepted = false;
    double tn = t, fn = f;
    CurveDerivatives dn;
    for (int ls = 0; ls < 30; ++ls) {
      tn = fold(t + step);
      dn = derivatives(curve, tn, 2);
      fn = (dn.point - q).squaredNorm();
      if (fn <= f) {
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) break;
    const double moved = std::abs(tn - t);
    t = tn;
    d = dn;
    f = fn;
    if (moved <= 1e-15 * period) break;
  }
  return t;
}

CurveProjection curve_projection(const BSplineCurve& curve, const Eigen::Vector3d& q, double t) {
  CurveProjection p;
  p.t = t;
  p.point = evaluate(curve, t);
  p.distance = (p.point - q).norm();
  return p;
}

void check_curve_input(const BSplineCurve& curve, const Eigen::Vector3d& q, const char* who) {
  validate(curve, "curve to project onto");
  if (!(std::isfinite(q.x()) && std::isfinite(q.y()) && std::isfinite(q.z())))
    throw Error(ErrorCategory::InvalidGeometry,
                std::string(who) + ": the point to project is not finite");
}

}  // namespace

CurveProjection project_normal(const BSplineCurve& curve, const Eigen::Vector3d& point, double t0,
                               bool periodic) {
  check_curve_input(curve, point, "project_normal");
  return curve_projection(curve, point, curve_foot(curve, point, t0, periodic));
}

CurveProjection closest_point(const BSplineCurve& curve, const Eigen::Vector3d& point,
                              int samples_per_span) {
  check_curve_input(curve, point, "closest_point");
  if (samples_per_span < 1)
    throw Error(
        ErrorCategory::InvalidArgument,
        "closest_point: samples_per_span = " + std::to_string(samples_per_span) + " must be >= 1");
  const auto ts = span_samples(curve.basis, samples_per_span);
  std::vector<std::pair<double, double>> ranked;  // squared distance, parameter
  ranked.reserve(ts.size());
  for (double t : ts) ranked.emplace_back((evaluate(curve, t) - point).squaredNorm(), t);
  const std::size_t keep = std::min<std::size_t>(3, ranked.size());
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep),
                    ranked.end());
  double best_t = ranked.front().second, best = ranked.front().first;
  for (std::size_t k = 0; k < keep; ++k) {
    const double t = curve_foot(curve, point, ranked[k].second, false);
    const double f = (evaluate(curve, t) - point).squaredNorm();
    if (f < best) {
      best = f;
      best_t = t;
    }
  }
  return curve_projection(curve, point, best_t);
}

}  // namespace clay::surface
