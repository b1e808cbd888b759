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
    Refit
  } method = Method::Skipped;  ///< disabled, composed, refitted
  std::string reason;     ///< why a step was refitted (the exact composition's refusal), else empty
  ComposeReport compose;  ///< when exact
  RefitReport refit;      ///< when refitted
};

/// Per-step outcomes and the result's size.
struct CLAY_DEFORM_API SurfaceDeformationReport {
  std::vector<StepOutcome> steps;  ///< one per stack step, in order
  bool exact = true;               ///< every enabled step was composed exactly
  bool certified = true;           ///< every refitted step carries a certified bound
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
/// exact NURBS; a refitted step's bound is its own (a later step may stretch it by its Lipschitz
/// constant; the report does not propagate bounds). Throws clay::Error: InvalidGeometry for an
/// invalid stack or surface, InvalidArgument for bad options, and for a step that is not exact
/// when no refit is allowed the exact composition's own error (DegreeLimit, OutOfDomain or
/// InvalidArgument, naming the step) or InvalidArgument for a non-polynomial kind.
/// ToleranceNotMet, naming the step, its figure and the tolerance, for a refit that misses its
/// tolerance (unless options.accept_out_of_tolerance), and before any refit for a lattice step
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
