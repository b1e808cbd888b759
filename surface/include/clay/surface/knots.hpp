#pragma once
/// Knot insertion (Boehm), knot refinement, Bézier extraction and knot removal. None of these
/// change the shape: the new representation describes the same curve or surface (exactly, up to
/// rounding; knot removal within its tolerance).
///
/// Every function validates its input and throws clay::Error: InvalidGeometry for an invalid
/// object, OutOfDomain for a knot outside the parameter domain, InvalidArgument for a request that
/// would raise a knot's multiplicity above the degree (above degree + 1 at the domain ends of an
/// unclamped vector's outermost value).
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <span>
#include <vector>

namespace clay::surface {

/// Inserts knot t `times` times (Boehm's algorithm, The NURBS Book A5.1).
CLAY_SURFACE_API BSplineCurve insert_knot(const BSplineCurve& curve, double t, int times = 1);
/// Inserts knot u `times` times in the u direction of the surface.
CLAY_SURFACE_API BSplineSurface insert_knot_u(const BSplineSurface& surface, double u,
                                              int times = 1);
/// Inserts knot v `times` times in the v direction of the surface.
CLAY_SURFACE_API BSplineSurface insert_knot_v(const BSplineSurface& surface, double v,
                                              int times = 1);

/// The part of `surface` over [u0, u1] x [v0, v1], exactly: each cut inserted to full
/// multiplicity (Boehm), the net between kept. The same parameters: the result evaluates like
/// the surface at every (u, v) of the box, so a trimmed face's pcurves stay valid on it. A box
/// side on the domain's side cuts nothing there. Throws InvalidArgument for a box not inside the
/// domain or empty in a direction, or an unclamped basis.
CLAY_SURFACE_API BSplineSurface restricted(const BSplineSurface& surface, double u0, double u1,
                                           double v0, double v1);

/// Inserts all of `knots` (sorted or not, repeats allowed) at once (The NURBS Book A5.4).
CLAY_SURFACE_API BSplineCurve refine_knots(const BSplineCurve& curve,
                                           std::span<const double> knots);
/// Knot refinement in the u direction of the surface.
CLAY_SURFACE_API BSplineSurface refine_knots_u(const BSplineSurface& surface,
                                               std::span<const double> knots);
/// Knot refinement in the v direction of the surface.
CLAY_SURFACE_API BSplineSurface refine_knots_v(const BSplineSurface& surface,
                                               std::span<const double> knots);

/// Splits the curve into its Bézier segments, one per non-empty knot span of the domain, each a
/// clamped curve of the same degree on its own span [t_k, t_k+1] (parameters are kept, not
/// normalized), so segment k evaluates like the curve on that span.
CLAY_SURFACE_API std::vector<BSplineCurve> extract_bezier(const BSplineCurve& curve);

/// The Bézier patches of a surface, one per pair of non-empty knot spans.
struct BezierPatches {
  std::vector<double> breaks_u;         ///< distinct knot values of the u domain, ends included
  std::vector<double> breaks_v;         ///< same in v
  std::vector<BSplineSurface> patches;  ///< patch (i, j) at i * count_v() + j

  int count_u() const noexcept { return static_cast<int>(breaks_u.size()) - 1; }
  int count_v() const noexcept { return static_cast<int>(breaks_v.size()) - 1; }
  /// Patch over [breaks_u[i], breaks_u[i+1]] x [breaks_v[j], breaks_v[j+1]].
  const BSplineSurface& patch(int i, int j) const {
    return patches[static_cast<size_t>(i * count_v() + j)];
  }
};

/// Splits the surface into its Bézier patches (The NURBS Book A5.7 by way of refinement); each
/// patch keeps the surface's parameters on its span, so it evaluates like the surface there.
CLAY_SURFACE_API BezierPatches extract_bezier(const BSplineSurface& surface);

/// The inverse of extract_bezier: one surface from a grid of Bézier patches, joined with
/// interior knots of full multiplicity (C0 at every break, so remove_knots_u/_v afterwards takes
/// out the knots the continuity allows). Patch (i, j) must be one clamped Bézier span over
/// [breaks_u[i], breaks_u[i+1]] x [breaks_v[j], breaks_v[j+1]] of any degrees; each is elevated
/// (exactly) to the largest degrees of all, and the control points that neighbouring patches
/// share are averaged in homogeneous coordinates (w P, w). The result is rational when some patch
/// is. Throws clay::Error: InvalidArgument when the breaks and patches do not match (count, span,
/// clamping), InvalidGeometry when neighbouring patches do not meet — their shared homogeneous
/// points differ by more than `relative_gap` times the largest homogeneous point — or a weight
/// is not positive.
CLAY_SURFACE_API BSplineSurface join_bezier_patches(const BezierPatches& patches,
                                                    double relative_gap = 1e-9);

/// The knot vector of degree p joining Bézier spans over `breaks` (distinct, increasing, ends
/// included) with C0 continuity: the ends p + 1 times, every interior break p times, as
/// join_bezier_patches writes it.
CLAY_SURFACE_API std::vector<double> c0_knots(const std::vector<double>& breaks, int p);

/// The Bézier extraction operator of one non-empty span [a, b] of a basis: the span's Bézier
/// control point r is sum_q matrix(r, q) P[first + q] (first = span index − degree).
struct SpanExtraction {
  double a = 0, b = 1;
  int first = 0;
  Eigen::MatrixXd matrix;  ///< (degree + 1) x (degree + 1)
};

/// The extraction operator of every non-empty span of the domain, by the same refinement as
/// extract_bezier (applied to the identity), for nets of any dimension such as FFD lattices.
CLAY_SURFACE_API std::vector<SpanExtraction> bezier_extraction(const BSplineBasis& basis);

/// A curve after remove_knots, and how many knots were taken out.
struct CurveKnotRemoval {
  BSplineCurve curve;
  int removed = 0;
};
/// A surface after remove_knots, remove_knots_u or _v, and how many knots were taken out.
struct SurfaceKnotRemoval {
  BSplineSurface surface;
  int removed = 0;
};

/// Removes every interior knot as often as its removal moves the homogeneous control points
/// (w·P, w) by at most `tolerance_mm` in all (The NURBS Book A5.8; the gaps of repeated
/// removals of one knot value add up within the tolerance). For a polynomial curve that bounds
/// how far the curve moves; exact composition joins Bézier patches with full-multiplicity knots
/// and calls this with 1e-12 of the model size to return the smallest exact representation.
/// Throws InvalidGeometry for an invalid curve, InvalidArgument for a negative or non-finite
/// tolerance.
CLAY_SURFACE_API CurveKnotRemoval remove_knots(const BSplineCurve& curve, double tolerance_mm);
/// remove_knots in the u direction: a u knot goes only when every column of the net allows it.
CLAY_SURFACE_API SurfaceKnotRemoval remove_knots_u(const BSplineSurface& surface,
                                                   double tolerance_mm);
/// remove_knots in the v direction.
CLAY_SURFACE_API SurfaceKnotRemoval remove_knots_v(const BSplineSurface& surface,
                                                   double tolerance_mm);
/// remove_knots in both directions, u then v (the gaps of each direction within `tolerance_mm`):
/// the result of remove_knots_v(remove_knots_u(s, t).surface, t), with one homogeneous net and
/// no surface in between.
CLAY_SURFACE_API SurfaceKnotRemoval remove_knots(const BSplineSurface& surface,
                                                 double tolerance_mm);

}  // namespace clay::surface
