#pragma once
// What the recipe runner's two files share (recipe_run.cpp: the Runner, curves, surfaces and
// exports; recipe_run_models.cpp: whole models and deform_model). Internal to the recipe library.
#include <clay/deform/light_map.hpp>
#include <clay/deform/style.hpp>
#include <clay/deform/surface_deformation.hpp>
#include <clay/error.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/surface/build_report.hpp>

#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "recipe_model.hpp"

namespace clay::recipe::detail {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

inline std::string format(const char* fmt, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

/// Runs a library builder, rewording its error in the recipe's keys: the command and recipes name
/// recipe keys, never the C++ option that holds them (`words` maps one to the other).
using Words = std::vector<std::pair<std::string_view, std::string_view>>;

template <class F>
auto in_recipe_words(const Words& words, F&& build) {
  try {
    return build();
  } catch (const clay::Error& e) {
    std::string m = e.message();
    for (const auto& [cpp, key] : words)
      for (auto at = m.find(cpp); at != std::string::npos; at = m.find(cpp, at + key.size()))
        m.replace(at, cpp.size(), key);
    throw clay::Error(e.category(), m);
  }
}

/// `m` with every "WORD #k" replaced by WORD "names[k]" (a builder's "curve #1" in the recipe's
/// names).
std::string named(std::string m, const std::vector<std::string>& names, const std::string& word);

/// A built surface's figures and message (degrees, control points, rational, exact, deviation).
void build_figures(const surface::BuildReport& b, StepReport& rep);

/// Why a step is light, in the recipe's words: the exact size against the budget.
std::string light_reason(const deform::StepOutcome& o, const Composition& c);

/// A style step's figures (docs/recipe.md, report): its mode, class, key points, deviations,
/// curvature, boundary figures and sizes.
void style_figures(const deform::StyleResult& r, StepReport& rep);

/// A style step as a run makes it (run_style.cpp): the style of `parent` toward `target` inside
/// `bound` (null: the target's support band), its figures, message and warnings in `rep`. A drag
/// update (options.preview) styles on the first net, and with a bound and options.cache from a
/// StyleEditor kept there without the sampled figures; `previewed` then says the release must
/// style again. Throws ToleranceNotMet when the target is missed and the step does not accept it.
struct StyleStep {
  surface::BSplineSurface surface;
  bool previewed = false;
};
StyleStep style_step(const StyleDef& d, const surface::BSplineSurface& parent,
                     const surface::BSplineCurve* bound, const surface::BSplineCurve& target,
                     const RunOptions& options, StepReport& rep);

/// The composition's settings as deform_surface's (the Runner and deform_model use them).
deform::SurfaceDeformationOptions deformation_options(const Composition& c);
/// A refit of a composition without a budget: its degree, tolerance and max_control_points,
/// keeping the input's breakpoints.
deform::RefitOptions fit_keeping_breakpoints(const Composition& c);
/// The light form's fit of a composition: its degree and tolerance, from the input's rough
/// breakpoints (deform::Budget::light_fit), within the budget's and max_control_points' nets.
deform::RefitOptions light_fit(const Composition& c);
/// The sides `parent` shares with `surfaces` (deform::shared_boundaries, within 1e-9 of its
/// size), when a fit may be made of it (a refit or a budget) and the composition matches edges
/// ("edges" not "none"): each surface is fitted alone, so two built to meet (fills on one
/// boundary curve, mirrored halves) keep meeting only if both follow their shared sides.
std::vector<deform::MatchedCurve> shared_sides(
    const surface::BSplineSurface& parent,
    const std::vector<std::pair<std::string, surface::BSplineSurface>>& surfaces,
    const Composition& c);
/// `o` following `shared` within the composition's edge figures (nothing when it is empty).
void follow_shared(deform::RefitOptions& o, const std::vector<deform::MatchedCurve>& shared,
                   const Composition& c);
/// A lattice step's figures: fold_free and the Jacobian's volume ratio bounds, and a warning
/// when it may fold.
void lattice_figures(const deform::Deformation& d, StepReport& rep);

/// A recipe stroke fitted (sketch::fit_stroke, run_stroke.cpp): its curve, or its pieces NAME.1 ..
/// NAME.N, with the step's figures and message in `rep`. clay::Error when the fit gives another
/// number of curves than its "pieces" asks, or misses its tolerance without
/// "accept_out_of_tolerance" (then kept, with a warning). Fitted through `cache` when given
/// (RunCache::fit_stroke: a stroke the studio asked about is not fitted again).
std::vector<std::pair<std::string, surface::BSplineCurve>> stroke_curves(const StrokeDef& s,
                                                                         StepReport& rep,
                                                                         RunCache* cache);

/// The recipe's deformation stack named `deformation`, or its only one when the name is empty.
const StackDef& pick_stack(const RecipeData& d, std::string_view deformation);

/// One of the recipe's models: imported, flattened, and deformed when it names a stack, for
/// `profile` (RunOptions::profile) when given, else for its own "profile", if any.
ModelRunResult run_model(const RecipeData& d, const ModelDef& def, const std::string& profile);

// ---- what an earlier run gives (RunOptions::previous; run_reuse.cpp) -------------------------

/// True when the surface needs one of the `changed` deformations, or a surface `previous` only
/// previewed, through its deform, the surfaces and the curves it is built from. `memo` keeps the
/// answers by surface name for one run.
bool needs_changed(const RecipeData& d, const RunResult& previous,
                   const std::vector<std::string>& changed, const std::string& surface,
                   std::map<std::string, bool>& memo);

/// Appends the surface `previous` made for `def` to `into`, with its step reports (each passed
/// to `progress` when set), its stages and its bound (into `bounds`); false when `previous` has
/// no such surface.
bool take_surface(const RunResult& previous, const SurfaceDef& def, RunResult& into,
                  std::map<std::string, double>& bounds,
                  const std::function<void(const StepReport&)>& progress);

/// A lattice step's light net for a drag preview, and the map that gave it (null when fitted at
/// once).
struct PreviewLight {
  surface::BSplineSurface net;
  std::shared_ptr<const deform::LatticeLightMap> map;  ///< kept for the next update of the drag
};

/// The light net of a lattice step for a drag preview, on the knots of the light form `previous`
/// gave the step: by `previous`'s map when it applies (deform::applies_to); by a new map when the
/// step's input is the one `previous` deformed (the lattice is dragged); fitted at once otherwise
/// (the input is dragged: deform::light_fit). Empty when the deformation is not a Bézier or
/// B-spline lattice or the step was neither a light form nor a refit.
std::optional<PreviewLight> preview_light(const RunResult& previous, const deform::Deformation& d,
                                          const surface::BSplineSurface& s,
                                          const std::string& step);

/// The figures and message of a step previewed by its light map: light, preview, not
/// certified, the bound ledger unbounded until the release.
void preview_figures(const surface::BSplineSurface& net, StepReport& rep);

}  // namespace clay::recipe::detail
