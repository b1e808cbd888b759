#pragma once
/// Umbrella header of the surface module: NURBS value types, evaluation, knot operations, degree
/// elevation, projection, self-intersection of curves, parent-surface builders (fill, loft, sweep,
/// revolve, primitives) and STEP/IGES/glTF exchange.
#include <clay/error.hpp>
#include <clay/summary.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/build_report.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/exchange.hpp>
#include <clay/surface/fill.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/primitives.hpp>
#include <clay/surface/projection.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/self_intersection.hpp>
#include <clay/surface/skin.hpp>
#include <clay/surface/tessellate.hpp>
#include <clay/tolerance.hpp>
