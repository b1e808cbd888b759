#pragma once
/// BSplineCurve — a (rational) B-spline curve as plain data.
///
/// C(t) = sum_i N_{i,p}(t) w_i P_i / sum_i N_{i,p}(t) w_i. Weights are all 1 for a polynomial
/// curve; one type serves both so that no algorithm exists twice.
#include <clay/surface/basis.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <string>
#include <string_view>
#include <vector>

namespace clay::surface {

/// Control points, one row per point (x, y, z in millimetres), row-major so each point is
/// contiguous.
using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// A B-spline curve: basis, control points (basis.count() rows) and weights (basis.count() entries,
/// positive, all 1 when polynomial).
struct CLAY_SURFACE_API BSplineCurve {
  BSplineBasis basis;
  Points3 points;
  Eigen::VectorXd weights;

  /// True when some weight differs from 1.
  bool is_rational() const noexcept;
};

/// Builds and validates a curve; `weights` empty means polynomial (all 1).
/// Throws clay::Error(InvalidGeometry) naming every broken invariant.
CLAY_SURFACE_API BSplineCurve make_curve(int degree, std::vector<double> knots, Points3 points,
                                         Eigen::VectorXd weights = {});

/// Every invariant the curve breaks, in words, each naming `name`. Empty when valid.
CLAY_SURFACE_API std::vector<std::string> problems(const BSplineCurve& curve,
                                                   std::string_view name = "curve");

/// Throws clay::Error(InvalidGeometry) listing problems(curve, name) when there are any.
CLAY_SURFACE_API void validate(const BSplineCurve& curve, std::string_view name = "curve");

/// True when degree, knots, control points and weights are equal bit for bit.
CLAY_SURFACE_API bool identical(const BSplineCurve& a, const BSplineCurve& b) noexcept;

/// The same curve run backwards on the same domain [a, b]: reversed(c)(t) = c(a + b - t). Knots
/// are mirrored, control points and weights reversed (exact up to the rounding of a + b - t).
CLAY_SURFACE_API BSplineCurve reversed(const BSplineCurve& curve);

/// The curve mirrored in the plane through `origin` with normal `normal` (any length): control
/// points reflected, p - 2 ((p - origin) . n) n, knots and weights kept, so the mirrored curve
/// is the reflection of the curve at every parameter (up to the rounding of the reflection).
/// Throws clay::Error(InvalidArgument) for a zero or non-finite normal or origin.
CLAY_SURFACE_API BSplineCurve mirrored(const BSplineCurve& curve, const Eigen::Vector3d& origin,
                                       const Eigen::Vector3d& normal);

}  // namespace clay::surface
