// The size of an exact composition from its patches' degrees (compose_size.hpp).
#include "compose_size.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace clay::deform::detail {

namespace {

/// Control points along one direction (see predicted_size).
long count_along(const surface::BSplineBasis& original, const std::vector<double>& breaks,
                 const std::vector<double>& planes, int P, int lattice_continuity) {
  const auto [d0, d1] = original.domain();
  const double merge = 1e-12 * (d1 - d0);  // as split_at_planes merges crossings
  long n = P + 1;
  for (std::size_t k = 1; k + 1 < breaks.size(); ++k) {
    const double t = breaks[k];
    long c = original.degree - std::count(original.knots.begin(), original.knots.end(), t);
    if (std::any_of(planes.begin(), planes.end(),
                    [&](double x) { return std::abs(x - t) <= merge; }))
      c = std::min<long>(c, lattice_continuity);
    n += P - std::clamp<long>(c, 0, P - 1);
  }
  return n;
}

}  // namespace

ExactSize predicted_size(const surface::BSplineSurface& original, const surface::BezierPatches& bp,
                         const std::vector<std::pair<int, int>>& degrees,
                         const PlaneCrossings& planes, int lattice_continuity) {
  ExactSize size;
  for (const auto& [du, dv] : degrees) {
    size.degree_u = std::max(size.degree_u, du);
    size.degree_v = std::max(size.degree_v, dv);
  }
  size.degree_u = std::max(size.degree_u, 1);
  size.degree_v = std::max(size.degree_v, 1);
  size.control_points =
      count_along(original.u, bp.breaks_u, planes[0], size.degree_u, lattice_continuity) *
      count_along(original.v, bp.breaks_v, planes[1], size.degree_v, lattice_continuity);
  return size;
}

int lattice_continuity(const BSplineLattice& lattice) {
  int c = std::numeric_limits<int>::max();
  for (const auto& b : lattice.bases) {
    const auto first = b.knots.begin() + b.degree + 1, last = b.knots.end() - b.degree - 1;
    for (auto k = first; k < last; ++k)
      c = std::min<int>(c, b.degree - static_cast<int>(std::count(first, last, *k)));
  }
  return c == std::numeric_limits<int>::max() ? 0 : c;
}

void check_size(const ExactSize& size, const ComposeOptions& options,
                const std::string& degree_message) {
  if (std::max(size.degree_u, size.degree_v) > options.max_degree)
    throw ExactSizeError(degree_message, size);
  if (options.max_control_points > 0 && size.control_points > options.max_control_points)
    throw ExactSizeError(
        "compose_exact: the exact composition would have up to " +
            std::to_string(size.control_points) + " control points (degree " +
            std::to_string(size.degree_u) + " x " + std::to_string(size.degree_v) +
            "), above the limit " + std::to_string(options.max_control_points) +
            " (ComposeOptions::max_control_points); raise it, use a lattice of lower degree, or "
            "approximate the deformed surface within a tolerance (a light form)",
        size);
}

}  // namespace clay::deform::detail
