#pragma once
/// Barr's regular deformations — taper, twist and bend (Barr 1984, as given in Güdükbay & Özgüç
/// 1990 §3.1) — about any axis, as plain value types with the PointDeformation pair
/// (`deform_point`, `deform_points`), their analytic Jacobian matrices and validation.
///
/// Conventions (docs/deform.md):
/// - Each deformation carries an AxisFrame: an origin, Barr's deformation axis and a reference
///   direction that fixes the two other axes. The formulas are applied in Barr's local
///   coordinates (x, y, z) of a point, X − origin in the orthonormal basis below, and the result
///   is mapped back to world coordinates. Any orientation is allowed; `reference` need not be
///   perpendicular to `axis` (its component along the axis is removed).
/// - Taper and twist: `axis` is Barr's z axis, `reference` his x axis, y = z × x.
/// - Bend: `axis` is Barr's y axis (the centreline that is bent), `reference` his z axis (towards
///   the centre of curvature when rate > 0), x = y × z (the direction of the bend axis).
/// - Profiles are polynomials in the axial coordinate z (mm): coefficient i multiplies z^i, so
///   polynomial tapers compose exactly with polynomial surfaces.
/// - The maps are global: they deform all of space (the bend outside its region rigidly).
#include <clay/deform/deformation.hpp>
#include <clay/deform/export.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <string>
#include <string_view>
#include <vector>

namespace clay::deform {

using surface::Points3;

/// Origin and orientation of a regular deformation: Barr's deformation axis through `origin`
/// and a reference direction fixing the other two axes (see the conventions above). Both
/// directions are normalised internally; they must be finite, non-zero and not parallel.
struct AxisFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();      ///< a point of the axis (mm)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();       ///< the deformation axis (any length > 0)
  Eigen::Vector3d reference = Eigen::Vector3d::UnitX();  ///< fixes the other axes (not parallel)
};

/// Every problem of the frame, in words naming `name`: non-finite vectors, a zero axis or
/// reference, or a reference parallel to the axis (its part perpendicular to the axis shorter
/// than 1e-9 of its length). Empty when valid.
CLAY_DEFORM_API std::vector<std::string> problems(const AxisFrame& frame,
                                                  std::string_view name = "axis frame");

/// Throws clay::Error(InvalidGeometry) listing problems(frame, name) when there are any.
CLAY_DEFORM_API void validate(const AxisFrame& frame, std::string_view name = "axis frame");

/// Most coefficients a taper profile or twist angle polynomial may have (degree 63, the kernel's
/// degree limit).
inline constexpr int max_profile_coefficients = 64;

/// Barr's taper (Güdükbay–Özgüç §3.1.1): r = f(z), X = r x, Y = r y, Z = z in local
/// coordinates, with f the polynomial r(z) = profile[0] + profile[1] z + profile[2] z^2 + ...
/// (z in mm). r ≡ 1 is the identity; r < 0 everts the object.
struct Taper {
  AxisFrame frame;                   ///< axis = Barr's z, reference = Barr's x
  std::vector<double> profile{1.0};  ///< coefficients of r(z), constant term first; {1, slope}
                                     ///< is the linear taper
};

/// Barr's twist (Güdükbay–Özgüç §3.1.2): θ = f(z), X = x cos θ − y sin θ, Y = x sin θ +
/// y cos θ, Z = z, with f the polynomial θ(z) = angle[0] + angle[1] z + ... (radians, z in mm):
/// {offset, rate} twists at `rate` rad/mm. θ ≡ 0 is the identity; the twist preserves volume.
struct Twist {
  AxisFrame frame;                 ///< axis = Barr's z, reference = Barr's x
  std::vector<double> angle{0.0};  ///< coefficients of θ(z) (rad), constant term first
};

/// Barr's bend (Güdükbay–Özgüç §3.1.3) along the y axis in the y-z plane: the region
/// y_min <= y <= y_max is bent at `rate` k rad/mm around the axis [s, y0, 1/k] (radius of
/// curvature 1/k, centre of the bend at y = y0 = `center`); the parts below and above the
/// region move rigidly with its ends. The centreline (x = z = 0) keeps its length. rate = 0 is
/// the identity; rate < 0 bends towards −z.
struct Bend {
  AxisFrame frame{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(),
                  Eigen::Vector3d::UnitZ()};  ///< axis = Barr's y, reference = Barr's z
  double y_min = -1;                          ///< start of the bent region along the axis (mm)
  double y_max = 1;                           ///< end of the bent region (mm), >= y_min
  double center = 0;                          ///< y0: where the bend angle is zero (mm)
  double rate = 0;  ///< k: bending rate (rad/mm); the radius of curvature is 1/k
};

/// Every problem of the deformation, in words naming `name`: frame problems, an empty profile
/// or one with more than max_profile_coefficients coefficients, non-finite coefficients (naming
/// the index). Empty when valid.
CLAY_DEFORM_API std::vector<std::string> problems(const Taper& taper,
                                                  std::string_view name = "taper");
/// Same for a twist (naming angle[i]).
CLAY_DEFORM_API std::vector<std::string> problems(const Twist& twist,
                                                  std::string_view name = "twist");
/// Same for a bend: frame problems, non-finite y_min, y_max, center or rate, y_min > y_max.
CLAY_DEFORM_API std::vector<std::string> problems(const Bend& bend, std::string_view name = "bend");

/// Throws clay::Error(InvalidGeometry) listing problems(taper, name) when there are any.
CLAY_DEFORM_API void validate(const Taper& taper, std::string_view name = "taper");
/// Throws clay::Error(InvalidGeometry) listing problems(twist, name) when there are any.
CLAY_DEFORM_API void validate(const Twist& twist, std::string_view name = "twist");
/// Throws clay::Error(InvalidGeometry) listing problems(bend, name) when there are any.
CLAY_DEFORM_API void validate(const Bend& bend, std::string_view name = "bend");

/// Tapered position of x (§3.1.1). Precondition: a valid taper (this one-off does not check).
CLAY_DEFORM_API Eigen::Vector3d deform_point(const Taper& taper, const Eigen::Vector3d& x);
/// Twisted position of x (§3.1.2). Precondition: a valid twist.
CLAY_DEFORM_API Eigen::Vector3d deform_point(const Twist& twist, const Eigen::Vector3d& x);
/// Bent position of x (§3.1.3); evaluated in a form without 1/k, so small rates are accurate
/// and rate = 0 returns x exactly. Precondition: a valid bend.
CLAY_DEFORM_API Eigen::Vector3d deform_point(const Bend& bend, const Eigen::Vector3d& x);

/// The 3 x 3 derivative dX/dx (world coordinates) of the taper at x: analytic.
CLAY_DEFORM_API Eigen::Matrix3d jacobian_matrix(const Taper& taper, const Eigen::Vector3d& x);
/// The derivative of the twist at x (determinant 1 everywhere).
CLAY_DEFORM_API Eigen::Matrix3d jacobian_matrix(const Twist& twist, const Eigen::Vector3d& x);
/// The derivative of the bend at x. Inside the region the y column is scaled by 1 − k z with
/// respect to the rigid parts, so across y_min and y_max the map is continuous everywhere but
/// its derivative only on the neutral plane z = 0 (docs/deform.md). At y = y_min or y_max
/// exactly, the derivative of the bent side is returned.
CLAY_DEFORM_API Eigen::Matrix3d jacobian_matrix(const Bend& bend, const Eigen::Vector3d& x);

/// Deforms every row of `points` (N x 3 row-major, mm) into `out` (resized when needed; may be
/// `points` itself), bit-identical to deform_point per row, on options.threads workers over
/// contiguous ranges, no allocation per point. Throws clay::Error: InvalidGeometry for an
/// invalid taper, InvalidArgument for bad options.
CLAY_DEFORM_API void deform_points(const Taper& taper, const Points3& points, Points3& out,
                                   const DeformOptions& options = {});
/// Same for a twist.
CLAY_DEFORM_API void deform_points(const Twist& twist, const Points3& points, Points3& out,
                                   const DeformOptions& options = {});
/// Same for a bend.
CLAY_DEFORM_API void deform_points(const Bend& bend, const Points3& points, Points3& out,
                                   const DeformOptions& options = {});

/// The deformed rows as a new matrix (see the overload with `out`).
CLAY_DEFORM_API Points3 deform_points(const Taper& taper, const Points3& points,
                                      const DeformOptions& options = {});
/// The deformed rows as a new matrix.
CLAY_DEFORM_API Points3 deform_points(const Twist& twist, const Points3& points,
                                      const DeformOptions& options = {});
/// The deformed rows as a new matrix.
CLAY_DEFORM_API Points3 deform_points(const Bend& bend, const Points3& points,
                                      const DeformOptions& options = {});

}  // namespace clay::deform
