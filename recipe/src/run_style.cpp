// A recipe's style step (Han, De Amicis & Conti; clay/deform/style.hpp) as a run makes it: the
// settings a drag update uses, the style, its figures and what it warns of (recipe_run.hpp).
#include <clay/internal/format.hpp>

#include <cmath>
#include <string>

#include "recipe_run.hpp"
#include "run_cache.hpp"

namespace clay::recipe::detail {

StyleStep style_step(const StyleDef& d, const surface::BSplineSurface& parent,
                     const surface::BSplineCurve* bound, const surface::BSplineCurve& target,
                     const RunOptions& options, StepReport& rep) {
  deform::StyleOptions o = d.options;
  StyleStep out;
  const bool first_net_only = options.preview && o.net_convergence > 0;
  if (first_net_only) {
    // A drag update previews the style on its first net (tenths of a second where the
    // convergence rounds take seconds); the release builds it again with them, since a
    // previewed surface is never kept.
    o.net_convergence = 0;
    out.previewed = true;
  }
  // A drag update of the target (a preview, with a cache to keep it in) goes to a kept
  // StyleEditor: the region, the projector and the exact nets' factorizations are made once
  // per drag, not per update. Previewed, so the release styles once more from scratch.
  const bool from_editor = options.preview && options.cache && bound;
  if (from_editor) {
    out.previewed = true;
    o.report_curves = false;  // the sampled figures (global closest points) wait for the release
  }
  const deform::StyleResult r =
      from_editor ? CacheAccess::style_editor(*options.cache, parent, *bound, o)->update(target)
      : bound     ? deform::style_deform(parent, *bound, target, o)
                  : deform::style_deform(parent, target, o);
  const deform::StyleReport& x = r.report;
  style_figures(r, rep);
  rep.message += ": " + x.message;
  if (first_net_only) rep.message += "; a drag's preview on the first net (converged on release)";
  if (from_editor) rep.message += "; a drag's preview from the kept style editor";
  rep.figures.emplace_back("outcome", std::string(x.summary.converged() ? "met" : "missed"));
  if (!x.summary.converged()) {
    if (!d.accept_out_of_tolerance)
      throw Error(ErrorCategory::ToleranceNotMet,
                  x.summary.message +
                      ". Nothing was written; to keep such a result anyway, set "
                      "\"accept_out_of_tolerance\": true on this step");
    rep.warning = true;
    rep.message += "; accepted out of tolerance: " + x.summary.message;
  }
  if (o.net_convergence_best_effort && !first_net_only && !(x.net_change <= o.net_convergence)) {
    // Best effort (the studio's calm default): the finest net's result, said to be short.
    rep.warning = true;
    rep.message += std::isnan(x.net_change)
                       ? std::string("; net convergence not checked: the net could not be halved")
                       : "; net convergence stopped at " + format("%.3g", 100 * x.net_change) +
                             " % (best effort for " + format("%g", 100 * o.net_convergence) +
                             " %: one more halving no longer shrinks the change, or "
                             "max_refinements was used; a target that runs into its bound "
                             "does not converge)";
  }
  if (x.curvature_waves > deform::curvature_waves_calm && !first_net_only) {
    // Rings: not a tolerance missed (the target is met), but a shape the stylist should see.
    rep.warning = true;
    rep.message += "; rings: the change of mean curvature turns " +
                   std::to_string(x.curvature_waves) +
                   " times along one section of the region (a calm push: up to " +
                   std::to_string(deform::curvature_waves_calm) +
                   "); for calmer reflections set \"net_convergence\" (0.05 calmed the "
                   "examples' styles) or \"mode\": \"paper\"";
  }
  out.surface = r.surface;
  return out;
}

}  // namespace clay::recipe::detail
