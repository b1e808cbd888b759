#pragma once
/// BSplineSurface — a tensor-product (rational) B-spline surface as plain data.
///
/// S(u,v) = sum_ij N_i(u) N_j(v) w_ij P_ij / sum_ij N_i(u) N_j(v) w_ij.
/// Storage: control point (i, j), 0 <= i < u.count(), 0 <= j < v.count(), is row
/// i * v.count() + j of `points` (u-major); `weights` uses the same index and is all 1 when the
/// surface is polynomial.
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <string>
#include <string_view>
#include <vector>

namespace clay::surface {

/// A B-spline surface: a basis per direction, the control net and its weights.
struct CLAY_SURFACE_API BSplineSurface {
  BSplineBasis u;
  BSplineBasis v;
  Points3 points;           ///< u.count() * v.count() rows, index i * v.count() + j
  Eigen::VectorXd weights;  ///< same index, positive; all 1 when polynomial

  int count_u() const noexcept { return u.count(); }
  int count_v() const noexcept { return v.count(); }
  /// Row of control point (i, j) in `points` and `weights`.
  Eigen::Index index(int i, int j) const noexcept {
    return static_cast<Eigen::Index>(i) * v.count() + j;
  }
  /// True when some weight differs from 1.
  bool is_rational() const noexcept;
};

/// Builds and validates a surface; `weights` empty means polynomial (all 1).
/// Throws clay::Error(InvalidGeometry) naming every broken invariant.
CLAY_SURFACE_API BSplineSurface make_surface(BSplineBasis u, BSplineBasis v, Points3 points,
                                             Eigen::VectorXd weights = {});

/// Every invariant the surface breaks, in words, each naming `name`. Empty when valid: both bases
/// valid, points.rows() == u.count() * v.count(), weights of the same size, positive and finite,
/// coordinates finite.
CLAY_SURFACE_API std::vector<std::string> problems(const BSplineSurface& surface,
                                                   std::string_view name = "surface");

/// Throws clay::Error(InvalidGeometry) listing problems(surface, name) when there are any.
CLAY_SURFACE_API void validate(const BSplineSurface& surface, std::string_view name = "surface");

/// True when degrees, knots, control points and weights are equal bit for bit.
CLAY_SURFACE_API bool identical(const BSplineSurface& a, const BSplineSurface& b) noexcept;

/// The surface mirrored in the plane through `origin` with normal `normal` (any length), with
/// its u direction reversed so that its normal is the mirror image of the original's (a mirrored
/// half of a symmetric body faces outward as the original does): mirrored(s)(u, v) is the
/// reflection of s(a + b - u, v) on the same domain [a, b] x [c, d]; v, weights and degrees
/// kept. Throws clay::Error(InvalidArgument) for a zero or non-finite normal or origin.
CLAY_SURFACE_API BSplineSurface mirrored(const BSplineSurface& surface,
                                         const Eigen::Vector3d& origin,
                                         const Eigen::Vector3d& normal);

/// Axis-aligned box of the control points {min, max} (it contains the surface).
CLAY_SURFACE_API std::pair<Eigen::Vector3d, Eigen::Vector3d> control_box(
    const BSplineSurface& surface);

}  // namespace clay::surface
