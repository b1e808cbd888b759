#pragma once
/// Triangle meshes of whole models as plain data: how finely to mesh (MeshOptions) and the mesh
/// of a model's trimmed faces (ModelMesh). The mesher itself needs OpenCASCADE and lives in the
/// OCCT library (brep::tessellate in clay/occt/model_exchange.hpp); the renderer and the viewer's
/// files only read meshes, so they need this header and not the OCCT library.
#include <clay/brep/export.hpp>
#include <clay/brep/model.hpp>

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace clay::brep {

/// How finely tessellate() and a .glb preview mesh a model's faces. Checked by validate().
struct CLAY_BREP_API MeshOptions {
  /// The largest distance from a triangle to its face OpenCASCADE's mesher aims at, as a fraction
  /// of the model's size (the diagonal of the box of its control points), in [1e-6, 0.1].
  double relative_deflection = 5e-4;
  /// The largest angle, in radians, between the normals at a triangle's corners on a curved face,
  /// in [0.01, 1].
  double angular_deflection_rad = 0.35;

  /// Every bad field, naming it, its value and the range; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems().
  void validate() const;
};

/// Triangles of a model's trimmed faces: holes are holes. Faces are those of flattened(model)
/// (the model's own when it has no assembly), in world coordinates.
struct ModelMesh {
  std::vector<Eigen::Vector3d> positions;     ///< nodes, mm
  std::vector<Eigen::Vector3d> normals;       ///< unit outward normal at each node
  std::vector<Eigen::Vector2d> uv;            ///< each node's (u, v) on its face's NURBS
  std::vector<int> node_face;                 ///< the face each node lies on
  std::vector<std::array<int, 3>> triangles;  ///< node indices, counter-clockwise from outside
  std::vector<int> triangle_face;             ///< the face each triangle lies on
  std::vector<int> face_body;                 ///< the body of each face (-1: in no body)
  /// The colour of each face: its own, else its body's; nullopt when neither has one.
  std::vector<std::optional<Colour>> face_colours;
  /// The largest distance from a triangle's centroid to its face (the NURBS at the mean of the
  /// corners' (u, v)), measured over every triangle: how far the mesh strays from the model.
  double max_deflection_mm = 0;
};

}  // namespace clay::brep
