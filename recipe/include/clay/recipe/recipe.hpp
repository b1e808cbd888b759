#pragma once
/// Recipes: a styling session recorded as JSON (schema "clayform.recipe", version 1, every field
/// in docs/recipe.md) — strokes, curves and sketches, parent surfaces, deformation stacks, the
/// composition mode and the exports — checked with every problem at once, replayed bit for bit,
/// and applied to other surfaces (Coquillart's recording operator). The `clayform` command is a
/// shell over these functions.
#include <clay/brep/model.hpp>
#include <clay/deform/light_map.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/recipe/export.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace clay::recipe {

/// One problem of a recipe: where (a JSON path such as "surfaces.sail.fill.curves[2]", or
/// "(top level)") and what is wrong, with the fix. Syntax errors carry a 1-based line and column
/// (0 when not applicable).
struct Problem {
  std::string path;     ///< JSON path of the offending value
  std::string message;  ///< what is wrong and how to fix it
  int line = 0;         ///< 1-based line of a syntax error, else 0
  int column = 0;       ///< 1-based column of a syntax error, else 0
};

/// "path: message", or "line L, column C: message" for a syntax error.
CLAY_RECIPE_API std::string to_string(const Problem& problem);

struct RecipeData;  // the checked recipe (recipe_model.hpp, internal)

/// A checked recipe: every reference resolved, every field typed and in range. Cheap to copy
/// (shared, immutable).
struct CLAY_RECIPE_API Recipe {
  std::shared_ptr<const RecipeData> data;
  /// The recipe's name (its "name", or the file stem when read with load_recipe).
  const std::string& name() const;
  /// Names of its deformation stacks, in document order.
  std::vector<std::string> deformation_names() const;
};

/// Every problem of the recipe text, all at once, in document order: JSON syntax (with line and
/// column), wrong format or version, unknown keys, missing or mistyped fields, values out of
/// range, names that are malformed or defined twice, references to missing or later objects.
/// Files named by `import` surfaces are resolved against `base_dir` and must exist. Empty when
/// the recipe can be run. Never throws for bad text.
CLAY_RECIPE_API std::vector<Problem> check_recipe(std::string_view text,
                                                  const std::filesystem::path& base_dir = {});

/// The checked recipe. Throws clay::Error(Document) listing every problem of check_recipe, one per
/// line. `default_name` names a recipe whose text has no "name" (load_recipe gives the file
/// stem).
CLAY_RECIPE_API Recipe parse_recipe(std::string_view text,
                                    const std::filesystem::path& base_dir = {},
                                    std::string_view default_name = {});

/// Reads and parses a recipe file (imports resolved next to it; the name defaults to the stem).
/// Throws clay::Error: Io when the file cannot be read, Recipe for its problems.
CLAY_RECIPE_API Recipe load_recipe(const std::filesystem::path& file);

/// A figure of a step's report: a flag, a count, a measure (mm, degrees, ratio) or a word.
using Figure = std::variant<bool, long long, double, std::string>;

/// What one step of a run did.
struct StepReport {
  std::string path;  ///< "strokes.leech", "surfaces.sail", "surfaces.sail.steps[1]", "exports.sail"
  std::string kind;  ///< "stroke", "bspline", "fill", "bezier_lattice", "style", "step", ...
  double seconds = 0;    ///< wall time of the step
  bool warning = false;  ///< produced its result but an outcome fell short (see message)
  /// Taken with its result from an earlier run (RunOptions::cache or previous) instead of being
  /// done again; `seconds` is then what it took when it was done.
  bool reused = false;
  std::string message;                                  ///< what happened, in words
  std::vector<std::pair<std::string, Figure>> figures;  ///< in a fixed order per kind
};

namespace detail {
class CacheAccess;
}

/// The results of a recipe's steps kept from one run for the next (issue #40: an edit re-runs
/// only the steps it reaches). Every stroke, curve, sketch and surface a run builds is kept
/// under a key made of its own definition (its JSON as written), the recipe's composition and
/// the keys of everything it is built from: for a deformed surface its stack's definition too
/// and the surfaces built before it (whose shared sides its fits follow), for an import the
/// file's size and time. A later run meeting the same key takes the kept result, bit for bit
/// what building it gives, its step reports marked `reused`. One cache serves the runs of a
/// studio session, of a Python program or of a sweep's variants in one process (variants that
/// share a prefix compute it once); safe to share between threads. The least recently used
/// results go first once the kept ones exceed `capacity_bytes` (estimated from their nets).
class CLAY_RECIPE_API RunCache {
 public:
  explicit RunCache(std::size_t capacity_bytes = std::size_t{256} << 20);
  ~RunCache();
  RunCache(const RunCache&) = delete;
  RunCache& operator=(const RunCache&) = delete;

  /// What the cache did since it was made (or cleared) and holds now.
  struct Counts {
    long long reused = 0;       ///< steps taken from it (a surface with its stack counts once)
    long long kept = 0;         ///< results built and stored
    long long evicted = 0;      ///< results dropped for the capacity
    long long entries = 0;      ///< results held now
    std::size_t bytes = 0;      ///< their estimated size
    long long fits_reused = 0;  ///< stroke fits taken from it (fit_stroke)
  };
  Counts counts() const;
  /// Drops every kept result and zeroes the counts.
  void clear();

  /// sketch::fit_stroke, each stroke fitted once: a stroke whose points, plane and settings are
  /// bit for bit those of one of the most recent fits gets that fit (the studio asks how a
  /// stroke fits before it writes it, and the run of that edit fits it again). Throws as
  /// sketch::fit_stroke does; nothing is kept for a stroke that throws.
  sketch::StrokeFit fit_stroke(const sketch::Stroke& stroke, const sketch::FitOptions& options);

 private:
  friend class detail::CacheAccess;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Settings of run_recipe / deform_surfaces.
struct RunResult;
struct RunOptions {
  /// Called after each step (progress lines); may be empty.
  std::function<void(const StepReport&)> progress;
  /// Called before each step that is built (not one taken from `cache` or `previous`), with its
  /// path and kind: what a long run is doing now (the studio's progress line); may be empty.
  std::function<void(const std::string& path, const std::string& kind)> starting;
  /// Non-empty: every export and every deformed model is written for this receiver profile
  /// (deform::receiver_profile: "exact", "opencascade", "catia", "class_a", "bicubic") instead
  /// of its own.
  std::string profile;
  /// An earlier run of this recipe whose definitions differed only in the deformations named in
  /// `changed_deformations` (the studio's lattice edits; the caller compares the texts). Every
  /// surface that needs none of them (through its deform, the surfaces and the curves it is built
  /// from) is taken from it with its step reports, stages and bound instead of being built
  /// again; a surface RunResult::previewed lists is always built again.
  std::shared_ptr<const RunResult> previous;
  std::vector<std::string> changed_deformations;
  /// With `previous`: a Bézier or B-spline lattice step whose light form the previous run made
  /// gives the light net on that form's knots (deform::light_net, one product per update) without
  /// a certificate: a drag preview, listed in RunResult::previewed. Run again without it to fit
  /// and certify.
  bool preview = false;
  /// With `previous`: false when the edit changed more than `changed_deformations` (a curve
  /// dragged): `previous` then only gives a preview its lattice steps' light maps, and no surface
  /// is taken from it (the cache takes what is unchanged).
  bool take_from_previous = true;
  /// Results kept between runs (RunCache): each stroke, curve, sketch and surface whose
  /// definition and inputs are unchanged is taken from it; what is built is kept in it. Empty:
  /// everything is built. Previewed surfaces are never kept.
  std::shared_ptr<RunCache> cache;
};

/// One export: the surfaces written together and what the exchange layer reported.
struct ExportResult {
  std::string name;                               ///< the export's name (file stem)
  std::vector<std::string> surface_names;         ///< in the recipe's order
  std::vector<surface::BSplineSurface> surfaces;  ///< what is written
  std::vector<std::string> formats;               ///< "step", "iges", "glb"
  std::string schema = "AP214";                   ///< STEP schema
  /// The receiver profile the surfaces were made to conform to (deform::receiver_profile).
  std::string profile = "opencascade";
  /// Per surface: how far what is written may be from the all-exact recipe (mm): the surface's
  /// bound ledger plus the profile's certified refit; inf when not bounded.
  std::vector<double> bounds_mm;
  // Filled in by write_outputs:
  std::vector<std::string> files;     ///< file names written (in out_dir)
  bool checked = false;               ///< the STEP (or IGES) file was read back and checked
  bool valid = false;                 ///< BRepCheck of the read-back surfaces at 1e-7 mm
  bool read_back_identical = false;   ///< the read-back surfaces equal the written ones bit for bit
  std::vector<std::string> problems;  ///< BRepCheck findings
};

/// One enabled step of a deformed surface's stack: the surface before and after it (what a
/// viewer's before/after toggle shows), and the named curves it used (a style step's bound and
/// target).
struct Stage {
  std::string surface;  ///< the deformed surface's name ("sail"; "<stem>-<k>" for deform_surfaces)
  std::string step;     ///< the step's report path ("surfaces.sail.steps[1]")
  std::string kind;     ///< the step's kind ("style", "bezier_lattice", ...)
  surface::BSplineSurface before, after;
  std::vector<std::string> curves;  ///< names of the curves the step used, in RunResult::curves
  /// The step's deformation of space, point by point (`after` equals it applied to `before`,
  /// exactly or within the refit's bound); empty for a style step, which moves control points.
  std::function<Eigen::Vector3d(const Eigen::Vector3d&)> map;
  /// A lattice step's light form as a linear map of its points (RunOptions::preview), kept for
  /// the next update of the same drag; empty otherwise.
  std::shared_ptr<const deform::LatticeLightMap> light_map;
};

/// A whole model deformed by a recipe's deformation stack (the "clayform deform" use, and each
/// entry of a recipe's "models").
struct ModelRunResult {
  std::string recipe;       ///< the recipe's name
  std::string name;         ///< the recipe's name for the model (file stem of its outputs)
  std::string source;       ///< the file it was imported from
  std::string deformation;  ///< the stack's name ("" when the model is written as read)
  /// The bodies and faces the recipe chose to deform, by name (both empty: every face).
  std::vector<std::string> bodies, faces;
  brep::Model model;  ///< the deformed model (flattened when it was an assembly)
  deform::ModelDeformationReport report;
  bool fold_free = true;  ///< every lattice step's Jacobian bounds are positive
  /// What each lattice step with "keep" corrected: the properties before the step and after it
  /// (measured on the exact result), the Newton steps and the largest correction of a point.
  struct Kept {
    std::string step;  ///< "deformations.lift.steps[0] 'lift'"
    std::vector<std::string> properties;
    double volume_before_mm3 = 0, volume_after_mm3 = 0;  ///< when "volume" or "centroid" is kept
    double centroid_shift_mm = 0;                        ///< |centroid after − before|
    double area_before_mm2 = 0, area_after_mm2 = 0;      ///< when "area" is kept
    int iterations = 0;
    double largest_correction_mm = 0;
  };
  std::vector<Kept> kept;
  std::vector<std::string> formats;  ///< "step", "iges", "glb" (the model's, or for `clayform
                                     ///< deform` the recipe's first export's; all three when none)
  std::string schema = "AP214";      ///< STEP schema
  double seconds = 0;                ///< wall time
  // Filled in by write_outputs:
  std::vector<std::string> files;  ///< file names written (in out_dir)
  bool valid = false;              ///< BRepCheck of every STEP/IGES file written, read back
};

/// Everything a run computed, in memory. Nothing is written until write_outputs.
struct CLAY_RECIPE_API RunResult {
  std::string recipe;                                                     ///< the recipe's name
  std::vector<std::pair<std::string, surface::BSplineCurve>> curves;      ///< every named curve
  std::vector<std::pair<std::string, surface::BSplineSurface>> surfaces;  ///< every named surface
  std::vector<ExportResult> exports;                                      ///< in document order
  std::vector<ModelRunResult> models;  ///< the recipe's imported models, in document order
  std::vector<StepReport> steps;       ///< every step in order of execution
  std::vector<Stage> stages;           ///< every enabled deformation step, in order of execution
  /// The bound ledger: per surface that is not exact, how far it may be from the all-exact
  /// recipe (mm; inf when not bounded); a surface not listed is exact.
  std::vector<std::pair<std::string, double>> bounds;
  /// Surfaces built in a preview run (RunOptions::preview): uncertified, never reused.
  std::vector<std::string> previewed;
  double seconds = 0;  ///< wall time of the whole run
  /// The named surface. Throws clay::Error(InvalidArgument) naming the defined ones when absent.
  const surface::BSplineSurface& surface(std::string_view name) const;
  /// The named curve. Throws clay::Error(InvalidArgument) naming the defined ones when absent.
  const surface::BSplineCurve& curve(std::string_view name) const;
};

/// Runs every step of the recipe in memory: strokes, curves, sketches, surfaces (deformed ones
/// by their stacks, composed per the composition mode), exports prepared. Deterministic: the same
/// recipe gives bit-identical surfaces (no step's arithmetic depends on timing or on how work is
/// split between threads). Throws clay::Error with the
/// failing step's path first ("surfaces.sail.steps[2] (twist): ...") and that step's category.
CLAY_RECIPE_API RunResult run_recipe(const Recipe& recipe, const RunOptions& options = {});

/// Fills e.surfaces from e.surface_names (surfaces of `run`, a run of `recipe`) made to
/// conform to the receiver profile e.profile, as a recipe export does: as they are when they
/// conform, else refitted (certified, within the recipe composition's tolerance); the exact
/// profile recomputes a light surface's exact reference. e.bounds_mm gets each surface's bound
/// from the all-exact recipe. Throws clay::Error: InvalidArgument for an unknown profile or
/// surface, ToleranceNotMet or DegreeLimit naming the surface that cannot conform.
CLAY_RECIPE_API void conform_export(ExportResult& e, const Recipe& recipe, const RunResult& run);

/// The recipe's surfaces that no "deform" surface takes as its parent, in document order: what
/// a picture of the design shows (a styled hood, not also the hood before styling). Throws
/// clay::Error(InvalidArgument) for an empty recipe.
CLAY_RECIPE_API std::vector<std::string> final_surfaces(const Recipe& recipe);

/// Applies the recipe's deformation stack `deformation` (may be empty when the recipe has
/// exactly one) to each of `surfaces` with the recipe's composition mode: the "clayform deform"
/// use. The result's surfaces are named "<stem>-<k>" (k from 0) and one export "<stem>" holds
/// them all, with the recipe's first export's formats (all three when it has none).
CLAY_RECIPE_API RunResult deform_surfaces(const Recipe& recipe,
                                          const std::vector<surface::BSplineSurface>& surfaces,
                                          std::string_view stem, std::string_view deformation = {},
                                          const RunOptions& options = {});

/// Deforms `model` by the recipe's deformation stack `deformation` (may be empty when the recipe
/// has exactly one) with the recipe's composition mode (deform::deform_model). Lattices, regular
/// deformations and direct manipulation with moves given in space apply; a style step, or a move
/// from a surface point, is refused (InvalidArgument naming the step): they shape one surface.
/// A lattice whose Jacobian bounds do not prove it fold-free (Sederberg–Parry §4) is refused
/// (InvalidGeometry naming the step and its smallest coefficient: a folded solid intersects
/// itself) unless `allow_fold`. `profile` (deform::receiver_profile's names; empty: none, faces
/// above degree 25 refitted) is the receiver the model is written for: the faces it would not
/// take are refitted to it with their edges (deform::ModelDeformationOptions::profile). Throws
/// the deformation's clay::Error in the recipe's words, naming the stack; InvalidArgument for
/// an unknown profile.
CLAY_RECIPE_API ModelRunResult deform_model(const Recipe& recipe, const brep::Model& model,
                                            std::string_view deformation = {},
                                            bool allow_fold = false, std::string_view profile = {});

/// Deforms `model` by `stack`, a stack built in code (Python's Model.deform), as the overload
/// above deforms it by a recipe's, with a recipe's default composition mode (docs/recipe.md §
/// composition): the same fold check (a lattice step not proven fold-free is refused, naming the
/// step, unless `allow_fold`) and receiver `profile`. `faces` (indices into
/// flattened(model).faces; empty: every face) are the faces deformed; the others are kept.
/// `refit_tolerance_mm` > 0: a face that cannot be composed exactly (crossing a knot plane off
/// its iso-lines; twist, bend, extended lattices) is refitted within it, certified, with its
/// edges; 0: such a face is refused, naming it. Throws InvalidArgument for a negative or
/// non-finite tolerance.
CLAY_RECIPE_API ModelRunResult deform_model(const deform::DeformationStack& stack,
                                            const brep::Model& model, bool allow_fold = false,
                                            std::string_view profile = {},
                                            const std::vector<int>& faces = {},
                                            double refit_tolerance_mm = 0);

/// Writes STEM.step, STEM.igs and STEM.glb (result.formats; the .glb a preview of the trimmed
/// faces, brep::write_model), report.json and the view folder (the model's trimmed mesh, for
/// `clayform view`) into `out_dir`, through a temporary folder as
/// write_outputs does: each STEP and IGES file is read back (read_model) and checked (BRepCheck,
/// the same counts) before anything is moved into `out_dir`. Returns the paths written. Throws
/// clay::Error (Io, Exchange) naming the file.
CLAY_RECIPE_API std::vector<std::filesystem::path> write_model_outputs(
    const ModelRunResult& result, const std::filesystem::path& out_dir, std::string_view stem);

/// The report of a run as JSON text (schema "clayform.report", version 1, docs/recipe.md):
/// per step its path, kind, seconds, warning, message and figures; per export its files and
/// exchange figures (valid is filled in by write_outputs; report_json alone leaves it out).
CLAY_RECIPE_API std::string report_json(const RunResult& result);

/// The steps of a run as a JSON array, each step exactly as in report_json's "steps":
/// {path, kind, seconds, warning, message, figures} (the studio's replies carry this).
CLAY_RECIPE_API std::string step_reports_json(const std::vector<StepReport>& steps);

/// Writes every export (NAME.step, NAME.igs, NAME.glb per its formats), report.json and the view
/// folder (view/manifest.json and view/NNN.bin, clay/recipe/view.hpp) into `out_dir` (created when
/// missing). The files are first written into a temporary folder next
/// to `out_dir` and each STEP file is read back and checked (BRepCheck); only when everything
/// succeeded are they moved into `out_dir`, so a failure leaves no partial files. Returns the
/// paths written (the view folder as one entry, last). Throws clay::Error (Io, Exchange) naming
/// the file; Exchange, with BRepCheck's findings, when an export reads back invalid (then
/// nothing is written into `out_dir`).
CLAY_RECIPE_API std::vector<std::filesystem::path> write_outputs(
    RunResult& result, const std::filesystem::path& out_dir);

/// A library message in the recipe's words: the fixes it suggests name recipe keys, never C++
/// options ("SurfaceDeformationOptions::refit" becomes "composition": {"mode": "refit", ...}),
/// and fixes recipes cannot apply are left out. Every message the command prints about a recipe
/// goes through it (the checker's problems and the run's step errors).
CLAY_RECIPE_API std::string recipe_wording(std::string message);

}  // namespace clay::recipe
