#pragma once
/// Filling: a surface spanned by boundary curves. fill() is exact for 2, 3 or 4 curves
/// (OpenCASCADE's GeomFill_BSplineCurves: the boundary curves are the surface's edges);
/// fill_n_sided() approximates a plate through any number of boundary curves and optional interior
/// curves (OpenCASCADE's BRepOffsetAPI_MakeFilling), reporting how far each curve is from it.
#include <clay/occt/export.hpp>
#include <clay/surface/build_report.hpp>

#include <string>
#include <vector>

namespace clay::surface {

/// How fill() blends the boundary curves into the interior (OpenCASCADE's GeomFill styles).
enum class FillStyle {
  Stretch,  ///< the flattest patch
  Coons,    ///< a rounded patch (Coons construction with cubic blending on the control points)
  Curved,   ///< the most rounded patch
};

/// Settings of fill().
struct CLAY_OCCT_API FillOptions {
  FillStyle style = FillStyle::Coons;  ///< interior blend
  double gap_tolerance = 1e-7;    ///< mm, > 0 and finite: ends of consecutive boundary curves must
                                  ///< meet within this; they are then joined at their midpoint
  double min_span_ratio = 0.05;   ///< in [0, 0.5): slivers of opposite sides' knot union (spans
                                  ///< shorter than this times their longer neighbour) are merged
                                  ///< (make_compatible with KnotMergeOptions); 0 keeps every span
  double merge_tolerance = 1e-5;  ///< relative to the model size, in (0, 1e-2]: how far merging
                                  ///< may move a side; the report is then not exact and its
                                  ///< max_deviation_mm measures the edges against the curves

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// The surface bounded by 2, 3 or 4 B-spline curves, exact (GeomFill_BSplineCurves). Curves may
/// come in any order and direction: from curve #0 each next curve is the one whose end is nearest,
/// reversed when needed, until the loop closes; corners within options.gap_tolerance are joined at
/// their midpoint. Curves are clamped and reparametrized to [0, 1], opposite sides made compatible
/// (degree elevation and knot refinement; slivers of their knot union merged, see
/// options.min_span_ratio), and, for Coons, sides with fewer than 4 control points
/// raised to degree 3 (OpenCASCADE refuses Coons below 4). 4 curves: u runs along the first curve
/// of the loop (v = 0), v along the second (u = 1); 3 curves: the side u = 0 collapses to the
/// corner where the loop closes; 2 curves: Stretch and Coons give the ruled surface between them
/// (the second curve turned to run like the first; no loop needed), Curved the patch spanned by two
/// curves that share a corner. The report is exact unless a sliver was merged; its
/// max_deviation_mm is the largest distance between each input curve and the surface edge it
/// became, on dense samples (rounding, plus at most half a joined gap, plus what a merge moved,
/// measured at the parameter the merge's reparametrization maps to), and its method lists what was
/// reversed, raised, joined or merged. A sliver that cannot be merged within merge_tolerance
/// throws InvalidGeometry naming both curves and the fix. Throws
/// clay::Error: InvalidArgument for a count outside [2, 4] or bad options; InvalidGeometry for an
/// invalid or degenerate curve (named "curve #k", 0-based), for curves that do not close,
/// naming each gap, e.g. "curve #1 end and curve #2 start are 0.25 mm apart (tolerance 1e-07 mm)",
/// and for a boundary that crosses, touches or doubles back onto itself within the larger of
/// gap_tolerance and 1e-7 × size (find_self_intersection on the closed loop, so two curves
/// crossing each other count too: "curve #1 at t = 0.5 and curve #3 at t = 0.5 meet at point
/// ..."; with 2 curves each is checked on its own); InvalidGeometry with OpenCASCADE's message if
/// it still fails.
CLAY_OCCT_API BuiltSurface fill(const std::vector<BSplineCurve>& boundary,
                                const FillOptions& options = {});

/// Settings of fill_n_sided(): BRepOffsetAPI_MakeFilling's parameters. Defaults are OpenCASCADE's
/// except degree (5, not 3), tolerance_3d (1e-5, not 1e-4) and max_segments (20, not 9): on a
/// 5-sided sphere cap and a cubic dome (~200 mm) they bring the measured curve-to-surface distance
/// from 6e-4 and 1.7e-3 mm down to 3.4e-6 and 1.2e-6 mm, at the same cost (20-40 ms).
struct CLAY_OCCT_API NSidedFillOptions {
  int degree = 5;              ///< order of the plate's energy criterion, 2..14 (OCCT "Degree")
  int points_on_curve = 15;    ///< constraint points per curve, 2..1000 (OCCT "NbPtsOnCur")
  int iterations = 2;          ///< plate iterations, 1..50 (OCCT "NbIter")
  bool anisotropy = false;     ///< favour the longer parametric direction (OCCT "Anisotropie")
  double tolerance_2d = 1e-5;  ///< parametric tolerance, > 0 (OCCT "Tol2d")
  double tolerance_3d = 1e-5;  ///< mm, > 0: distance the plate may leave the curves by (OCCT
                               ///< "Tol3d"); the measured distance can be larger, see the report
  double angular_tolerance = 1e-2;   ///< radians, > 0 (OCCT "TolAng"; used for G1 constraints)
  double curvature_tolerance = 0.1;  ///< > 0 (OCCT "TolCurv"; used for G2 constraints)
  int max_degree = 8;  ///< degree of the B-spline approximating the plate, 3..25 (OCCT "MaxDeg")
  int max_segments =
      20;  ///< knot spans per direction of that B-spline, 1..1000 (OCCT "MaxSegments")
  double gap_tolerance = 1e-7;  ///< mm, > 0: boundary corners must meet within this (joined at
                                ///< their midpoint)
  int samples_per_curve = 64;   ///< points per curve where the deviation is measured, >= 2

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// What fill_n_sided() built and how far each curve is from it.
struct NSidedFill {
  BuiltSurface built;                    ///< the plate as one B-spline surface (report not exact)
  std::vector<double> curve_deviations;  ///< mm: boundary curves in input order, then interior
                                         ///< curves; each the largest closest-point distance of
                                         ///< its samples to the surface
};

/// A smooth surface through 3 or more boundary curves (any order and direction, chained as in
/// fill()) and optional interior curves it must pass through: OpenCASCADE's plate
/// (BRepOffsetAPI_MakeFilling, GeomPlate: a thin-plate energy minimized under point constraints,
/// then approximated by a B-spline), returned as that B-spline surface, untrimmed: it covers the
/// N-sided region and extends beyond it (the boundary curves trim it). Not exact: max_deviation_mm
/// is the largest of curve_deviations, measured with closest_point() on options.samples_per_curve
/// points of every curve. Throws clay::Error: InvalidArgument for fewer than 3 boundary curves or
/// bad options; InvalidGeometry for invalid or degenerate curves, a boundary that does not close
/// (naming each gap as fill() does), a boundary loop that crosses, touches or doubles back onto
/// itself (as fill() checks it), or when OpenCASCADE fails (its message included).
CLAY_OCCT_API NSidedFill fill_n_sided(const std::vector<BSplineCurve>& boundary,
                                      const std::vector<BSplineCurve>& interior = {},
                                      const NSidedFillOptions& options = {});

}  // namespace clay::surface
