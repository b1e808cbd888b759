#pragma once
/// BSplineBasis — degree and knot vector of one parametric direction, and the B-spline basis
/// functions on it (The NURBS Book, Piegl & Tiller, A2.1–A2.3).
///
/// Vocabulary (docs/glossary.md): degree p (not order); a knot vector of length n + p + 1 for n
/// control points, non-decreasing, clamped (end knots repeated p + 1 times) or unclamped; the
/// parameter domain is [knots[p], knots[n]] with 0-based indices.
#include <clay/surface/export.hpp>

#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace clay::surface {

/// Highest degree the kernel's algorithms accept (exchange formats stop earlier, at 25).
inline constexpr int max_kernel_degree = 63;

/// Degree and knot vector of one direction of a B-spline curve or surface.
struct BSplineBasis {
  int degree = 0;             ///< polynomial degree p >= 1
  std::vector<double> knots;  ///< flat knot vector, length count() + degree + 1

  /// Number of control points (basis functions) this basis spans: knots.size() - degree - 1.
  int count() const noexcept { return static_cast<int>(knots.size()) - degree - 1; }
  /// Parameter domain [knots[p], knots[count()]]. Precondition: the basis is valid.
  std::pair<double, double> domain() const noexcept {
    return {knots[static_cast<size_t>(degree)], knots[static_cast<size_t>(count())]};
  }
};

/// Clamped uniform knot vector for `count` control points of degree `degree` on [first, last].
/// Throws clay::Error(InvalidArgument) when degree < 1, count < degree + 1 or first >= last.
CLAY_SURFACE_API BSplineBasis clamped_uniform_basis(int degree, int count, double first = 0.0,
                                                    double last = 1.0);

/// Every invariant the basis breaks, in words, each naming `name` (e.g. "surface 'hood' u basis").
/// Empty when the basis is valid: 1 <= degree <= max_kernel_degree, finite non-decreasing knots, at
/// least degree + 1 control points, interior multiplicity <= degree, end multiplicity <= degree +
/// 1, and a domain of positive length.
CLAY_SURFACE_API std::vector<std::string> problems(const BSplineBasis& basis,
                                                   std::string_view name);

/// Throws clay::Error(InvalidGeometry) listing problems(basis, name) when there are any.
CLAY_SURFACE_API void validate(const BSplineBasis& basis, std::string_view name);

/// True when both end knots are repeated degree + 1 times.
CLAY_SURFACE_API bool is_clamped(const BSplineBasis& basis) noexcept;

/// Number of knots equal (bit for bit) to `t`.
CLAY_SURFACE_API int multiplicity(const BSplineBasis& basis, double t) noexcept;

/// Distinct knot values inside the domain, ends included, in increasing order.
CLAY_SURFACE_API std::vector<double> breakpoints(const BSplineBasis& basis);

/// Parameters `per_span` (>= 1) evenly spaced in every non-empty knot span, the domain end added:
/// a sample that follows the knots. Throws clay::Error(InvalidArgument) for per_span < 1.
CLAY_SURFACE_API std::vector<double> span_samples(const BSplineBasis& basis, int per_span);

/// Greville abscissae xi_i = (k_{i+1} + ... + k_{i+p}) / p, one per control point: the parameters
/// "under" each control point (a polynomial spline with control points f(xi_i) of a linear f is f
/// itself). Strictly increasing for a valid basis. Precondition: a valid basis.
CLAY_SURFACE_API std::vector<double> greville_abscissae(const BSplineBasis& basis);

/// Index k of the knot span [knots[k], knots[k+1]) holding t, with degree <= k < count(); the
/// domain end maps to the last non-empty span. Throws clay::Error(OutOfDomain) when t is outside
/// the domain or not finite. (The NURBS Book A2.1.)
CLAY_SURFACE_API int find_span(const BSplineBasis& basis, double t);

/// The degree + 1 non-zero basis functions N_{k-p..k}(t) on span k, written to `values`
/// (size >= degree + 1). (The NURBS Book A2.2.)
CLAY_SURFACE_API void basis_functions(const BSplineBasis& basis, int span, double t,
                                      std::span<double> values);

/// Basis functions and their derivatives up to `order` on span k: `derivs` is row-major
/// (order + 1) x (degree + 1), row r holding the r-th derivatives. (The NURBS Book A2.3.)
CLAY_SURFACE_API void basis_derivatives(const BSplineBasis& basis, int span, double t, int order,
                                        std::span<double> derivs);

}  // namespace clay::surface
