#pragma once
// Interpolation of compatible sections across v (The NURBS Book §10.3), shared by loft and sweep
// (internal to clay_surface).
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <vector>

namespace clay::surface::detail {

/// Knots by averaging (The NURBS Book eq. 9.8) for parameters v (v.front() = 0, v.back() = 1).
BSplineBasis averaged_basis(const std::vector<double>& v, int q);

/// The surface whose iso-curve v = v[k] is sections[k] (all compatible: same basis), with the
/// basis basis_v in v. Rational sections are interpolated in homogeneous coordinates; polynomial
/// ones in Cartesian coordinates so the weights stay exactly 1.
BSplineSurface interpolate_sections(const std::vector<BSplineCurve>& sections,
                                    const std::vector<double>& v, const BSplineBasis& basis_v);

/// Same with knots by averaging (The NURBS Book eq. 9.8) for degree q.
BSplineSurface interpolate_sections(const std::vector<BSplineCurve>& sections,
                                    const std::vector<double>& v, int q);

}  // namespace clay::surface::detail
