#pragma once
/// Umbrella header of the sketch module: sketch planes and entities (and, with them, strokes and
/// stroke fitting).
#include <clay/sketch/entities.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/surface.hpp>
