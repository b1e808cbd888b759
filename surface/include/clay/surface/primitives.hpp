#pragma once
/// Superquadric primitives (Barr, as used by Güdükbay–Özgüç 1990 §2.1) as B-spline surfaces.
///
/// A superquadric is the spherical product x(eta, omega) = (a1 m1(eta) h1(omega),
/// a2 m1(eta) h2(omega), a3 m2(eta)) of two planar curves m (north–south, exponent e1) and h
/// (east–west, exponent e2) built from signed powers C^e = sign(cos) |cos|^e, S^e likewise.
/// The spherical product of two (rational) B-spline curves is exactly a tensor-product
/// (rational) B-spline surface (spherical_product below), so each primitive is exact in a
/// direction whose exponent is 1 (a circle or hyperbola arc, rational quadratic) and elsewhere
/// approximated by adaptive cubic interpolation until the surface is within the tolerance.
/// Every result reports its measured deviation from the analytic surface on a dense sample.
///
/// Parameters. An exact direction (exponent 1) is a rational arc on [0, 1]. An approximated
/// direction with exponent e runs over s in [0, K] for its K angle segments (quarter turns
/// [-pi, -pi/2, 0, pi/2, pi] around, halves [-pi/2, 0, pi/2] north–south, [-L, 0, L] for the
/// hyperbolic ones): s in [k, k + 1] maps to the angle b_k + (b_k+1 - b_k) w(s - k) with
/// w(x) = x^m / (x^m + (1 - x)^m), m = max(1, 1/e). This stretch makes the signed powers, whose
/// slope is infinite where cos or sin vanish when e < 1, smooth in s, so a few hundred spans reach
/// 1e-3 mm even for e = 0.3.
#include <clay/surface/build_report.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace clay::surface {

/// Settings of the superquadric builders.
struct CLAY_SURFACE_API SuperquadricOptions {
  double tolerance_mm = 1e-3;  ///< largest allowed distance from the analytic surface, > 0
  int degree = 3;              ///< degree of approximated directions, in [2, 7]
  int max_spans = 4096;        ///< knot spans per approximated direction before giving up, >= 8
  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// Superellipsoid (eq. 2.1.1): eta in [-pi/2, pi/2], omega in [-pi, pi].
struct Superellipsoid {
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();  ///< a1, a2, a3 in mm, > 0
  double e1 = 1.0;                                  ///< north–south exponent, in (0, 10]
  double e2 = 1.0;                                  ///< east–west exponent, in (0, 10]
};

/// Supertoroid (eq. 2.1.4): x = (a1 (a4 + C^e1) C^e2, a2 (a4 + C^e1) S^e2, a3 S^e1),
/// eta, omega in [-pi, pi].
struct Supertoroid {
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();  ///< a1, a2, a3 in mm, > 0
  double hole = 2.0;  ///< a4, the ring radius in units of a1/a2, > 1 (the tube does not self-cross)
  double e1 = 1.0;    ///< tube exponent, in (0, 10]
  double e2 = 1.0;    ///< ring exponent, in (0, 10]
};

/// Superhyperboloids (eqs. 2.1.2, 2.1.3), cut to a finite range of their unbounded parameters.
struct Superhyperboloid {
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();  ///< a1, a2, a3 in mm, > 0
  double e1 = 1.0;                                  ///< in (0, 10]
  double e2 = 1.0;                                  ///< in (0, 10]
  double eta_limit = 1.0;    ///< eta in [-eta_limit, eta_limit], radians in (0, pi/2)
  double omega_limit = 1.0;  ///< two sheets: omega in [-omega_limit, omega_limit], in (0, pi/2)
};

/// The spherical product of two planar curves (their x and y coordinates; z is ignored):
/// S(s, t) = (m_x(s) h_x(t), m_x(s) h_y(t), m_y(s)). Exact: control point (i, j) is
/// (M_i.x H_j.x, M_i.x H_j.y, M_i.y) with weight w_i w_j. Throws clay::Error(InvalidGeometry)
/// for an invalid curve.
CLAY_SURFACE_API BSplineSurface spherical_product(const BSplineCurve& m, const BSplineCurve& h);

/// Superellipsoid as a B-spline surface: u along eta (south to north pole), v along omega. With
/// e1 = e2 = 1 it is the exact rational ellipsoid (a sphere for equal radii).
CLAY_SURFACE_API BuiltSurface superellipsoid(const Superellipsoid& shape,
                                             const SuperquadricOptions& options = {});

/// Supertoroid as a B-spline surface (closed in both directions). With e1 = e2 = 1 and equal
/// radii r it is the exact rational torus of major radius r * hole and minor radius r.
CLAY_SURFACE_API BuiltSurface supertoroid(const Supertoroid& shape,
                                          const SuperquadricOptions& options = {});

/// Superhyperboloid of one sheet (closed around z). Exact rational when e1 = e2 = 1.
CLAY_SURFACE_API BuiltSurface superhyperboloid_one_sheet(const Superhyperboloid& shape,
                                                         const SuperquadricOptions& options = {});

/// Superhyperboloid of two sheets: two surfaces, the sheet around +x (omega in
/// [-omega_limit, omega_limit]) and the sheet around -x (omega + pi), which is the first mirrored
/// in the yz plane. Exact when e1 = e2 = 1.
CLAY_SURFACE_API std::vector<BuiltSurface> superhyperboloid_two_sheets(
    const Superhyperboloid& shape, const SuperquadricOptions& options = {});

}  // namespace clay::surface
