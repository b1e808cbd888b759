#pragma once
/// Umbrella header of the constraints module (geometric constraint solver).
/// The module builds on clay/sketch; its own topic headers arrive with issue #3.
#include <clay/sketch.hpp>
