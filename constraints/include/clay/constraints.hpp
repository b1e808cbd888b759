#pragma once
/// Umbrella header of the constraints module: constraint types and the solver with its
/// degrees-of-freedom and redundancy/conflict diagnosis.
#include <clay/constraints/constraint.hpp>
#include <clay/constraints/solve.hpp>
#include <clay/sketch.hpp>
