#pragma once
// Quadrature over a face's trimmed domain, shared by the volume (volume.cpp) and the mass
// properties with their gradients (mass_properties.cpp): Gauss–Legendre rules, the adaptive rule
// with its budget, knot breaks, a pcurve's crossings of knot lines, and the reference point and
// scale of the divergence-theorem fields. Private to clay_brep.
#include <clay/brep/model.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace clay::brep::detail {

/// The n-point Gauss–Legendre rule, n in [1, 64], computed once.
const internal::GaussRule& rule(int n);

/// The integral of f over [a, b] by n-point Gauss–Legendre (exact for degree 2n - 1).
template <class F>
double gauss(int n, double a, double b, F&& f) {
  const auto& r = rule(n);
  double sum = 0;
  for (std::size_t g = 0; g < r.nodes.size(); ++g)
    sum += r.weights[g] * f(0.5 * (a + b) + 0.5 * (b - a) * r.nodes[g]);
  return 0.5 * (b - a) * sum;
}

/// What one face's adaptive integration may spend, and whether it converged. A 7 KB IGES file
/// with one weight of 1e6 ran the unbounded recursion for ever: once the halved tolerance fell
/// below rounding, every branch descended to the depth cap, 2^40 times (issue #36).
struct Budget {
  long intervals = 0;  // subdivisions still allowed on this face
  bool converged = true;
};

/// Adaptive: accepts [a, b] when the 16- and 10-point rules agree to `tol` (absolute; both exact
/// to degree 19, so agreement means the integrand is resolved), or to the rounding of the rule
/// itself (32 ulps of ∫|f| over the interval: a tolerance below that can never be met), else
/// halves the interval. Past the depth cap or the budget the interval is accepted unconverged.
template <class F>
double adaptive(double a, double b, F&& f, double tol, Budget& budget, int depth = 0) {
  const auto& r = rule(16);
  double fine = 0, magnitude = 0;
  for (std::size_t g = 0; g < r.nodes.size(); ++g) {
    const double y = r.weights[g] * f(0.5 * (a + b) + 0.5 * (b - a) * r.nodes[g]);
    fine += y;
    magnitude += std::abs(y);
  }
  fine *= 0.5 * (b - a);
  magnitude *= 0.5 * std::abs(b - a);
  const double gap = std::abs(fine - gauss(10, a, b, f));
  if (!std::isfinite(fine)) {
    budget.converged = false;
    return fine;
  }
  if (gap <= tol || gap <= 32 * std::numeric_limits<double>::epsilon() * magnitude) return fine;
  if (depth >= 40 || --budget.intervals < 0) {
    budget.converged = false;
    return fine;
  }
  const double m = 0.5 * (a + b);
  return adaptive(a, m, f, 0.5 * tol, budget, depth + 1) +
         adaptive(m, b, f, 0.5 * tol, budget, depth + 1);
}

/// The distinct knots of a basis strictly inside (a, b), with a and b around them.
std::vector<double> breaks(const surface::BSplineBasis& basis, double a, double b);

/// `pieces` (a pcurve's parameters, increasing) with the parameters added where the pcurve
/// crosses a knot of the surface's v basis. The loop integrand z (x_u y_v − x_v y_u) v'(t) is
/// only as smooth as the surface in v: at a C0 knot line (Alias's fillets carry triple knots in a
/// cubic v) it jumps, and an adaptive rule halving the tolerance with the interval can never meet
/// it there (issue #39: Alias's k1 key was refused). Crossings are bracketed by 32 samples per
/// piece and bisected to rounding; a pcurve that only touches a knot line keeps a kink, not a
/// jump.
std::vector<double> with_knot_crossings(const surface::BSplineCurve& pcurve,
                                        const std::vector<double>& pieces,
                                        const surface::BSplineBasis& v_basis, double t_lo,
                                        double t_hi);

/// A face's budget: 200,000 subdivisions and 1,000 more per knot span (the real files of
/// tests/data/cad need at most about 42,000 on a face; a weight of 1e6 takes all of them, about
/// 3 s).
long face_budget(const surface::BSplineSurface& s);

/// The cube of the diagonal of the model's control points: the scale of volume tolerances.
double size_cubed(const Model& m);

/// A surface along u at a fixed v: the homogeneous isocurve at v and its v derivative, made once
/// for the control rows [lo, hi] uses, so each point sums p + 1 of them instead of (p + 1)(q + 1)
/// control points with both bases (surface::derivatives' own sums, in its order: the same
/// numbers). The volume integration spent three quarters of reading a real file in the full sums.
class Isocurve {
 public:
  /// The isocurve of `s` at v (clamped to the domain) for u in [lo, hi].
  Isocurve(const surface::BSplineSurface& s, double v, double lo, double hi);

  /// A point of the isocurve: the surface's point and first derivatives, the weight function W
  /// and its derivatives, the u span and the u basis (N_i at 0..p, N_i' at p + 1..2p + 1).
  struct Point {
    Eigen::Vector3d point, du, dv;
    double weight = 1, weight_u = 0, weight_v = 0;
    int span = 0;
    std::array<double, 2 * (surface::max_kernel_degree + 1)> basis{};
  };
  /// The point at u in [lo, hi] (clamped to the domain).
  void at(double u, Point& out) const;
  /// The point and its first derivatives only.
  void at(double u, Eigen::Vector3d& point, Eigen::Vector3d& du, Eigen::Vector3d& dv) const;

 private:
  const surface::BSplineSurface& s_;
  int row0_ = 0;
  std::vector<Eigen::Vector4d> rows_;  // per control row: the isocurve's point, its v derivative
};

/// The points whose mean is body_centre: the vertices the bodies' faces' edges end at (each
/// once), or, when there are none, every control point of the bodies' faces (`faces`).
struct CentrePoints {
  std::vector<int> vertices;
  std::vector<int> faces;
};
CentrePoints centre_points(const Model& m, const std::vector<int>& bodies);

/// The centre of the field (x − c) / 3 for the bodies `bodies` (indices into m.bodies): the mean of
/// the vertices its faces' edges end at (each once), else of its faces' control points (a body of
/// untrimmed closed faces). Any c gives the same volume on a watertight shell; on a real file's
/// shell with gaps (up to its edge tolerances) the figure is the flux through the faces only, and a
/// c that moves with the model keeps it covariant: an affine map x -> A x + b maps the vertices'
/// mean to A c + b, so it multiplies the figure by det A exactly. The field (0, 0, z) of the first
/// version was not: NX 9's gappy bracket, stretched, was 6.5e-5 off det A x V (issue #39). Near the
/// body, c also keeps the gaps' lever arm short.
Eigen::Vector3d body_centre(const Model& m, const std::vector<int>& bodies);

}  // namespace clay::brep::detail
