#pragma once
/// Umbrella header of the surface module: NURBS value types, evaluation, knot operations, degree
/// elevation, projection and STEP/IGES/glTF exchange.
#include <clay/error.hpp>
#include <clay/summary.hpp>
#include <clay/tolerance.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/exchange.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/projection.hpp>
