#pragma once
/// Extended lattices (Coquillart 1990, "EFFD"): FFD lattices of any initial shape, made of
/// tricubic Bézier chunks that share control points. Welded faces and merged points (the axis of
/// a cylindrical lattice) are shared rows, so the lattice is C0 by construction.
///
/// The workflow is Coquillart's §3.3–3.4: *freeze* the points once — find each point's chunk by
/// the convex hull property and its (u, v, w) in the chunk by Newton's method from
/// (0.5, 0.5, 0.5) on the rest shape, with the Moore–Penrose pseudo-inverse on degenerate chunks
/// and subdivision when Newton does not converge — then move the control points as often as
/// wanted and re-evaluate Coquillart eq. (1) at the frozen (u, v, w). Points in no chunk are left
/// unchanged. The undisplaced lattice maps every frozen point to itself up to the Newton
/// tolerance (1e-12 of the chunk size by default), whatever the rest shape.
///
/// Conventions (docs/deform.md): control point (i, j, k) of a chunk (i along u, j along v, k
/// along w) is row chunk[(i * 4 + j) * 4 + k] of `rest` / `points`, the s-major order of
/// BezierLattice (k fastest).
#include <clay/deform/deformation.hpp>
#include <clay/deform/export.hpp>
#include <clay/summary.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace clay::deform {

using surface::Points3;

/// Control points of a tricubic chunk: 4 x 4 x 4.
inline constexpr int chunk_control_points = 64;

/// One tricubic Bézier chunk: 64 row indices into the lattice's control points, control point
/// (i, j, k) at entry (i * 4 + j) * 4 + k.
using Chunk = std::array<int, chunk_control_points>;

/// A lattice of tricubic Bézier chunks on shared control points (Coquillart §3.1).
struct ExtendedLattice {
  Points3 rest;               ///< undisplaced control points (N x 3, mm): what freezing inverts
  Points3 points;             ///< current control points (N x 3, mm), moved by the user
  std::vector<Chunk> chunks;  ///< each chunk's 64 indices into the rows of rest / points
};

/// Every invariant the lattice breaks, in words naming `name`: rest and points of different row
/// counts, no chunks, an index outside [0, N) (naming the chunk and its control point (i, j, k)),
/// non-finite coordinates (naming the row), a chunk whose rest control points all coincide (zero
/// extent). Degenerate chunks (collapsed faces or edges, flat chunks) are allowed. Empty when
/// valid.
CLAY_DEFORM_API std::vector<std::string> problems(const ExtendedLattice& lattice,
                                                  std::string_view name = "extended lattice");

/// Throws clay::Error(InvalidGeometry) listing problems(lattice, name) when there are any.
CLAY_DEFORM_API void validate(const ExtendedLattice& lattice,
                              std::string_view name = "extended lattice");

/// Coquillart eq. (1): L(u, v, w) = sum_ijk B_i(u) B_j(v) B_k(w) P_ijk with the cubic Bernstein
/// polynomials B and P_ijk = control.row(chunk[(i * 4 + j) * 4 + k]) — pass `rest` for the rest
/// shape, `points` for the current one. Any (u, v, w), also outside [0, 1]^3 (the polynomial).
/// Precondition: the indices are rows of `control`.
CLAY_DEFORM_API Eigen::Vector3d chunk_point(const Points3& control, const Chunk& chunk,
                                            const Eigen::Vector3d& uvw);

/// Welds control points whose rest positions lie within `tolerance` (mm) of each other
/// (Coquillart §3.1.4: welding is merging points): they become one row (the lowest index's rest
/// and current position), chunks are re-indexed, rows no chunk uses are dropped. Use it to weld
/// elementary lattices into a composite one (append rows and chunks, then weld). Throws
/// clay::Error: InvalidArgument for a negative or non-finite tolerance, InvalidGeometry for an
/// invalid lattice.
CLAY_DEFORM_API ExtendedLattice merge_coincident_points(const ExtendedLattice& lattice,
                                                        double tolerance);

// ---- cylindrical lattice ----------------------------------------------------------------------

/// A cylinder cut into sectors (around the axis), rings (radial) and layers (along the axis).
struct CLAY_DEFORM_API CylinderSpec {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();      ///< centre of the bottom disc (mm)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();       ///< axis direction (normalized)
  Eigen::Vector3d reference = Eigen::Vector3d::UnitX();  ///< angle 0 (made orthogonal to the axis)
  double radius = 1;                                     ///< outer radius (mm), > 0
  double inner_radius = 0;  ///< 0: a full cylinder whose axis points are merged; else a tube (mm)
  double height = 1;        ///< along the axis (mm), > 0
  int sectors = 8;          ///< chunks around the axis, 3..1024 (each arc spans 360°/sectors)
  int rings = 1;            ///< chunks along the radius, 1..1024
  int layers = 1;           ///< chunks along the axis, 1..1024

  /// Throws clay::Error(InvalidArgument) naming the field, its value and the rule broken.
  void validate() const;
};

/// Coquillart's cylindrical lattice (§3.1.1, Fig. 2): a parallelepipedal lattice whose opposite
/// faces are welded (the last sector's v = 1 face is the first sector's v = 0 face: same rows)
/// and, when inner_radius = 0, whose axis points are merged (one row per height), so the chunks
/// of the innermost ring have a collapsed u = 0 face. Chunk (ring a, sector b, layer c) is
/// chunks[(a * sectors + b) * layers + c]; u runs outward, v counter-clockwise about the axis
/// (from `reference` towards axis × reference), w along the axis. Rest shape:
/// L(u, v, w) = origin + h(w) axis + rho(u) C(v), with rho linear in u, h linear in w and C the
/// cubic Bézier approximation of the sector's unit arc (inner control points at
/// 4/3 tan(angle / 4) along the end tangents). An exact circle needs rational splines
/// (Coquillart §3.1.1); this arc lies on or just outside the circle (radial error 2.7e-4 of the
/// radius at 90°, 3.7e-7 at 30°), so the lattice contains the cylinder. The identity of the
/// undisplaced lattice comes from freezing, not from the arc being a circle.
/// Throws clay::Error(InvalidArgument) for a bad spec.
CLAY_DEFORM_API ExtendedLattice make_cylindrical_lattice(const CylinderSpec& spec);

/// Row of control point (radial, angular, axial) of make_cylindrical_lattice(spec):
/// radial in [0, 3 rings], angular any integer (taken modulo 3 sectors: the seam is welded),
/// axial in [0, 3 layers]. With inner_radius = 0 every (0, angular, axial) is the one axis row
/// `axial`. Throws clay::Error: OutOfDomain for radial or axial out of range, InvalidArgument for
/// a bad spec.
CLAY_DEFORM_API int cylindrical_index(const CylinderSpec& spec, int radial, int angular, int axial);

// ---- prismatic lattice lofted from planar curves ------------------------------------------------

/// A prism over a planar 2D lattice lofted from section curves (Coquillart §3.1.4: "EFFD
/// lattices can also be created from two-dimensional lattices ... loft, sweep, extrusion").
struct CLAY_DEFORM_API PrismSpec {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   ///< where 2D point (0, 0) sits (mm)
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();  ///< 2D x direction (normalized)
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();  ///< 2D y direction (made orthogonal to x)
  /// The prism's height vector (mm), off the plane.
  Eigen::Vector3d extrusion = Eigen::Vector3d::UnitZ();
  /// Two or more section curves, each a piecewise cubic Bézier curve in the plane (mm): 3 s + 1
  /// control points for s segments (joints shared), every section with the same count. A closed
  /// curve repeats its first point last (the seam is then welded).
  std::vector<std::vector<Eigen::Vector2d>> sections;
  int layers = 1;  ///< chunks along the extrusion, 1..1024

  /// Throws clay::Error(InvalidArgument) naming the field, its value and the rule broken
  /// (fewer than two sections, counts not 3 s + 1 or unequal, non-finite values, axes that do not
  /// span a plane, an extrusion in the plane).
  void validate() const;
};

/// The prismatic lattice: the 2D lattice is the ruled loft between consecutive sections (u: from
/// section a to a + 1, control rows C_a, (2 C_a + C_{a+1}) / 3, (C_a + 2 C_{a+1}) / 3, C_{a+1},
/// so it is linear across and C0 at each section), v along the curves, w along the extrusion
/// (linear). Chunk (gap a, segment b, layer c) is chunks[(a * segments + b) * layers + c] before
/// welding; coincident rest points (a closed curve's seam, sections that touch) are then welded
/// by merge_coincident_points at 1e-12 of the lattice size, which drops duplicate rows.
/// Throws clay::Error(InvalidArgument) for a bad spec.
CLAY_DEFORM_API ExtendedLattice make_prismatic_lattice(const PrismSpec& spec);

// ---- freezing and deformation -----------------------------------------------------------------

/// Settings of freeze().
struct CLAY_DEFORM_API FreezeOptions {
  /// Residual |L(u,v,w) − x| / chunk size at convergence, (0, 1e-3].
  double newton_tolerance = 1e-12;
  /// A root this far outside [0, 1]^3 still counts as inside, [0, 1e-3].
  double parameter_tolerance = 1e-9;
  double pseudo_inverse_threshold = 1e-12;  ///< below this |det J| / max|column|^3 the
                                            ///< pseudo-inverse replaces the inverse, [0, 1e-3]
  int max_iterations = 50;                  ///< Newton iterations per start, 1..1000
  int max_subdivision_depth = 4;  ///< de Casteljau halvings of a chunk when Newton fails, 0..10
  int threads = 0;                ///< parts the points are split into, 0 = one per hardware
                                  ///< thread (at least 1,024 points per part), 0..1024
  Executor executor = {};         ///< who runs the parts (clay/parallel.hpp); empty = std::threads

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// FrozenPoint::chunk of a point in no chunk (no chunk's hull holds it, or every root lies
/// outside [0, 1]^3): left unchanged by evaluate().
inline constexpr int outside_chunk = -1;
/// FrozenPoint::chunk of a point that some chunk's hull holds but where Newton did not converge
/// even after subdivision (reported in FreezeReport::unresolved): left unchanged.
inline constexpr int unresolved_chunk = -2;

/// A point's place in the lattice: its chunk (or outside_chunk / unresolved_chunk) and (u, v, w)
/// in that chunk, within parameter_tolerance of [0, 1]^3 (not clamped, so that the rest shape
/// reproduces the point to the Newton tolerance).
struct FrozenPoint {
  int chunk = outside_chunk;
  Eigen::Vector3d uvw = Eigen::Vector3d::Zero();
};

/// What freezing did.
struct CLAY_DEFORM_API FreezeReport {
  /// Converged when no point is unresolved; iterations = Newton iterations over all points,
  /// final_residual = the largest |L(u,v,w) − x| over inside points (mm, rest shape).
  Summary summary;
  Eigen::Index inside = 0;                ///< points given a chunk
  Eigen::Index outside = 0;               ///< points in no chunk (unchanged)
  Eigen::Index unresolved = 0;            ///< points Newton could not place (unchanged)
  Eigen::Index subdivided = 0;            ///< inside points found only after subdividing a chunk
  Eigen::Index splits = 0;                ///< de Casteljau splits of a (sub)chunk into eight
  Eigen::Index pseudo_inverse_steps = 0;  ///< Newton steps taken with the pseudo-inverse

  /// One line: "frozen 1000 points: 990 inside, 10 outside, 0 unresolved; ...".
  std::string brief() const;
};

/// Frozen points: one FrozenPoint per input row, the input itself (returned unchanged where
/// outside), the summary, and the lattice's row and chunk counts (evaluate() checks them: only
/// moving control points keeps a freeze valid, Coquillart §3.4).
struct FrozenPoints {
  std::vector<FrozenPoint> points;
  Points3 positions;  ///< the frozen points (N x 3, mm)
  FreezeReport report;
  Eigen::Index control_points = 0;  ///< rows of the lattice when frozen
  std::size_t chunks = 0;           ///< chunks of the lattice when frozen
};

/// Coquillart §3.3: (u, v, w) of every row of `points` in the rest shape. Per point: candidate
/// chunks from a uniform grid of chunk bounding boxes, kept when the point is inside a k-DOP of
/// the chunk's 64 rest control points (13 fixed directions plus the chunk's own three face
/// normals: it contains their convex hull, hence the chunk, so it never rejects a point inside);
/// Newton from (0.5, 0.5, 0.5) until the tolerance, plus one polishing step kept when it lowers
/// the residual (so the identity holds to rounding), with the inverse Jacobian, or the
/// Moore–Penrose pseudo-inverse (JacobiSVD) when det J is below pseudo_inverse_threshold
/// (degenerate chunks, Lukács); chunks where Newton diverges or stalls are split by de Casteljau
/// into eight and Newton restarts from the centre of each sub-chunk whose k-DOP holds the point,
/// up to max_subdivision_depth. The first root within parameter_tolerance of [0, 1]^3 wins (on
/// shared faces any chunk gives the same image). Throws clay::Error: InvalidGeometry for an
/// invalid lattice or non-finite points, InvalidArgument for bad options.
CLAY_DEFORM_API FrozenPoints freeze(const ExtendedLattice& lattice, const Points3& points,
                                    const FreezeOptions& options = {});

/// Coquillart §3.4: the deformed frozen points, eq. (1) on the current control points at the
/// frozen (u, v, w); points outside (or unresolved) are returned unchanged. Throws clay::Error:
/// InvalidGeometry for an invalid lattice, InvalidArgument when the lattice's row or chunk count
/// changed since freezing (freeze again) or for bad options.
CLAY_DEFORM_API Points3 evaluate(const ExtendedLattice& lattice, const FrozenPoints& frozen,
                                 const DeformOptions& options = {});

/// One point: freezes x in the rest shape (default FreezeOptions) and evaluates the current
/// shape there; x itself when outside. Throws like freeze().
CLAY_DEFORM_API Eigen::Vector3d deform_point(const ExtendedLattice& lattice,
                                             const Eigen::Vector3d& x);

/// One-off freeze + evaluate of every row (threads as `options` says). Throws like freeze().
CLAY_DEFORM_API Points3 deform_points(const ExtendedLattice& lattice, const Points3& points,
                                      const DeformOptions& options = {});

}  // namespace clay::deform
