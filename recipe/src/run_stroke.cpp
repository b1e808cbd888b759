// A recipe's stroke as a run fits it (sketch::fit_stroke): its curve or its pieces, the step's
// figures, and the failures the recipe's settings name (recipe_run.hpp).
#include <clay/error.hpp>
#include <clay/sketch/fit.hpp>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "recipe_run.hpp"

namespace clay::recipe::detail {

std::vector<std::pair<std::string, surface::BSplineCurve>> stroke_curves(const StrokeDef& s,
                                                                         StepReport& rep,
                                                                         RunCache* cache) {
  const sketch::StrokeFit fit =
      cache ? cache->fit_stroke(s.stroke, s.fit) : sketch::fit_stroke(s.stroke, s.fit);
  const std::size_t wanted = s.pieces == 0 ? 1 : static_cast<std::size_t>(s.pieces);
  if (fit.curves.size() != wanted) {
    const std::string found = std::to_string(fit.curves.size());
    throw Error(ErrorCategory::InvalidGeometry,
                s.pieces == 0
                    ? "the stroke was fitted with " + found +
                          " curves; a recipe stroke without \"pieces\" gives one curve: draw "
                          "it as separate strokes"
                    : "the stroke turns by more than " + format("%g", s.fit.corner_angle) +
                          " degrees at " + std::to_string(fit.corners.size()) +
                          " corners, so it gives " + found + " curves, not " +
                          std::to_string(s.pieces) + ": set \"pieces\": " + found + " (curves " +
                          piece_name(s.name, 1) + " .. " +
                          piece_name(s.name, static_cast<int>(fit.curves.size())) +
                          "), change \"corner_angle\", or draw it again");
  }
  long long control_points = 0;
  double rms = 0;
  for (const auto& c : fit.curves) {
    control_points += c.control_points;
    rms = std::max(rms, c.rms_deviation_mm);
  }
  rep.figures = {{"control_points", control_points},
                 {"max_deviation_mm", fit.max_deviation_mm},
                 {"rms_deviation_mm", rms},
                 {"closed", fit.closed}};
  if (s.pieces > 0) {
    rep.figures.emplace_back("pieces", static_cast<long long>(fit.curves.size()));
    rep.figures.emplace_back("corners", static_cast<long long>(fit.corners.size()));
  }
  rep.message = fit.summary.brief();
  if (!fit.summary.converged()) {  // a fit that misses its tolerance is a failure unless accepted
    if (!s.accept_out_of_tolerance)
      throw Error(ErrorCategory::ToleranceNotMet,
                  "the fit misses its tolerance (" + fit.summary.brief() +
                      "): raise the stroke's \"tolerance_mm\" or its \"degree\", or draw it again; "
                      "to keep the fit "
                      "anyway, set \"accept_out_of_tolerance\": true on the stroke");
    rep.warning = true;
  }
  std::vector<std::pair<std::string, surface::BSplineCurve>> out;
  if (s.pieces == 0) {
    out.emplace_back(s.name, fit.curves.front().curve);
    return out;
  }
  for (std::size_t k = 0; k < fit.curves.size(); ++k)
    out.emplace_back(piece_name(s.name, static_cast<int>(k + 1)), fit.curves[k].curve);
  return out;
}

}  // namespace clay::recipe::detail
