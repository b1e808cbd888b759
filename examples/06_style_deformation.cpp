// Example 06 — the stylist's main gesture (Han, De Amicis & Conti 2007): a closed bound curve on a
// car hood says where, a target curve says what shape. The paper's force mode approximates the
// target; the exact mode makes the hood pass through every key point while the surface around
// the bound stays untouched. Both results are exported to STEP and read back.
//
//   example_06_style_deformation [output folder]
//
// Exits non-zero if the exact mode misses a key point by more than 1e-6 of the model size, turns
// the tangent plane at the bound by more than 0.5 degrees, moves a vertex outside the bound, or if
// the STEP round trip changes the surface.
#include <clay/deform.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/basis.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>

using namespace clay;
using namespace clay::deform;

namespace {

// A 1200 x 800 mm hood with a crown: a 16 x 16 bicubic net over the Greville points.
surface::BSplineSurface hood() {
  const int n = 16;
  const auto basis = surface::clamped_uniform_basis(3, n);
  const auto xi = surface::greville_abscissae(basis);
  surface::Points3 p(n * n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = -600 + 1200 * xi[static_cast<size_t>(i)],
                   y = -400 + 800 * xi[static_cast<size_t>(j)];
      p.row(i * n + j) << x, y,
          80 * (1 - (x / 700) * (x / 700)) * (1 - (y / 500) * (y / 500)) + 0.05 * x;
    }
  return surface::make_surface(basis, basis, p);
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path out =
      argc > 1 ? argv[1] : std::filesystem::temp_directory_path() / "clayform_06";
  std::filesystem::create_directories(out);
  const surface::BSplineSurface parent = hood();

  // The bound: an ellipse 700 x 500 mm drawn above the hood (it is projected onto it).
  surface::BSplineCurve bound =
      surface::circular_arc({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1.0, 0.0, 2 * M_PI);
  for (Eigen::Index r = 0; r < bound.points.rows(); ++r)
    bound.points.row(r) << 350 * bound.points(r, 0), 250 * bound.points(r, 1), 150;
  // The target: a crease line across the hood rising up to 50 mm above it.
  surface::Points3 t(4, 3);
  t << -60, -180, 70, -40, -60, 150, -40, 60, 150, -60, 180, 70;
  const surface::BSplineCurve target = surface::make_curve(3, {0, 0, 0, 0, 1, 1, 1, 1}, t);

  StyleOptions options;  // paper mode, λ = 1, relaxation, smoothing
  const InfluenceRegion region = influence_factors(parent, bound, options);  // eq. 2
  const StyleResult paper = style_deform(parent, region, target, options);
  options.mode = StyleMode::Exact;  // through every key point, G1 at the bound
  const StyleResult exact = style_deform(parent, region, target, options);

  const double size = exact.report.model_size;
  for (const auto* r : {&paper, &exact}) {
    const StyleReport& q = r->report;
    std::printf("%-5s: %s\n", q.mode == StyleMode::Paper ? "paper" : "exact", q.message.c_str());
    std::printf("       key-point deviation %.3g mm (%.1e of the size), along the target %.3g mm\n",
                q.target_deviation, q.target_deviation / size, q.target_curve_deviation);
    std::printf("       at the bound: position %.3g mm, tangent plane %.3g deg; locality %.3g mm\n",
                q.boundary_position_jump, q.boundary_tangent_angle, q.locality);
  }
  const auto step = surface::write_step({paper.surface, exact.surface}, out / "hood.step");
  const auto back = surface::read_step(out / "hood.step");
  const bool round_trip = back.size() == 2 && surface::identical(back[1], exact.surface);
  std::printf("STEP: %s, %d faces, valid %s, read back bit for bit: %s\n",
              (out / "hood.step").c_str(), step.faces, step.valid ? "yes" : "no",
              round_trip ? "yes" : "no");

  const bool ok = exact.report.target_deviation <= 1e-6 * size &&
                  exact.report.boundary_tangent_angle <= 0.5 && exact.report.locality == 0 &&
                  paper.report.locality == 0 && round_trip && step.valid;
  return ok ? 0 : 1;
}
