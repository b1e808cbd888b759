#pragma once
// Shared checks of control nets (internal).
#include <Eigen/Core>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

namespace clay::surface::detail {

/// Appends a problem for every non-finite coordinate and non-positive or non-finite weight;
/// `label(r)` names row r ("control point (2, 3)"). Stops after a few findings per kind.
template <class Label>
void check_net(const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>& points,
               const Eigen::VectorXd& weights, std::string_view name, Label label,
               std::vector<std::string>& found) {
  if (weights.size() != points.rows()) {
    found.push_back(std::string(name) + ": has " + std::to_string(weights.size()) +
                    " weights for " + std::to_string(points.rows()) +
                    " control points; give one weight per control point (all 1 when polynomial)");
    return;
  }
  int bad_points = 0, bad_weights = 0;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    if (!internal::all_finite(points.row(r)) && bad_points++ < 3)
      found.push_back(std::string(name) + ": " + label(r) +
                      " has a non-finite coordinate (NaN or infinity); give finite coordinates");
    const double w = weights[r];
    if (!(std::isfinite(w) && w > 0.0) && bad_weights++ < 3)
      found.push_back(std::string(name) + ": weight of " + label(r) + " is " + std::to_string(w) +
                      "; weights must be positive and finite");
  }
}

}  // namespace clay::surface::detail
