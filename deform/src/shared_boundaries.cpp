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
  constexpr int samples = 9;
  struct Samples {
    std::array<Eigen::Vector3d, samples> points, normals;
    bool pole = false;
  };
  const std::array<Side, 4> sides = sides_of(s);
  std::array<Samples, 4> at_side;
  int live = 0;  // sides that are not poles
  for (std::size_t q = 0; q < 4; ++q) {
    const Side& side = sides[q];
    double length = 0;
    for (std::size_t k = 0; k < samples; ++k) {
      // ends excluded: a corner lies on two sides of every neighbour
      const double t = side.t0 + (side.t1 - side.t0) * (static_cast<double>(k) + 0.5) / samples;
      const surface::SurfaceDerivatives d = at(s, side, t, 1);
      at_side[q].points[k] = d.point;
      at_side[q].normals[k] = unit_normal(d);
      if (k > 0) length += (at_side[q].points[k] - at_side[q].points[k - 1]).norm();
    }
    at_side[q].pole = length <= tolerance_mm;
    live += !at_side[q].pole;
  }
  std::array<bool, 4> shared{};
  std::array<double, 4> angle{};
  for (const surface::BSplineSurface* o : neighbours) {
    if (o == nullptr || o == &s) continue;
    std::array<bool, 4> on{};
    std::array<double, 4> worst{};
    int count = 0;
    for (std::size_t q = 0; q < 4; ++q) {
      if (at_side[q].pole) continue;
      for (const Side& other : sides_of(*o)) {
        bool all = true;
        double w = 0;
        for (std::size_t k = 0; k < samples && all; ++k) {
          const Eigen::Vector3d& p = at_side[q].points[k];
          const surface::SurfaceDerivatives d = at(*o, other, nearest(*o, other, p), 1);
          all = (d.point - p).norm() <= tolerance_mm;
          const double c = std::abs(unit_normal(d).dot(at_side[q].normals[k]));
          w = std::max(w, std::acos(std::min(c, 1.0)) * 180 / std::numbers::pi);
        }
        if (all) on[q] = true, worst[q] = std::max(worst[q], w);
      }
      count += on[q];
    }
    // the same patch all round (a copy, the surface it was styled or rebuilt from, a variant of
    // it): not a neighbour, nothing is built to meet it
    if (count == live) continue;
    for (std::size_t q = 0; q < 4; ++q)
      if (on[q]) shared[q] = true, angle[q] = std::max(angle[q], worst[q]);
  }
  std::vector<MatchedCurve> out;
  for (std::size_t q = 0; q < 4; ++q) {
    if (!shared[q]) continue;
    const Side& side = sides[q];
    surface::Points3 ends(2, 3);
    ends << (side.u_fixed ? side.fixed : side.t0), (side.u_fixed ? side.t0 : side.fixed), 0,
        (side.u_fixed ? side.fixed : side.t1), (side.u_fixed ? side.t1 : side.fixed), 0;
    out.push_back({surface::make_curve(1, {side.t0, side.t0, side.t1, side.t1}, ends), side.t0,
                   side.t1, angle[q] <= 1 ? 2 : 0});
  }
  return out;
}

}  // namespace clay::deform
