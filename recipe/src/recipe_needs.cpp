// What each recipe definition needs built before it, and the check for definitions that need
// each other: curves may be taken from surfaces (iso, boundary, project, offset), and surfaces
// are built from curves, so the run follows these needs rather than a fixed order of sections.
#include "recipe_model.hpp"

#include <algorithm>
#include <functional>
#include <map>

namespace clay::recipe {

namespace {

void add(std::vector<std::string>& to, const std::string& name) {
  if (!name.empty()) to.push_back(name);
}

}  // namespace

Needs curve_needs(const RecipeData& d, const std::string& name) {
  Needs n;
  for (const CurveDef& c : d.curves)
    if (c.name == name) {
      add(n.curves, c.reversed_of);
      add(n.curves, c.mirror_of);
      add(n.curves, c.source);
      add(n.surfaces, c.surface);
      return n;
    }
  for (const SketchDef& s : d.sketches)
    for (const auto& [entity, id] : s.entities)
      if (entity == name) {
        n.curves = s.uses;
        return n;
      }
  return n;  // a stroke, or an inline curve: needs nothing
}

Needs surface_needs(const RecipeData& d, const SurfaceDef& def) {
  Needs n;
  std::visit(
      [&](const auto& b) {
        using T = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<T, FillDef>) {
          n.curves = b.curves;
        } else if constexpr (std::is_same_v<T, SkinDef>) {
          n.curves = b.sections;
        } else if constexpr (std::is_same_v<T, SweepDef>) {
          add(n.curves, b.profile);
          add(n.curves, b.path);
        } else if constexpr (std::is_same_v<T, RevolveDef>) {
          add(n.curves, b.profile);
        } else if constexpr (std::is_same_v<T, MirrorDef> || std::is_same_v<T, RebuildDef>) {
          add(n.surfaces, b.surface);
        } else if constexpr (std::is_same_v<T, DeformDef>) {
          add(n.surfaces, b.surface);
          for (const StackDef& stack : d.stacks)
            if (stack.name == b.deformation)
              for (const StepDef& step : stack.steps)
                if (const auto* style = std::get_if<StyleDef>(&step.step)) {
                  add(n.curves, style->target);
                  add(n.curves, style->bound);
                }
        }
      },
      def.build);
  return n;
}

bool built_on(const RecipeData& d, const std::string& surface) {
  const auto named = [&](const Needs& n) {
    return std::find(n.surfaces.begin(), n.surfaces.end(), surface) != n.surfaces.end();
  };
  return std::any_of(d.surfaces.begin(), d.surfaces.end(),
                     [&](const SurfaceDef& s) { return named(surface_needs(d, s)); }) ||
         std::any_of(d.curves.begin(), d.curves.end(),
                     [&](const CurveDef& c) { return c.surface == surface; });
}

std::vector<std::string> dependency_cycle(const RecipeData& d) {
  // Depth-first search over "curve NAME" and "surface NAME" nodes; a node met again while on
  // the path closes a cycle.
  std::map<std::string, int> state;  // 1: on the path, 2: done
  std::vector<std::string> path, cycle;
  std::map<std::string, const SurfaceDef*> surfaces;
  for (const SurfaceDef& s : d.surfaces) surfaces[s.name] = &s;
  std::function<bool(const std::string&)> visit = [&](const std::string& node) {
    const int st = state[node];
    if (st == 2) return false;
    if (st == 1) {
      cycle.assign(std::find(path.begin(), path.end(), node), path.end());
      cycle.push_back(node);
      return true;
    }
    state[node] = 1;
    path.push_back(node);
    Needs n;
    if (node.rfind("curve ", 0) == 0) {
      n = curve_needs(d, node.substr(6));
    } else if (const auto it = surfaces.find(node.substr(8)); it != surfaces.end()) {
      n = surface_needs(d, *it->second);
    }
    for (const std::string& c : n.curves)
      if (visit("curve " + c)) return true;
    for (const std::string& s : n.surfaces)
      if (visit("surface " + s)) return true;
    path.pop_back();
    state[node] = 2;
    return false;
  };
  for (const CurveDef& c : d.curves)
    if (visit("curve " + c.name)) return cycle;
  for (const SurfaceDef& s : d.surfaces)
    if (visit("surface " + s.name)) return cycle;
  return {};
}

}  // namespace clay::recipe
