#pragma once
/// Umbrella header of the deform module (style deformation, FFD lattices, exact composition).
/// The module builds on clay/constraints; its own topic headers arrive with issues #5-#7.
#include <clay/constraints.hpp>
