#pragma once
/// Umbrella header of the sketch module: sketch planes, strokes and stroke fitting.
/// The module builds on clay/surface.
#include <clay/surface.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/sketch/stroke.hpp>
