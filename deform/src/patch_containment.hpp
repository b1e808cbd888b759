#pragma once
// Whether a composed coordinate c = C / W stays within [lo, hi] over a whole patch (internal to
// clay_deform): the exact composition is one polynomial only inside the lattice (compose.cpp).
#include "bernstein_poly.hpp"

#include <optional>

namespace clay::deform::detail {

/// Where c = C / W leaves [lo, hi] (beyond tol) on the patch: the patch-local parameter and value,
/// `certain` false when the search could not decide within its budget (then `value` is a bound of
/// c from the convex hull, not a value of the surface).
struct Violation {
  double x = 0, y = 0, value = 0;
  bool certain = true;
};

/// Certifies lo − tol <= C / W <= hi + tol on the patch (W > 0), or finds where it fails: the
/// polynomials g = C − (hi + tol) W and (lo − tol) W − C must stay <= 0; each is decided cell by
/// cell (decide above), subdividing undecided cells down to 2^-max_depth of the patch, at most
/// `budget` cells per side. A violation found is a point of the surface (certain, with its true
/// value); a search that runs out of budget reports the convex hull's bound (not certain).
std::optional<Violation> leaves(const Poly& cw, double lo, double hi, double tol);

}  // namespace clay::deform::detail
