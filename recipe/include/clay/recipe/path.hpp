#pragma once
/// Recipe paths: "deformations.billow[0].moves[1].by[2]" names one value of a recipe's JSON, keys
/// joined by "." and list items as [i]. The one grammar of the studio's edits and the sweeps'
/// parameters (issue #37: it was written twice, in C++ and in Python, and the two disagreed).
#include <clay/recipe/export.hpp>

#include <cstddef>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace clay::recipe {

/// One step of a recipe path: an object's key, or a list's index.
using PathStep = std::variant<std::string, std::size_t>;

/// The steps of `path`: a key is any run of characters other than ".", "[" and "]"; an index is
/// [digits]. A key follows "." or starts the path; an index follows a key or an index. Throws
/// clay::Error(InvalidArgument) naming the path and the rule broken for an empty path, an empty
/// key ("a..b", ".a", "a."), a malformed or too large index ("a[x]", "a[]", "a[1"), or a key
/// right after an index without "." ("a[0]b").
CLAY_RECIPE_API std::vector<PathStep> parse_path(std::string_view path);

/// The path of `steps`, written back in the same grammar (parse_path(path_text(s)) == s).
CLAY_RECIPE_API std::string path_text(const std::vector<PathStep>& steps);

}  // namespace clay::recipe
