#pragma once
/// Umbrella header of the sketch module: sketch planes and strokes.
/// The module builds on clay/surface.
#include <clay/surface.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/sketch/stroke.hpp>
