#pragma once
/// The whole of Clayform in one include: the NURBS core and exchange (clay/surface.hpp), sketches
/// and the constraint solver (clay/constraints.hpp, with clay/sketch.hpp), deformations
/// (clay/deform.hpp) and recipes (clay/recipe/recipe.hpp), with clay/version.hpp. Link
/// Clayform::recipe, which brings every library. Include the module headers instead to depend on
/// less.
#include <clay/constraints.hpp>
#include <clay/deform.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/surface.hpp>
#include <clay/version.hpp>
