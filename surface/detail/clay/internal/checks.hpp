#pragma once
// Input checks shared by every module (internal, not installed): finiteness without arithmetic,
// and throwing a list of problems as one clay::Error.
#include <clay/error.hpp>

#include <Eigen/Core>

#include <cmath>
#include <string>
#include <vector>

namespace clay::internal {

/// True when every coefficient is finite. std::isfinite on each, no arithmetic: Eigen's
/// allFinite() computes x - x, which raises FE_INVALID on an infinity, and the Debug suite traps
/// FE_INVALID (tests/main.cpp).
template <class Derived>
bool all_finite(const Eigen::DenseBase<Derived>& m) {
  for (Eigen::Index c = 0; c < m.cols(); ++c)
    for (Eigen::Index r = 0; r < m.rows(); ++r)
      if (!std::isfinite(m(r, c))) return false;
  return true;
}

/// Appends `more` to `out` (an Options struct's problems() gathering those of its parts).
inline void append(std::vector<std::string>& out, const std::vector<std::string>& more) {
  out.insert(out.end(), more.begin(), more.end());
}

/// The problems, "; "-separated, in one line.
inline std::string join_problems(const std::vector<std::string>& list) {
  std::string text;
  for (size_t k = 0; k < list.size(); ++k) text += (k ? "; " : "") + list[k];
  return text;
}

/// Throws clay::Error(category) whose message lists every problem.
[[noreturn]] inline void throw_problems(ErrorCategory category,
                                        const std::vector<std::string>& list) {
  throw Error(category, join_problems(list));
}

/// throw_problems when there is any problem; nothing otherwise.
inline void throw_if(ErrorCategory category, const std::vector<std::string>& list) {
  if (!list.empty()) throw_problems(category, list);
}

}  // namespace clay::internal
