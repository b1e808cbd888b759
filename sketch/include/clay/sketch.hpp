#pragma once
/// Umbrella header of the sketch module: sketch planes, strokes, stroke fitting, oversketch and
/// sketch entities (points, lines, circles, arcs, B-spline curves). Builds on clay/surface.
#include <clay/sketch/entities.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/oversketch.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/sketch/stroke.hpp>
#include <clay/surface.hpp>
