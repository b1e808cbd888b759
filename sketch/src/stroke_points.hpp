#pragma once
// Stroke points as the fitters see them (internal).
#include <clay/sketch/stroke.hpp>

namespace clay::sketch::detail {

/// The stroke's points, or their plane coordinates (x, y, 0) when it has a plane.
Points3 working_points(const Stroke& stroke);

/// Two consecutive points closer than this (1e-12 of the size of `points`) are one point.
double duplicate_distance(const Points3& points);

/// True when the points span no more than rounding (1e-12 of their magnitude).
bool zero_length(const Points3& points);

}  // namespace clay::sketch::detail
