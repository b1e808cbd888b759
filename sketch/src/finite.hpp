#pragma once
// Finiteness of user input without arithmetic (internal). Eigen's allFinite() computes x - x,
// which raises FE_INVALID on an infinity: debug test runs trap that.
#include <Eigen/Core>

#include <cmath>

namespace clay::sketch::detail {

/// True when every coefficient is finite (std::isfinite on each, no arithmetic).
template <class Derived>
bool all_finite(const Eigen::DenseBase<Derived>& m) {
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      if (!std::isfinite(m(r, c))) return false;
  return true;
}

}  // namespace clay::sketch::detail
