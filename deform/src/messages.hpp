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

}  // namespace clay::deform::detail
