// Sides two surfaces share (refit.hpp: shared_boundaries), for refits that keep them meeting
// (issue #38 step 3: surfaces built to meet).
#include <clay/deform/refit.hpp>
#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace clay::deform {

namespace {

// A side of a surface: the iso-curve at `fixed` of u (across_u: u fixed, t runs along v) or v.
struct Side {
  bool u_fixed = true;
  double fixed = 0, t0 = 0, t1 = 0;
};

std::array<Side, 4> sides_of(const surface::BSplineSurface& s) {
  const auto [u0, u1] = s.u.domain();
  const auto [v0, v1] = s.v.domain();
  return {Side{true, u0, v0, v1}, Side{true, u1, v0, v1}, Side{false, v0, u0, u1},
          Side{false, v1, u0, u1}};
}

surface::SurfaceDerivatives at(const surface::BSplineSurface& s, const Side& side, double t,
                               int order) {
  return side.u_fixed ? surface::derivatives(s, side.fixed, t, order)
                      : surface::derivatives(s, t, side.fixed, order);
}

// The side's point nearest p: the nearest of 65 samples, then Newton on (C(t) - p) . C'(t) = 0.
double nearest(const surface::BSplineSurface& s, const Side& side, const Eigen::Vector3d& p) {
  double best = side.t0, best_d = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= 64; ++k) {
    const double t = side.t0 + (side.t1 - side.t0) * k / 64.0;
    const double d = (at(s, side, t, 0).point - p).squaredNorm();
    if (d < best_d) best_d = d, best = t;
  }
  for (int it = 0; it < 12; ++it) {
    const surface::SurfaceDerivatives d = at(s, side, best, 2);
    const Eigen::Vector3d c1 = side.u_fixed ? d.dv : d.du, c2 = side.u_fixed ? d.dvv : d.duu;
    const Eigen::Vector3d r = d.point - p;
    const double f = r.dot(c1), df = c1.squaredNorm() + r.dot(c2);
    if (!(df > 0)) break;
    const double next = std::clamp(best - f / df, side.t0, side.t1);
    if (next == best) break;
    best = next;
  }
  return best;
}

Eigen::Vector3d unit_normal(const surface::SurfaceDerivatives& d) {
  const Eigen::Vector3d n = d.du.cross(d.dv);
  return n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
}

}  // namespace

std::vector<MatchedCurve> shared_boundaries(
    const surface::BSplineSurface& s, const std::vector<const surface::BSplineSurface*>& neighbours,
    double tolerance_mm) {
  if (!(tolerance_mm > 0 && std::isfinite(tolerance_mm)))
    throw Error(ErrorCategory::InvalidArgument,
                "shared_boundaries: tolerance_mm is " + internal::shortest(tolerance_mm) +
                    "; give a distance > 0 mm (how far apart two sides may be and still be one)");
  surface::validate(s, "shared_boundaries surface");
  std::vector<MatchedCurve> out;
  constexpr int samples = 9;
  for (const Side& side : sides_of(s)) {
    std::array<Eigen::Vector3d, samples> points;
    std::array<Eigen::Vector3d, samples> normals;
    double length = 0;
    for (int k = 0; k < samples; ++k) {
      // ends excluded: a corner lies on two sides of every neighbour
      const double t = side.t0 + (side.t1 - side.t0) * (k + 0.5) / samples;
      const surface::SurfaceDerivatives d = at(s, side, t, 1);
      points[static_cast<std::size_t>(k)] = d.point;
      normals[static_cast<std::size_t>(k)] = unit_normal(d);
      if (k > 0)
        length +=
            (points[static_cast<std::size_t>(k)] - points[static_cast<std::size_t>(k - 1)]).norm();
    }
    if (length <= tolerance_mm) continue;  // a pole
    bool shared = false;
    double angle = 0;
    for (const surface::BSplineSurface* o : neighbours) {
      if (o == nullptr || o == &s) continue;
      for (const Side& other : sides_of(*o)) {
        bool on = true;
        double worst = 0;
        for (int k = 0; k < samples && on; ++k) {
          const Eigen::Vector3d& p = points[static_cast<std::size_t>(k)];
          const surface::SurfaceDerivatives d = at(*o, other, nearest(*o, other, p), 1);
          on = (d.point - p).norm() <= tolerance_mm;
          const double c = std::abs(unit_normal(d).dot(normals[static_cast<std::size_t>(k)]));
          worst = std::max(worst, std::acos(std::min(c, 1.0)) * 180 / std::numbers::pi);
        }
        if (!on) continue;
        shared = true;
        angle = std::max(angle, worst);
      }
    }
    if (!shared) continue;
    surface::Points3 ends(2, 3);
    ends << (side.u_fixed ? side.fixed : side.t0), (side.u_fixed ? side.t0 : side.fixed), 0,
        (side.u_fixed ? side.fixed : side.t1), (side.u_fixed ? side.t1 : side.fixed), 0;
    out.push_back({surface::make_curve(1, {side.t0, side.t0, side.t1, side.t1}, ends), side.t0,
                   side.t1, angle <= 1 ? 2 : 0});
  }
  return out;
}

}  // namespace clay::deform
