#pragma once
// The checked recipe (internal): what recipe_check.cpp builds from the JSON and recipe_run.cpp
// executes. Every inline object is already a validated value; references are names known to
// exist and to be defined earlier.
#include <clay/constraints/constraint.hpp>
#include <clay/constraints/solve.hpp>
#include <clay/deform/direct_manipulation.hpp>
#include <clay/deform/stack.hpp>
#include <clay/deform/style.hpp>
#include <clay/occt/fill.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/stroke.hpp>
#include <clay/surface/primitives.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/skin.hpp>
#include <clay/surface/surface_curves.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace clay::recipe {

/// "budget": how large an exact result may be (deform::Budget). Within it a lattice or taper step
/// is composed exactly; above it the step yields its light form, a certified fit at the
/// composition's degree and tolerance, and the exact net is never built; a surface that leaves
/// the recipe above it (a style result) leaves as such a light copy. "none": exact whatever the
/// size (up to the exchange degree 25).
struct Budget {
  int max_degree = 15;
  int max_control_points = 10000;
};

/// The composition mode of deform surfaces.
struct Composition {
  bool refit = false;                ///< "refit": steps that cannot be exact are refitted
  double relative_tolerance = 1e-4;  ///< "relative_tolerance": a fraction of the size, or
  double tolerance_mm = 0;           ///< "tolerance_mm": exactly one of the two > 0
  int degree = 3;
  int check_samples = 4;
  bool accept_out_of_tolerance = false;  ///< "accept_out_of_tolerance": keep a refit that misses
  int max_control_points = 40000;        // refit: the net may not grow beyond this (RefitOptions)
  std::optional<Budget> budget = Budget{};  ///< "budget"; empty: "none"
  /// "edges" (models): a refitted face follows its edges within these (ModelDeformationOptions);
  /// "alone": both 0.
  double edge_gap_mm = 0.0005, edge_angle_deg = 0.008;
};

struct StrokeDef {
  std::string name, path;
  sketch::Stroke stroke;
  sketch::FitOptions fit;
  bool accept_out_of_tolerance = false;  ///< keep a fit that misses its tolerance
  /// 0: one curve named after the stroke, never split; N >= 1: split at its corners into exactly
  /// N curves, named piece_name(name, 1) .. piece_name(name, N) (the stroke's name is no curve).
  int pieces = 0;
};

/// The name of a stroke's k-th curve (1-based) when it is split at its corners: "NAME.k", as a
/// sketch's entities are "SKETCH.ENTITY".
inline std::string piece_name(const std::string& stroke, int k) {
  return stroke + "." + std::to_string(k);
}

/// A curve given inline (already built) or the reverse of another named curve.
/// A mirror plane: through `origin`, normal `normal` (unit).
struct MirrorPlane {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

struct CurveDef {
  std::string name, path, kind;  // kind: bspline, line, arc, arc_through, arc_radius, polyline,
                                 // reversed, mirror, iso, boundary, project, offset
  std::optional<surface::BSplineCurve> curve;
  std::string reversed_of;
  std::string mirror_of;  ///< mirror: the curve mirrored in `plane`
  MirrorPlane plane;
  // Taken from a surface (iso, boundary, project, offset): built once that surface is.
  std::string surface;           ///< the surface the curve is taken from
  std::string source;            ///< project, offset: the curve projected or offset
  bool fixed_u = false;          ///< iso, boundary: u is fixed (the curve runs along v)
  double at = 0;                 ///< iso, boundary: the fixed parameter as a fraction of its domain
  double distance = 0;           ///< offset: mm along the surface normal
  surface::CurveFitOptions fit;  ///< project, offset

  /// Taken from a surface, so built at run time in dependency order.
  bool from_surface() const { return !surface.empty(); }
};

struct SketchDef {
  std::string name, path;
  sketch::Sketch sketch;
  std::vector<constraints::Constraint> constraints;
  constraints::SolveOptions solve;
  std::vector<std::pair<std::string, sketch::EntityId>> entities;  // curve name "SKETCH.E"
  // A sketch using curves known only when the recipe runs (strokes, reversed curves) was checked
  // with stand-ins and is built again by rebuild_sketch from its JSON with the real curves.
  std::string deferred_json;
  std::vector<std::string> uses;  ///< the named curves its "curve" entities take
};

/// The sketch `def` (deferred) built again with the run's curves (`curve` returns nullptr for an
/// unknown name). Throws clay::Error(InvalidGeometry) listing the problems the real curves bring
/// (a fitted curve off the sketch's plane, ...).
SketchDef rebuild_sketch(
    const SketchDef& def,
    const std::function<const surface::BSplineCurve*(const std::string&)>& curve);

struct FillDef {
  std::vector<std::string> curves;
  surface::FillOptions options;
  bool snap = false;  ///< "join": "snap": ends within gap_tolerance (stated) are moved together
};
struct SkinDef {
  std::vector<std::string> sections;
  surface::LoftOptions options;
};
struct SweepDef {
  std::string profile, path;
  surface::SweepOptions options;
};
struct RevolveDef {
  std::string profile;
  surface::Axis axis;
  double angle = 360;
};
struct SuperellipsoidDef {
  surface::Superellipsoid shape;
  surface::SuperquadricOptions options;
};
struct SupertoroidDef {
  surface::Supertoroid shape;
  surface::SuperquadricOptions options;
};
struct ImportDef {
  std::filesystem::path file;
  int index = 0;
};
struct DeformDef {
  std::string surface, deformation;
  Composition composition;
};
struct MirrorDef {
  std::string surface;
  MirrorPlane plane;
};

/// "rebuild": the surface refitted on a fixed, uniform net (deform::refit_surface with counts).
struct RebuildDef {
  std::string surface;
  int count_u = 0, count_v = 0, degree = 3;
  double relative_tolerance = 1e-3;  ///< relative to the surface's size
};

struct SurfaceDef {
  std::string name, path, kind;
  std::variant<surface::BSplineSurface, FillDef, SkinDef, SweepDef, RevolveDef, SuperellipsoidDef,
               SupertoroidDef, ImportDef, DeformDef, MirrorDef, RebuildDef>
      build;
};

struct StyleDef {
  std::string target, bound;  // bound empty: the target's support band (§5)
  deform::StyleOptions options;
  bool accept_out_of_tolerance = false;  ///< keep a result that misses its target or folds
};

struct DirectMove {
  bool on_surface = false;  // point holds (u, v, 0) on the deformed step's input surface
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d to = Eigen::Vector3d::Zero();
};

struct DirectDef {
  std::variant<deform::BezierLattice, deform::BSplineLattice> lattice;
  std::vector<DirectMove> moves;
  deform::DirectManipulationOptions options;
  bool accept_out_of_tolerance = false;  ///< keep a least-squares answer to moves it cannot meet
};

struct StepDef {
  std::string path, name, kind;
  bool enabled = true;
  std::variant<deform::Deformation, StyleDef, DirectDef> step;
  /// A lattice step's "keep": the model properties its move must not change ("volume",
  /// "centroid"); the step's points are corrected by deform::keep_properties (issue #41).
  std::vector<std::string> keep = {};
};

struct StackDef {
  std::string name, path;
  std::vector<StepDef> steps;
};

struct ExportDef {
  std::string name, path;
  std::vector<std::string> surfaces;
  std::vector<std::string> formats;
  std::string schema = "AP214";
  std::string profile = "opencascade";  ///< "profile": the receiver (deform/receiver.hpp)
};

/// A whole model imported from a STEP or IGES file and, optionally, deformed by a stack.
struct ModelDef {
  std::string name, path;
  std::filesystem::path file;
  bool sew = false;         ///< sew loose faces into shells and solids
  bool allow_fold = false;  ///< deform by a lattice not proven fold-free (the solid may fold)
  std::string deformation;  ///< "" when the model is written as read
  std::vector<std::string> bodies, faces;  ///< names chosen to deform; both empty: every face
  /// "profile": the receiver its deformed faces are written for (deform::receiver_profile's
  /// names); "" = none (faces exact where they can be, light above the composition's budget)
  std::string profile;
  std::vector<std::string> formats{"step", "iges", "glb"};
  std::string schema = "AP214";
};

namespace detail {
struct DocumentJson;  // run_cache.hpp
}

struct RecipeData {
  std::string name, description;
  /// The JSON as checked: the run's cache keys (RunCache) start with each step's own text. Null
  /// for a recipe made in code; then nothing is cached.
  std::shared_ptr<const detail::DocumentJson> document;
  Composition composition;
  std::vector<StrokeDef> strokes;
  std::vector<CurveDef> curves;
  std::vector<SketchDef> sketches;
  std::vector<SurfaceDef> surfaces;
  std::vector<StackDef> stacks;
  std::vector<ExportDef> exports;
  std::vector<ModelDef> models;
};

/// What a curve or surface definition needs built before it: curve and surface names.
struct Needs {
  std::vector<std::string> curves, surfaces;
};
/// The needs of the curve (stroke, curve or sketch entity) named `name`.
Needs curve_needs(const RecipeData& d, const std::string& name);
/// The needs of a surface definition (a deform step's style curves included).
Needs surface_needs(const RecipeData& d, const SurfaceDef& def);
/// True when another surface or a curve is built from the surface named `surface` (a deform,
/// rebuild or mirror of it, a curve taken from it).
bool built_on(const RecipeData& d, const std::string& surface);
/// A cycle of definitions that need each other ("curve edge", "surface panel", "curve edge"), or
/// empty.
std::vector<std::string> dependency_cycle(const RecipeData& d);

/// The checked model, or problems (then the model is incomplete and must not be run).
struct CheckOutcome {
  RecipeData data;
  std::vector<Problem> problems;
};
CheckOutcome check(std::string_view text, const std::filesystem::path& base_dir);

}  // namespace clay::recipe
