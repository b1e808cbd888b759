#pragma once
// Pieces shared by the paper mode (style.cpp) and the exact mode (style_exact.cpp).
#include <clay/deform/style.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <vector>

namespace clay::deform::detail {

/// A sample of a curve and its projection onto the surface.
struct TraceSample {
  double t = 0;                                      // curve parameter
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // C(t)
  double u = 0, v = 0;                               // foot point parameters
};

/// `count` samples of the curve (uniform in its parameter, ends included) projected onto the
/// surface: the first by closest_point, the others by Newton continuation from the previous foot
/// point, falling back to closest_point where Newton does not converge.
std::vector<TraceSample> trace_on_surface(const surface::BSplineSurface& surface,
                                          const surface::BSplineCurve& curve, int count,
                                          const surface::ProjectionOptions& options);

/// True when (u, v) lies inside or on the closed polygon (winding number; points within 1e-12 of
/// the domain size from an edge count as inside, like φ <= 0 in Han et al. eq. 2).
bool inside_polygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p,
                    double on_edge_tolerance);

/// E(Q_ij) of every vertex of `surface` for the region's polygon or, without one, the target trace
/// (its support band widened by `margin` vertices). Recomputed on a refined net: knot insertion
/// does not move the surface, so the parameter-space region stays.
std::vector<std::uint8_t> region_factors(const surface::BSplineSurface& surface,
                                         const std::vector<Eigen::Vector2d>& polygon,
                                         const std::vector<Eigen::Vector2d>& trace,
                                         int margin);

/// Diagonal of the control box: the model size tolerances are relative to.
double model_size(const surface::BSplineSurface& surface);

/// Continuous index of x among the increasing abscissae xi: i + (x - xi_i) / (xi_{i+1} - xi_i),
/// clamped to [0, size - 1].
double continuous_index(const std::vector<double>& xi, double x);

/// Key points of the traced target on `surface` (whose net `region.factors` describes): Han et
/// al. eq. 8 with `per_row` key points per control-net row interval crossed (1 in paper mode).
KeyPoints find_key_points(const surface::BSplineSurface& surface, const InfluenceRegion& region,
                          const surface::BSplineCurve& target,
                          const std::vector<TraceSample>& trace, int per_row,
                          const StyleOptions& options);

/// Fills the quality figures of `report` that compare `result` with `parent` on the region:
/// locality, boundary jumps, target deviations (key points and, when `samples` is not empty, the
/// target samples inside the region). `factors` are those of `parent`'s net.
void measure(const surface::BSplineSurface& parent, const surface::BSplineSurface& result,
             const std::vector<std::uint8_t>& factors, const InfluenceRegion& region,
             const std::vector<TraceSample>& samples, const StyleOptions& options,
             StyleReport& report);

/// Exact mode (style_exact.cpp).
StyleResult style_exact(const surface::BSplineSurface& parent, const InfluenceRegion& region,
                        const surface::BSplineCurve& target, const StyleOptions& options);

}  // namespace clay::deform::detail
