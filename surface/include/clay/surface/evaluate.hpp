#pragma once
/// Evaluation of B-spline curves and surfaces: points, derivatives up to order 2, batch grids.
///
/// Rational derivatives follow The NURBS Book A3.6 (homogeneous derivatives) and A4.4 (quotient
/// rule). Every function throws clay::Error(OutOfDomain) for a parameter outside the domain and
/// clay::Error(InvalidArgument) for a derivative order outside [0, 2]. Single-point functions
/// assume a valid object (see validate()); batch functions validate it once.
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <span>
#include <vector>

namespace clay::surface {

/// Point and derivatives of a curve at t; entries above the requested order are zero.
struct CurveDerivatives {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d d1 = Eigen::Vector3d::Zero();  ///< dC/dt
  Eigen::Vector3d d2 = Eigen::Vector3d::Zero();  ///< d2C/dt2
};

/// Point and partial derivatives of a surface at (u, v); entries above the order are zero.
struct SurfaceDerivatives {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d du = Eigen::Vector3d::Zero();
  Eigen::Vector3d dv = Eigen::Vector3d::Zero();
  Eigen::Vector3d duu = Eigen::Vector3d::Zero();
  Eigen::Vector3d duv = Eigen::Vector3d::Zero();
  Eigen::Vector3d dvv = Eigen::Vector3d::Zero();
};

/// C(t).
CLAY_SURFACE_API Eigen::Vector3d evaluate(const BSplineCurve& curve, double t);
/// C(t) and its derivatives up to `order` (0, 1 or 2).
CLAY_SURFACE_API CurveDerivatives derivatives(const BSplineCurve& curve, double t, int order = 2);

/// S(u, v).
CLAY_SURFACE_API Eigen::Vector3d evaluate(const BSplineSurface& surface, double u, double v);
/// S(u, v) and its partial derivatives up to total `order` (0, 1 or 2).
CLAY_SURFACE_API SurfaceDerivatives derivatives(const BSplineSurface& surface, double u, double v,
                                                int order = 2);

/// Unit normal (S_u x S_v) / |S_u x S_v| at (u, v). Throws clay::Error(InvalidGeometry) where the
/// surface is degenerate (|S_u x S_v| below 1e-300 relative to |S_u||S_v|).
CLAY_SURFACE_API Eigen::Vector3d unit_normal(const BSplineSurface& surface, double u, double v);

/// Points of a curve at each parameter, one row each.
CLAY_SURFACE_API Points3 evaluate_many(const BSplineCurve& curve, std::span<const double> ts);

/// Points of the grid us x vs: row iu * vs.size() + iv holds S(us[iu], vs[iv]). The basis functions
/// of each u and v are computed once and the control net is contracted a direction at a time, so a
/// grid costs about (p+1)*count_v + (q+1) multiply-adds per point instead of (p+1)(q+1) plus a
/// basis evaluation.
CLAY_SURFACE_API Points3 evaluate_grid(const BSplineSurface& surface, std::span<const double> us,
                                       std::span<const double> vs);

/// S and its partial derivatives up to order 2 on the grid us x vs (row iu * vs.size() + iv),
/// equal to derivatives(surface, u, v, 2) to rounding: the basis functions and their derivatives
/// of each parameter computed once, the homogeneous net contracted in u first, then the rational
/// quotient rule (The NURBS Book A2.3, A3.6, A4.4). The tessellator and the viewer use it.
CLAY_SURFACE_API std::vector<SurfaceDerivatives> derivatives_grid(const BSplineSurface& surface,
                                                                  std::span<const double> us,
                                                                  std::span<const double> vs);

/// `count` >= 2 evenly spaced parameters covering [first, last], ends exact.
CLAY_SURFACE_API std::vector<double> linspace(double first, double last, int count);

}  // namespace clay::surface
