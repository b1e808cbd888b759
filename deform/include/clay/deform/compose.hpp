#pragma once
/// Exact composition of an FFD with a (rational) B-spline surface: the deformed surface is again
/// a NURBS surface, computed exactly (Sederberg–Parry 1986 §2.1, "a deformed parametric surface
/// remains a parametric surface... a simple composition"), not resampled.
///
/// How (docs/deform.md, "Exact composition"):
/// - The surface is cut into its Bézier patches. On a patch, each lattice local coordinate
///   (Sederberg–Parry eq. (1)) is affine in the homogeneous coordinates (wX, w), so it is a
///   bivariate Bernstein polynomial S(α, β) over the weight W(α, β): s = S / W.
/// - Eq. (2) is evaluated with polynomials in place of numbers (homogeneous de Casteljau:
///   level r = (W − S) · level r−1 [i] + S · level r−1 [i+1], exact Bernstein products), giving a
///   patch with weights W^(l+m+n) for a rational surface.
/// - Degrees are the smallest exact ones: in α at most l·d_α(s) + m·d_α(t) + n·d_α(u), where d_α(c)
/// is
///   0 when c is constant on the patch and otherwise the larger of the α-degrees of its
///   homogeneous numerator and of W (the plain degree of c for a polynomial surface). A degree is
///   read off the Bernstein coefficients: the polynomial has degree e < p when the form reduced
///   to degree e (power-basis truncation) and elevated back to p reproduces every coefficient to
///   1e-14 of the rounding scale of the coordinates (control points times the dual edge vectors).
///   When the lattice's polynomial has lower total degree than l + m + n (an affine lattice has
///   1), the patch is composed monomial by monomial and gets max over the monomials s^a t^b u^c of
///   a·d_α(s) + b·d_α(t) + c·d_α(u) + (T − a − b − c)·d_α(W), T the largest a + b + c: an affine
///   lattice keeps the surface's degrees (docs/deform.md, "The lattice's true total degree").
/// - The patches are elevated to a common degree, joined into one B-spline surface with interior
///   knots of full multiplicity, and every interior knot whose removal is exact (The NURBS Book
///   A5.8 in homogeneous coordinates, ComposeOptions::knot_tolerance) is removed: the continuity
///   of the original surface carries over.
///
/// The FFD is the identity outside the lattice (lattice.hpp), so a surface that leaves the lattice
/// is not one polynomial patch there: compose_exact certifies (Bernstein bounds and subdivision)
/// that every patch lies in the lattice and throws otherwise; it never returns a wrong surface.
#include <clay/deform/export.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/regular.hpp>
#include <clay/summary.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <string>
#include <vector>

namespace clay::deform {

/// Settings of compose_exact.
struct CLAY_DEFORM_API ComposeOptions {
  /// Knot removal tolerance, relative to the largest homogeneous control point of the composed
  /// net (dimensionless, in [0, 1e-6]). 0 keeps every patch boundary (a C0 patchwork).
  double knot_tolerance = 1e-12;
  /// Samples per patch and direction at which the result is compared with the pointwise
  /// deformation of the original for ComposeReport::max_relative_deviation (>= 0; 0 skips the
  /// check).
  int check_samples = 4;
  /// The highest degree the exact composition may have, in [1, 50]: above it compose_exact
  /// throws DegreeLimit naming the degree and the ways out. 25 is what OpenCASCADE, and so our
  /// STEP/IGES export, accepts (surface::max_exchange_degree in clay/occt/surface_exchange.hpp);
  /// give the receiver's own limit (CATIA's order 16 is degree 15) to fail early.
  int max_degree = 25;
  /// > 0: the most control points the exact composition may have, predicted from every patch's
  /// exact degrees and the continuity the surface's knot multiplicities give, before any patch is
  /// composed (so a net of millions is never built; an upper bound, as knot removal may find the
  /// surface smoother than its multiplicities say): above it compose_exact throws DegreeLimit
  /// naming the size. 0 (the default): no limit. deform_surface's budget
  /// (SurfaceDeformationOptions::budget) sets it.
  long max_control_points = 0;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// The size of an exact composition: its degrees and control points.
struct ExactSize {
  int degree_u = 0;
  int degree_v = 0;
  long control_points = 0;
};

/// What compose_exact built, and how closely it matches the pointwise deformation.
struct CLAY_DEFORM_API ComposeReport {
  int degree_u = 0;         ///< degree of the result in u
  int degree_v = 0;         ///< degree of the result in v
  int patches = 0;          ///< Bézier patches composed (after any splits at lattice knot planes)
  long control_points = 0;  ///< control points of the result
  int knots_removed = 0;    ///< interior knots removed exactly after the patches were joined
  int splits = 0;           ///< knots inserted to split the surface at lattice knot planes
  /// Largest distance between the result and the pointwise deformation (deform_point of the
  /// original surface's points) over check_samples² parameters per patch, divided by `size`
  /// (dimensionless; ~1e-15 for an exact composition). 0 when check_samples is 0.
  double max_relative_deviation = 0.0;
  double size = 0.0;  ///< the reference length (mm): the lattice control points' box
                      ///< diagonal, or the surface's control box diagonal for a taper
  bool exact = true;  ///< true: the result is the composition, exact up to rounding
  /// Converged (a composition that cannot be exact throws instead); message = brief(),
  /// final_residual = max_relative_deviation.
  Summary summary;

  /// One line: degrees, patches, control points, knots removed, deviation.
  std::string brief() const;
};

/// The composed surface and its report.
struct ComposeResult {
  surface::BSplineSurface surface;  ///< the deformed surface, same parameter domain
  ComposeReport report;
};

/// The surface deformed by the Bézier lattice, exactly: Sederberg–Parry eq. (2) composed with the
/// surface patch by patch (see above). Throws clay::Error: InvalidGeometry for an invalid lattice
/// or surface, InvalidArgument for bad options, OutOfDomain when part of the surface lies outside
/// the lattice (naming the patch, the local coordinate and a parameter where it is outside),
/// DegreeLimit when the exact degree exceeds ComposeOptions::max_degree (naming the degree and
/// the ways out: a lattice of lower degree in the thickness direction, or a refit tolerance).
CLAY_DEFORM_API ComposeResult compose_exact(const BezierLattice& lattice,
                                            const surface::BSplineSurface& surface,
                                            const ComposeOptions& options = {});

/// The surface deformed by the B-spline lattice (Hsu–Hughes–Kaufman eq. (1)), exactly, through
/// its Bézier cells (bezier_cells). Where a local coordinate that depends on one surface
/// parameter only crosses a knot plane, the surface is split there by knot insertion; every
/// resulting patch must then lie in one cell and is composed with it. Throws as the Bézier
/// overload, and clay::Error(InvalidArgument) when a patch crosses a knot plane otherwise (naming
/// the patch, the plane and a parameter of the crossing): such a surface needs a refit tolerance.
CLAY_DEFORM_API ComposeResult compose_exact(const BSplineLattice& lattice,
                                            const surface::BSplineSurface& surface,
                                            const ComposeOptions& options = {});

/// The surface tapered by a polynomial profile (Güdükbay–Özgüç 1990 §3.1.1: X = r(z) x,
/// Y = r(z) y, Z = z), exactly: with D the profile degree, degree D·d(z) + e per direction, where
/// d(z) is the degree of Barr's axial coordinate on the patch (0 when constant) and e that of the
/// patch, weights W^(D+1). The taper deforms all of space, so no containment is required.
/// Throws clay::Error: InvalidGeometry for an invalid taper or surface, InvalidArgument for bad
/// options, DegreeLimit above ComposeOptions::max_degree (naming the degree; ways out: a
/// profile of lower degree, or a refit tolerance).
CLAY_DEFORM_API ComposeResult compose_exact(const Taper& taper,
                                            const surface::BSplineSurface& surface,
                                            const ComposeOptions& options = {});

}  // namespace clay::deform
