#pragma once
/// Deformation stacks: an ordered list of deformations applied hierarchically — the first step
/// is the global one, each later step deforms the result of the steps before it (Güdükbay–Özgüç
/// 1990 §3, Fig. 7: regular deformations and FFDs combined in any order; Coquillart 1990
/// extended lattices among them) — and their JSON form (schema "clayform.deformation-stack"
/// version 1, docs/deform.md), which round-trips every number bit for bit.
#include <clay/deform/deformation.hpp>
#include <clay/deform/export.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/regular.hpp>
#include <clay/summary.hpp>

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace clay::deform {

/// One deformation of space, of any kind. Adding a kind: add it here, then one line in each of
/// the per-kind overload sets of stack.cpp (kind name, JSON writer, JSON reader, in-place bulk).
/// An ExtendedLattice step deforms its input as deform_points(ExtendedLattice) does: the points
/// reaching the step are frozen on the rest shape, then evaluated on the moved control points.
using Deformation =
    std::variant<BezierLattice, BSplineLattice, ExtendedLattice, Taper, Twist, Bend>;

/// A step of a stack: a deformation, a name for people and recipes (may be empty, need not be
/// unique) and whether it is applied (a disabled step is kept but skipped).
struct DeformationStep {
  Deformation deformation;  ///< what the step does
  std::string name;         ///< label ("hood taper"); free text
  bool enabled = true;      ///< false: skipped by deform_point / deform_points
};

/// An ordered list of deformations: steps[0] is applied first (the global deformation), every
/// following step to its result.
struct DeformationStack {
  std::vector<DeformationStep> steps;  ///< in the order of application
};

/// The JSON name of a deformation kind: "bezier_lattice", "bspline_lattice",
/// "extended_lattice", "taper", "twist" or "bend".
CLAY_DEFORM_API std::string_view kind_name(const Deformation& deformation) noexcept;

/// Every problem of every step (disabled ones too), each naming the step as
/// "steps[i] (kind 'name')" followed by the deformation's own problems(). Empty when valid.
CLAY_DEFORM_API std::vector<std::string> problems(const DeformationStack& stack);

/// Throws clay::Error(InvalidGeometry) listing problems(stack) when there are any.
CLAY_DEFORM_API void validate(const DeformationStack& stack);

/// x deformed by every enabled step in order, each by its reference deform_point (lattices by
/// de Casteljau / de Boor, not frozen; an extended lattice freezes x alone, default
/// FreezeOptions, and leaves it unchanged when outside or unresolved). Precondition: a valid
/// stack (this one-off does not check, except that an extended lattice step validates itself).
CLAY_DEFORM_API Eigen::Vector3d deform_point(const DeformationStack& stack,
                                             const Eigen::Vector3d& x);

/// What deform_points did at the steps that iterate. An extended lattice step freezes the points
/// reaching it by Newton's method (Coquillart §3.3); a point it cannot place (unresolved) is left
/// unchanged by that step and the step's FreezeReport is NotConverged — an outcome, not an
/// error, so the deformation goes on and this report is the only place it shows.
struct CLAY_DEFORM_API StackReport {
  /// The freeze of one enabled extended lattice step.
  struct Freeze {
    std::size_t step = 0;  ///< index of the step in stack.steps
    FreezeReport report;   ///< inside / outside / unresolved counts, Newton residuals
  };
  std::vector<Freeze> freezes;  ///< one per enabled extended lattice step, in order of application
  /// Converged when no freeze left a point unresolved, else NotConverged (those points are left
  /// unchanged); message = brief().
  Summary summary;

  /// True when no freeze left a point unresolved (also when the stack has no extended lattice).
  bool converged() const noexcept;
  /// "no extended lattice step", or one "steps[i]: frozen N points: ..." per freeze, "; "-joined.
  std::string brief() const;
};

/// Every row of `points` (N x 3 row-major, mm) deformed by every enabled step in order: each
/// lattice is frozen once (FrozenLattice; an extended lattice by freeze() with default
/// FreezeOptions and options.threads) and every step deforms the whole set in place with its
/// bulk function (options.threads workers). Agrees with deform_point per row to rounding (the
/// frozen power form, ~1e-15 of the lattice size per lattice step, amplified by the later steps'
/// derivatives). Points an extended lattice cannot place are left unchanged by that step: use
/// the overload with a StackReport to learn about them. Throws clay::Error: InvalidGeometry for
/// an invalid stack, InvalidArgument for bad options.
CLAY_DEFORM_API Points3 deform_points(const DeformationStack& stack, const Points3& points,
                                      const DeformOptions& options = {});

/// Same into `out` (resized when needed; may be `points` itself).
CLAY_DEFORM_API void deform_points(const DeformationStack& stack, const Points3& points,
                                   Points3& out, const DeformOptions& options = {});

/// Same into `out`, and `report` (overwritten) lists the freeze of every enabled extended
/// lattice step: check report.converged().
CLAY_DEFORM_API void deform_points(const DeformationStack& stack, const Points3& points,
                                   Points3& out, StackReport& report,
                                   const DeformOptions& options = {});

/// The stack as JSON text (schema "clayform.deformation-stack", version 1, in docs/deform.md):
/// numbers are written in shortest round-trip form, so stack_from_json(to_json(s)) restores every
/// double bit for bit. Throws clay::Error: InvalidGeometry for an invalid stack (JSON has no
/// NaN), InvalidArgument for a step name that is not valid UTF-8.
CLAY_DEFORM_API std::string to_json(const DeformationStack& stack);

/// Parses a stack written by to_json (or by hand). Throws clay::Error(Document) for malformed
/// input, naming the JSON path and the fix ("steps[2].points[5]: expected 3 numbers, found 2;
/// ..."): not JSON, a wrong format or version, unknown kinds or keys, missing or mistyped fields,
/// wrong counts, non-finite numbers, and every problems() of the resulting stack.
CLAY_DEFORM_API DeformationStack stack_from_json(std::string_view json);

}  // namespace clay::deform
