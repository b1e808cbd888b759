// Recipe paths (clay/recipe/path.hpp): the grammar the studio's edits and the sweeps share.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/recipe/path.hpp>

#include <random>
#include <string>
#include <vector>

#include "error_of.hpp"

using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::recipe::parse_path;
using clay::recipe::path_text;
using clay::recipe::PathStep;

TEST_CASE("recipe paths: keys and list items, as written", "[path]") {
  const std::vector<PathStep> expected = {std::string("deformations"),
                                          std::string("lift"),
                                          std::size_t{0},
                                          std::string("moves"),
                                          std::size_t{12},
                                          std::size_t{3},
                                          std::string("by")};
  CHECK(parse_path("deformations.lift[0].moves[12][3].by") == expected);
  CHECK(path_text(expected) == "deformations.lift[0].moves[12][3].by");
  // A key may hold any character but . [ ]: digits, spaces, ~ and / (the studio escapes them in
  // its JSON pointers), UTF-8.
  CHECK(parse_path("a.8888888889.b c.~x/y.é") ==
        std::vector<PathStep>{std::string("a"), std::string("8888888889"), std::string("b c"),
                              std::string("~x/y"), std::string("é")});
}

TEST_CASE("recipe paths: random paths read back what wrote them", "[path]") {
  std::mt19937 rng(37);
  std::uniform_int_distribution<int> length(1, 8), coin(0, 2), letter('a', 'z');
  std::uniform_int_distribution<std::size_t> index(0, 1'000'000);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<PathStep> steps{std::string(1, static_cast<char>(letter(rng)))};
    for (int k = length(rng); k > 0; --k) {
      if (coin(rng) == 0) {
        steps.emplace_back(index(rng));
      } else {
        std::string key;
        for (int c = length(rng); c > 0; --c) key += static_cast<char>(letter(rng));
        steps.emplace_back(key);
      }
    }
    CHECK(parse_path(path_text(steps)) == steps);
  }
}

TEST_CASE("recipe paths: a malformed path names the rule it breaks", "[path]") {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "is empty"},
      {"a..b", "empty key"},
      {".a", "empty key"},
      {"a.", "ends with \".\""},
      {"a[x]", "malformed list index"},
      {"a[]", "malformed list index []"},
      {"a[1", "[ without ]"},
      {"a]", "] without ["},
      {"a[0]b", "right after a list index"},
      {"[0]", "starts with a list index"},
      {"a.[0]", "empty key before ["},
      {"a[18446744073709551616]", "too large"}};
  for (const auto& c : cases) {
    const std::string& path = c.first;  // (clang 14 cannot capture a structured binding)
    const std::string& rule = c.second;
    INFO(path);
    const auto [category, what] = clay::test::error_of([&] { parse_path(path); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains(rule) && Contains("[i]"));
  }
  CHECK(std::get<std::size_t>(parse_path("a[18446744073709551615]")[1]) == 18446744073709551615ULL);
}
