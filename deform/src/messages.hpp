#pragma once
// Small helpers shared by the deform sources for checking input and wording clay::Error
// messages: full-precision numbers and points, a finiteness test that cannot trap, and the
// "every problem in one message" throw.
#include <clay/error.hpp>

#include <Eigen/Core>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace clay::deform::detail {

/// "(x, y, z)" with `precision` significant digits (17: the double round-trips).
inline std::string format(const Eigen::Vector3d& v, int precision = 17) {
  std::ostringstream m;
  m.precision(precision);
  m << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return m.str();
}

/// v with `precision` significant digits (17: the double round-trips).
inline std::string format(double v, int precision = 17) {
  std::ostringstream m;
  m.precision(precision);
  m << v;
  return m.str();
}

/// std::isfinite on every coordinate (Eigen's allFinite computes x − x, which raises FE_INVALID
/// on an infinity where floating-point traps are on).
template <class V>
bool finite(const V& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v(i))) return false;
  return true;
}

/// Throws clay::Error(category) whose message lists every problem, "; "-separated.
[[noreturn]] inline void throw_problems(ErrorCategory category, const std::vector<std::string>& list) {
  std::string text;
  for (size_t k = 0; k < list.size(); ++k) text += (k ? "; " : "") + list[k];
  throw Error(category, text);
}

}  // namespace clay::deform::detail
