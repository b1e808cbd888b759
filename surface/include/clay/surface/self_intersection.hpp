#pragma once
/// Self-intersection of a curve: where a B-spline curve crosses, touches or runs back over itself.
///
/// The surface builders use it to refuse sections, profiles, paths and boundary curves that meet
/// themselves (the surface built on them would intersect itself).
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <optional>

namespace clay::surface {

/// Two points of a curve closer than the tolerance even though the curve between them is much
/// longer (more than self_intersection_arc_factor × tolerance).
struct CurveSelfIntersection {
  double t0 = 0;        ///< first parameter, in the curve's own domain
  double t1 = 0;        ///< second parameter, t0 < t1
  double distance = 0;  ///< |C(t0) - C(t1)| in mm, <= the tolerance (~0 at a crossing)
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< midpoint of C(t0) and C(t1), mm
  double angle_degrees = 0;  ///< angle between the tangents C'(t0) and C'(t1), in [0, 180]: near
                             ///< 0 where the curve touches itself running the same way, near 180
                             ///< where it runs back over itself, in between where it crosses
  double arc_length = 0;     ///< length of the curve between the two points, mm (the shorter way
                             ///< round on a closed curve), measured on the search's fine polyline
};

/// Two points closer than `tolerance` count as one point only when the curve between them is
/// longer than this many tolerances; nearer pairs are the same neighbourhood (a smooth bend, a
/// corner), not a self-intersection.
inline constexpr double self_intersection_arc_factor = 100.0;

/// Where the curve meets itself within `tolerance` (mm): a crossing, a touching, or a stretch
/// that runs back over itself (a retrace, a cusp folding back), or std::nullopt when it does not.
/// Pairs of points nearer each other along the curve than self_intersection_arc_factor ×
/// tolerance are ignored, and so is the seam of a closed curve (first point within tolerance of
/// the last), where the shorter way round counts: a smooth bend, a G0 corner, a closed circle or a
/// helix are not self-intersections; a figure-8, a loop, a curve doubling back over itself are.
/// When the curve meets itself more than once, the pair with the smallest t0 is returned.
///
/// Method: every Bézier segment is subdivided (de Casteljau, homogeneous coordinates) into pieces
/// whose control polygon turns by at most 15 degrees; a piece's control points bound it (convex
/// hull, weights > 0): its box, its distance from its chord, a cone holding its tangents. A
/// bounding-volume tree over the pieces in curve order yields the pairs whose boxes come within
/// the tolerance, skipping runs of the curve that advance monotonically along one direction (all
/// tangents within 80 degrees of it: such a run cannot come back to itself). For each pair, the
/// nearest points of the two chords at an admissible distance along the curve decide: farther
/// apart than the tolerance plus the chord errors, the pair is done; else the pieces are halved
/// until nearly straight (2 degrees) and Newton's method on |C(s) - C(t)|^2, bounded to the two
/// pieces, finds the nearest points from there. The cost grows with the number of pieces and of
/// near pairs, not with their square (bench/self_intersection_bench.cpp: a 100-span cubic helix
/// takes about 0.06 ms, 1000 spans 0.9 ms).
///
/// Throws clay::Error: InvalidGeometry for an invalid curve (see validate()); InvalidArgument for
/// a tolerance that is not positive and finite.
CLAY_SURFACE_API std::optional<CurveSelfIntersection> find_self_intersection(
    const BSplineCurve& curve, double tolerance);

}  // namespace clay::surface
