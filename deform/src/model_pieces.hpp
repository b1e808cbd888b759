#pragma once
// Pieces of a model's deformation shared by deform_model (model_deformation.cpp) and the model
// Jacobian (model_derivatives.cpp). Private to clay_deform.
#include <clay/brep/model.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace clay::deform::detail {

/// True when every point lies strictly on the outer side of one face of the frame's box: the
/// lattice's FFD is the identity on their convex hull.
bool outside(const Frame& frame, const surface::Points3& points);

/// The ruled surface C(t) x [0, 1] whose every v-row is the curve: its composition's row 0 is the
/// curve's composition on the same t.
surface::BSplineSurface ruled(const surface::BSplineCurve& c);

/// Row v = 0 of a surface (control points j = 0): a curve on the surface's u basis.
surface::BSplineCurve row_zero(const surface::BSplineSurface& s);

/// The box [u0, u1, v0, v1] of a trimmed face's pcurves' control points (which holds the
/// pcurves: convex hull property) within its surface's domain, when it is smaller than the
/// domain; nullopt for an untrimmed face or one whose trims span the whole domain.
std::optional<std::array<double, 4>> trims_box(const brep::Face& face);

/// The diagonal of the model's control box (faces and free edges), at least 1e-300.
double size_of(const brep::Model& m);

/// "face 3 (\"top\")": a face named for messages.
std::string face_name(const brep::Model& m, std::size_t f);

/// After a deformation has moved `m` (vertex_touched: the vertices it moved), the tolerances
/// follow the file's own gaps, stretched with the geometry: returns the largest edge gap
/// measured (mm). See the comments in the definition.
double widen_stretched_tolerances(brep::Model& m, const std::vector<bool>& vertex_touched,
                                  double size);

}  // namespace clay::deform::detail
