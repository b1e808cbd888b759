#pragma once
/// Umbrella header of the sketch module (strokes, stroke fitting, sketch entities).
/// The module builds on clay/surface; its own topic headers arrive with issue #3.
#include <clay/surface.hpp>
