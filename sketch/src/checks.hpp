#pragma once
// Input checks of the sketch module (internal).
#include <clay/error.hpp>

#include <Eigen/Core>

#include <cmath>
#include <string>
#include <vector>

namespace clay::sketch::detail {

/// True when every coefficient is finite: std::isfinite on each, no arithmetic (Eigen's
/// allFinite() computes x - x, which raises FE_INVALID on an infinity, and debug test runs trap
/// that).
template <class Derived>
bool all_finite(const Eigen::DenseBase<Derived>& m) {
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      if (!std::isfinite(m(r, c))) return false;
  return true;
}

/// Throws clay::Error(InvalidGeometry) listing `found` (problems in words), if any.
inline void throw_if(const std::vector<std::string>& found) {
  if (found.empty()) return;
  std::string text;
  for (const auto& f : found) text += (text.empty() ? "" : "; ") + f;
  throw Error(ErrorCategory::InvalidGeometry, text);
}

}  // namespace clay::sketch::detail
