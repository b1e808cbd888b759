#pragma once
// The size of an exact composition, known before any patch is composed (internal to
// clay_deform): compose_exact finds every patch's exact degrees first (cheap), predicts the
// joined net from them and the source's continuity, and refuses above ComposeOptions' limits
// with ExactSizeError, which deform_surface catches to make the step's light form instead.
#include <clay/deform/compose.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/error.hpp>
#include <clay/surface/knots.hpp>

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace clay::deform::detail {

/// A clay::Error(DegreeLimit) that also carries the exact composition's predicted size.
class ExactSizeError : public Error {
 public:
  ExactSizeError(const std::string& message, ExactSize size)
      : Error(ErrorCategory::DegreeLimit, message), size_(size) {}
  const ExactSize& size() const noexcept { return size_; }

 private:
  ExactSize size_;
};

/// Where a surface crosses a lattice's interior knot planes along iso-parameter lines: the
/// parameters in u (0) and v (1).
using PlaneCrossings = std::array<std::vector<double>, 2>;

/// The joined net of the patches of `bp` composed to `degrees` (patch (a, b) at a * count_v + b):
/// every patch is elevated to the largest degrees P, Q, and a break where the composition is C^c
/// holds P − min(c, P − 1) knots (ends P + 1). A polynomial map keeps the continuity the
/// `original` surface's knot multiplicities give (c = p − r; a knot inserted to split it adds
/// none); at a crossing of a lattice's knot plane, c is at most `lattice_continuity`. An upper
/// bound of what compose_exact returns: its knot removal also takes out knots where the surface
/// is smoother than their multiplicity says (exact, in exact arithmetic, elsewhere).
ExactSize predicted_size(const surface::BSplineSurface& original, const surface::BezierPatches& bp,
                         const std::vector<std::pair<int, int>>& degrees,
                         const PlaneCrossings& planes = {}, int lattice_continuity = 0);

/// How smooth a B-spline lattice's map is across its knot planes: C^(p − r) for the largest
/// interior multiplicity r of any axis of degree p (0 without interior knots: unused then).
int lattice_continuity(const BSplineLattice& lattice);

/// Throws ExactSizeError when `size` is above options.max_degree (message `degree_message`,
/// which names the first patch above it) or above options.max_control_points.
void check_size(const ExactSize& size, const ComposeOptions& options,
                const std::string& degree_message);

}  // namespace clay::deform::detail
