#pragma once
// The one JSON form of a step's report (docs/recipe.md "report.json"), shared by report.json,
// the view's manifest and, through step_reports_json(), the studio's replies.
#include <clay/recipe/recipe.hpp>

#include <nlohmann/json.hpp>

namespace clay::recipe::detail {

using ReportJson = nlohmann::ordered_json;

/// A figure as JSON: true/false, an integer, a number or a string.
ReportJson figure_json(const Figure& figure);

/// A step's figures as one object, in their fixed order; {} for no step.
ReportJson figures_json(const StepReport* step);

/// A step: {path, kind, seconds, warning, message, figures}.
ReportJson step_json(const StepReport& step);

}  // namespace clay::recipe::detail
