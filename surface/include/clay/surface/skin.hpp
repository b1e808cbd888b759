#pragma once
/// Skinning: a surface through section curves (loft) and a profile moved along a path (sweep).
///
/// Both are our own code on the value types (no OpenCASCADE). The surface's u direction runs along
/// the sections (the profile), its v direction across them (along the path).
#include <clay/surface/build_report.hpp>
#include <clay/surface/export.hpp>

#include <string>
#include <vector>

namespace clay::surface {

/// How loft() places the sections across the surface (their v parameters).
enum class LoftParametrization {
  ChordLength,  ///< v steps proportional to the distance between sections (The NURBS Book eq. 9.5)
  Centripetal,  ///< proportional to its square root (eq. 9.6); steadier for uneven spacing
  Uniform,      ///< equal steps
};

/// Settings of loft().
struct CLAY_SURFACE_API LoftOptions {
  int degree = 3;  ///< degree across the sections (v), 1..max_kernel_degree; the loft uses
                   ///< min(degree, sections - 1), so the surface is C^(degree-1) across sections
  LoftParametrization parametrization = LoftParametrization::ChordLength;  ///< v spacing
  bool auto_orient = true;  ///< reverse a section that runs against its predecessor (else reject)
  double relative_tolerance =
      1e-7;  ///< relative to the model size (diagonal of the sections' control
             ///< points): consecutive sections closer than this coincide, a section
             ///< whose control polygon is shorter is degenerate; in (0, 1e-2]
  double min_span_ratio = 0.05;   ///< in [0, 0.5): slivers of the sections' knot union (spans
                                  ///< shorter than this times their longer neighbour) are merged
                                  ///< (make_compatible with KnotMergeOptions); 0 keeps every span
  double merge_tolerance = 1e-5;  ///< relative to the model size, in (0, 1e-2]: how far merging
                                  ///< may move a section (the report is then not exact and gives
                                  ///< the measured deviation)

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// The curves written compatibly: every one clamped, reparametrized linearly to [0, 1], raised to
/// the highest degree (degree elevation, The NURBS Book A5.9) and refined to the union of all knot
/// vectors (A5.4; knots within 1e-12 of each other are merged). Same shapes, so curve k at t equals
/// input k at a_k + t (b_k - a_k) for its domain [a_k, b_k] (up to rounding). Every result has the
/// same degree and knot vector. Throws clay::Error(InvalidGeometry) for an invalid curve (named
/// "curve #k", 0-based) or when the degree would exceed max_kernel_degree; InvalidArgument for an
/// empty list. Keeps every span of the union, however short (the overload with KnotMergeOptions
/// merges slivers).
CLAY_SURFACE_API std::vector<BSplineCurve> make_compatible(const std::vector<BSplineCurve>& curves);

/// How make_compatible merges sliver spans of the knot union.
struct CLAY_SURFACE_API KnotMergeOptions {
  double min_span_ratio = 0.05;  ///< in [0, 0.5): a span of the union shorter than this times its
                                 ///< longer neighbour is a sliver and is merged away; 0 keeps all
  double tolerance_mm = 1e-4;    ///< > 0 and finite: how far the merges may move a curve, in all

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// One knot of one curve moved by make_compatible to merge a sliver span.
struct KnotMerge {
  int curve = 0;         ///< index of the curve (0-based)
  double from = 0;       ///< the knot's value on [0, 1] before
  double to = 0;         ///< its value after (the neighbouring knot of the union); equal to `from`
                         ///< when the knot was removed because the curve already had `to`
  bool removed = false;  ///< the curve already had a knot at `to`: this one was removed
  bool reparametrized = false;  ///< the curve was reparametrized near the knot (see below)
  double lo = 0, hi = 0;    ///< the reparametrization's interval (the curve's neighbouring knots)
  int knots_added = 0;      ///< knots the reparametrized fit added, halving [lo, to] and [to, hi]
  double deviation_mm = 0;  ///< largest distance the curve moved (sampled, see below)
};

/// Curves made compatible with their sliver spans merged, and what the merging did.
struct CompatibleCurves {
  std::vector<BSplineCurve> curves;  ///< one degree and knot vector, on [0, 1]
  std::vector<KnotMerge> merges;     ///< in the order made
  double max_deviation_mm = 0;       ///< the largest sum of the deviations of one curve's merges
};

/// make_compatible, merging sliver spans of the union first. While some span of the union of the
/// curves' breakpoints (0 and 1 included) is shorter than options.min_span_ratio times its longer
/// neighbour (the worst first), one of its two end knots is moved onto the other in every curve
/// that has it (removed where that curve has both); of the two directions the one that moves the
/// curves less is taken. Per curve the move is, in order of preference:
/// - a least-squares fit of the curve on the moved knot vector at its own parameters (end points
///   kept): exact up to rounding when the knot is removable (The NURBS Book §5.4) and otherwise
///   within tolerance when the knot carries little of the shape; deviation_mm is the largest
///   |new(t) − old(t)| on 16 samples per span;
/// - else a reparametrization: the fit of old(phi(t)), phi(t) = t + (from − to) h(t) with h the
///   C2 quintic step (6s^5 − 15s^4 + 10s^3) rising from the curve's previous knot lo to `to` and
///   falling to its next knot hi, so the curve's own break lands on `to`; deviation_mm is the
///   largest |new(t) − old(phi(t))|, a bound of the distance from the old curve's points. Where
///   that misses, [lo, to] and [to, hi] are halved (up to 3 times, while no new knot makes a
///   sliver of the union) and the fit repeated.
/// The merges of one curve add up within options.tolerance_mm. input_parameter() maps a parameter
/// of a result back to its input's. Throws as make_compatible, and clay::Error(InvalidGeometry)
/// naming both curves, the two knots, the sliver's ratio and the smallest move when a sliver
/// cannot be merged within the tolerance (the message says to raise the tolerance, or to keep the
/// sliver with min_span_ratio 0); InvalidArgument for bad options. `names` (optional, one per
/// curve) replace "curve #k" in messages.
CLAY_SURFACE_API CompatibleCurves make_compatible(const std::vector<BSplineCurve>& curves,
                                                  const KnotMergeOptions& options,
                                                  const std::vector<std::string>& names = {});

/// The parameter of input `curve` (normalized to [0, 1]) whose point result.curves[curve] carries
/// at `t`: t itself unless a merge reparametrized that curve, then phi of each such merge applied
/// from the last to the first.
CLAY_SURFACE_API double input_parameter(const CompatibleCurves& result, int curve, double t);

/// The smallest ratio of a non-empty knot span of `basis` to its longer neighbour (1 for a single
/// span): the figure make_compatible's merging keeps at or above KnotMergeOptions::min_span_ratio.
CLAY_SURFACE_API double smallest_span_ratio(const BSplineBasis& basis);

/// The v parameter at which loft(sections, options) interpolates each section (0 first, 1 last):
/// the chord-length (or centripetal, or uniform) parameters of the compatible sections' control
/// points averaged over the control point columns (The NURBS Book §10.3, eq. 10.8). Throws as loft.
CLAY_SURFACE_API std::vector<double> loft_parameters(const std::vector<BSplineCurve>& sections,
                                                     const LoftOptions& options = {});

/// A surface through 2 or more section curves (skinning, The NURBS Book §10.3): the sections are
/// made compatible (make_compatible), then each column of their control points (homogeneous, so
/// rational sections work) is interpolated across the sections with degree
/// min(options.degree, sections - 1), the averaged parameters of loft_parameters and knots by
/// averaging (eq. 9.8). Exact: S(u, v_k) equals section k at its normalized parameter u in [0, 1];
/// the report's max_deviation_mm measures exactly that on a dense sample (rounding, ~1e-15 of
/// size). A section running against its predecessor is reversed when options.auto_orient (the
/// report's method says which). Throws clay::Error: InvalidArgument for fewer than 2 sections or
/// bad options; InvalidGeometry naming the section index (0-based) for an invalid or degenerate
/// section (control polygon ~0 long, e.g. a point), a section that crosses, touches or doubles
/// back onto itself within options.relative_tolerance × size (find_self_intersection; the message
/// gives both parameters and the point), two consecutive coincident sections, a reversed section
/// when auto_orient is false, or rational sections whose interpolated weights are not positive.
CLAY_SURFACE_API BuiltSurface loft(const std::vector<BSplineCurve>& sections,
                                   const LoftOptions& options = {});

/// Settings of sweep().
struct CLAY_SURFACE_API SweepOptions {
  double twist_degrees = 0;  ///< total rotation of the profile about the path tangent from start to
                             ///< end, spread in proportion to arc length; finite
  int sections = 0;          ///< profile copies placed along the path: 0 = adaptive (refined until
                             ///< the deviation is within tolerance), else a fixed count >= 2
  double relative_tolerance =
      1e-6;                 ///< relative to the model size (diagonal of the profile's and path's
                            ///< control points): the deviation the adaptive sweep must reach, and
                            ///< the largest tangent turn (radians) at a path knot; in (0, 1e-1]
  int max_sections = 1025;  ///< adaptive refinement stops here, >= 2

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// The profile moved along the path without twisting: rotation-minimizing frames by the double
/// reflection method (Wang, Jüttler, Zheng, Liu 2008, "Computation of rotation minimizing frames",
/// Algorithm 1) on a fine table of the path, plus options.twist_degrees about the tangent. The
/// profile is given in world coordinates at the path start, where the frame maps it to itself;
/// at path parameter t a profile point X goes to C(t) + M(t) (X - C(t0)), M(t) the rotation from
/// the start frame to the frame at t. The surface interpolates exact copies of the profile placed
/// at equal arc-length steps (cubic across them, v = arc-length fraction, u = the profile's own
/// clamped parameter), doubling their number until the largest distance between S(u, v) and the
/// exactly moved profile at 1/4, 1/2, 3/4 of every interval is within tolerance (report: exact =
/// false, max_deviation_mm, the sections used in the method). At path knots where the curvature (or
/// its derivative) jumps, a copy sits on the knot and v gets a triple (double) knot, matching the
/// sweep's own C0 (C1) continuity there. A straight path without twist gives the exact extrusion
/// (degree 1 across, exact = true). Throws clay::Error(InvalidGeometry) naming "profile" or "path"
/// for an invalid or degenerate curve (control polygon ~0 long), a profile or path that crosses,
/// touches or doubles back onto itself within 1e-7 × size (find_self_intersection), a path with a
/// zero tangent or a corner (tangent turning by more than tolerance radians at a knot: split the
/// path there), and a profile that reaches as far toward the path's centre of curvature as its
/// radius of curvature (kappa n . q >= 1 - 1e-3 for a profile offset q in the moving frame, on the
/// path table: the surface would fold through itself; the message gives the path parameter, the
/// radius and the reach); InvalidArgument for bad options and when the adaptive sweep still misses
/// the tolerance with max_sections sections (the message gives the deviation and the tolerance in
/// mm).
CLAY_SURFACE_API BuiltSurface sweep(const BSplineCurve& profile, const BSplineCurve& path,
                                    const SweepOptions& options = {});

}  // namespace clay::surface
