#pragma once
/// Deformation stacks: an ordered list of deformations applied hierarchically — the first step
/// is the global one, each later step deforms the result of the steps before it (Güdükbay–Özgüç
/// 1990 §3, Fig. 7: regular deformations and FFDs combined in any order) — and their JSON form
/// (schema "clayform.deformation-stack" version 1, docs/deform.md), which round-trips every
/// number bit for bit.
#include <clay/deform/deformation.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/regular.hpp>

#include <Eigen/Core>

#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace clay::deform {

/// One deformation of space, of any kind. Adding a kind: add it here, then one line in each of
/// the per-kind overload sets of stack.cpp (kind name, JSON writer, JSON reader, in-place bulk).
using Deformation = std::variant<BezierLattice, BSplineLattice, Taper, Twist, Bend>;

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

/// The JSON name of a deformation kind: "bezier_lattice", "bspline_lattice", "taper", "twist"
/// or "bend".
std::string_view kind_name(const Deformation& deformation) noexcept;

/// Every problem of every step (disabled ones too), each naming the step as
/// "steps[i] (kind 'name')" followed by the deformation's own problems(). Empty when valid.
std::vector<std::string> problems(const DeformationStack& stack);

/// Throws clay::Error(InvalidGeometry) listing problems(stack) when there are any.
void validate(const DeformationStack& stack);

/// x deformed by every enabled step in order, each by its reference deform_point (lattices by
/// de Casteljau / de Boor, not frozen). Precondition: a valid stack (this one-off does not check).
Eigen::Vector3d deform_point(const DeformationStack& stack, const Eigen::Vector3d& x);

/// Every row of `points` (N x 3 row-major, mm) deformed by every enabled step in order: each
/// lattice is frozen once (FrozenLattice) and every step deforms the whole set in place with its
/// bulk function (options.threads workers). Agrees with deform_point per row to rounding (the
/// frozen power form, ~1e-15 of the lattice size per lattice step). Throws clay::Error:
/// InvalidGeometry for an invalid stack, InvalidArgument for bad options.
Points3 deform_points(const DeformationStack& stack, const Points3& points,
                      const DeformOptions& options = {});

/// Same into `out` (resized when needed; may be `points` itself).
void deform_points(const DeformationStack& stack, const Points3& points, Points3& out,
                   const DeformOptions& options = {});

/// The stack as JSON text (schema "clayform.deformation-stack", version 1, in docs/deform.md):
/// numbers are written in shortest round-trip form, so stack_from_json(to_json(s)) restores every
/// double bit for bit. Throws clay::Error: InvalidGeometry for an invalid stack (JSON has no
/// NaN), InvalidArgument for a step name that is not valid UTF-8.
std::string to_json(const DeformationStack& stack);

/// Parses a stack written by to_json (or by hand). Throws clay::Error(Recipe) for malformed
/// input, naming the JSON path and the fix ("steps[2].points[5]: expected 3 numbers, found 2;
/// ..."): not JSON, a wrong format or version, unknown kinds or keys, missing or mistyped fields,
/// wrong counts, non-finite numbers, and every problems() of the resulting stack.
DeformationStack stack_from_json(std::string_view json);

}  // namespace clay::deform
