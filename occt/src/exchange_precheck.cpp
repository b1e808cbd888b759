// Text checks of STEP and IGES files before OpenCASCADE reads them (exchange_precheck.hpp).
#include "exchange_precheck.hpp"

#include <clay/error.hpp>
#include <clay/internal/fenv.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace clay::surface::detail {
namespace {

namespace fs = std::filesystem;

/// Why the number written as `token` is refused, or "" when it is fine. IGES may write
/// exponents with D (Fortran).
std::string bad_number(std::string_view token) {
  std::string t(token);
  for (char& c : t)
    if (c == 'D' || c == 'd') c = 'E';
  errno = 0;
  char* end = nullptr;
  const double x = std::strtod(t.c_str(), &end);
  const std::string shown = "'" + std::string(token.substr(0, 40)) + "'";
  if (end == t.c_str() || *end != '\0') return shown + " is not a number";
  if (std::isnan(x)) return shown + " is not a number (NaN)";
  if (std::isinf(x)) return shown + " is beyond the range of a double";
  if (std::abs(x) > max_file_number)
    return shown + " is larger in magnitude than 1e100, which no geometry needs";
  return {};
}

[[noreturn]] void fail(std::string_view caller, const fs::path& file, int line,
                       const std::string& where, const std::string& what) {
  throw Error(ErrorCategory::Exchange,
              std::string(caller) + ": '" + file.string() + "' line " + std::to_string(line) +
                  (where.empty() ? "" : ", " + where) + ": " + what +
                  "; the file is malformed (it is refused before OpenCASCADE, "
                  "which may crash or hang on such files): export it again or repair it");
}

// ---- STEP -------------------------------------------------------------------------------------

struct Token {
  enum Kind { End, Ref, Word, Number, String, Enum, Symbol } kind = End;
  std::string text;  // Ref: the digits; Symbol: the character
  int line = 0;
};

/// The tokens of an ISO 10303-21 file: comments skipped, strings and enumerations whole.
class StepTokens {
 public:
  // The stream buffer directly: istream::get and peek build a sentry per character, which made
  // the scan a third of a read's time.
  explicit StepTokens(std::istream& in) : in_{*in.rdbuf()} {}
  int line() const { return line_; }
  bool unterminated() const { return unterminated_; }

  Token next() {
    for (;;) {
      int c = get();
      if (c == EOF) return {Token::End, "", line_};
      if (std::isspace(c)) continue;
      if (c == '/' && in_.peek() == '*') {  // a comment
        get();
        const int start = line_;
        for (int prev = 0;;) {
          const int d = get();
          if (d == EOF) return unterminated_ = true, Token{Token::End, "", start};
          if (prev == '*' && d == '/') break;
          prev = d;
        }
        continue;
      }
      Token t{Token::Symbol, std::string(1, static_cast<char>(c)), line_};
      if (c == '\'' || c == '"') {  // a string ('' inside is a quote) or a binary
        t.kind = Token::String;
        for (;;) {
          const int d = get();
          if (d == EOF) return unterminated_ = true, Token{Token::End, "", t.line};
          if (d == c) {
            if (c == '\'' && in_.peek() == '\'') {
              get();
              continue;
            }
            break;
          }
        }
      } else if (c == '#') {
        t.kind = Token::Ref;
        t.text.clear();
        while (std::isdigit(in_.peek())) t.text += static_cast<char>(get());
      } else if (c == '.' && std::isalpha(in_.peek())) {  // .T., .UNSPECIFIED.
        t.kind = Token::Enum;
        while (in_.peek() != EOF && in_.peek() != '.' && in_.peek() != '\n')
          t.text += static_cast<char>(get());
        if (in_.peek() == '.') get();
      } else if (std::isalpha(c) || c == '_' || c == '!') {
        t.kind = Token::Word;
        while (std::isalnum(in_.peek()) || in_.peek() == '_' || in_.peek() == '-')
          t.text += static_cast<char>(get());
      } else if (std::isdigit(c) || c == '+' || c == '-' || c == '.') {
        t.kind = Token::Number;  // greedy, so that "1E999", "-nan" and "1.2.3" are one token
        for (int prev = c;;) {
          const int d = in_.peek();
          const bool sign = (d == '+' || d == '-') && (prev == 'E' || prev == 'e');
          if (!(std::isalnum(d) || d == '.' || sign)) break;
          t.text += static_cast<char>(get());
          prev = d;
        }
      }
      return t;
    }
  }

 private:
  /// The stream buffer with istream's names.
  struct Buffer {
    std::streambuf& buffer;
    int peek() { return buffer.sgetc(); }
    int get() { return buffer.sbumpc(); }
  } in_;
  int line_ = 1;
  bool unterminated_ = false;

  int get() {
    const int c = in_.get();
    if (c == '\n') ++line_;
    return c;
  }
};

/// How many degrees an entity's parameters start with (after its name): 2 for B-spline surfaces,
/// 1 for curves, 0 otherwise. In a complex entity ("( BOUNDED_SURFACE() B_SPLINE_SURFACE(3,3,
/// (...),...) B_SPLINE_SURFACE_WITH_KNOTS((4,4),...) ... )") each part lists only its own
/// attributes: the degrees are B_SPLINE_SURFACE's (B_SPLINE_CURVE's), unnamed.
int degree_count(const std::string& word, bool complex) {
  if (word == "B_SPLINE_SURFACE") return 2;
  if (word == "B_SPLINE_CURVE") return 1;
  if (complex) return 0;
  for (const char* s : {"B_SPLINE_SURFACE_WITH_KNOTS", "BEZIER_SURFACE", "UNIFORM_SURFACE",
                        "QUASI_UNIFORM_SURFACE"})
    if (word == s) return 2;
  for (const char* c :
       {"B_SPLINE_CURVE_WITH_KNOTS", "BEZIER_CURVE", "UNIFORM_CURVE", "QUASI_UNIFORM_CURVE"})
    if (word == c) return 1;
  return 0;
}

}  // namespace

void precheck_step(const fs::path& file, std::string_view caller, int max_degree) {
  const internal::FpTrapsHeld traps_held;  // bad_number's strtod
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw Error(ErrorCategory::Io,
                std::string(caller) + ": '" + file.string() + "' cannot be opened");
  StepTokens tokens(in);
  std::unordered_map<std::string, int> defined;  // entity number -> the line defining it
  // Entries of each open list (one counter per open parenthesis): OpenCASCADE took past the
  // reader's 120 s limit on a list of 10^5 references (issue #36).
  std::vector<std::size_t> entries;
  struct Use {
    std::string id, entity;
    int line;
  };
  std::vector<Use> uses;
  bool data = false;
  int depth = 0;
  std::string entity;  // "#N" of the entity being read, "" between entities
  auto where = [&] { return entity.empty() ? std::string() : "entity " + entity; };
  // A B-spline entity's degrees: expected while parameters at `degree_depth` are read.
  int degrees_left = 0, degree_depth = 0;
  std::string degree_entity;
  Token t = tokens.next();
  while (t.kind != Token::End) {
    const Token after = tokens.next();
    const bool call = after.kind == Token::Symbol && after.text == "(";
    const bool expecting = degrees_left > 0;  // set by an earlier token
    if (t.kind == Token::Word && depth == 0 && (t.text == "DATA" || t.text == "ENDSEC")) {
      data = t.text == "DATA";
    } else if (!data) {
      // the HEADER section holds no geometry
    } else if (t.kind == Token::Ref) {
      if (t.text.empty() || t.text.size() > 18)
        fail(caller, file, t.line, where(), "'#" + t.text + "' is not an entity number");
      if (depth == 0 && after.kind == Token::Symbol && after.text == "=") {
        entity = "#" + t.text;
        // ISO 10303-21 defines each entity number once; OpenCASCADE silently took one of two
        // definitions, and the model read back with a negative volume and a 25 mm edge gap.
        if (const auto [at, added] = defined.emplace(t.text, t.line); !added)
          fail(caller, file, t.line, where(),
               "#" + t.text + " is defined twice, on line " + std::to_string(at->second) +
                   " and here (ISO 10303-21 allows one definition per entity number); keep one "
                   "and renumber the other");
      } else {
        uses.push_back({t.text, entity, t.line});
      }
    } else if (t.kind == Token::Word) {
      // Inside parameters a word is an entity name (or a typed value) followed by "(": a bare
      // word such as NaN or INF is no STEP value.
      if (depth > 0 && !call)
        fail(caller, file, t.line, where(),
             "'" + t.text + "' is not a STEP value (numbers must be finite)");
      if (const int n = call ? degree_count(t.text, depth > 0) : 0; n > 0) {
        degrees_left = n;
        degree_depth = depth + 1;
        degree_entity = t.text;
      }
    } else if (t.kind == Token::Number && depth > 0) {
      if (const std::string why = bad_number(t.text); !why.empty())
        fail(caller, file, t.line, where(), why);
    } else if (t.kind == Token::Symbol) {
      if (t.text == "(") {
        ++depth;
        entries.push_back(1);
      }
      if (t.text == "," && !entries.empty() && ++entries.back() > max_list_entries)
        fail(caller, file, t.line, where(),
             "a list has more than " + std::to_string(max_list_entries) +
                 " entries (a limit of this reader: OpenCASCADE takes minutes on such lists); "
                 "split the entity (a shell of fewer faces, a loop of fewer edges)");
      if (t.text == ")") {
        if (--depth < 0) fail(caller, file, t.line, where(), "a ')' closes no '('");
        entries.pop_back();
      }
      if (t.text == ";" && depth == 0) entity.clear();
    }
    // The degrees: the first integers of the B-spline's own parameter list (after its name).
    if (expecting && depth == degree_depth && t.kind == Token::Number) {
      char* end = nullptr;
      const long d = std::strtol(t.text.c_str(), &end, 10);
      if (*end != '\0' || d < 1 || d > max_degree)
        fail(caller, file, t.line, where(),
             degree_entity + " has degree " + t.text + "; degrees are integers in [1, " +
                 std::to_string(max_degree) + "]");
      --degrees_left;
    } else if (expecting &&
               !(depth == degree_depth && (t.kind == Token::String || t.kind == Token::Symbol) &&
                 (t.kind == Token::String || t.text == "," || t.text == "("))) {
      degrees_left = 0;  // no degrees where they belong: OpenCASCADE reports such a file itself
    }
    t = after;
  }
  if (tokens.unterminated())
    fail(caller, file, tokens.line(), "", "a string or comment does not end");
  if (depth != 0) fail(caller, file, tokens.line(), "", "parentheses do not balance");
  for (const Use& u : uses)
    if (!defined.count(u.id))
      fail(caller, file, u.line, u.entity.empty() ? "" : "entity " + u.entity,
           "it refers to #" + u.id + ", which the file does not define (a dangling reference)");
}

// ---- IGES -------------------------------------------------------------------------------------

namespace {

/// One parameter-data record: its parameters as written, where it starts and its directory entry.
struct IgesRecord {
  std::vector<std::string> parameters;  // trimmed; Hollerith strings as "H"
  int line = 0;
  std::string directory_entry;
};

std::string trimmed(std::string_view s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

/// Splits a record's text at `delimiter` up to `end`, keeping Hollerith strings ("3Habc") whole.
std::vector<std::string> split_parameters(const std::string& text, char delimiter, char end) {
  std::vector<std::string> out;
  std::string current;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == delimiter || c == end) {
      out.push_back(trimmed(current));
      current.clear();
      if (c == end) break;
      continue;
    }
    // (One trimmed copy: begin() and end() of two temporaries made a range across two strings,
    // so every string parameter was refused as "not a number".)
    const std::string count = trimmed(current);
    if ((c == 'H' || c == 'h') && !count.empty() &&
        std::all_of(count.begin(), count.end(),
                    [](char d) { return std::isdigit(static_cast<unsigned char>(d)); })) {
      const std::size_t n = std::strtoul(count.c_str(), nullptr, 10);
      i += std::min(n, text.size() - i - 1);
      current = "H";
      continue;
    }
    current += c;
  }
  return out;
}

long integer_parameter(const IgesRecord& r, std::size_t k, std::string_view caller,
                       const fs::path& file, const std::string& where, const char* name) {
  if (k >= r.parameters.size())
    fail(caller, file, r.line, where, std::string("the record ends before its ") + name);
  char* end = nullptr;
  const std::string& p = r.parameters[k];
  const long v = std::strtol(p.c_str(), &end, 10);
  if (p.empty() || *end != '\0')
    fail(caller, file, r.line, where, std::string(name) + " '" + p + "' is not an integer");
  return v;
}

/// Degrees and counts of a 126 (curve) or 128 (surface) record against the parameters it holds.
void check_bspline(const IgesRecord& r, int type, std::string_view caller, const fs::path& file,
                   const std::string& where, int max_degree) {
  // The largest upper index a record may declare: its control points alone take 4 parameters
  // each, so a record cannot hold more than its parameter count allows.
  const long most = static_cast<long>(r.parameters.size());
  auto degree = [&](std::size_t k, const char* name) {
    const long m = integer_parameter(r, k, caller, file, where, name);
    if (m < 1 || m > max_degree)
      fail(caller, file, r.line, where,
           std::string(name) + " " + std::to_string(m) + " is outside [1, " +
               std::to_string(max_degree) + "]");
    return m;
  };
  auto upper = [&](std::size_t k, long m, const char* name) {
    const long u = integer_parameter(r, k, caller, file, where, name);
    if (u < m || u > most)
      fail(caller, file, r.line, where,
           std::string(name) + " " + std::to_string(u) + " is inconsistent (below the degree " +
               std::to_string(m) + " or beyond the " + std::to_string(most) +
               " parameters of the record)");
    return u;
  };
  long needed = 0;
  if (type == 126) {  // K, M, PROP1-4, knots, weights, points, V0, V1[, normal]
    const long m = degree(2, "degree M");
    const long k = upper(1, m, "upper index K");
    // The unit normal of a planar curve closes the record, and writers leave it out (Spatial's
    // XPlus for Solid Edge writes 2D trim curves without it; OpenCASCADE reads them).
    needed = 1 + 2 + 4 + (k + 1 + m + 1) + (k + 1) + 3 * (k + 1) + 2;
  } else {  // K1, K2, M1, M2, PROP1-5, knots S and T, weights, points, U0, U1, V0, V1
    const long m1 = degree(3, "degree M1"), m2 = degree(4, "degree M2");
    const long k1 = upper(1, m1, "upper index K1"), k2 = upper(2, m2, "upper index K2");
    const long c = (k1 + 1) * (k2 + 1);
    needed = 1 + 4 + 5 + (k1 + 1 + m1 + 1) + (k2 + 1 + m2 + 1) + c + 3 * c + 4;
  }
  if (most < needed)
    fail(caller, file, r.line, where,
         "the record holds " + std::to_string(most) + " parameters but its counts need " +
             std::to_string(needed));
}

}  // namespace

void precheck_iges(const fs::path& file, std::string_view caller, int max_degree) {
  const internal::FpTrapsHeld traps_held;  // bad_number's strtod
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw Error(ErrorCategory::Io,
                std::string(caller) + ": '" + file.string() + "' cannot be opened");
  char delimiter = ',', end = ';';
  std::string global;
  IgesRecord record;
  std::string text;  // the current record's parameter text
  auto finish = [&] {
    if (text.empty()) return;
    record.parameters = split_parameters(text, delimiter, end);
    text.clear();
    const std::string where =
        "entity " + (record.parameters.empty() ? std::string("?") : record.parameters[0]) +
        " (directory entry " + record.directory_entry + ")";
    for (std::size_t k = 0; k < record.parameters.size(); ++k) {
      const std::string& p = record.parameters[k];
      if (p.empty() || p == "H") continue;  // a default value or a string
      if (const std::string why = bad_number(p); !why.empty())
        fail(caller, file, record.line, where, "parameter " + std::to_string(k + 1) + " " + why);
    }
    if (!record.parameters.empty() &&
        (record.parameters[0] == "126" || record.parameters[0] == "128"))
      check_bspline(record, record.parameters[0] == "126" ? 126 : 128, caller, file, where,
                    max_degree);
  };
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() < 73) continue;  // not a fixed-format record (OpenCASCADE reports those)
    const char section = line[72];
    if (section == 'G') {
      global += line.substr(0, 72);
      // "1H,,1H;,...": the delimiters, when given, open the global section
      if (global.size() >= 3 && global.compare(0, 2, "1H") == 0) delimiter = global[2];
      if (global.size() >= 7 && global.compare(4, 2, "1H") == 0) end = global[6];
    } else if (section == 'P') {
      // A record is every line pointing back to the same directory entry (its end delimiter may
      // sit inside a string).
      const std::string entry = trimmed(line.substr(64, 8));
      if (entry != record.directory_entry) finish();
      if (text.empty()) {
        record.line = number;
        record.directory_entry = entry;
      }
      text += line.substr(0, 64);
    } else {
      finish();
    }
  }
  finish();
}

}  // namespace clay::surface::detail
