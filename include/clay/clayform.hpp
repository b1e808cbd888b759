#pragma once
/// The whole of Clayform in one include: the NURBS core (clay/surface.hpp), B-rep models
/// (clay/brep.hpp), exchange and the OCCT-backed builders (clay/occt.hpp), sketches and the
/// constraint solver (clay/constraints.hpp, with clay/sketch.hpp), deformations (clay/deform.hpp),
/// recipes (clay/recipe/recipe.hpp) and pictures (clay/render/render.hpp), with clay/version.hpp.
/// It belongs to no module: link Clayform::all, which brings every library. Include the module
/// headers instead to depend on less.
#include <clay/brep.hpp>
#include <clay/constraints.hpp>
#include <clay/deform.hpp>
#include <clay/occt.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/render/render.hpp>
#include <clay/surface.hpp>
#include <clay/version.hpp>
