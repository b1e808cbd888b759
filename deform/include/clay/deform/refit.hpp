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
#include <vector>

namespace clay::deform {

/// Settings of refit_deformed().
struct CLAY_DEFORM_API RefitOptions {
  int degree = 3;           ///< degree of the fit in u and v, 1..25 (the exchange limit)
  double tolerance = 1e-4;  ///< > 0: allowed deviation, relative to the size when `relative`
  bool relative = true;     ///< true: tolerance x diagonal of the deformed surface's bounding
                            ///< box (of a sample); false: tolerance in mm
  int max_iterations = 12;  ///< >= 1: fit / certify / refine rounds
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
  bool certified = false;  ///< certified_bound_mm is a true upper bound of |fit − D∘S|
  double tolerance = 0;    ///< the tolerance applied (mm)
  double size = 0;         ///< diagonal of the deformed sample's bounding box (mm)
  double sampled_max = 0;  ///< largest deviation at the certificate's samples (mm)
  double certified_bound_mm =
      std::numeric_limits<double>::infinity();  ///< mm; inf if not certified
  long samples = 0;         ///< number of points sampled by the last certificate
  int degree_u = 0;         ///< degree of the fit in u
  int degree_v = 0;         ///< degree of the fit in v
  int knots_added_u = 0;    ///< knots added to the original's breakpoints in u (by refinement)
  int knots_added_v = 0;    ///< same in v
  int lipschitz_cells = 0;  ///< cells bounded by first derivatives only (D not C1 there)
  std::vector<KnotPlaneCrossing> crossings;  ///< every lattice plane crossing of the final fit

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
/// copy of an exact result, within options.tolerance everywhere on its domain. Throws as the
/// taper overload.
CLAY_DEFORM_API RefitResult refit_surface(const surface::BSplineSurface& surface,
                                          const RefitOptions& options = {});

/// Refit of taper(S): certified. Throws clay::Error: InvalidArgument for bad options,
/// InvalidGeometry for an invalid surface or taper, or a deformed surface of zero size with a
/// relative tolerance.
CLAY_DEFORM_API RefitResult refit_deformed(const Taper& taper,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});
/// Refit of twist(S): certified. Throws as the taper overload.
CLAY_DEFORM_API RefitResult refit_deformed(const Twist& twist,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});
/// Refit of bend(S): certified (first-derivative remainder in cells crossing y_min or y_max,
/// where the bend is only C0 off its neutral plane). Throws as the taper overload.
CLAY_DEFORM_API RefitResult refit_deformed(const Bend& bend, const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});
/// Refit of lattice(S), Sederberg–Parry eq. (2): certified; cells crossing the lattice's faces
/// are reported in crossings. Throws as the taper overload.
CLAY_DEFORM_API RefitResult refit_deformed(const BezierLattice& lattice,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});
/// Refit of lattice(S), Hsu–Hughes–Kaufman eq. (1): certified; every cell whose hull crosses a
/// knot plane or face is reported in crossings with its sampled maximum and bound. Throws as the
/// taper overload.
CLAY_DEFORM_API RefitResult refit_deformed(const BSplineLattice& lattice,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});
/// Refit of lattice(S) (pointwise, each point frozen alone): not certified (no derivative bounds
/// for a Newton-frozen map); the report has the sampled maximum. Throws as the taper overload.
CLAY_DEFORM_API RefitResult refit_deformed(const ExtendedLattice& lattice,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});
/// Refit of stack(S): certified when every enabled step is (derivative bounds chained through the
/// steps), otherwise sampled only. Throws as the taper overload (invalid stack: InvalidGeometry).
CLAY_DEFORM_API RefitResult refit_deformed(const DeformationStack& stack,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});
/// Refit of map(S) for any point map: not certified (nothing is known of its derivatives).
/// Throws as the taper overload, and InvalidArgument for an empty map or one returning a
/// non-finite point (naming the point).
CLAY_DEFORM_API RefitResult refit_deformed(const PointMap& map,
                                           const surface::BSplineSurface& surface,
                                           const RefitOptions& options = {});

}  // namespace clay::deform
