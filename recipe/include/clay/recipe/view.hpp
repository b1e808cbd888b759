#pragma once
/// The view data of a run (issue #9): grid tessellations of every exported surface and of every
/// deformation stage's before/after, with exact normals, Gaussian and mean curvature and the
/// refit deviation, written as `view/manifest.json` and `view/NNN.bin` for the browser viewer
/// (`clayform view`, docs/recipe.md "Viewing a run").
#include <clay/recipe/export.hpp>
#include <clay/recipe/recipe.hpp>

#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <functional>
#include <vector>

namespace clay::recipe {

/// A grid tessellation: rows x cols vertices, vertex (i, j) at index i * cols + j, u along rows
/// (parameter us[i]) and v along columns (vs[j]); or, for a whole model's trimmed faces, a
/// triangle mesh (rows = cols = 0, `triangles` not empty).
struct ViewMesh {
  int rows = 0, cols = 0;
  std::vector<std::array<int, 3>> triangles;  ///< a model's mesh; empty for a grid
  std::vector<double> us, vs;
  std::vector<Eigen::Vector3d> position;  ///< S(u, v), mm
  std::vector<Eigen::Vector3d>
      normal;  ///< surface::tessellate's: unit S_u x S_v, the limit normal at a pole
  std::vector<double> gaussian;   ///< K, 1/mm^2
  std::vector<double> mean;       ///< H, 1/mm, positive when the surface bends towards its normal
  std::vector<double> deviation;  ///< mm; 0 unless set by set_deviation
  std::vector<char>
      degenerate;  ///< 1 where S_u x S_v vanishes (curvatures are the neighbours' average)
};

/// The grid parameters of one direction: about 8 samples per knot span following the knots, at
/// least 17 and at most 161 in all, ends included.
CLAY_RECIPE_API std::vector<double> view_parameters(const surface::BSplineBasis& basis);

/// The surface as surface::tessellate meshes it (the grid view_parameters(u) x
/// view_parameters(v), its positions and normals, so the viewer, the PNG renderer and the glTF
/// preview shade alike, poles included), with exact curvatures from the first and second
/// derivatives: K = (LN - M^2) / (EG - F^2), H = (EN - 2FM + GL) / (2 (EG - F^2)). Where the
/// surface is degenerate — on a grid line collapsed to less than 1e-3 of the longest line of its
/// direction (a pole, a collapsed edge, or the tiny ring a refit leaves of one, where the
/// formulas blow up), |S_u| or |S_v| below 1e-5 of its largest on the grid, or S_u parallel to
/// S_v — K and H are the average of the non-degenerate neighbouring vertices'. Deviation all 0.
CLAY_RECIPE_API ViewMesh view_mesh(const surface::BSplineSurface& surface);

/// A whole model's trimmed faces as a triangle mesh (brep::tessellate of `model`, holes are
/// holes) with the exact normals and, at every node, the Gaussian and mean curvature of its face's
/// NURBS at the node's (u, v), by the formulas of view_mesh (a degenerate node takes the mean of
/// its non-degenerate neighbours'). Deviation all 0. Throws what brep::tessellate throws.
CLAY_RECIPE_API ViewMesh view_mesh(const brep::Model& model);

/// Sets mesh.deviation to |S(u, v) - map(B(u, v))| at every vertex, with S the tessellated
/// surface (the refit) and B the surface before the step, its domain mapped affinely onto S's.
CLAY_RECIPE_API void set_deviation(
    ViewMesh& mesh, const surface::BSplineSurface& before,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& map);

/// The .bin layout: little-endian float32, attribute after attribute (position 3, normal 3,
/// gaussian 1, mean 1, deviation 1 floats per vertex), 9 floats per vertex; a triangle mesh's file
/// then holds its triangles as little-endian uint32 node indices (3 per triangle, written by
/// write_view_data after these floats).
CLAY_RECIPE_API std::vector<float> view_floats(const ViewMesh& mesh);

/// Writes `dir/view/manifest.json` (format "clayform.view", version 1) and the meshes
/// `dir/view/NNN.bin`: every surface of every export (its final mesh, its control net, the figures
/// of the step that made it) and per enabled deformation step its before/after meshes and nets,
/// the curves it used (200-point polylines) and its figures; a refitted step's `after` carries its
/// deviation from the step's deformation applied pointwise to `before`. Identical meshes share a
/// file. Throws clay::Error(Io) naming the file that cannot be written.
CLAY_RECIPE_API void write_view_data(const RunResult& result, const std::filesystem::path& dir);

}  // namespace clay::recipe
