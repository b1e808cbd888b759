#pragma once
/// STEP, IGES and glTF exchange of B-spline surfaces (through OpenCASCADE, kept out of this
/// header).
///
/// Writing is lossless: control points, weights and knots are written with 17 significant digits,
/// so reading a file back gives bit-identical data. Each surface becomes one face bounded by its
/// exact iso-parameter edges. Files are written to a temporary file in the target folder and
/// renamed on success: a failed write leaves no file behind. All exchange calls are serialized
/// internally (OpenCASCADE 7.6's translators are not thread-safe), so they may be called from
/// several threads.
#include <clay/occt/export.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace clay::surface {

/// Largest degree OpenCASCADE (and so our STEP/IGES export) accepts.
inline constexpr int max_exchange_degree = 25;

/// STEP application protocol written.
enum class StepSchema { AP214, AP242 };

/// Settings of write_step.
struct StepWriteOptions {
  StepSchema schema = StepSchema::AP214;  ///< AP214 (automotive design) by default
  std::string product_name = "clayform";  ///< product name written in the file header
};

/// Settings of write_gltf.
struct GltfWriteOptions {
  /// The mesh's area is within this fraction of the surface's (tessellate_to_area), in (0, 0.5).
  double relative_area = 0.005;
  /// The budget of the whole preview: each of n surfaces gets at most sqrt(max_vertices / n)
  /// samples a direction (17 to 1025), so a model of thousands of faces stays a preview. >= 289.
  long max_vertices = 4'000'000;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// What was written (or checked): size figures and OpenCASCADE's BRepCheck verdict.
struct ExchangeReport {
  int faces = 0;               ///< faces written
  int max_degree = 0;          ///< largest degree over both directions of every surface
  long control_points = 0;     ///< control points over all surfaces
  bool valid = false;          ///< every face passes BRepCheck_Analyzer at `tolerance_mm`
  double tolerance_mm = 1e-7;  ///< tolerance of the faces' edges and vertices, never raised
  /// Largest gap (mm) between OpenCASCADE's cached evaluation (power basis per knot span, what
  /// BRepCheck and the mesher use) and exact de Boor evaluation, measured on the faces that fail
  /// BRepCheck; 0 when every face passes. For degree 20-25 surfaces with long (Bezier-like) spans
  /// and a rough control net it can reach millimetres although the edges are exact; a face then
  /// fails BRepCheck at `tolerance` in OpenCASCADE only (see `problems`).
  double evaluation_error = 0.0;
  std::vector<std::string> problems;  ///< BRepCheck findings, in words, per face

  /// One line: "3 faces, max degree 3, 147 control points, valid (BRepCheck at 1e-07 mm)", or
  /// "... NOT valid (BRepCheck at 1e-07 mm): 2 problems, the first: <problem>".
  CLAY_OCCT_API std::string brief() const;
};

/// Writes `surfaces` as faces to a STEP file (millimetres). Throws clay::Error: InvalidGeometry for
/// an invalid surface, DegreeLimit above max_exchange_degree, Exchange when OpenCASCADE refuses the
/// model, Io when the file cannot be written. Returns the face count and BRepCheck verdict.
CLAY_OCCT_API ExchangeReport write_step(const std::vector<BSplineSurface>& surfaces,
                                        const std::filesystem::path& file,
                                        const StepWriteOptions& options = {});

/// Writes `surfaces` as faces to an IGES file (trimmed surfaces, entity 144, over rational B-spline
/// surfaces, entity 128; millimetres). Throws as write_step.
CLAY_OCCT_API ExchangeReport write_iges(const std::vector<BSplineSurface>& surfaces,
                                        const std::filesystem::path& file);

/// How read_step and read_iges protect the caller from a malformed file. OpenCASCADE 7.6 crashes
/// (SIGSEGV) or hangs inside its translators on some malformed files — a single dangling `#n`
/// reference in STEP, a corrupt IGES B-spline record, NaN, infinite or denormal coordinates, degree
/// 99 (issue #18) — where no exception can reach the caller.
struct CLAY_OCCT_API ReadOptions {
  /// Scan the file's text before OpenCASCADE sees it: STEP — every `#n` reference names a
  /// defined entity, numbers are finite, not denormal and at most 1e100 in magnitude, B-spline
  /// degrees are in [1, max_exchange_degree]; IGES — the parameter data's numbers the same, and
  /// B-spline curve (126) and surface (128) records have such degrees and as many parameters as
  /// their counts need. One pass over the text (about 40 ms of a 0.9 s read of a 4.7 MB file).
  bool precheck = true;
  /// Read in a forked child process under the limits below and pass the surfaces back through a
  /// pipe: an OpenCASCADE crash, hang or memory blow-up becomes clay::Error(Exchange) ("OpenCASCADE
  /// crashed (SIGSEGV) while reading 'f.step'", "took longer than 60 s", "needed more than
  /// 4096 MB") and the calling process goes on. Costs a fork and a pipe per read (about 9 ms:
  /// 7 ms direct, 16 ms isolated for a 22 KB file). Exchange calls of other threads wait while
  /// the child reads. Off by default; the `clayform` command reads every file this way.
  bool isolate = false;
  double time_limit_seconds = 120;  ///< isolate: the child is killed after this, in (0, 86400]
  long memory_limit_mb = 4096;      ///< isolate: address space the child may add, in [1, 1048576]

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// Reads the surface of every face of a STEP file, in file order (other analytic surfaces are
/// converted to B-splines exactly by OpenCASCADE; periodic ones are made non-periodic). Reading
/// what write_step wrote gives bit-identical surfaces, except that a surface whose weights are all
/// equal but not 1 (a polynomial in disguise) comes back with weights 1. Throws clay::Error(Io)
/// when the file is missing or cannot be opened, Exchange when it cannot be parsed, holds no
/// surface, fails the pre-check (naming the entity and line) or, isolated, crashes, hangs or
/// exhausts the child process (see ReadOptions); InvalidArgument for bad options.
CLAY_OCCT_API std::vector<BSplineSurface> read_step(const std::filesystem::path& file,
                                                    const ReadOptions& options = {});

/// Reads every B-spline surface of an IGES file. Throws as read_step.
CLAY_OCCT_API std::vector<BSplineSurface> read_iges(const std::filesystem::path& file,
                                                    const ReadOptions& options = {});

/// Builds the faces that write_step/write_iges write and runs BRepCheck_Analyzer on them.
CLAY_OCCT_API ExchangeReport check_faces(const std::vector<BSplineSurface>& surfaces);

/// Writes a binary glTF (.glb) preview: each surface as the grid mesh of tessellate_to_area (the
/// viewer's tessellation, refined until its area is within options.relative_area of the
/// surface's), with exact normals. glTF's units are metres and its up axis is Y; the writer
/// converts. Throws as write_step, InvalidArgument for bad options, and ToleranceNotMet when a
/// surface's mesh cannot meet the area tolerance.
CLAY_OCCT_API void write_gltf(const std::vector<BSplineSurface>& surfaces,
                              const std::filesystem::path& file,
                              const GltfWriteOptions& options = {});

}  // namespace clay::surface
