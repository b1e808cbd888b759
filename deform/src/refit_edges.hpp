#pragma once
// Internal to clay_deform: the refit's matched curves (RefitOptions::matched_curves, issue #38
// step 7). Samples of D∘S along curves on the surface, a least squares that weights them, and
// the fit's figures at them.
#include <clay/deform/refit.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <functional>
#include <vector>

#include "seal.hpp"

namespace clay::deform::detail {

/// D∘S at one point of a matched curve: where (u, v), and the map's position and first partial
/// derivatives there (mm, mm per unit of parameter).
struct EdgeSample {
  double u = 0, v = 0;
  Eigen::Vector3d point, du, dv;
  Eigen::Vector3d duu, duv, dvv;  ///< second partial derivatives (the curvature rows)
  bool seam = false;  ///< on a seam tied to order >= 1 (see SeamTie): its own side is the neighbour
  int order = 2;      ///< its curve's MatchedCurve::order, 0 near a pole (see edge_samples)
  /// the curve's direction in (u, v), each component relative to its domain's width
  double along_u = 0, along_v = 0;
};

/// How the fit ties a closed side of the source (a cylinder's or a revolution's seam), where the
/// face meets itself: `order` = -1 an open side; 0 the first and last rows are one (G0); 1 and 2
/// also the first and second derivatives across, the far end's k-th derivative `ratio`^k times
/// the near end's, as the source's own are (so the fit is C1 or C2 across its seam whatever its
/// error: a class-A net of 32 points around a cylinder otherwise opened its seams 0.053 deg).
/// The second derivatives may also differ by `tangential` times the near end's first (a rational
/// circle's speed grows at one end of its seam and shrinks at the other: G2, not C2).
struct SeamTie {
  int order = -1;
  double ratio = 1, tangential = 0;
};
struct SeamTies {
  SeamTie u, v;
};

/// The ties a fit of D∘S keeps across `source`'s closed sides: the order to which S itself is
/// continuous across each with one reparametrization along the whole side (S_a(far) = r S_a(near),
/// S_aa(far) = r^2 S_aa(near) + t S_a(near); 1e-9 relative, sampled 4 times per span; up to 2),
/// which D∘S keeps for a smooth D. A fit of degree p
/// on `count` control points ties at most min(order, p - 1) and needs count > 2 order + 1.
SeamTies seam_ties(const surface::BSplineSurface& source, ClosedSides closed);

/// Marks the samples of every curve lying on a seam tied to order >= 1 (all of the curve's
/// `per_curve` samples on u = u0, u = u1, v = v0 or v = v1 of `surface`'s domain).
void mark_seams(std::vector<EdgeSample>& samples, int per_curve,
                const surface::BSplineSurface& surface, SeamTies ties);

/// `per_curve` samples of each curve (t uniform in [t0, t1], ends included), (u, v) clamped to
/// the surface's domain. The derivatives are D'(S) S_u and D'(S) S_v, D' by central differences
/// of `map` in space over 1e-5 of `size` (an O(1e-10) relative error for a smooth map); the
/// second ones D''(S)[S_a, S_b] + D'(S) S_ab, D'' by second differences over 1e-3 of `size`
/// (D''[a, b] by polarization), all in space: an edge lies on the domain's border, where
/// differences in (u, v) would leave it. Near a pole (one of D∘S's speeds below 1 % of the
/// other) the normal is not defined well enough to match: the sample keeps its position only
/// (order 0; a cone's edges to its apex split spans there until the least squares lost every
/// digit). Without `second` (no curvature rows), or on a curve
/// of order < 2, the second derivatives are left zero: they cost 12 of the 17 map evaluations.
std::vector<EdgeSample> edge_samples(
    const surface::BSplineSurface& surface, const std::vector<MatchedCurve>& curves,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& map, double size, int per_curve,
    bool second = true);

/// The net on bu x bv minimising Σ_grid |fit − values|² + w² Σ_samples (|fit − D∘S|² +
/// h_u² |fit_u − (D∘S)_u|² + h_v² |fit_v − (D∘S)_v|²), h_u = gap_mm / (angle |(D∘S)_u|) (each
/// row in units of its allowance, the angle in radians; 0 where D∘S's derivative vanishes): the
/// grid's normal equations are (A_u^T A_u) ⊗ (A_v^T A_v), banded. With `curvature` > 0 the
/// second derivatives are rows too, in units of an allowance of that fraction of the normal
/// curvature (G2 edges keep their curvature; see the .cpp). The
/// samples add small blocks, so the system is sparse (Cholesky, LDL^T). A tied side's last
/// rows are not unknowns but combinations of its first (`ties`; copying one onto the other after
/// the fit would move the last row by the two fits' difference, which a short end span turns
/// into a normal angle); a tie is lowered to what bu, bv allow (see seam_ties).
surface::BSplineSurface least_squares_matching(
    const surface::BSplineBasis& bu, const surface::BSplineBasis& bv, const std::vector<double>& us,
    const std::vector<double>& vs, const surface::Points3& values,
    const std::vector<EdgeSample>& samples, double weight, double gap_mm, double angle_deg,
    double curvature, double size, SeamTies ties = {});

/// The fit's distance from D∘S and angle between the normals at one sample.
struct EdgeMiss {
  double gap_mm = 0;
  double angle_deg = 0;
};

/// The fit's figures at every sample (angle 0 where D∘S's normal vanishes: a pole).
std::vector<EdgeMiss> edge_misses(const surface::BSplineSurface& fit,
                                  const std::vector<EdgeSample>& samples);

}  // namespace clay::deform::detail
