#pragma once
// The OpenCASCADE shapes of a brep::Model and the XCAF document holding them (model_write.cpp),
// shared by the STEP and IGES writer and the mesher and glTF writer (model_mesh.cpp).
#include <clay/brep/model.hpp>
#include <clay/occt/model_exchange.hpp>

#include <filesystem>

#include <vector>

#include <STEPControl_Writer.hxx>
#include <TDocStd_Document.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Vertex.hxx>

namespace clay::brep {

/// The OCCT shapes of a model: vertices, edges and faces shared as in the model, one shape per
/// body (a solid, a shell or a compound of shells, a compound of loose faces).
struct Shapes {
  std::vector<TopoDS_Vertex> vertices;
  std::vector<TopoDS_Edge> edges;
  std::vector<TopoDS_Face> faces;  // forward
  std::vector<TopoDS_Shape> bodies;
};

/// Builds the shapes from the model's data, exactly (every surface, curve and pcurve copied;
/// planes written as planes). Validates the model first (clay::Error(InvalidGeometry)).
Shapes build_shapes(const Model& m);

/// Fills an XCAF document with the shapes, the names, colours and the assembly tree.
void fill_document(const Model& m, const Shapes& s, const Handle(TDocStd_Document) & document);

/// After `writer` has translated the shapes: a face's loop that is only its seam (and poles),
/// beside other loops, is written as the seam's EDGE_LOOP instead of OpenCASCADE's VERTEX_LOOP,
/// which its reader drops when the face has other bounds (model_write_seams.cpp). Throws
/// clay::Error(Exchange) naming the face when it cannot.
void write_seam_loops(const Model& m, const Shapes& s, STEPControl_Writer& writer);

/// Meshes the shapes (tessellate()'s mesh) and writes the document as a binary glTF, atomically.
void write_glb(const Model& m, const Shapes& shapes, const std::filesystem::path& file,
               const MeshOptions& options, const Handle(TDocStd_Document) & document);

}  // namespace clay::brep
