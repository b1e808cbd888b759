#pragma once
/// A recipe held parsed, for a program that edits it in place and runs it again (the studio's
/// session: issue #40). Checking the document it holds spares printing the recipe and parsing
/// the text again on every edit, which grew with the recipe (a 40-stroke design: a third of an
/// edit's time). Needs nlohmann-json (Debian's nlohmann-json3-dev) on the include path, which
/// <clay/recipe/recipe.hpp> does not.
#include <clay/recipe/recipe.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <string_view>

namespace clay::recipe {

/// The checked recipe of a parsed document (an ordered_json: the recipe's order of definitions
/// is its order of building), as parse_recipe checks a text: every problem listed in one
/// clay::Error(Document). The document is shared, not copied: the recipe keeps it (its run's
/// cache keys are read from it), so do not change it afterwards; edit a copy. What only a text
/// can have (syntax, a key given twice, its 64 MiB size) is the caller's to check;
/// clay::Error(InvalidArgument) for a null document.
CLAY_RECIPE_API Recipe parse_recipe_document(std::shared_ptr<const nlohmann::ordered_json> document,
                                             const std::filesystem::path& base_dir = {},
                                             std::string_view default_name = {});

}  // namespace clay::recipe
