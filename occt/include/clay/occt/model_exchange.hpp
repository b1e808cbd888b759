#pragma once
/// Reading and writing whole B-rep models (trimmed faces, shared edges, solids, assemblies,
/// names, colours) as STEP and IGES files, and OpenCASCADE's checks of them (issue #20).
///
/// Implemented in the OCCT library (Clayform::occt, through OpenCASCADE's XCAF readers); this
/// header carries no OpenCASCADE type.
///
/// Every face becomes a NURBS face. B-spline and Bézier faces are kept as they are, with their
/// pcurves. Planes, linear extrusions and offsets by 0 keep their parametrization when converted,
/// so their pcurves convert exactly. Cylinders, cones, spheres, tori and revolutions become
/// rational B-splines whose parameter equals the angle only at knots: each of their pcurves is
/// re-derived. It is exact where the composed parameter map is (an iso-line, or a conic on a plane
/// converted with the same angle map as its edge); otherwise it is a cubic interpolant refined
/// until the face along it is within 1e-10 × model size of the original face along the original
/// pcurve. The report says how many pcurves took each path and the largest re-derivation error,
/// and brep::edge_gaps measures the result independently.
#include <clay/brep/mesh.hpp>
#include <clay/brep/model.hpp>
#include <clay/occt/export.hpp>
#include <clay/occt/surface_exchange.hpp>

#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace clay::brep {

/// What OpenCASCADE's BRep format does not hold and an embedding CAD system keeps beside its
/// shape (FreeCAD: a document object's label, its ShapeColor and its faces' DiffuseColor). Faces
/// are numbered from 0 as TopExp::MapShapes numbers the shape's faces, which is the order of
/// FreeCAD's Shape.Faces.
struct CLAY_OCCT_API BrepAttributes {
  std::string name;              ///< the shape's name: its body's, when it holds one body
  std::optional<Colour> colour;  ///< the shape's colour: its body's, when it holds one body
  /// Empty, or one entry per face (none: the face takes the body's colour).
  std::vector<std::optional<Colour>> face_colours;
  /// Empty, or one entry per face ("": unnamed).
  std::vector<std::string> face_names;

  /// Every bad field (a colour outside [0, 1] or not finite), naming it; empty when valid.
  std::vector<std::string> problems() const;
};

/// Settings of read_model.
struct CLAY_OCCT_API ModelReadOptions {
  /// Sew loose faces (IGES 144 files, STEP shells exported face by face) into shells, and closed
  /// shells into solids (BRepBuilderAPI_Sewing, then ShapeFix_Solid).
  bool sew = false;
  /// Largest gap sewing closes (mm), in (0, 1].
  double sewing_tolerance_mm = 1e-3;
  /// The text pre-check and the isolated read (a child process under time and memory limits)
  /// of surface::ReadOptions: a file that crashes or hangs OpenCASCADE becomes
  /// clay::Error(Exchange). When only OpenCASCADE's XCAF reader crashes, an isolated read tries
  /// its plain reader in a second child (no names, colours or assembly tree; the report's
  /// healing says so). The `clayform` command reads every model isolated.
  surface::ReadOptions read;
  /// The reader before issue #39's healing: pcurves that leave their surface's domain are not
  /// pulled in, tolerances are not set to gaps wider than 1.5 times a file's own tolerance (or
  /// 1e-4 of the model's size), and a hole taken for the outer loop stays first: problems()
  /// names each, and the report lists them, as for a broken file.
  bool strict = false;
  /// A .brep file only: the names and colours to put on what it holds (a STEP or IGES file
  /// carries its own: giving any for one is refused). The face lists must be empty or hold one
  /// entry per face of the file, else clay::Error(InvalidArgument) says how many it has.
  BrepAttributes brep;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// What a read found and did.
struct CLAY_OCCT_API ModelReadReport {
  Counts counts;
  double size_mm = 0;     ///< diagonal of the model's bounding box (control points of its surfaces)
  int faces_bspline = 0;  ///< faces whose surface was a B-spline or Bézier: kept as they were
  int faces_affine = 0;   ///< planes, linear extrusions: converted with the same (u, v)
  int faces_angular = 0;  ///< cylinders, cones, spheres, tori, revolutions: angle maps changed
  /// Offsets (by a distance other than 0) of surfaces with no exact NURBS form: approximated on
  /// their own (u, v), the edges' tolerances widened by the approximation's measured error.
  int faces_approximated = 0;
  /// Largest distance between an approximated face and its offset surface, measured on a dense
  /// grid of the face's parameter box (mm); 0 when no face was approximated.
  double max_approximation_error_mm = 0;
  int pcurves_kept = 0;    ///< pcurves converted exactly with their face's unchanged (u, v)
  int pcurves_exact = 0;   ///< re-derived exactly (an iso-line or a shared angle map)
  int pcurves_fitted = 0;  ///< re-derived by a refined interpolant
  /// Largest distance between the face along a re-derived pcurve and the original face along the
  /// original pcurve (mm); 0 when every pcurve was kept or re-derived exactly.
  double max_rederivation_error_mm = 0;
  /// Largest gap between an edge and a face along its pcurve, by brep::edge_gaps (mm): includes
  /// the file's own gaps, which its edge tolerances allow.
  double max_edge_gap_mm = 0;
  /// The largest edge tolerance of the model read: the file's, widened for approximated offset
  /// faces and raised to measured gaps where `healing` says so.
  double max_edge_tolerance_mm = 0;
  /// Healing done, one line each ("built 3D curves of 4 edges", "sewed 12 faces into 1 shell").
  std::vector<std::string> healing;
  /// Entities of the file OpenCASCADE does not know and ignored, one line per type:
  /// "FOO_BAR x 3 (the first #999)" (STEP) or "entity type 999 x 2 (the first D17)" (IGES).
  std::vector<std::string> ignored;
  /// Entities OpenCASCADE failed to transfer and left out (with what it built on them), one line
  /// each: "#73 CYLINDRICAL_SURFACE: <OpenCASCADE's failure>". The rest of the file is read; a
  /// file none of whose shapes transfer is refused, naming the first.
  std::vector<std::string> skipped;
  /// Shapes OpenCASCADE read that a model cannot hold, one line each, naming the shape and why:
  /// an unbounded line (OpenCASCADE's range +-2e100: no extent to deform or write back), free
  /// points. A file whose shapes are all left out is read as an empty model with these lines.
  std::vector<std::string> left_out;
  /// brep::problems(model): invariants the model breaks (empty for a clean file). The model is
  /// still returned, so that it can be inspected; deforming it refuses it.
  std::vector<std::string> problems;
  /// A .brep read only: for each face of the model, its index (from 0) among the text's faces as
  /// TopExp::MapShapes numbers them (FreeCAD's Shape.Faces). The model numbers its faces solids
  /// first and holds a face two solids share twice, so the two orders can differ. Empty for STEP
  /// and IGES.
  std::vector<int> brep_faces;

  /// One line: "1 solid, 1 shell, 42 faces (18 trimmed, 6 holes), 104 edges, 66 vertices;
  /// 30 faces converted; pcurves 160 kept, 40 exact, 8 fitted (<= 3e-12 mm); edge gap 1e-7 mm".
  std::string brief() const;
};

/// A model and the report of its reading.
struct ImportedModel {
  Model model;
  ModelReadReport report;
};

/// Reads a STEP (.step, .stp), IGES (.iges, .igs) or OpenCASCADE BRep (.brep, .brp) file, chosen
/// by its extension, into a model (a BRep file holds no names or colours: ModelReadOptions::brep
/// gives them):
/// solids, shells and loose faces become bodies, and free curves wire bodies (a body per free
/// wire, one for the loose edges; unbounded curves are left out, named in the report); an assembly
/// becomes parts and instances with their placements; names and colours of parts, bodies and faces
/// are kept. Throws clay::Error(Io) when the file is missing or cannot be opened, Exchange when it
/// cannot be parsed, fails the pre-check, holds no face or curve, or holds geometry that cannot be
/// converted (naming the face or edge and what failed), InvalidGeometry for a surface or curve with
/// non-finite coordinates or weights that no exact reparametrization makes positive (naming the
/// face), InvalidArgument for bad options or an unknown extension.
CLAY_OCCT_API ImportedModel read_model(const std::filesystem::path& file,
                                       const ModelReadOptions& options = {});

/// Meshes every face of `model` within its loops by OpenCASCADE's mesher (BRepMesh_Incremental
/// Mesh) on the shapes check_model builds, shared edges discretized once, so neighbouring faces
/// meet without cracks. Normals are the faces' exact normals (S_u × S_v of the NURBS at each
/// node's (u, v), turned for reversed faces; at a pole, the mean of the triangles around it).
/// Throws clay::Error as check_model, InvalidArgument for bad options, Exchange naming the face
/// when the mesher leaves a face without triangles.
CLAY_OCCT_API ModelMesh tessellate(const Model& model, const MeshOptions& options = {});

/// Settings of write_model.
struct ModelWriteOptions {
  surface::StepSchema schema = surface::StepSchema::AP214;  ///< STEP only
  MeshOptions mesh;  ///< .glb only: how finely the faces are meshed
  /// Run check_model's BRepCheck and volumes on the shapes written (about half the time of a
  /// write of a 200-face solid); false: the returned check says it was not run.
  bool check = true;
};

/// What OpenCASCADE makes of a model: its validity (BRepCheck_Analyzer on the shapes built from
/// it, with the model's own tolerances) and the volume of its solids.
struct CLAY_OCCT_API ModelCheck {
  bool checked = true;  ///< false: write_model was asked not to check (the rest is empty)
  bool valid = false;
  /// BRepCheck findings in words, each naming the body and face ("body 0 face 3: ...").
  std::vector<std::string> problems;
  /// Volume of the solids (mm^3) by brep::volume_mm3 (Green's theorem on the trimmed faces, to
  /// about 1e-13); instances count once each.
  double volume_mm3 = 0;
  /// The same by OpenCASCADE (BRepGProp::VolumeProperties with precision 1e-9), for comparison:
  /// about 2e-7 off on rational spheres and tori, 0.03 % with its default precision.
  double occt_volume_mm3 = 0;
  /// One line: "valid (BRepCheck), volume 45123.7 mm^3" or "NOT valid: 2 problems, the first: ...".
  std::string brief() const;
};

/// Builds OpenCASCADE shapes from `model` (exactly: every surface, curve and pcurve copied) and
/// checks them. Throws clay::Error(InvalidGeometry) listing problems(model) when the model
/// breaks an invariant, DegreeLimit above degree 25.
CLAY_OCCT_API ModelCheck check_model(const Model& model);

/// Writes `model` as STEP (.step, .stp: AP214 or AP242), IGES 5.3 (.iges, .igs: solids and
/// shells as 186/514 B-rep entities when the model has a solid, otherwise trimmed surfaces 144),
/// chosen by the extension, with the names, colours and assembly tree (IGES: OpenCASCADE's
/// translator has no assemblies, so an assembly is written flattened(), each placed instance a
/// named, coloured body), or a binary glTF preview (.glb: the faces meshed as by tessellate(),
/// holes are holes, with the names, colours and assembly tree; in metres, y up, as glTF wants).
/// STEP and IGES are lossless: 17 significant
/// digits, so read_model gives the same surfaces, curves and pcurves bit for bit. Atomic: written
/// to a temporary file and renamed, nothing is left behind on failure. Throws clay::Error as
/// check_model, Io when the file cannot be written, InvalidArgument for an unknown extension,
/// Exchange when OpenCASCADE refuses the model. Returns the check of the shapes written.
CLAY_OCCT_API ModelCheck write_model(const Model& model, const std::filesystem::path& file,
                                     const ModelWriteOptions& options = {});

/// Reads a model from OpenCASCADE's BRep text (BRepTools::Write, FreeCAD's
/// Shape.exportBrepToString) with the names and colours of options.brep, as read_model reads a
/// .brep file (through a private temporary file, so that options.read.isolate can read it in a
/// child process). Throws as read_model; Exchange when the text is not BRep or holds no shape.
CLAY_OCCT_API ImportedModel read_brep(std::string_view text, const ModelReadOptions& options = {});

/// A model as OpenCASCADE's BRep text, with what the text cannot hold.
struct BrepText {
  std::string text;  ///< BRepTools::Write of the bodies (one body: itself; else a compound)
  BrepAttributes attributes;  ///< per face in the written shape's TopExp::MapShapes order
};

/// Writes `model` (an assembly flattened(): each placed instance a body) as OpenCASCADE's BRep
/// text, exactly as write_model builds its shapes, with its names and colours beside it (a face's
/// colour is its own or else its body's). OpenCASCADE writes geometry with 17 significant digits,
/// so read_brep gives the same surfaces, curves and pcurves bit for bit; it writes edge parameter
/// ranges and vertex points with 15 (those come back within 1e-14, relative). Throws
/// clay::Error as check_model.
CLAY_OCCT_API BrepText write_brep(const Model& model);

}  // namespace clay::brep
