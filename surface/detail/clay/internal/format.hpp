#pragma once
// Numbers in messages (internal, not installed).
#include <charconv>
#include <cstdio>
#include <string>
#include <string_view>

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

/// `text` for a message: at most `bytes` bytes, cut at a UTF-8 character boundary (a cut inside
/// a character made the message invalid UTF-8, and every JSON writer of it threw), with "..."
/// when cut.
inline std::string clip_utf8(std::string_view text, std::size_t bytes) {
  if (text.size() <= bytes) return std::string(text);
  std::size_t end = bytes;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return std::string(text.substr(0, end)) + "...";
}

}  // namespace clay::internal
