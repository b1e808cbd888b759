#pragma once
/// A NURBS surface through a whole deformation stack (issue #7 items 5 and 6): every step is
/// composed exactly where the mathematics allows (compose.hpp: Bézier lattices, B-spline lattices
/// whose knot planes the surface meets along iso-parameter lines, polynomial tapers) and refitted
/// with a certified bound where it does not (refit.hpp: twist, bend, extended lattices, knot-plane
/// crossings, surfaces leaving a lattice, results above the exchange degree limit) — the latter
/// only when a refit is allowed; otherwise the step is refused with the reason and the way out.
/// The report says, per step, which it was and with what figures.
#include <clay/deform/compose.hpp>
#include <clay/deform/export.hpp>
#include <clay/deform/refit.hpp>
#include <clay/deform/stack.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <optional>
#include <string>
#include <vector>

namespace clay::deform {

/// How large an exact result may be (issue #38). A step whose exact composition would stay within
/// it is composed exactly; above it the step yields its light form: a certified low-degree fit of
/// the same map of the step's input (refit_deformed with `light`), and the exact net, whose size
/// is predicted from the patches' degrees before anything is composed, is never built. The exact
/// result stays available: deform_surface without a budget computes it.
struct CLAY_DEFORM_API Budget {
  /// Highest degree kept exact, in [1, 25]: 15 is CATIA's order 16, the lowest receiver cap that
  /// still keeps a Bézier (3, 1, 1) lattice on a bicubic exact.
  int max_degree = 15;
  /// Most control points kept exact, >= 1: 10,000 keeps a studio drag and an export interactive
  /// (a 2.6 M-point exact net took 15 s per drag and 9 minutes to export).
  long max_control_points = 10000;
  /// The light form's fit: bicubic within 1e-4 of the size, starting from the input's rough
  /// breakpoints only (keep_breakpoints false), so knots go where the error needs them.
  RefitOptions light = light_fit();

  /// The default light fit (see `light`).
  static RefitOptions light_fit();
  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
};

/// Settings of deform_surface.
struct CLAY_DEFORM_API SurfaceDeformationOptions {
  ComposeOptions compose;  ///< for the steps composed exactly
  /// For the steps that cannot be composed exactly; empty: such a step is an error that names it
  /// and why (give a refit tolerance, lower the lattice degree, move the knot plane).
  std::optional<RefitOptions> refit;
  /// false (the default): a refitted step whose certified bound (or, uncertified, sampled
  /// maximum) misses the refit tolerance is an error, clay::Error(ToleranceNotMet); true: it is
  /// returned, with its figures in the step's RefitReport (summary NotConverged).
  bool accept_out_of_tolerance = false;
  /// Empty (the default): exact results are kept whatever their size, up to compose.max_degree.
  /// Set: steps above it yield their light form (see Budget).
  std::optional<Budget> budget;
  /// How far the input surface may already be from its own exact reference (mm, >= 0, inf when
  /// unknown): a light or refitted form from earlier steps. Starts the bound ledger (see
  /// StepOutcome::accumulated_bound_mm).
  double input_bound_mm = 0;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// What happened at one step.
struct StepOutcome {
  int step = 0;      ///< index in the stack
  std::string kind;  ///< kind_name of the deformation
  std::string name;  ///< the step's name
  enum class Method {
    Skipped,
    Exact,
    Refit,  ///< not polynomial (or not exact here): refitted, SurfaceDeformationOptions::refit
    Light   ///< exact but above the budget: its light form, Budget::light
  } method = Method::Skipped;  ///< disabled, composed, refitted, light
  std::string reason;  ///< why a step was refitted or made light (the exact composition's refusal)
  ComposeReport compose;  ///< when exact
  RefitReport refit;      ///< when refitted or light
  ExactSize exact_size;   ///< when light: the exact form's predicted size (control_points an upper
                         ///< bound; 0 when only its degree was found, for a taper above the degree)
  /// This step's certified deviation from its map applied to its input (mm): 0 when exact, the
  /// refit's certified bound when refitted or light, inf when that is not certified.
  double bound_mm = 0;
  /// How far the result may be from the exact reference, the input's exact reference deformed
  /// by every step exactly (mm): E = bound_mm + L·E_in, L = sup|D'| over the input's control box
  /// grown by E_in (a Lipschitz bound, certifier.hpp); inf when a step is not certified.
  double accumulated_bound_mm = 0;
};

/// Per-step outcomes and the result's size.
struct CLAY_DEFORM_API SurfaceDeformationReport {
  std::vector<StepOutcome> steps;  ///< one per stack step, in order
  bool exact = true;               ///< every enabled step was composed exactly
  bool certified = true;           ///< every refitted step carries a certified bound
  int light_steps = 0;             ///< steps given their light form (above the budget)
  /// The result's bound from the exact reference (the last step's accumulated_bound_mm, or
  /// SurfaceDeformationOptions::input_bound_mm when no step ran).
  double accumulated_bound_mm = 0;
  int degree_u = 0, degree_v = 0;  ///< degrees of the result
  long control_points = 0;         ///< control points of the result
  /// Converged (a step that misses its tolerance throws ToleranceNotMet unless accepted, then
  /// NotConverged); message = brief().
  Summary summary;
  /// One line per step: "steps[1] twist 'spin': refit, certified 3.1e-3 mm (tolerance ...)".
  std::string brief() const;
};

/// The deformed surface and its report.
struct SurfaceDeformationResult {
  surface::BSplineSurface surface;
  SurfaceDeformationReport report;
};

/// `surface` deformed by every enabled step of `stack` in order. Exact steps keep the result an
/// exact NURBS; above options.budget a step yields its light form; a refitted or light step's
/// bound is its own, and the report stacks the bounds (StepOutcome::accumulated_bound_mm).
/// Throws clay::Error: InvalidGeometry for an
/// invalid stack or surface, InvalidArgument for bad options, and for a step that is not exact
/// when no refit is allowed the exact composition's own error (DegreeLimit, OutOfDomain or
/// InvalidArgument, naming the step) or InvalidArgument for a non-polynomial kind.
/// ToleranceNotMet, naming the step, its figure and the tolerance, for a refit that misses its
/// tolerance (unless options.accept_out_of_tolerance), the same for a light form (naming the
/// budget and the exact size), and before any refit for a lattice step
/// whose map is torn where the surface crosses the lattice's boundary: outside the lattice the
/// FFD is the identity, so a displaced face makes the deformed surface jump there by
/// |F(x) − x|, and no continuous fit comes closer than half that jump; when half the jump
/// (measured at the crossings of an 8-per-span sample grid, bisected to the face) exceeds the
/// tolerance, the step is refused at once.
CLAY_DEFORM_API SurfaceDeformationResult
deform_surface(const DeformationStack& stack, const surface::BSplineSurface& surface,
               const SurfaceDeformationOptions& options = {});

/// The same for one deformation.
CLAY_DEFORM_API SurfaceDeformationResult
deform_surface(const Deformation& deformation, const surface::BSplineSurface& surface,
               const SurfaceDeformationOptions& options = {});

}  // namespace clay::deform
