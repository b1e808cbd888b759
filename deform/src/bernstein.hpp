#pragma once
// Internal helpers on Bernstein and B-spline coefficients shared by the lattice, Jacobian and
// frozen-lattice code.
#include <clay/deform/lattice.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Core>

#include <array>
#include <vector>

namespace clay::deform::detail {

/// Span extraction (the Bézier extraction operator of one direction) is the core's
/// surface::bezier_extraction.
using surface::SpanExtraction;

/// Control points of Bézier cell (ea, eb, ec) of the lattice, s-major (p+1)(q+1)(r+1) x 3.
Points3 cell_points(const BSplineLattice& lattice, const SpanExtraction& ea,
                    const SpanExtraction& eb, const SpanExtraction& ec);

/// Power-basis coefficients of a trivariate Bernstein polynomial with `dim` values per
/// coefficient: `bernstein` is s-major ((i (m+1) + j)(n+1) + k) * dim + c; the result uses the
/// same layout with coefficient a_ijk of s^i t^j u^k (forward differences: a_e = C(p, e) Δ^e b_0
/// in each direction).
std::vector<double> bernstein_to_power(const std::vector<double>& bernstein,
                                       std::array<int, 3> degrees, int dim);

/// Local coordinates of x when inside the lattice (clamped to [0, 1]^3); false when outside.
bool clamped_local(const Frame& frame, const Eigen::Vector3d& x, Eigen::Vector3d& local) noexcept;

}  // namespace clay::deform::detail
