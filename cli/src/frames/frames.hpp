#pragma once
// The studio's binary geometry frames (clay/studio.hpp, docs/studio.md "Frames"): a model's mesh,
// its faces' nets, a surface's deviation map, and what a mesh depends on. Internal to the
// command's studio.
#include <clay/brep/model.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/recipe/recipe.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace clay::recipe {

/// A model's trimmed mesh: the length and JSON header as in net_frame ({"kind": "mesh", "name",
/// "vertices": n, "triangles": m, "faces"}), then n * 3 float64 positions, n * 3 float64 unit
/// normals, n * 2 float64 (u, v) on each node's face, m * 3 uint32 node indices and n uint32
/// face indices, little-endian.
std::vector<std::uint8_t> mesh_frame(const std::string& header_json, const brep::ModelMesh& mesh);

/// A model's faces as nets, one frame: {"kind": "model_nets", "name", "faces": [...]}, then each
/// face's points and weights in turn (sent instead of a mesh while its topology holds).
std::vector<std::uint8_t> model_nets_frame(const std::string& name, const brep::Model& model);

/// The viewer's deviation map of a surface on a rows x cols grid: the distance from the surface
/// to its last stage's pointwise deformation of the surface before it.
std::vector<std::uint8_t> deviation_frame(const std::string& name, const surface::BSplineSurface& s,
                                          const Stage& stage, int rows, int cols);

/// A frame's content (FNV-1a, 64 bits): a run's reply leaves out a frame the page already holds.
std::uint64_t frame_key(const std::vector<std::uint8_t>& frame);

/// What a model's mesh depends on besides its faces' control points (FNV-1a, 64 bits).
std::uint64_t topology_key(const brep::Model& model);

}  // namespace clay::recipe
