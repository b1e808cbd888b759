#pragma once
/// Sketch-constraint styling deformation (Han, De Amicis & Conti 2007): a closed *bound curve*
/// drawn on the parent surface says where the surface may move, a *target curve* says what shape
/// it should take, and the control vertices inside the bound move toward the target.
///
/// Two modes (docs/deform.md, "Style deformation"):
/// - `StyleMode::Paper` follows the paper: influence factors (eq. 2), key points and their signed
///   normal distances (eqs. 3, 8), the force shared by area weights and distributed along the
///   control-net curve (eqs. 4-7) with the symmetric smoothing of eqs. 12-13, relaxation intervals
///   (eqs. 10-11) and the approximation scale λ (eq. 9). It approximates the target.
/// - `StyleMode::Exact` goes beyond the paper: the displacement field is the least fairness
///   energy *of the surface* (thin-plate for G1, third derivatives for G2; not of its control net)
///   that passes through the key points, which are those of eq. 8 on a region net (the parent
///   with at least 32 spans over the region) plus the target's ends, and more where the target
///   curve is still missed: the whole target curve is met within curve_tolerance. Vertices outside
///   the bound, a band of `boundary_rows` region-net layers inside it and the surface's own edges
///   stay fixed, so the deformed region joins the untouched surface with (for cubics) C^2
///   continuity. Optionally the net is refined until the shape converges (net_convergence).
///
/// Both return a surface with the same degrees (and, in paper mode, the same knots): control
/// vertices move, nothing is refitted. Exact mode may insert knots (exactly, reported) where the
/// control net is too coarse for the key points.
#include <clay/deform/export.hpp>
#include <clay/summary.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/projection.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace clay::deform {

/// Which of the two algorithms style_deform runs.
enum class StyleMode {
  Paper,  ///< Han–De Amicis–Conti forces (eqs. 3-13): approximates the target
  Exact,  ///< fair least-norm displacements through the key points (beyond the paper)
};

/// Exact mode: how the styled region joins the untouched surface at the region's edge, in the
/// limit of a fine net (docs/deform.md, "Fairness energy").
enum class BoundContinuity {
  G1,  ///< thin-plate energy (second derivatives): position and tangent plane held
  G2,  ///< third-derivative energy and one more fixed layer: curvature held too; degree >= 3
};

/// Name of a continuity ("G1", "G2").
CLAY_DEFORM_API std::string_view to_string(BoundContinuity c) noexcept;

/// How the target curve relates to the bound (Han et al. §4.3).
enum class ConstraintClass {
  OverConstrained,   ///< the target lies completely outside the bound: the surface is unchanged
  UnderConstrained,  ///< the target lies partly inside the bound
  WellConstrained,   ///< the target lies completely inside the bound
};

/// Name of a constraint class ("over-constrained", ...).
CLAY_DEFORM_API std::string_view to_string(ConstraintClass c) noexcept;

/// Direction the target runs along in parameter space (Han et al. eq. 8): `u` means it crosses
/// the control-net rows i = const (vertices (i, 0..count_v-1)), so there is a key point per row and
/// its force is distributed along that row, in v.
enum class KeyDirection { U, V };

/// Settings of the style deformation. Lengths in mm.
struct CLAY_DEFORM_API StyleOptions {
  StyleMode mode = StyleMode::Paper;  ///< paper forces or exact key-point interpolation
  double lambda = 1.0;     ///< approximation scale λ in [0, 1] (eq. 9); 0 leaves the surface as is
  bool relaxation = true;  ///< paper: let the end forces fall off to the bound (eqs. 10-11)
  bool smoothing = true;   ///< paper: distribute each force symmetrically along its control-net
                           ///< curve down to the bound (eqs. 12-13); false: only the two
                           ///< neighbouring vertices get it, by area weights (eqs. 4-5)
  int curve_samples = 0;   ///< samples of the target curve (key-point search, class, figures):
                           ///< 0 = 16 per knot span of the target, at least 32; else >= 8
  int bound_samples = 256;     ///< samples of the bound curve (its parameter-space polygon), >= 8
  int key_points_per_row = 1;  ///< exact: key points per control-net row crossed, >= 1
  int boundary_rows = 2;       ///< exact: layers of region-net vertices inside the bound edge kept
                               ///< fixed, 0..4 (G2: one more)
  double relative_tolerance = 1e-9;  ///< exact: key-point deviation accepted, relative to the
                                     ///< model size
  int max_refinements = 6;           ///< exact: rounds of knot insertion allowed, 0..10
  BoundContinuity continuity = BoundContinuity::G1;  ///< exact: the energy, and the join at the
                                                     ///< bound in the limit of a fine net
  double net_convergence = 0;  ///< exact: the net is halved over the region until one more
                               ///< halving changes the styled shape by less than this fraction
                               ///< of its largest displacement (0 = no such rounds; see
                               ///< docs/deform.md for what convergence costs)
  bool net_convergence_best_effort = false;  ///< exact: a net that stops short of
                                             ///< net_convergence (max_refinements used, or a
                                             ///< halving that no longer shrinks the change: a
                                             ///< target that runs into the bound) keeps its
                                             ///< finest result and reports its net_change
                                             ///< instead of failing (the studio's calm default)
  double curve_tolerance =
      1e-4;                      ///< exact: where the result misses the target curve (at its
                                 ///< samples) by more than this, relative to the model size,
                                 ///< key points are added at the worst samples; 0 = key points only
  int max_key_point_rounds = 6;  ///< exact: rounds of such additions, >= 0
  bool report_curves = true;     ///< measure target_curve_deviation and the boundary figures by
                                 ///< sampling (the cost of ~curve_samples + bound_samples
                                 ///< projections); off for interactive drags: they are then NaN
  surface::ProjectionOptions projection;  ///< projection of the curves onto the surface

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
  /// Field by field (a kept StyleEditor serves only the settings it was made with).
  bool operator==(const StyleOptions&) const = default;
};

/// Influence factors E(Q_ij) of every control vertex (Han et al. eq. 2) and where they came from.
struct CLAY_DEFORM_API InfluenceRegion {
  int count_u = 0;                    ///< control vertices along u of the surface they belong to
  int count_v = 0;                    ///< control vertices along v
  std::vector<std::uint8_t> factors;  ///< E(Q_ij) in {0, 1} at i * count_v + j
  /// The bound curve projected into parameter space, a closed polygon (first point not
  /// repeated); empty when the region comes from the target (no bound curve, §5).
  std::vector<Eigen::Vector2d> polygon;
  /// Without a bound: the projected target samples (u, v) the region was made from, so that it
  /// can be recomputed on a refined net (knot insertion keeps the parametrization).
  std::vector<Eigen::Vector2d> target_trace;
  /// Without a bound: layers of vertices added around the target's support band.
  int margin = 0;

  /// E(Q_ij).
  bool inside(int i, int j) const noexcept {
    return factors[static_cast<size_t>(i) * static_cast<size_t>(count_v) +
                   static_cast<size_t>(j)] != 0;
  }
  /// Number of vertices with E = 1.
  int inside_count() const noexcept;
};

/// Influence factors from a closed bound curve (eq. 2): the curve is sampled, projected onto the
/// surface (closest point, then Newton continuation) into a parameter-space polygon, and E = 1 for
/// each control vertex whose Greville point (xi_i, eta_j) lies inside or on it. Throws
/// clay::Error: InvalidGeometry for an invalid surface or curve, a bound curve that is not closed
/// (ends farther apart than 1e-7 of its size) or whose projection crosses itself (naming where),
/// InvalidArgument for bad options.
CLAY_DEFORM_API InfluenceRegion influence_factors(const surface::BSplineSurface& parent,
                                                  const surface::BSplineCurve& bound,
                                                  const StyleOptions& options = {});

/// The region without a bound curve (Han et al. §5): the target curve is projected onto the
/// surface and E = 1 for every control vertex whose basis function is non-zero at a projected
/// sample (the vertices that move the surface under the target), widened by
/// options.boundary_rows layers so that the exact mode's fixed edge layers leave that band free.
/// Throws as influence_factors.
CLAY_DEFORM_API InfluenceRegion influence_from_target(const surface::BSplineSurface& parent,
                                                      const surface::BSplineCurve& target,
                                                      const StyleOptions& options = {});

/// A key point K_i of the target curve and its force (eqs. 3, 8).
struct KeyPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< K_i on the target curve (mm)
  double curve_parameter = 0;                        ///< its parameter on the target curve
  double u = 0, v = 0;                               ///< parameters of its projection P
  Eigen::Vector3d foot = Eigen::Vector3d::Zero();    ///< P = S(u, v) (mm)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit normal N_i at P
  double distance = 0;                               ///< D(K_i) = (K_i - P) . N_i, signed (mm)
  int row = 0;              ///< control-net row (direction u) or column (v) the key point drives
  bool influenced = false;  ///< E(Q_j) = 1 for the vertex Q_j nearest to P (eq. 3)
};

/// The key points of a target on a region: direction, class and points.
struct KeyPoints {
  KeyDirection direction = KeyDirection::U;  ///< eq. 8: the direction the target runs along
  ConstraintClass constraint_class = ConstraintClass::OverConstrained;  ///< §4.3
  std::vector<KeyPoint> points;  ///< in order along the target curve; m = points.size()
};

/// Key points of `target` (eq. 8): the target is projected onto the surface; it runs along u when
/// it spans at least as many Greville intervals in u as in v; there is one key point where its
/// projection crosses each control-net row it covers (u = xi_i), found by regula falsi to 1e-13 of
/// the domain (at least one key point: the middle of the target when it crosses no row). The
/// class: over-constrained when no projected sample lies in the region, well-constrained when all
/// do. Throws as influence_factors, and InvalidArgument when the region was made for another net.
CLAY_DEFORM_API KeyPoints key_points(const surface::BSplineSurface& parent,
                                     const InfluenceRegion& region,
                                     const surface::BSplineCurve& target,
                                     const StyleOptions& options = {});

/// The most curvature_waves a calm style has. A push is a crest and its two shoulders (3 turns
/// of the change of mean curvature across it); measured on the examples' exact styles, calm
/// results (Zebra) show 3-4, rings 5-7 (docs/deform.md, "Rings").
inline constexpr int curvature_waves_calm = 4;

/// The most turning points along one row or one column of `grid`: local extrema between swings of
/// at least `swing` each way (a hysteresis, so that noise below it does not count); the ends of a
/// line are not turns, and NaN cells break a line into runs counted apart. 0 when `swing` is not
/// positive. StyleReport::curvature_waves is this of the change of mean curvature sampled over the
/// region, with swing a tenth of its largest magnitude.
CLAY_DEFORM_API int grid_waves(const Eigen::MatrixXd& grid, double swing);

/// What a style deformation did and how well (DESIGN.md quality figures). Lengths in mm.
struct CLAY_DEFORM_API StyleReport {
  StyleMode mode = StyleMode::Paper;
  ConstraintClass constraint_class = ConstraintClass::OverConstrained;
  KeyDirection direction = KeyDirection::U;
  std::vector<KeyPoint> key_points;  ///< on the parent surface
  int influenced_vertices = 0;       ///< vertices with E = 1
  int moved_vertices = 0;            ///< vertices actually displaced
  double max_displacement = 0;       ///< largest control-vertex move
  double target_deviation = 0;  ///< largest distance from an influenced key point to the result
  double target_curve_deviation = 0;  ///< largest distance from a target sample inside the
                                      ///< region to the result
  double locality = 0;  ///< largest move of a control vertex with E = 0 (0 by construction)
  double boundary_position_jump = 0;  ///< largest |S' - S| along the region edge
  double boundary_tangent_angle = 0;  ///< largest angle (degrees) between the result's and the
                                      ///< parent's normals along the region edge
  // exact mode only
  int knots_inserted = 0;                   ///< knots inserted (u and v together) before deforming
  int added_key_points = 0;                 ///< key points added where the target curve was missed
  int degrees_of_freedom = 0;               ///< 3 (free vertices - rank of the key-point system)
  int rank = 0;                             ///< rank of the key-point system (scalar rows)
  std::vector<int> conflicting_key_points;  ///< key points that cannot all be met (indices)
  /// exact: the largest change of the shape made by the last halving of the net, relative to the
  /// largest displacement of the surface; NaN when not measured (net_convergence = 0, the net
  /// could not be halved, or paper mode)
  double net_change = std::numeric_limits<double>::quiet_NaN();
  double fairness_energy =
      0;  ///< exact: E_k of the displacement (dimensionless); NaN in paper mode
  // both modes, sampled on a grid over the region (NaN with report_curves off)
  double target_curve_distance = 0;  ///< largest distance from the target curve (inside the
                                     ///< region) to the result, sampled 4 times as densely as the
                                     ///< key-point search, each by a global closest point
  double mean_curvature_min = 0;     ///< smallest mean curvature of the result inside the region
                                     ///< (1/mm, sign along the surface normal)
  double mean_curvature_max = 0;     ///< largest mean curvature of the result inside the region
  /// Rings (issue #40 item 8): the most turns (local extrema, each swing at least a tenth of the
  /// largest |ΔH|) of the change of mean curvature ΔH = H(result) − H(parent) along one line of
  /// the 41 × 41 grid over the region, rows and columns. A calm push across a target has up to
  /// 3 (the two shoulders and the crest); more are waves the target did not ask for, what Zebra
  /// shows as rings (curvature_waves_calm). −1 when not measured (report_curves off).
  int curvature_waves = -1;
  double model_size = 0;  ///< diagonal of the parent's control box
  std::string message;    ///< what happened, in words
  /// Whether the step did what it was asked (judge_style): Converged; NotConverged when the
  /// target is missed (exact mode: a key point beyond tolerance x size, the target curve beyond
  /// curve_tolerance x size, key points that cannot be met) or a control vertex moves more than
  /// 10 times the farthest key point's distance (the surface folds); Failed when nothing could
  /// move (over-constrained: the target lies outside the bound). λ = 0 is Converged: unchanged
  /// as asked. The message names the figure and the way out.
  Summary summary;

  /// One line: the summary, the class of the constraint and the figures that judge it.
  std::string brief() const;
};

/// The outcome of a style deformation from its report and options (the rules of
/// StyleReport::summary); style_deform and StyleEditor::update set report.summary with it.
CLAY_DEFORM_API Summary judge_style(const StyleReport& report, const StyleOptions& options);

/// The deformed surface and its report.
struct StyleResult {
  surface::BSplineSurface surface;  ///< same degrees; same knots unless report.knots_inserted > 0
  /// The parent on the result's knots: the same surface, with the inserted knots (exact knot
  /// insertion); the parent itself when none were inserted. Locality is measured against it.
  surface::BSplineSurface refined_parent;
  StyleReport report;
};

/// Deforms `parent` toward `target` inside `region` (influence_factors or influence_from_target of
/// the same surface). λ = 0 and the over-constrained class return the parent bit for bit; vertices
/// with E = 0 are never written. Throws as key_points.
CLAY_DEFORM_API StyleResult style_deform(const surface::BSplineSurface& parent,
                                         const InfluenceRegion& region,
                                         const surface::BSplineCurve& target,
                                         const StyleOptions& options = {});

namespace detail {
struct ExactCache;  // the exact mode's free vertices and fairness matrix (style_exact.cpp)
}  // namespace detail

/// A style deformation prepared for dragging the target curve over one region (geometry-central's
/// "solver class beside the one-off function"): the parent is validated and prepared for
/// projection once, each update starts the projection of the target from its previous position,
/// and the exact mode keeps its free vertices and fairness matrix while the net stays the same.
/// update(target) returns what style_deform(parent, region, target, options) returns, up to the
/// projection tolerance (the Newton starts differ) — in exact mode, where those differences can
/// change which key points are added, up to curve_tolerance. Copies share the cache (immutable).
class CLAY_DEFORM_API StyleEditor {
 public:
  /// Throws clay::Error: InvalidGeometry for an invalid parent, InvalidArgument for bad options or
  /// a region made for another control net.
  StyleEditor(surface::BSplineSurface parent, InfluenceRegion region,
              const StyleOptions& options = {});

  /// The deformation toward `target`. Throws clay::Error(InvalidGeometry) for an invalid target.
  StyleResult update(const surface::BSplineCurve& target);

  /// The parent surface.
  const surface::BSplineSurface& parent() const noexcept { return projector_.surface(); }
  /// The influence region.
  const InfluenceRegion& region() const noexcept { return region_; }
  /// The options.
  const StyleOptions& options() const noexcept { return options_; }

 private:
  surface::SurfaceProjector projector_;  // of the parent
  InfluenceRegion region_;
  StyleOptions options_;
  std::vector<Eigen::Vector2d> warm_;  // the previous target's projected samples (u, v)
  std::shared_ptr<const detail::ExactCache> exact_;  // exact mode: free vertices, fairness matrix
};

/// One-off with a bound curve: influence_factors, then style_deform.
CLAY_DEFORM_API StyleResult style_deform(const surface::BSplineSurface& parent,
                                         const surface::BSplineCurve& bound,
                                         const surface::BSplineCurve& target,
                                         const StyleOptions& options = {});

/// One-off without a bound curve (§5): influence_from_target, then style_deform.
CLAY_DEFORM_API StyleResult style_deform(const surface::BSplineSurface& parent,
                                         const surface::BSplineCurve& target,
                                         const StyleOptions& options = {});

}  // namespace clay::deform
