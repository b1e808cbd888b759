#pragma once
// A Bézier patch of a surface in a lattice's local coordinates and the factors of Sederberg–Parry
// eq. (2) on it (S = the coordinate, V = W − S, as Bernstein polynomials in the patch's
// parameters), shared by exact composition (compose.cpp) and its derivatives (derivatives.cpp).
// Internal to clay_deform.
#include <clay/deform/lattice.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Core>

#include <array>
#include <string_view>
#include <utility>
#include <vector>

#include "bernstein_poly.hpp"
#include "compose_size.hpp"
#include "patch_containment.hpp"

namespace clay::deform::detail {

/// Homogeneous coordinate polys of a patch: W and, per coordinate, its numerator C (c = C / W),
/// with the rounding scale of each (for the exact degree tests).
struct PatchCoordinates {
  Poly w;
  std::array<Poly, 3> c;
  double w_scale = 1, c_scale = 1;
};

/// Coordinates c_d = dual_d · (X − origin) of a Bézier patch, homogeneous: C = w dual · (P − X0).
PatchCoordinates patch_coordinates(const surface::BSplineSurface& patch,
                                   const Eigen::Vector3d& origin,
                                   const std::array<Eigen::Vector3d, 3>& dual);

/// Dual vectors of a frame: local coordinate d of X is dual[d] · (X − X0) (Sederberg–Parry eq.
/// (1)).
std::array<Eigen::Vector3d, 3> dual_vectors(const Frame& f);

/// Relative tolerance of the exact degree tests (docs: 1e-14 of the rounding scale).
inline constexpr double degree_tolerance = 1e-14;

/// A factor of eq. (2) on a patch: a constant coordinate (S = value, V = 1 − value, degree 0) or
/// the homogeneous pair (S, V = W − S) at degrees (du, dv), scaled.
struct Factor {
  bool constant = false;
  double value = 0;
  int du = 0, dv = 0;
  Poly s, v;  // scaled
  Poly w;     // W, scaled, at its exact degrees: the powers W^k of compose_by_monomials
};

/// W's exact degrees (reduced coefficients kept positive).
std::pair<int, int> weight_degrees(const PatchCoordinates& pc);

/// The factor of coordinate numerator `c` with weight `w` (scale `c_scale`), W's exact degrees
/// `wd`: constant, or the pair at the homogeneous degrees max(deg C, deg W) per direction.
Factor make_factor(const Poly& c, const Poly& w, double c_scale, std::pair<int, int> wd);

/// Homogeneous de Casteljau with polynomial parameter: level r point i = V · P_i + S · P_{i+1}
/// (Sederberg–Parry eq. (2) in one direction), points given scaled; returns the scaled result.
Poly casteljau(std::vector<Poly> pts, const Factor& f);

/// C and W of coordinate d as one dim-2 poly.
Poly ratio_poly(const PatchCoordinates& pc, int d);

/// Per coordinate d, the factor for composing a patch with a cell whose local coordinate is
/// (c_d − lo_d) / width_d in the coordinates of `pc`.
std::array<Factor, 3> cell_factors(const PatchCoordinates& pc, std::array<double, 3> lo,
                                   std::array<double, 3> width);

/// A surface in a B-spline lattice's Bézier cells: split where it meets a knot plane along an
/// iso-parameter line, its Bézier patches, and per patch (a * bp.count_v() + b) the cell holding
/// it and eq. (2)'s factors in that cell's coordinates.
struct LatticePatches {
  surface::BSplineSurface split;
  int splits = 0;         ///< knots inserted by the split
  PlaneCrossings planes;  ///< every crossing of a knot plane (compose_size.hpp)
  surface::BezierPatches bp;
  std::vector<std::array<int, 3>> cells;
  std::vector<std::array<Factor, 3>> factors;
};

/// Throws clay::Error(OutOfDomain): patch (a, b) of `bp` leaves the lattice along local
/// coordinate d (`v` from leaves), naming the patch, the coordinate and the surface parameter,
/// the message starting with `caller`.
[[noreturn]] void throw_leaves_lattice(const surface::BezierPatches& bp, int a, int b, int d,
                                       const Violation& v, std::string_view lattice_kind,
                                       std::string_view caller);

/// Locates the surface's patches in the lattice's cells (compose.cpp). Throws clay::Error, each
/// message starting with `caller`: OutOfDomain when a patch leaves the lattice, InvalidArgument
/// when one crosses a knot plane other than along an iso-parameter line.
LatticePatches locate_patches(const BSplineLattice& lattice, const BezierCells& cells,
                              const surface::BSplineSurface& surface,
                              std::string_view caller = "compose_exact");

}  // namespace clay::deform::detail
