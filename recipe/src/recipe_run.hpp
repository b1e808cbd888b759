#pragma once
// What the recipe runner's two files share (recipe_run.cpp: the Runner, curves, surfaces and
// exports; recipe_run_models.cpp: whole models and deform_model). Internal to the recipe library.
#include <clay/deform/surface_deformation.hpp>

#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

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

/// The composition's settings as deform_surface's (the Runner and deform_model use them).
deform::SurfaceDeformationOptions deformation_options(const Composition& c);
/// A refit of a composition without a budget: its degree, tolerance and max_control_points,
/// keeping the input's breakpoints.
deform::RefitOptions fit_keeping_breakpoints(const Composition& c);
/// The light form's fit of a composition: its degree and tolerance, from the input's rough
/// breakpoints (deform::Budget::light_fit), within the budget's and max_control_points' nets.
deform::RefitOptions light_fit(const Composition& c);

/// The recipe's deformation stack named `deformation`, or its only one when the name is empty.
const StackDef& pick_stack(const RecipeData& d, std::string_view deformation);

/// One of the recipe's models: imported, flattened, and deformed when it names a stack.
ModelRunResult run_model(const RecipeData& d, const ModelDef& def);

}  // namespace clay::recipe::detail
