#pragma once
// Numbers in messages (internal, not installed).
#include <charconv>
#include <cstdio>
#include <string>

namespace clay::internal {

/// x with `digits` significant digits (printf's %g): short figures for messages.
inline std::string with_digits(double x, int digits) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
  return buffer;
}

/// The shortest text that reads back as x (std::to_chars): a value the user can paste back.
inline std::string shortest(double x) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, x).ptr;
  return std::string(buffer, end);
}

}  // namespace clay::internal
