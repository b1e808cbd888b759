#pragma once
/// Umbrella header of the sketch module: sketch planes, strokes, stroke fitting and oversketch.
/// The module builds on clay/surface.
#include <clay/surface.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/oversketch.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/sketch/stroke.hpp>
