#pragma once
/// Named tolerances of the kernel. Model units are millimetres; parameters are dimensionless.
/// These are defaults that Options structs copy; nothing reads them as globals at run time.
namespace clay::tolerance {

/// Relative geometric tolerance behind every "exact" claim (multiply by the model size).
inline constexpr double exact_relative = 1e-7;
/// Absolute geometric tolerance in millimetres used when no model size is known.
inline constexpr double geometric_mm = 1e-7;
/// Two knots closer than this (relative to the knot span of the vector) count as one value.
inline constexpr double knot_relative = 1e-12;
/// Tolerance of parameter-space Newton iterations (relative to the domain size).
inline constexpr double parametric_relative = 1e-14;

}  // namespace clay::tolerance
