#pragma once
// The one JSON form of a step's report (docs/recipe.md "report.json"), shared by report.json,
// the view's manifest and, through step_reports_json(), the studio's replies.
#include <clay/brep/continuity.hpp>
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

/// How a model's faces meet, before and after its deformation, per shared edge (report.json's
/// "model.continuity" and the view's model entries; docs/recipe.md "Outputs"): the worst
/// figures, and per edge its gap, normal angle and curvature jumps, its figures before, and the
/// class the source had there ("G2": tangent within 1 deg and a relative curvature jump <= 5 %,
/// "G1": tangent, "G0": sharp), which is what a refit keeps (deform::ModelDeformationOptions).
ReportJson continuity_json(const brep::ContinuityReport& before,
                           const brep::ContinuityReport& after);

}  // namespace clay::recipe::detail
