#pragma once
/// Degree elevation: the same curve or surface written with a higher degree (The NURBS Book A5.9).
/// Each distinct knot's multiplicity grows by the elevation so the continuity is kept. An unclamped
/// knot vector is clamped first (its domain and shape are kept; the knots outside the domain go).
///
/// Throws clay::Error: InvalidGeometry for an invalid object, InvalidArgument for times < 0 or a
/// result above max_kernel_degree.
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/export.hpp>

namespace clay::surface {

/// The curve with degree raised by `times`.
CLAY_SURFACE_API BSplineCurve elevate_degree(const BSplineCurve& curve, int times = 1);
/// The surface with its u degree raised by `times`.
CLAY_SURFACE_API BSplineSurface elevate_degree_u(const BSplineSurface& surface, int times = 1);
/// The surface with its v degree raised by `times`.
CLAY_SURFACE_API BSplineSurface elevate_degree_v(const BSplineSurface& surface, int times = 1);

/// The curve with a clamped knot vector on the same domain (returned bit for bit if already
/// clamped).
CLAY_SURFACE_API BSplineCurve clamp(const BSplineCurve& curve);
/// The surface with clamped knot vectors in both directions on the same domain (a direction
/// already clamped is kept bit for bit).
CLAY_SURFACE_API BSplineSurface clamp(const BSplineSurface& surface);

}  // namespace clay::surface
