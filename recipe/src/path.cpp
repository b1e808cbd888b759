// Recipe paths (clay/recipe/path.hpp).
#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/recipe/path.hpp>

#include <limits>

namespace clay::recipe {

namespace {

[[noreturn]] void refuse(std::string_view path, const std::string& rule) {
  throw Error(ErrorCategory::InvalidArgument,
              "path \"" + internal::clip_utf8(std::string(path), 120) + "\" " + rule +
                  "; write keys joined by \".\" with list items as [i], e.g. "
                  "\"deformations.lift[0].moves[1].by[2]\"");
}

}  // namespace

std::vector<PathStep> parse_path(std::string_view path) {
  std::vector<PathStep> steps;
  std::size_t i = 0;
  bool expect_key = true;  // at the start or after ".": a key must come
  while (i < path.size()) {
    const char c = path[i];
    if (c == '[') {
      if (steps.empty()) refuse(path, "starts with a list index");
      if (expect_key) refuse(path, "has an empty key before [");
      const std::size_t close = path.find(']', i);
      if (close == std::string_view::npos) refuse(path, "has a [ without ]");
      const std::string_view digits = path.substr(i + 1, close - i - 1);
      if (digits.empty()) refuse(path, "has a malformed list index []");
      std::size_t index = 0;
      for (const char d : digits) {
        if (d < '0' || d > '9') refuse(path, "has a malformed list index; write items as [i]");
        const auto digit = static_cast<std::size_t>(d - '0');
        if (index > (std::numeric_limits<std::size_t>::max() - digit) / 10)
          refuse(path, "has a list index too large");
        index = index * 10 + digit;
      }
      steps.emplace_back(index);
      i = close + 1;
    } else if (c == '.') {
      if (expect_key) refuse(path, "has an empty key");
      expect_key = true;
      ++i;
    } else if (c == ']') {
      refuse(path, "has a ] without [");
    } else {
      if (!expect_key) refuse(path, "has a key right after a list index; separate it with \".\"");
      const std::size_t end = path.find_first_of(".[]", i);
      const std::size_t stop = end == std::string_view::npos ? path.size() : end;
      steps.emplace_back(std::string(path.substr(i, stop - i)));
      i = stop;
      expect_key = false;
    }
  }
  if (steps.empty()) refuse(path, "is empty");
  if (expect_key) refuse(path, "ends with \".\"");
  return steps;
}

std::string path_text(const std::vector<PathStep>& steps) {
  std::string out;
  for (const PathStep& step : steps) {
    if (const auto* key = std::get_if<std::string>(&step))
      out += (out.empty() ? "" : ".") + *key;
    else
      out += "[" + std::to_string(std::get<std::size_t>(step)) + "]";
  }
  return out;
}

}  // namespace clay::recipe
