// A surface's deviation map as a studio frame (frames.hpp).
#include "frame_header.hpp"
#include "frames.hpp"

#include <clay/studio.hpp>
#include <clay/surface/evaluate.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>

namespace clay::recipe {

using frames::frame_with_header;
using Json = nlohmann::json;

/// The viewer's deviation map (docs/viewer.md) of a surface: on a rows x cols grid evenly over
/// its domain, the distance from the surface to its last stage's pointwise deformation of the
/// surface before it, at the same fractions of that surface's domain (exact composition: rounding;
/// a refit: its error). A frame {"kind": "deviation", "name", "step", "rows", "cols", "max"}
/// then rows * cols float64, row (u) by row.
std::vector<std::uint8_t> deviation_frame(const std::string& name, const surface::BSplineSurface& s,
                                          const Stage& stage, int rows, int cols) {
  // The same fractions of both domains, the last one each domain's end exactly.
  auto fractions = [](const surface::BSplineBasis& basis, int n) {
    const auto [first, last] = basis.domain();
    std::vector<double> t(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k)
      t[static_cast<std::size_t>(k)] = k == n - 1 ? last : first + (last - first) * k / (n - 1);
    return t;
  };
  const surface::Points3 after =
      surface::evaluate_grid(s, fractions(s.u, rows), fractions(s.v, cols));
  const surface::Points3 before = surface::evaluate_grid(
      stage.before, fractions(stage.before.u, rows), fractions(stage.before.v, cols));
  std::vector<double> values(static_cast<std::size_t>(after.rows()));
  double worst = 0;
  for (Eigen::Index k = 0; k < after.rows(); ++k) {
    const Eigen::Vector3d q = stage.map(before.row(k).transpose());
    const double d = (after.row(k).transpose() - q).norm();
    values[static_cast<std::size_t>(k)] = d;
    worst = std::max(worst, d);
  }
  const Json header = {{"kind", "deviation"}, {"name", name}, {"step", stage.step},
                       {"rows", rows},        {"cols", cols}, {"max", worst}};
  return net_frame(header.dump(), values, {});
}

}  // namespace clay::recipe
