#pragma once
// Pieces shared by the paper mode (style.cpp) and the exact mode (style_exact.cpp).
#include <clay/deform/style.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/projection.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace clay::deform::detail {

/// A sample of a curve and its projection onto the surface.
struct TraceSample {
  double t = 0;                                     // curve parameter
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // C(t)
  double u = 0, v = 0;                              // foot point parameters
};

/// `count` samples of the curve (uniform in its parameter, ends included) projected onto the
/// surface: by Newton from the same sample of `warm` (the previous position of a dragged curve)
/// when it has `count` samples, else the first by closest_point and the others by Newton
/// continuation from the previous foot point; closest_point wherever Newton does not converge.
std::vector<TraceSample> trace_on_surface(const surface::SurfaceProjector& projector,
                                          const surface::BSplineCurve& curve, int count,
                                          const std::vector<Eigen::Vector2d>* warm);

/// Point-in-polygon for a closed polygon in parameter space, by winding number over the edges of
/// one horizontal slab (edges are binned by their y-range once). Points within the tolerance of
/// an edge count as inside, like φ <= 0 in Han et al. eq. 2. Keeps a pointer to the polygon.
class PolygonLocator {
 public:
  PolygonLocator(const std::vector<Eigen::Vector2d>& polygon, double on_edge_tolerance);
  /// True when p lies inside or on the polygon (false for an empty polygon).
  bool inside(const Eigen::Vector2d& p) const;

 private:
  int bin_of(double y) const noexcept;
  const std::vector<Eigen::Vector2d>* polygon_;
  double tolerance_;
  double y_lo_ = 0, inverse_height_ = 0;
  std::vector<std::vector<int>> bins_;  // edges i (from vertex i to i + 1) overlapping each slab
};

/// Samples of the target curve: options.curve_samples, or when 0, 16 per knot span (32 to 4096).
int target_samples(const surface::BSplineCurve& target, const StyleOptions& options);

/// 1e-12 of the larger parameter domain: the on-edge tolerance of the region tests.
double parameter_tolerance(const surface::BSplineSurface& s);

/// E(Q_ij) of every vertex of `surface` for the region's polygon or, without one, the target trace
/// (its support band widened by `margin` vertices). Recomputed on a refined net: knot insertion
/// does not move the surface, so the parameter-space region stays.
std::vector<std::uint8_t> region_factors(const surface::BSplineSurface& surface,
                                         const std::vector<Eigen::Vector2d>& polygon,
                                         const std::vector<Eigen::Vector2d>& trace, int margin);

/// Diagonal of the control box: the model size tolerances are relative to.
double model_size(const surface::BSplineSurface& surface);

/// Continuous index of x among the increasing abscissae xi: i + (x - xi_i) / (xi_{i+1} - xi_i),
/// clamped to [0, size - 1].
double continuous_index(const std::vector<double>& xi, double x);

/// The key point K = `point` (curve parameter t) whose foot point on `s` is S(u, v): foot, unit
/// normal (zero at a pole), signed distance D(K) (eq. 3), the row it drives and E of the vertex
/// nearest to the foot point.
KeyPoint make_key_point(const surface::BSplineSurface& s, const InfluenceRegion& region,
                        const Eigen::Vector3d& point, double t, double u, double v,
                        KeyDirection direction);

/// Fills the report's mode, class, direction, m and key points; true (with the message) when the
/// surface stays as it is: the over-constrained class or λ = 0.
bool begin_report(const KeyPoints& keys, const StyleOptions& options, StyleMode mode,
                  StyleReport& report);

/// Key points of the traced target on the projector's surface (whose net `region.factors`
/// describes): Han et al. eq. 8 with `per_row` key points per control-net row interval crossed.
KeyPoints find_key_points(const surface::SurfaceProjector& projector, const InfluenceRegion& region,
                          const surface::BSplineCurve& target,
                          const std::vector<TraceSample>& trace, int per_row);

/// Projection of `x` by Newton from (u, v), the global closest point where Newton fails (the
/// projector validates its surface once and evaluates closest_point's start grid only then).
surface::SurfaceProjection project_from(const surface::SurfaceProjector& projector,
                                        const Eigen::Vector3d& x, double u, double v);

/// The parameter box of the region: the bound polygon's, else that of the influenced vertices'
/// Greville points widened by one Greville interval.
Eigen::AlignedBox2d region_box(const surface::BSplineSurface& s, const InfluenceRegion& region);

/// Fills the quality figures of `report` that compare `result` with `parent` on the region:
/// locality, boundary jumps, target deviations (key points and, when `samples` is not empty, the
/// target samples inside the region), the dense target-curve distance and the mean-curvature
/// range. `factors` are those of `parent`'s net.
void measure(const surface::BSplineSurface& parent, const surface::BSplineSurface& result,
             const std::vector<std::uint8_t>& factors, const InfluenceRegion& region,
             const surface::BSplineCurve& target, const std::vector<TraceSample>& samples,
             const StyleOptions& options, StyleReport& report);

/// The boundary figures of `report` (position jump, tangent angle) along the region's edge: the
/// bound polygon, or without one the midpoints between influenced and other vertices of `net`
/// (whose vertices `factors` describes), comparing `result` with `parent` there.
void measure_boundary(const surface::BSplineSurface& net, const std::vector<std::uint8_t>& factors,
                      const InfluenceRegion& region, const surface::BSplineSurface& parent,
                      const surface::BSplineSurface& result, StyleReport& report);

/// Paper mode on a traced target (style.cpp).
StyleResult style_paper(const surface::SurfaceProjector& projector, const InfluenceRegion& region,
                        const surface::BSplineCurve& target, const std::vector<TraceSample>& trace,
                        const StyleOptions& options);

/// Exact mode on a traced target (style_exact.cpp); reuses and replaces `cache`.
StyleResult style_exact(const surface::SurfaceProjector& projector, const InfluenceRegion& region,
                        const surface::BSplineCurve& target, const std::vector<TraceSample>& trace,
                        const StyleOptions& options, std::shared_ptr<const ExactCache>& cache);

}  // namespace clay::deform::detail
