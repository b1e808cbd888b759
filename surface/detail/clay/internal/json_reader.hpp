#pragma once
// The one path-aware JSON reader (internal, not installed) behind the recipe checker and the
// deformation-stack reader. Every read records a problem with the value's JSON path and returns
// nullopt (or a fallback), so a walk goes on and reports everything wrong at once; no caller ever
// needs to parse a message to learn where a problem is.
#include <clay/surface/bspline_curve.hpp>

#include <clay/internal/format.hpp>

#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace clay::internal {

using Json = nlohmann::ordered_json;

/// One problem: where (a JSON path such as "deformations.wing[0].points[5]") and what.
struct JsonProblem {
  std::string path;
  std::string message;
};

/// The value in words for messages: "the string \"x\"", "the number 3", "an array of 2", ...
inline std::string found(const Json& j) {
  if (j.is_null()) return "null";
  if (j.is_boolean()) return j.get<bool>() ? "true" : "false";
  if (j.is_number()) return "the number " + shortest(j.get<double>());
  if (j.is_string()) {
    const std::string& s = j.get_ref<const std::string&>();
    return "the string \"" + (s.size() > 40 ? clip_utf8(s, 37) : s) + "\"";
  }
  if (j.is_array()) return "an array of " + std::to_string(j.size());
  return "an object";
}

/// Where arrays and objects first nest deeper than `limit` in a JSON text, found by counting
/// brackets outside strings before any parser sees it: nlohmann's parser, given a text nested
/// 100,000 levels deep, recursed until the stack overflowed (issues #18 and #36). `at` is the
/// byte offset of the bracket, `top_key` the top-level key it is under ("" when none).
struct TooDeep {
  std::size_t at = 0;
  std::string top_key;
};
inline std::optional<TooDeep> nesting_too_deep(std::string_view text, int limit) {
  int depth = 0;
  std::size_t string_start = 0;
  bool in_string = false;
  std::string key, top_key;  // the last string closed at depth 1, and the key it became
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character cannot end the string
      } else if (c == '"') {
        in_string = false;
        if (depth == 1) key = clip_utf8(text.substr(string_start, i - string_start), 64);
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
      string_start = i + 1;
    } else if (c == ':' && depth == 1) {
      top_key = key;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return TooDeep{i, top_key};
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return std::nullopt;
}

inline std::string key_path(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}
inline std::string index_path(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

inline std::string join(const std::vector<std::string>& items, std::string_view sep = ", ") {
  std::string out;
  for (std::size_t k = 0; k < items.size(); ++k) out += (k ? std::string(sep) : "") + items[k];
  return out;
}

/// An allowed interval for a number, open or closed at each end.
struct Range {
  double lo = -std::numeric_limits<double>::infinity(),
         hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  bool contains(double x) const {
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  std::string text() const {
    const double inf = std::numeric_limits<double>::infinity();
    if (lo == -inf && hi == inf) return "any finite number";
    if (hi == inf) return std::string(lo_open ? "> " : ">= ") + shortest(lo);
    if (lo == -inf) return std::string(hi_open ? "< " : "<= ") + shortest(hi);
    return std::string(lo_open ? "(" : "[") + shortest(lo) + ", " + shortest(hi) +
           (hi_open ? ")" : "]");
  }
};

/// The reader: typed reads that record problems with their paths.
class JsonReader {
 public:
  std::vector<JsonProblem> problems;
  /// Every number must also lie within ±magnitude (a format's own limit; none by default), and
  /// the note says why when one does not.
  double magnitude = std::numeric_limits<double>::max();
  std::string magnitude_note;
  /// Said after a count above a format's ceiling.
  std::string limit_note = "a limit of the format";
  /// Whether a denormal number (nonzero, below 2.2e-308 in magnitude) is refused: recipes do
  /// (issue #36: one passed the check, then its run refused the STEP file it had written);
  /// deformation stack files keep every double they are given.
  bool refuse_denormal = false;

  virtual ~JsonReader() = default;

  /// Records a problem ("(top level)" for the empty path); `wording` may rephrase the message.
  void add(std::string path, std::string message) {
    problems.push_back(
        {path.empty() ? "(top level)" : std::move(path), wording(std::move(message))});
  }

  /// A key the format renamed (or dropped): said as such instead of "unknown key", with the fix.
  struct Renamed {
    std::string_view old_key;
    std::string_view new_key;  ///< empty: dropped
    std::string_view note;     ///< what the new key means, or what replaces a dropped one
  };

  /// True when j is an object; reports every key outside `allowed`, a renamed one by its new name.
  bool object(const Json& j, const std::string& path,
              std::initializer_list<std::string_view> allowed, std::string_view what,
              std::initializer_list<Renamed> renamed = {}) {
    if (!j.is_object()) {
      add(path, "expected " + std::string(what) + " (a JSON object), found " + found(j));
      return false;
    }
    for (const auto& [key, value] : j.items()) {
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      const auto r = std::find_if(renamed.begin(), renamed.end(),
                                  [&, k = &key](const Renamed& x) { return x.old_key == *k; });
      if (r != renamed.end()) {
        add(key_path(path, key),
            r->new_key.empty()
                ? "\"" + key + "\" is no longer a key of " + std::string(what) + ": " +
                      std::string(r->note)
                : "\"" + key + "\" was renamed \"" + std::string(r->new_key) + "\" (" +
                      std::string(r->note) + "); write \"" + std::string(r->new_key) + "\": " +
                      clip_utf8(value.dump(-1, ' ', false, Json::error_handler_t::replace), 40) +
                      " instead");
        continue;
      }
      std::vector<std::string> names(allowed.begin(), allowed.end());
      add(key_path(path, key),
          "unknown key \"" + key + "\" in " + std::string(what) + "; the keys are: " + join(names));
    }
    return true;
  }

  /// The member, or nullptr (reported when required, with `hint` saying what to give).
  const Json* member(const Json& obj, const std::string& path, std::string_view key, bool required,
                     std::string_view hint) {
    if (!obj.is_object()) return nullptr;
    const auto it = obj.find(std::string(key));
    if (it == obj.end()) {
      if (required) add(key_path(path, key), "missing; give " + std::string(hint));
      return nullptr;
    }
    return &*it;
  }

  std::optional<double> number(const Json& j, const std::string& path, Range r = {}) {
    // No range of its own: the format's magnitude is the range to name.
    if (r.lo == -std::numeric_limits<double>::infinity() &&
        r.hi == std::numeric_limits<double>::infinity() &&
        magnitude < std::numeric_limits<double>::max())
      r = Range{-magnitude, magnitude};
    if (!j.is_number()) {
      add(path, "expected a number (" + r.text() + "), found " + found(j));
      return std::nullopt;
    }
    const double x = j.get<double>();
    if (!std::isfinite(x) || !r.contains(x) || std::abs(x) > magnitude) {
      add(path, shortest(x) + " is out of range; give a number " + r.text() +
                    (std::abs(x) > magnitude ? " (" + magnitude_note + ")" : ""));
      return std::nullopt;
    }
    if (refuse_denormal && x != 0 && std::abs(x) < std::numeric_limits<double>::min()) {
      add(path, shortest(x) + " is denormal (nonzero, below 2.2e-308 in magnitude); write 0");
      return std::nullopt;
    }
    return x;
  }

  /// False (and the problem recorded) when the array j holds more than `max` items.
  bool at_most(const Json& j, const std::string& path, std::size_t max, std::string_view what) {
    if (!j.is_array() || j.size() <= max) return true;
    add(path, "an array of " + std::to_string(j.size()) + " " + std::string(what) + "; at most " +
                  std::to_string(max) + " are allowed (" + limit_note + ")");
    return false;
  }

  std::optional<int> integer(const Json& j, const std::string& path, int lo, int hi) {
    if (!j.is_number_integer() || j.get<long long>() < lo || j.get<long long>() > hi) {
      add(path, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                    "], found " + found(j));
      return std::nullopt;
    }
    return static_cast<int>(j.get<long long>());
  }

  std::optional<bool> boolean(const Json& j, const std::string& path) {
    if (!j.is_boolean()) {
      add(path, "expected true or false, found " + found(j));
      return std::nullopt;
    }
    return j.get<bool>();
  }

  std::optional<std::string> string(const Json& j, const std::string& path) {
    if (!j.is_string()) {
      add(path, "expected a string, found " + found(j));
      return std::nullopt;
    }
    return j.get<std::string>();
  }

  /// One of `choices` (the index), or nullopt.
  std::optional<int> choice(const Json& j, const std::string& path,
                            const std::vector<std::string>& choices) {
    if (j.is_string()) {
      const auto s = j.get<std::string>();
      for (std::size_t k = 0; k < choices.size(); ++k)
        if (choices[k] == s) return static_cast<int>(k);
    }
    add(path, "expected one of " + join(choices) + ", found " + found(j));
    return std::nullopt;
  }

  std::optional<Eigen::Vector3d> vec3(const Json& j, const std::string& path) {
    if (!j.is_array() || j.size() != 3) {
      add(path, "expected [x, y, z] (3 numbers, mm), found " + found(j));
      return std::nullopt;
    }
    Eigen::Vector3d v;
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      const auto x =
          number(j[static_cast<std::size_t>(k)], index_path(path, static_cast<std::size_t>(k)));
      ok = ok && x.has_value();
      v[k] = x.value_or(0.0);
    }
    return ok ? std::optional(v) : std::nullopt;
  }

  std::optional<Eigen::Vector2d> vec2(const Json& j, const std::string& path) {
    if (!j.is_array() || j.size() != 2) {
      add(path, "expected [a, b] (2 numbers, mm in the plane), found " + found(j));
      return std::nullopt;
    }
    const auto a = number(j[0], index_path(path, 0));
    const auto b = number(j[1], index_path(path, 1));
    if (!a || !b) return std::nullopt;
    return Eigen::Vector2d(*a, *b);
  }

  /// An array of [x, y, z] with at least `min` and at most `max` rows.
  std::optional<surface::Points3> points(
      const Json& j, const std::string& path, std::size_t min,
      std::size_t max = std::numeric_limits<std::size_t>::max()) {
    if (!at_most(j, path, max, "points")) return std::nullopt;
    if (!j.is_array() || j.size() < min) {
      add(path, "expected an array of " +
                    (min > 0 ? "at least " + std::to_string(min) + " " : std::string()) +
                    "points [x, y, z], found " + found(j));
      return std::nullopt;
    }
    surface::Points3 p(static_cast<Eigen::Index>(j.size()), 3);
    bool ok = true;
    for (std::size_t i = 0; i < j.size(); ++i) {
      const auto v = vec3(j[i], index_path(path, i));
      ok = ok && v.has_value();
      if (v) p.row(static_cast<Eigen::Index>(i)) = v->transpose();
    }
    return ok ? std::optional(p) : std::nullopt;
  }

  std::optional<std::vector<double>> numbers(
      const Json& j, const std::string& path, std::size_t min,
      std::size_t max = std::numeric_limits<std::size_t>::max(), Range r = {}) {
    if (!at_most(j, path, max, "numbers")) return std::nullopt;
    if (!j.is_array() || j.size() < min) {
      add(path, "expected an array of " +
                    (min > 0 ? "at least " + std::to_string(min) + " " : std::string()) +
                    "numbers, found " + found(j));
      return std::nullopt;
    }
    std::vector<double> out;
    bool ok = true;
    for (std::size_t i = 0; i < j.size(); ++i) {
      const auto x = number(j[i], index_path(path, i), r);
      ok = ok && x.has_value();
      out.push_back(x.value_or(0.0));
    }
    return ok ? std::optional(out) : std::nullopt;
  }

  // Optional members with a default: read when present, the default otherwise (or when bad).
  double number_or(const Json& obj, const std::string& path, std::string_view key, double def,
                   Range r = {}) {
    const Json* j = member(obj, path, key, false, "");
    return j ? number(*j, key_path(path, key), r).value_or(def) : def;
  }
  int integer_or(const Json& obj, const std::string& path, std::string_view key, int def, int lo,
                 int hi) {
    const Json* j = member(obj, path, key, false, "");
    return j ? integer(*j, key_path(path, key), lo, hi).value_or(def) : def;
  }
  bool boolean_or(const Json& obj, const std::string& path, std::string_view key, bool def) {
    const Json* j = member(obj, path, key, false, "");
    return j ? boolean(*j, key_path(path, key)).value_or(def) : def;
  }

  /// Adds each problems(x, label) message of the library at `label`; such messages start with
  /// the label they were given, which is taken off so the path is not said twice.
  void add_all(const std::string& label, const std::vector<std::string>& list) {
    for (const auto& p : list) {
      if (p.rfind(label + ": ", 0) == 0)
        add(label, p.substr(label.size() + 2));
      else if (p.rfind(label + " ", 0) == 0)
        add(label, p.substr(label.size() + 1));
      else
        add(label, p);
    }
  }

 protected:
  /// How a format words its messages (the recipe names recipe keys instead of C++ fields).
  virtual std::string wording(std::string message) const { return message; }
};

}  // namespace clay::internal
