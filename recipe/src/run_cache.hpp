#pragma once
// What run_recipe keeps between runs (RunCache, issue #40): the entries, their keys and the
// recipe's document the keys are read from. Internal to the recipe library.
#include <clay/recipe/recipe.hpp>

#include "recipe_model.hpp"

#include <clay/deform/style.hpp>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace clay::recipe::detail {

/// The recipe's JSON as checked (RecipeData::document): each step's key starts with its own
/// definition's text. Shared with the caller that checked a document it holds
/// (parse_recipe_document: the studio's edited recipe is neither copied nor parsed again).
struct DocumentJson {
  std::shared_ptr<const nlohmann::ordered_json> root;
};

/// The text of `root[section][name]` (its JSON, as written), or "" when absent.
std::string definition_text(const DocumentJson& doc, const char* section, const std::string& name);

/// A 128-bit digest of `key` in hex: how a step's key enters the keys of the steps built on it.
std::string digest(const std::string& key);

/// What one step (a stroke, curve, sketch or surface with its stack) added to a run.
struct CacheEntry {
  std::vector<std::pair<std::string, surface::BSplineCurve>> curves;
  std::vector<std::pair<std::string, surface::BSplineSurface>> surfaces;
  std::vector<StepReport> steps;
  std::vector<Stage> stages;
  std::vector<std::pair<std::string, double>> bounds;
};

/// The estimated bytes an entry holds (its nets, knots and reports).
std::size_t entry_bytes(const CacheEntry& e);

/// The digests of the keys of the steps that gave each curve and surface of a run.
struct Digests {
  std::map<std::string, std::string> curve, surface;
};

/// Records the digest `d` of the step that added `e`'s curves and surfaces.
void note_digests(Digests& g, const CacheEntry& e, const std::string& d);

/// A step's key: its section and definition as written, then the digest of every curve and
/// surface it needs (empty when one has none: then it is built, not kept).
std::optional<std::string> own_key(const RecipeData& data, const Digests& g, const char* section,
                                   const std::string& name, const Needs& needs);

/// A surface's key: own_key with the recipe's composition; for a deformed surface its stack's
/// definition, whether it leaves the recipe (a light copy above the budget) and every surface
/// built before it (`before`: its fits follow the sides it shares with them); for an import, the
/// file's size and time of change. With `stack_prefix` k, the key of the deformed surface's
/// first k stack steps alone (the stack's later steps left out: a sweep of a lattice after a
/// style takes the style from the variant before).
std::optional<std::string> surface_key(
    const RecipeData& data, const Digests& g, const SurfaceDef& def, const Needs& needs,
    const std::vector<std::pair<std::string, surface::BSplineSurface>>& before,
    std::optional<std::size_t> stack_prefix = std::nullopt);

/// The runner's access to a RunCache.
class CacheAccess {
 public:
  /// The entry kept under `key` (counted as reused and made the most recent), or null.
  static std::shared_ptr<const CacheEntry> find(RunCache& cache, const std::string& key);
  /// Keeps `entry` under `key`, dropping the least recently used entries beyond the capacity;
  /// an entry larger than the whole capacity is not kept.
  static void keep(RunCache& cache, const std::string& key, CacheEntry entry);
  /// A style editor of `parent` inside `bound` with `options` (deform::StyleEditor: its region,
  /// projector and exact factorizations made once), kept for a style's drag previews; the most
  /// recent few are kept, one per parent, bound and settings, each compared bit for bit.
  static std::shared_ptr<deform::StyleEditor> style_editor(RunCache& cache,
                                                           const surface::BSplineSurface& parent,
                                                           const surface::BSplineCurve& bound,
                                                           const deform::StyleOptions& options);
};

}  // namespace clay::recipe::detail
