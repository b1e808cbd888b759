#pragma once
/// Certified refit: a deformed surface approximated by a polynomial B-spline surface of chosen
/// degree where the exact composition is not polynomial (twist, bend, extended lattices, lattice
/// knot planes crossed by a patch), with a report of the tolerance, the sampled maximum deviation
/// and a certified upper bound of the deviation over the whole parameter domain.
///
/// Method (docs/deform.md, "Certified refit"):
/// - Fit: tensor-product least squares on Chebyshev–Lobatto parameters, degree + 1 intervals per
///   knot span, of the pointwise deformation D(S(u, v)) on the original's parameter domain. The fit
///   keeps the original's breakpoints with the same continuity (so C0 seams survive) and adds
///   knots at the middle of every span whose cell is not within the tolerance, until every cell is.
/// - Certificate, per cell (pair of knot spans) of the fit: the error e = fit − D∘S is sampled on
///   a uniform grid at least 4x denser than the fit's parameters (chosen denser when needed), and
///   the bilinear interpolation remainder is bounded by (h_u^2 / 8) sup|e_uu| + (h_v^2 / 8)
///   sup|e_vv|, where e_uu = fit_uu − D''[S_u, S_u] − D' S_uu is bounded by the convex hull of the
///   hodograph control nets of the fit and of S (rational S by the quotient rule) and by bounds
///   of |D'| and |D''| over the convex hull of the cell's control points (analytic for taper,
///   twist and bend; from the lattice's difference nets for Bézier and B-spline lattices; chained
///   for stacks). Where D is only continuous in the cell (the cell's hull crosses a lattice face,
///   a degree-1 lattice's knot plane or a bend's region end) the first-derivative remainder
///   (h_u / 2) sup|e_u| + (h_v / 2) sup|e_v| is used. The bound is max|e(grid)| plus that remainder
///   plus a rounding allowance of 1e-12 of the size: a true upper bound in exact arithmetic.
/// - Extended lattices (Newton-frozen, no derivative bounds) and plain point maps are fitted the
///   same way but not certified: the report then has certified == false and only the sampled
///   maximum, and says why.
#include <clay/deform/export.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/regular.hpp>
#include <clay/deform/stack.hpp>
#include <clay/summary.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <functional>
#include <limits>
#include <string>
#include <variant>
#include <vector>

namespace clay::deform {

/// A curve on a surface, as a pcurve: (u, v, 0) = pcurve(t) for t in [t0, t1] (brep::Coedge's
/// form). RefitOptions::matched_curves.
struct MatchedCurve {
  surface::BSplineCurve pcurve;
  double t0 = 0, t1 = 0;  ///< the part of the pcurve on the surface's edge, t0 < t1
  /// What the fit keeps along it: 0 the position (a sharp edge: its faces' angle there is not
  /// continuity), 1 also the normal (a tangent edge), 2 also the curvature (a G2 edge).
  int order = 2;
};

/// Settings of refit_deformed().
struct CLAY_DEFORM_API RefitOptions {
  int degree = 3;  ///< degree of the fit in u and v, 1..25 (the exchange limit)
  /// Allowed deviation, exactly one of the two > 0 (the other 0): relative_tolerance is a
  /// fraction of the deformed surface's size (the diagonal of a sample's bounding box),
  /// tolerance_mm is in millimetres.
  double relative_tolerance = 1e-4;
  double tolerance_mm = 0;             ///< see relative_tolerance
  int max_iterations = 12;             ///< >= 1: fit / certify / refine rounds
  int max_control_points = 40000;      ///< >= (degree + 1)^2: no refinement beyond this net size
  int max_count_per_direction = 1000;  ///< >= degree + 1: no refinement beyond this many control
                                       ///< points in u or in v (the dense least squares per
                                       ///< direction take 32 count^2 bytes)
  double certificate_share = 0.1;      ///< in (0, 1): share of the tolerance the certificate's
                                   ///< remainder may take when choosing each cell's sample density
  /// true: the fit starts from every breakpoint of the original, with its continuity; false:
  /// only from those where the original is rougher than the fit's own joins, C^(degree - 1)
  /// (creases and C1 joins for a cubic fit), and, for a cubic fit, from the C2 joins whose jump
  /// of the third derivative a cubic would feel (J h^3 above a tenth of the tolerance, h the
  /// shorter neighbouring span: a loft's joins between few sections), adding knots only where
  /// the tolerance needs them. An exact result of degree 12 with hundreds of smooth knots (a
  /// style refinement's simple knots) then refits to a small, editable net (the recipes'
  /// "editable" output uses false).
  bool keep_breakpoints = true;
  /// > 0: a fixed net of count_u x count_v control points on uniform knots over the original's
  /// domain (a rebuild: a regular, denser or lighter net), fitted once and certified, no knots
  /// added (termination NotConverged when the bound misses the tolerance); 0: adaptive. Both or
  /// neither, each in [degree + 1, max_count_per_direction].
  int count_u = 0;
  int count_v = 0;  ///< see count_u
  /// > 0 (adaptive fits only): start from a uniform net of initial_count x initial_count control
  /// points instead of the original's breakpoints, then add knots where cells miss. Near
  /// max_count_per_direction the spans with the worst cells are split first, so a capped net
  /// (class A: degree 5, at most 32 per direction) has its knots where the error is. 0, or in
  /// [degree + 1, max_count_per_direction].
  int initial_count = 0;

  /// Curves on the surface along which the fit follows the map more closely than the tolerance
  /// asks (a model face's edges, issue #38 step 7): their samples are weighted rows of the least
  /// squares for the position and both first derivatives of D∘S, and spans are split until, at
  /// every sample, the fit is within matched_gap_mm of D∘S and its normal within
  /// matched_angle_deg of D∘S's. Two faces fitted so along their shared edge then meet within
  /// twice these figures, wherever the exact result's faces meet (a tangent edge stays tangent).
  /// Sampled, not certified (the certificate still bounds the whole surface by the tolerance).
  /// A closed side's seam (the face meets itself) is tied instead: the fit keeps the source's
  /// own continuity across it (up to G2) exactly, and its samples only weigh in the fit.
  std::vector<MatchedCurve> matched_curves;
  double matched_gap_mm = 0;     ///< > 0 with matched_curves: largest distance along them (mm)
  double matched_angle_deg = 0;  ///< > 0 with matched_curves: largest normal angle along them
  /// With matched_curves: D∘S's second derivatives along them are rows too, each allowed this
  /// fraction of the larger normal curvature there (at least 1 / size), so that edges where the
  /// exact result is G2 keep their curvature; 0: position and normals only.
  double matched_curvature = 0.002;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// A cell of the fit whose control net's convex hull crosses a knot plane or a face of a lattice
/// (where the lattice's map is only C^(degree-1), or C0 at the faces): the fit has one polynomial
/// piece there, and these are its numbers.
struct KnotPlaneCrossing {
  int cell_u = 0;          ///< index of the fit's non-empty u knot span
  int cell_v = 0;          ///< index of the fit's non-empty v knot span
  int step = 0;            ///< index of the stack step (0 for a single lattice)
  int axis = 0;            ///< 0 = S, 1 = T, 2 = U (lattice local axes)
  double plane = 0;        ///< local coordinate of the plane (0 and 1 are the lattice's faces)
  double sampled_max = 0;  ///< largest sampled deviation in the cell (mm)
  double bound = std::numeric_limits<double>::infinity();  ///< certified bound in the cell (mm)
};

/// What refit_deformed() did.
struct CLAY_DEFORM_API RefitReport {
  /// Converged: the certified bound (or, when not certified, the sampled maximum) is within the
  /// tolerance; NotConverged: iteration or control point limit reached first.
  Summary summary;
  bool certified = false;   ///< certified_bound_mm is a true upper bound of |fit − D∘S|
  double tolerance_mm = 0;  ///< the tolerance applied
  double size = 0;          ///< diagonal of the deformed sample's bounding box (mm)
  double sampled_max = 0;   ///< largest deviation at the certificate's samples (mm)
  double certified_bound_mm =
      std::numeric_limits<double>::infinity();  ///< mm; inf if not certified
  long samples = 0;         ///< number of points sampled by the last certificate
  int degree_u = 0;         ///< degree of the fit in u
  int degree_v = 0;         ///< degree of the fit in v
  int knots_added_u = 0;    ///< knots added to the original's breakpoints in u (by refinement)
  int knots_added_v = 0;    ///< same in v
  int lipschitz_cells = 0;  ///< cells bounded by first derivatives only (D not C1 there)
  std::vector<KnotPlaneCrossing> crossings;  ///< every lattice plane crossing of the final fit
  /// With RefitOptions::matched_curves: the largest distance from D∘S (mm) and the largest angle
  /// between the normals (deg) at their samples (a tied seam's left out); 0 without.
  double matched_gap_mm = 0, matched_angle_deg = 0;
  long matched_samples = 0;  ///< samples along the matched curves

  /// One line: "certified 3.1e-03 mm <= 1.0e-02 mm (sampled 2.2e-03 mm), 12 x 9 control points,
  /// 3 iterations, 0 knot-plane crossings".
  std::string brief() const;
};

/// The fit and its report.
struct RefitResult {
  surface::BSplineSurface surface;  ///< polynomial B-spline, degree options.degree, on the
                                    ///< original's parameter domain
  RefitReport report;
};

/// Any map of space, point by point (mm to mm).
using PointMap = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

/// Certified refit of the surface itself (the identity map): an exchange-friendly, lower-degree
/// copy of an exact result, within the tolerance everywhere on its domain. Throws as
/// refit_deformed().
CLAY_DEFORM_API RefitResult refit_surface(const surface::BSplineSurface& surface,
                                          const RefitOptions& options = {});

/// What refit_deformed() maps the surface by: one deformation (Deformation: a Bézier, B-spline or
/// extended lattice, a taper, twist or bend), a stack of them, or any point map. Each converts
/// implicitly, so refit_deformed(taper, surface) reads as before.
using SpaceMap = std::variant<Deformation, DeformationStack, PointMap>;

/// Certified refit of map(S), the one entry for every kind of map. Certified for:
/// - taper and twist (analytic derivative bounds);
/// - bend (first-derivative remainder in cells crossing y_min or y_max, where the bend is only C0
///   off its neutral plane);
/// - Bézier lattices (Sederberg–Parry eq. (2)): cells crossing the lattice's faces are reported in
///   crossings;
/// - B-spline lattices (Hsu–Hughes–Kaufman eq. (1)): every cell whose hull crosses a knot plane or
///   face is reported in crossings with its sampled maximum and bound;
/// - stacks whose every enabled step is (derivative bounds chained through the steps).
/// Not certified, the report having only the sampled maximum and saying why: extended lattices
/// (pointwise, each point frozen alone: no derivative bounds for a Newton-frozen map), stacks with
/// such a step, and point maps (nothing is known of their derivatives).
/// Throws clay::Error: InvalidArgument for bad options, for an empty point map or one returning a
/// non-finite point (naming the point); InvalidGeometry for an invalid surface or deformation
/// (for a stack, every step's problems), or a deformed surface of zero size with a relative
/// tolerance.
CLAY_DEFORM_API RefitResult refit_deformed(const SpaceMap& map,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});

/// The sides of `surface` (its iso-curves u = u0, u = u1, v = v0, v = v1; poles left out) that
/// lie on a side of one of `neighbours` (9 points each within `tolerance_mm` of it), as matched
/// curves for a refit of `surface`: surfaces built to meet (fills sharing a boundary curve, a
/// loft's neighbours, mirrored halves) then keep meeting when each is refitted alone (issue #38
/// step 3). Order 0 (the position) where the two meet at more than 1 deg somewhere along the side
/// (a crease), else 2 (normal and curvature: a tangent or G2 join stays so). Normals are compared
/// up to orientation. A neighbour on every side of `surface` (a copy, the surface it was styled or
/// rebuilt from, a variant of it) is the same patch, not a neighbour. Throws
/// clay::Error(InvalidArgument) for a tolerance that is not > 0 and finite, InvalidGeometry for an
/// invalid surface.
CLAY_DEFORM_API std::vector<MatchedCurve> shared_boundaries(
    const surface::BSplineSurface& surface,
    const std::vector<const surface::BSplineSurface*>& neighbours, double tolerance_mm);

}  // namespace clay::deform
