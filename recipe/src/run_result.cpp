// What a run gives back, by name (RunResult's lookups), and which surfaces a picture of a
// recipe shows: small queries kept apart from the runner (recipe_run.cpp).
#include "recipe_run.hpp"

#include <clay/error.hpp>

#include <set>
#include <string>
#include <variant>

namespace clay::recipe {

namespace {

/// The value named `name` in a run's (name, value) list, or InvalidArgument naming the defined
/// ones.
template <class T>
const T& named(const std::vector<std::pair<std::string, T>>& list, std::string_view name,
               const char* what) {
  std::string known;
  for (const auto& [n, value] : list) {
    if (n == name) return value;
    known += (known.empty() ? "" : ", ") + n;
  }
  throw Error(ErrorCategory::InvalidArgument, "no " + std::string(what) + " named '" +
                                                  std::string(name) + "' in the run; its " + what +
                                                  "s: " + known);
}

}  // namespace

const surface::BSplineSurface& RunResult::surface(std::string_view name) const {
  return named(surfaces, name, "surface");
}

const surface::BSplineCurve& RunResult::curve(std::string_view name) const {
  return named(curves, name, "curve");
}

std::vector<std::string> final_surfaces(const Recipe& recipe) {
  if (!recipe.data)
    throw Error(ErrorCategory::InvalidArgument,
                "final_surfaces: empty recipe; load or parse one first");
  std::set<std::string> parents;
  for (const SurfaceDef& s : recipe.data->surfaces)
    if (const auto* d = std::get_if<DeformDef>(&s.build))
      parents.insert(d->surface);
    else if (const auto* r = std::get_if<RebuildDef>(&s.build))
      parents.insert(r->surface);
  std::vector<std::string> out;
  for (const SurfaceDef& s : recipe.data->surfaces)
    if (!parents.count(s.name)) out.push_back(s.name);
  return out;
}

}  // namespace clay::recipe
