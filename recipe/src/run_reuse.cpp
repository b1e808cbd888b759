// What a run takes from the run before it (RunOptions::previous, issue #38 step 4): the surfaces
// an edit of deformations leaves alone, and a lattice step's light form as one product of its
// points while a drag lasts (RunOptions::preview).
#include <algorithm>
#include <limits>

#include "recipe_run.hpp"

namespace clay::recipe::detail {

namespace {

bool curve_needs_changed(const RecipeData& d, const RunResult& previous,
                         const std::vector<std::string>& changed, const std::string& curve,
                         std::map<std::string, bool>& memo) {
  const Needs needs = curve_needs(d, curve);
  bool a = false;
  for (const auto& s : needs.surfaces) a = needs_changed(d, previous, changed, s, memo) || a;
  for (const auto& c : needs.curves) a = curve_needs_changed(d, previous, changed, c, memo) || a;
  return a;
}

}  // namespace

bool needs_changed(const RecipeData& d, const RunResult& previous,
                   const std::vector<std::string>& changed, const std::string& surface,
                   std::map<std::string, bool>& memo) {
  if (const auto it = memo.find(surface); it != memo.end()) return it->second;
  bool a = std::find(previous.previewed.begin(), previous.previewed.end(), surface) !=
           previous.previewed.end();
  for (const SurfaceDef& def : d.surfaces)
    if (def.name == surface) {
      if (const auto* deform = std::get_if<DeformDef>(&def.build))
        a = a || std::find(changed.begin(), changed.end(), deform->deformation) != changed.end();
      const Needs needs = surface_needs(d, def);
      for (const auto& s : needs.surfaces) a = needs_changed(d, previous, changed, s, memo) || a;
      for (const auto& c : needs.curves)
        a = curve_needs_changed(d, previous, changed, c, memo) || a;
    }
  return memo[surface] = a;
}

bool take_surface(const RunResult& previous, const SurfaceDef& def, RunResult& into,
                  std::map<std::string, double>& bounds,
                  const std::function<void(const StepReport&)>& progress) {
  const auto kept = std::find_if(previous.surfaces.begin(), previous.surfaces.end(),
                                 [&](const auto& s) { return s.first == def.name; });
  if (kept == previous.surfaces.end()) return false;
  // Its own steps: "surfaces.NAME", "surfaces.NAME.steps[k]", "surfaces.NAME.composition.budget".
  for (const StepReport& rep : previous.steps)
    if (rep.path == def.path || rep.path.rfind(def.path + ".", 0) == 0) {
      StepReport taken = rep;
      taken.reused = true;
      if (progress) progress(taken);
      into.steps.push_back(std::move(taken));
    }
  for (const Stage& st : previous.stages)
    if (st.surface == def.name) into.stages.push_back(st);
  for (const auto& [n, bound] : previous.bounds)
    if (n == def.name) bounds[n] = bound;
  into.surfaces.push_back(*kept);
  return true;
}

std::optional<PreviewLight> preview_light(const RunResult& previous, const deform::Deformation& d,
                                          const surface::BSplineSurface& s,
                                          const std::string& step) {
  if (!std::holds_alternative<deform::BezierLattice>(d) &&
      !std::holds_alternative<deform::BSplineLattice>(d))
    return {};
  const auto stage = std::find_if(previous.stages.begin(), previous.stages.end(),
                                  [&](const Stage& st) { return st.step == step; });
  if (stage == previous.stages.end()) return {};
  if (stage->light_map && deform::applies_to(*stage->light_map, d, s))
    return PreviewLight{deform::light_net(*stage->light_map, d), stage->light_map};
  const auto rep = std::find_if(previous.steps.begin(), previous.steps.end(),
                                [&](const StepReport& r) { return r.path == step; });
  // A light form, or a refit (composition "refit", or a B-spline lattice's knot planes): both are
  // refit's least squares on their final knots, so both are linear in the lattice's points.
  const std::pair<std::string, Figure> light{"composition", std::string("light")},
      refit{"composition", std::string("refit")};
  if (rep == previous.steps.end() ||
      (std::find(rep->figures.begin(), rep->figures.end(), light) == rep->figures.end() &&
       std::find(rep->figures.begin(), rep->figures.end(), refit) == rep->figures.end()))
    return {};
  // The knots of the last light form serve any input. The same input as the last run's: the
  // lattice is what is dragged, so its map is made (kept for the next update). Another input: a
  // drag upstream (a style's target), whose next update changes the input again, so the net is
  // fitted at once, a third of a map's columns or fewer.
  if (surface::identical(stage->before, s)) {
    auto map = std::make_shared<const deform::LatticeLightMap>(
        deform::lattice_light_map(d, s, stage->after));
    return PreviewLight{deform::light_net(*map, d), map};
  }
  return PreviewLight{deform::light_fit(d, s, stage->after), nullptr};
}

void preview_figures(const surface::BSplineSurface& net, StepReport& rep) {
  rep.figures.emplace_back("composition", std::string("light"));  // a refit's preview too
  rep.figures.emplace_back("preview", true);
  rep.figures.emplace_back("accumulated_bound", std::string("unbounded"));
  rep.figures.emplace_back("degree_u", static_cast<long long>(net.u.degree));
  rep.figures.emplace_back("degree_v", static_cast<long long>(net.v.degree));
  rep.figures.emplace_back("control_points", static_cast<long long>(net.points.rows()));
  rep.figures.emplace_back("exact", false);
  rep.figures.emplace_back("certified", false);
  rep.message +=
      ": light form on the knots of its last fit, one product of the lattice's points (a drag "
      "preview, not certified: fitted and certified again when the drag is let go)";
}

}  // namespace clay::recipe::detail
