#pragma once
/// Umbrella header of the surface module: NURBS value types, evaluation, knot operations, degree
/// elevation, projection, self-intersection of curves, the parent-surface builders that need no
/// OpenCASCADE (loft, sweep, revolve, primitives). Exchange and the fills are the OCCT library's
/// (clay/occt.hpp).
#include <clay/error.hpp>
#include <clay/summary.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/build_report.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/primitives.hpp>
#include <clay/surface/projection.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/self_intersection.hpp>
#include <clay/surface/skin.hpp>
#include <clay/surface/tessellate.hpp>
#include <clay/tolerance.hpp>
