#pragma once
// Internal to clay_deform: the parameters and collocation matrices of the light form's least
// squares (refit.cpp), shared with the light map (light_map.cpp) so that both fit the same samples.
#include <clay/surface/basis.hpp>

#include <Eigen/Core>

#include <vector>

namespace clay::deform::detail {

/// Chebyshev–Lobatto parameters, `intervals` per non-empty span, ends shared.
std::vector<double> fit_parameters(const surface::BSplineBasis& basis, int intervals);

/// Collocation matrix: row r holds N_j(t_r).
Eigen::MatrixXd collocation(const surface::BSplineBasis& basis, const std::vector<double>& t);

}  // namespace clay::deform::detail
