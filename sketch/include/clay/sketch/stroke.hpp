#pragma once
/// Stroke — what a stylist draws: a 3D polyline in the order it was drawn, optionally tied to a
/// sketch plane.
///
/// A stroke is raw input: noisy, densely sampled, possibly with corners. fit_stroke()
/// (clay/sketch/fit.hpp) turns it into B-spline curves; oversketch() (clay/sketch/oversketch.hpp)
/// uses one to redraw part of a curve.
#include <clay/sketch/export.hpp>
#include <clay/sketch/plane.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace clay::sketch {

/// Points of a stroke, one row per point (x, y, z in millimetres) in drawing order.
using Points3 = surface::Points3;

/// A drawn polyline. With a plane, the points are projected onto it before fitting and the fitted
/// curves lie in the plane (to rounding).
struct Stroke {
  Points3 points;                    ///< N x 3, drawing order
  std::optional<SketchPlane> plane;  ///< sketch plane, when the stroke was drawn on one
};

/// Every reason the stroke cannot be fitted, in words, each naming `name` and the point index:
/// fewer than 2 points, a non-finite coordinate, two consecutive points at the same place
/// (closer than 1e-12 of the stroke's size, after projection onto the plane when there is one;
/// not reported when `allow_duplicates`), a stroke of zero length, an invalid plane. Empty when
/// the stroke can be fitted.
CLAY_SKETCH_API std::vector<std::string> problems(const Stroke& stroke,
                                                  std::string_view name = "stroke",
                                                  bool allow_duplicates = false);

/// Throws clay::Error(InvalidGeometry) listing problems(stroke, name, allow_duplicates).
CLAY_SKETCH_API void validate(const Stroke& stroke, std::string_view name = "stroke",
                              bool allow_duplicates = false);

/// Length of the polyline (mm), after projection onto the plane when there is one.
CLAY_SKETCH_API double length(const Stroke& stroke);

}  // namespace clay::sketch
