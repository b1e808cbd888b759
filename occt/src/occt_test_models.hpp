#pragma once
// Whole B-rep models built by OpenCASCADE and written as STEP or IGES, and OpenCASCADE's own
// reading of such files, behind an OCCT-free interface (internal to tests and benchmarks, in
// clay_occt_reference). The tests of model reading and deformation compare with these.
#include <Eigen/Core>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace clay::surface::occt_reference {

/// The test models (issue #20's "Must show").
enum class TestModel {
  FilletedBlock,  ///< 60 x 40 x 20 box, vertical edges filleted (r 5), two through holes, a pocket
  Sphere,         ///< r 10: a seam and two poles
  Torus,          ///< R 20, r 5: seams in both directions
  Cone,           ///< r 10 to 4, height 15: a seam, a plane at each end
  Bottle,         ///< a revolved profile (lines and an arc), hollow: a solid with a void-free shell
  LabelBottle,    ///< the bottle with an embossed label band (r 16, z 14..30, named "label")
  Assembly,       ///< two parts, named and coloured; the second placed twice
  LooseFaces,     ///< a box's six faces written as loose IGES faces (144), to be sewn
  Separated,      ///< two solids apart: a box 20^3 at the origin, a sphere r 5 at (50, 10, 10)
  HolePlate,      ///< 200 faces: a 200 x 200 x 10 plate, vertical edges filleted (r 8), 190 holes
  ObliqueCut,     ///< a cylinder r 10 cut by a plane at 30 degrees: an ellipse across the angles
  OffsetSheet,    ///< one face: a bicubic bump 40 x 30 offset by 2 mm (STEP offset_surface)
  LoftWithHoles,  ///< a ruled loft through a circle r 20 (z 0), an ellipse 30 x 15 (z 30) and a
                  ///< circle r 12 (z 60), cut by two cylinders r 4 across it at 45 degrees (z 15
                  ///< and 45): B-spline side faces with four trimmed holes (Boolean rims)
  TurnedSeams,    ///< four loose full-turn faces whose seams are off u = 0: a cylinder (r 3.5,
                  ///< u from pi/2), a cone (u from 1), a sphere (r 5, u from -pi/2) and a torus
                  ///< (R 10, r 3, u from pi/2), as MicroStation and HiCAD write holes
};

/// Builds `model` with OpenCASCADE and writes it through XCAF (names, colours, assembly) as
/// STEP AP214 or, for a .igs/.iges path, IGES 5.3 (BRep mode, except LooseFaces).
void write_test_model(TestModel model, const std::filesystem::path& file);

/// What OpenCASCADE itself reads from a file (STEPControl_Reader / IGESControl_Reader).
struct ShapeFacts {
  int solids = 0, shells = 0, faces = 0, edges = 0, vertices = 0;
  double volume = 0;   ///< BRepGProp::VolumeProperties with Eps 1e-9 (0 without solids)
  double area = 0;     ///< BRepGProp::SurfaceProperties of each distinct face, Eps 1e-10
  bool valid = false;  ///< BRepCheck_Analyzer
  /// Faces per surface type (BRepAdaptor_Surface::GetType), distinct faces.
  int planes = 0, cylinders = 0, cones = 0, spheres = 0, tori = 0, other_surfaces = 0;
};

/// OpenCASCADE's counts (distinct sub-shapes), volume and validity of the shapes in `file`.
ShapeFacts facts_of_file(const std::filesystem::path& file);

/// For each face of `file` (TopExp_Explorer order) and each of its points in `points[face]`,
/// the distance to that face's surface (GeomAPI_ProjectPointOnSurf); the largest overall.
double max_distance_to_surfaces(const std::filesystem::path& file,
                                const std::vector<std::vector<Eigen::Vector3d>>& points);

/// For each edge of `file` (TopExp_Explorer order, distinct edges) and each parameter in
/// `parameters[edge]`, the point OpenCASCADE evaluates on that edge's 3D curve
/// (BRep_Adaptor_Curve, the edge's own parametrization and location).
std::vector<std::vector<Eigen::Vector3d>> edge_points(
    const std::filesystem::path& file, const std::vector<std::vector<double>>& parameters);

/// OpenCASCADE's own affine map of a whole shape, the reference of bench/model_bench.cpp: the
/// file's shape is read once (STEPControl_Reader); transform() runs BRepBuilderAPI_GTransform.
class GTransformReference {
 public:
  explicit GTransformReference(const std::filesystem::path& file);
  ~GTransformReference();
  GTransformReference(const GTransformReference&) = delete;
  GTransformReference& operator=(const GTransformReference&) = delete;
  /// The shape mapped by x -> A x + b (`affine` = [A | b]) with copies of its geometry; returns
  /// the face count of the result.
  int transform(const Eigen::Matrix<double, 3, 4>& affine) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clay::surface::occt_reference
