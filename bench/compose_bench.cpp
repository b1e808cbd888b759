// Exact FFD composition (issue #7): compose_exact of a bicubic surface of 10 x 10 Bézier patches
// (13 x 13 control points, uniform knots, C2) lying in a skewed frame, with a displaced Bézier
// lattice of degrees (3, 3, 1) (result degree 21 x 21) and (2, 2, 2) (result degree 18 x 18).
// Target: under 20 ms each. "checked" includes the default deviation check (4 x 4 pointwise
// samples per patch, ComposeOptions::check_samples = 4); "unchecked" sets it to 0. One thread.
#include <clay/deform/compose.hpp>
#include <clay/surface/basis.hpp>

#include <benchmark/benchmark.h>

#include "frames.hpp"

#include <random>

using namespace clay::deform;

namespace {

using clay::bench::skewed_frame;

clay::surface::BSplineSurface bicubic_sheet(const Frame& f) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> bump(0.3, 0.7), wiggle(-0.02, 0.02);
  clay::surface::BSplineSurface s;
  s.u = clay::surface::clamped_uniform_basis(3, 13);
  s.v = clay::surface::clamped_uniform_basis(3, 13);
  s.points.resize(13 * 13, 3);
  s.weights = Eigen::VectorXd::Ones(13 * 13);
  for (int i = 0; i < 13; ++i)
    for (int j = 0; j < 13; ++j)
      s.points.row(s.index(i, j)) = f.point(0.05 + 0.9 * i / 12.0 + wiggle(rng),
                                            0.05 + 0.9 * j / 12.0 + wiggle(rng), bump(rng))
                                        .transpose();
  return s;
}

BezierLattice lattice(std::array<int, 3> degrees) {
  BezierLattice l = make_bezier_lattice(skewed_frame(), degrees);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> c(-8.0, 8.0);
  for (Eigen::Index r = 0; r < l.points.rows(); ++r)
    l.points.row(r) += Eigen::RowVector3d(c(rng), c(rng), c(rng));
  return l;
}

// Arguments: lattice (0 = (3, 3, 1), 1 = (2, 2, 2)), check samples per patch and direction.
void BM_ComposeExact(benchmark::State& state) {
  const BezierLattice l =
      lattice(state.range(0) == 0 ? std::array<int, 3>{3, 3, 1} : std::array<int, 3>{2, 2, 2});
  const auto s = bicubic_sheet(l.frame);
  ComposeOptions options;
  options.check_samples = static_cast<int>(state.range(1));
  ComposeReport report;
  for (auto _ : state) {
    ComposeResult r = compose_exact(l, s, options);
    benchmark::DoNotOptimize(r.surface.points.data());
    report = r.report;
  }
  state.counters["degree"] = report.degree_u;
  state.counters["control_points"] = static_cast<double>(report.control_points);
  state.counters["knots_removed"] = report.knots_removed;
  state.counters["max_deviation"] = report.max_relative_deviation;
  state.SetLabel(state.range(0) == 0 ? "lattice (3,3,1)" : "lattice (2,2,2)");
}
BENCHMARK(BM_ComposeExact)
    ->ArgsProduct({{0, 1}, {4, 0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
