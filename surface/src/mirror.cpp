// Mirror images of curves and surfaces (bspline_curve.hpp, bspline_surface.hpp): control points
// reflected in a plane, exact up to the rounding of the reflection.
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <clay/error.hpp>

#include <cmath>
#include <string>

namespace clay::surface {
namespace {

/// The unit normal of a mirror plane, or InvalidArgument.
Eigen::Vector3d mirror_normal(const Eigen::Vector3d& origin, const Eigen::Vector3d& normal) {
  const double length = normal.norm();
  if (!std::isfinite(length) || !(length > 0) || !origin.allFinite())
    throw Error(ErrorCategory::InvalidArgument,
                "mirrored: the mirror plane needs a finite origin and a finite, non-zero normal");
  return normal / length;
}

/// Each row p reflected in the plane through `origin` with unit normal n.
Points3 reflected(const Points3& points, const Eigen::Vector3d& origin, const Eigen::Vector3d& n) {
  Points3 out = points;
  for (Eigen::Index r = 0; r < out.rows(); ++r) {
    const Eigen::Vector3d p = points.row(r).transpose();
    out.row(r) = (p - 2 * (p - origin).dot(n) * n).transpose();
  }
  return out;
}

}  // namespace

BSplineCurve mirrored(const BSplineCurve& curve, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& normal) {
  validate(curve);
  const Eigen::Vector3d n = mirror_normal(origin, normal);
  BSplineCurve c = curve;
  c.points = reflected(curve.points, origin, n);
  return c;
}

BSplineSurface mirrored(const BSplineSurface& surface, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& normal) {
  validate(surface);
  const Eigen::Vector3d n = mirror_normal(origin, normal);
  BSplineSurface s = surface;
  // u reversed: the reflection turns the frame (S_u, S_v, normal) left-handed; reversing u turns
  // it back, so the normal is the mirror image of the original's.
  const auto [a, b] = surface.u.domain();
  const std::size_t m = surface.u.knots.size();
  for (std::size_t i = 0; i < m; ++i) s.u.knots[i] = a + b - surface.u.knots[m - 1 - i];
  const int nu = surface.count_u(), nv = surface.count_v();
  const Points3 points = reflected(surface.points, origin, n);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      s.points.row(s.index(i, j)) = points.row(surface.index(nu - 1 - i, j));
      s.weights[s.index(i, j)] = surface.weights[surface.index(nu - 1 - i, j)];
    }
  return s;
}

}  // namespace clay::surface
