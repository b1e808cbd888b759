#pragma once
/// FFD lattices as plain data: the parallelepiped Frame, the Bézier lattice of Sederberg & Parry
/// (1986) and the B-spline lattice of Hsu, Hughes & Kaufman (1992), with the straightforward
/// pointwise deformation (the reference the fast path in frozen_lattice.hpp is tested against)
/// and the conversion of a B-spline lattice into its Bézier cells.
///
/// Conventions (docs/deform.md):
/// - Local coordinates (s, t, u) of a point X are those of Sederberg–Parry eq. (1):
///   X = X0 + s S + t T + u U. The lattice is the parallelepiped 0 <= s, t, u <= 1.
/// - Points outside the lattice are left unchanged: the FFD is the identity there (the paper
///   deforms what is embedded in the plastic). "Inside" is -face_tolerance <= s, t, u <=
///   1 + face_tolerance, the coordinates then clamped to [0, 1], so that a point on a face stays
///   inside whatever the rounding of eq. (1). Keep the faces undisplaced (continuity.hpp) when the
///   deformed region must join the space around it.
/// - Control points: row (i * (m + 1) + j) * (n + 1) + k of `points` holds P_ijk (i along S, j
///   along T, k along U; k fastest), the same s-major order for both lattice kinds.
#include <clay/deform/export.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products in Frame

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace clay::deform {

using surface::Points3;

/// Local coordinates within this distance of [0, 1] count as inside the lattice (then clamped).
/// Dimensionless: local coordinates are fractions of the edges.
inline constexpr double face_tolerance = 1e-12;

/// The parallelepiped of an FFD: origin X0 and edge vectors S, T, U (Sederberg–Parry §2, Fig. 3).
/// Any orientation; the edges must span space (S × T · U != 0).
struct Frame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< X0 (mm)
  Eigen::Vector3d s = Eigen::Vector3d::UnitX();      ///< edge S (mm)
  Eigen::Vector3d t = Eigen::Vector3d::UnitY();      ///< edge T (mm)
  Eigen::Vector3d u = Eigen::Vector3d::UnitZ();      ///< edge U (mm)

  /// Signed volume S × T · U (mm^3); negative for a left-handed frame.
  double volume() const noexcept { return s.cross(t).dot(u); }
  /// The point X0 + s S + t T + u U.
  Eigen::Vector3d point(double ls, double lt, double lu) const noexcept {
    return origin + ls * s + lt * t + lu * u;
  }
};

/// Every problem of the frame, in words naming `name`: non-finite vectors, an edge of zero length,
/// or edges that do not span space (|S × T · U| <= 1e-12 |S| |T| |U|). Empty when valid.
CLAY_DEFORM_API std::vector<std::string> problems(const Frame& frame,
                                                  std::string_view name = "lattice frame");

/// Throws clay::Error(InvalidGeometry) listing problems(frame, name) when there are any.
CLAY_DEFORM_API void validate(const Frame& frame, std::string_view name = "lattice frame");

/// Local coordinates (s, t, u) of x by Sederberg–Parry eq. (1):
/// s = T × U · (X − X0) / (T × U · S), and the same for t and u. Precondition: a valid frame.
CLAY_DEFORM_API Eigen::Vector3d local_coordinates(const Frame& frame,
                                                  const Eigen::Vector3d& x) noexcept;

/// True when the local coordinates lie within face_tolerance of the unit cube.
CLAY_DEFORM_API bool inside(const Eigen::Vector3d& local) noexcept;

// ---- Bézier lattice (Sederberg & Parry 1986) -------------------------------------------------

/// A trivariate Bernstein FFD: degrees (l, m, n) and (l+1)(m+1)(n+1) control points P_ijk,
/// row (i (m+1) + j)(n+1) + k of `points` (mm). Deforms a point by Sederberg–Parry eq. (2).
struct BezierLattice {
  Frame frame;                          ///< the parallelepiped (local coordinates, eq. (1))
  std::array<int, 3> degrees{1, 1, 1};  ///< l, m, n (along S, T, U), each >= 1
  Points3 points;                       ///< P_ijk, s-major as above

  /// Number of control points along S, T, U: l + 1, m + 1, n + 1.
  std::array<int, 3> counts() const noexcept {
    return {degrees[0] + 1, degrees[1] + 1, degrees[2] + 1};
  }
  /// Row of P_ijk in `points`.
  Eigen::Index index(int i, int j, int k) const noexcept {
    return (static_cast<Eigen::Index>(i) * (degrees[1] + 1) + j) * (degrees[2] + 1) + k;
  }
};

/// The undisplaced Bézier lattice of degrees (l, m, n) on `frame`:
/// P_ijk = X0 + i/l S + j/m T + k/n U (Sederberg–Parry §2), whose deformation is the identity.
/// Throws clay::Error: InvalidArgument for a degree < 1 or > surface::max_kernel_degree,
/// InvalidGeometry for an invalid frame.
CLAY_DEFORM_API BezierLattice make_bezier_lattice(const Frame& frame, std::array<int, 3> degrees);

/// Every invariant the lattice breaks, in words naming `name`: frame problems, degrees outside
/// [1, max_kernel_degree], a control point count other than (l+1)(m+1)(n+1), non-finite control
/// points (naming P_ijk). Empty when valid.
CLAY_DEFORM_API std::vector<std::string> problems(const BezierLattice& lattice,
                                                  std::string_view name = "Bézier lattice");

/// Throws clay::Error(InvalidGeometry) listing problems(lattice, name) when there are any.
CLAY_DEFORM_API void validate(const BezierLattice& lattice,
                              std::string_view name = "Bézier lattice");

/// The control points of the undisplaced lattice with the same frame and degrees.
CLAY_DEFORM_API Points3 undisplaced_points(const BezierLattice& lattice);

/// Deformed position of x by Sederberg–Parry eq. (2), evaluated by de Casteljau's algorithm in
/// u, then t, then s: the plain reference evaluation. Points outside the lattice are returned
/// unchanged. Precondition: a valid lattice (validate()); this one-off function does not check.
CLAY_DEFORM_API Eigen::Vector3d deform_point(const BezierLattice& lattice,
                                             const Eigen::Vector3d& x);

// ---- B-spline lattice (Hsu, Hughes & Kaufman 1992) -------------------------------------------

/// Knot vectors made by make_bspline_lattice.
enum class LatticeKnots {
  /// Clamped uniform knots on [0, 1] (end knots repeated degree + 1 times): the lattice image
  /// fills the frame and its faces interpolate the border control points — what Hsu et al. get
  /// by tripling the border points — while every control point stays free and the undisplaced
  /// lattice is exactly the identity. The default.
  Clamped,
  /// Uniform knots of step 1/cells extended past [0, 1] (Hsu et al.'s "phantom control points"):
  /// the undisplaced border control points lie outside the frame, at their Greville abscissae.
  Uniform,
};

/// A trivariate tensor-product B-spline FFD (Hsu–Hughes–Kaufman eq. (1), any degree per
/// direction): bases along S, T, U, each with parameter domain [0, 1] (local coordinates are the
/// B-spline parameters), and bases[0].count() * bases[1].count() * bases[2].count() control
/// points, row (i * count_t + j) * count_u + k (mm).
struct BSplineLattice {
  Frame frame;                                 ///< the parallelepiped (local coordinates, eq. (1))
  std::array<surface::BSplineBasis, 3> bases;  ///< along S, T, U; domains exactly [0, 1]
  Points3 points;                              ///< P_ijk, s-major as above

  /// Number of control points along S, T, U.
  std::array<int, 3> counts() const noexcept {
    return {bases[0].count(), bases[1].count(), bases[2].count()};
  }
  /// Row of P_ijk in `points`.
  Eigen::Index index(int i, int j, int k) const noexcept {
    return (static_cast<Eigen::Index>(i) * bases[1].count() + j) * bases[2].count() + k;
  }
};

/// The undisplaced B-spline lattice with `cells` knot spans of degree `degrees` per direction:
/// knots as `knots` says; control points at the Greville abscissae
/// xi_i = (k_{i+1} + ... + k_{i+p}) / p, P_ijk = X0 + xi_i S + xi_j T + xi_k U, so the map is
/// exactly the identity (linear precision of B-splines). Throws clay::Error: InvalidArgument for
/// a degree < 1 (or > max_kernel_degree) or cells < 1, InvalidGeometry for an invalid frame.
CLAY_DEFORM_API BSplineLattice make_bspline_lattice(const Frame& frame, std::array<int, 3> degrees,
                                                    std::array<int, 3> cells,
                                                    LatticeKnots knots = LatticeKnots::Clamped);

/// The undisplaced lattice on given bases (any valid knot vectors with domain [0, 1]), control
/// points at the Greville abscissae. Throws clay::Error(InvalidGeometry) naming the basis.
CLAY_DEFORM_API BSplineLattice make_bspline_lattice(const Frame& frame,
                                                    std::array<surface::BSplineBasis, 3> bases);

/// Every invariant the lattice breaks, in words naming `name`: frame and basis problems, a
/// domain other than [0, 1], a control point count other than the product of the basis counts,
/// non-finite control points (naming P_ijk). Empty when valid.
CLAY_DEFORM_API std::vector<std::string> problems(const BSplineLattice& lattice,
                                                  std::string_view name = "B-spline lattice");

/// Throws clay::Error(InvalidGeometry) listing problems(lattice, name) when there are any.
CLAY_DEFORM_API void validate(const BSplineLattice& lattice,
                              std::string_view name = "B-spline lattice");

/// The Greville control points of the undisplaced lattice with the same frame and bases.
CLAY_DEFORM_API Points3 undisplaced_points(const BSplineLattice& lattice);

/// Deformed position of x by Hsu–Hughes–Kaufman eq. (1): the tensor-product sum over the
/// (p+1)(q+1)(r+1) non-zero basis functions (The NURBS Book A2.1/A2.2 from clay::surface).
/// Points outside the lattice are returned unchanged. Precondition: a valid lattice.
CLAY_DEFORM_API Eigen::Vector3d deform_point(const BSplineLattice& lattice,
                                             const Eigen::Vector3d& x);

/// The B-spline lattice cut into Bézier lattices, one per non-empty knot span in each direction.
/// Cell (a, b, c) covers [breaks[0][a], breaks[0][a+1]] x ... in local coordinates and is a
/// BezierLattice on the sub-frame X0 + breaks S ..., edges (break width) S, ...: it deforms every
/// point of its cell like the B-spline lattice (up to rounding).
struct BezierCells {
  std::array<std::vector<double>, 3>
      breaks;                        ///< distinct knots in [0, 1] per direction, ends included
  std::vector<BezierLattice> cells;  ///< cell (a, b, c) at (a * cells_t + b) * cells_u + c

  /// Number of cells along S, T, U.
  std::array<int, 3> counts() const noexcept {
    return {static_cast<int>(breaks[0].size()) - 1, static_cast<int>(breaks[1].size()) - 1,
            static_cast<int>(breaks[2].size()) - 1};
  }
  /// Cell (a, b, c).
  const BezierLattice& cell(int a, int b, int c) const {
    const auto n = counts();
    return cells[static_cast<size_t>((a * n[1] + b) * n[2] + c)];
  }
};

/// Bézier extraction per direction (knot insertion to full multiplicity, computed as blossoms:
/// Bézier point r of span [a, b] is the blossom f(a^(p−r), b^r)). Throws clay::Error
/// (InvalidGeometry) for an invalid lattice.
CLAY_DEFORM_API BezierCells bezier_cells(const BSplineLattice& lattice);

}  // namespace clay::deform
