#pragma once
/// Curves taken from a surface: iso-curves and boundaries (exact), a curve projected onto the
/// surface and a curve offset along the surface normal (fitted within a stated tolerance, with
/// the measured deviation). A designer draws on the surface with these (issue #21).
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/export.hpp>

#include <string>
#include <vector>

namespace clay::surface {

/// The iso-curve v -> S(u, v) at fixed u, exact: its control points are the homogeneous columns
/// of the net contracted with the u basis at u (sum_i N_i(u) (w_ij P_ij, w_ij)); basis and
/// domain are the surface's v basis. At the domain ends it is the boundary curve. Throws
/// clay::Error: InvalidGeometry for an invalid surface, OutOfDomain for u outside the u domain.
CLAY_SURFACE_API BSplineCurve iso_curve_u(const BSplineSurface& surface, double u);
/// The iso-curve u -> S(u, v) at fixed v, exact; as iso_curve_u with the directions swapped.
CLAY_SURFACE_API BSplineCurve iso_curve_v(const BSplineSurface& surface, double v);

/// Settings of project_curve() and offset_along_normal().
struct CLAY_SURFACE_API CurveFitOptions {
  double tolerance_mm = 1e-3;     ///< > 0 and finite: largest deviation of the fit from its target
  int degree = 3;                 ///< degree of the fitted curve, 1..9
  int max_control_points = 2000;  ///< > degree: the fit's spans are halved up to this count

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// A fitted curve and how close it came.
struct FittedCurve {
  BSplineCurve curve;           ///< polynomial, on the input curve's domain
  double max_deviation_mm = 0;  ///< largest |fit(t) - target(t)| at the samples
  int samples = 0;              ///< where it was measured (16 per span of the fit)
  int iterations = 0;           ///< fit rounds (spans halved between them)
};

/// The curve projected onto the surface: each point C(t) goes to its closest point on the
/// surface (closest_point), and a polynomial B-spline of options.degree on the curve's own
/// breakpoints is fitted by least squares to those feet at Chebyshev-Lobatto parameters (end
/// feet interpolated), its spans halved where the fit misses, until the largest distance between
/// fit(t) and the foot of C(t) on 16 samples per span is within options.tolerance_mm. That figure
/// also bounds the fit's distance to the surface. Throws clay::Error: InvalidArgument for bad
/// options; InvalidGeometry for an invalid curve or surface, and when the fit still misses at
/// max_control_points (the message gives the deviation, where, and that the curve may jump
/// between two branches of closest points there: draw it nearer the surface, or split it).
CLAY_SURFACE_API FittedCurve project_curve(const BSplineCurve& curve, const BSplineSurface& surface,
                                           const CurveFitOptions& options = {});

/// The curve offset along the surface normal: each point C(t) goes to its closest point F(t) on
/// the surface plus `distance` times the unit normal there (S_u x S_v, so the side follows the
/// surface's orientation; a negative distance goes the other way), fitted as in project_curve.
/// For a curve on the surface (an iso-curve, a projection) F(t) is C(t) itself. Throws as
/// project_curve, and InvalidArgument for a distance that is not finite; InvalidGeometry where
/// the normal is undefined (a degenerate point of the surface).
CLAY_SURFACE_API FittedCurve offset_along_normal(const BSplineCurve& curve,
                                                 const BSplineSurface& surface, double distance,
                                                 const CurveFitOptions& options = {});

}  // namespace clay::surface
