// Exact FFD composition (issue #7): compose_exact of a bicubic surface of 10 x 10 Bézier patches
// (13 x 13 control points, uniform knots, C2) lying in a skewed frame, with a displaced Bézier
// lattice of degrees (3, 3, 1) (result degree 21 x 21) and (2, 2, 2) (result degree 18 x 18).
// Target: under 20 ms each. "checked" includes the default deviation check (4 x 4 pointwise
// samples per patch, ComposeOptions::check_samples = 4); "unchecked" sets it to 0. One thread.
#include <clay/deform/compose.hpp>
#include <clay/deform/derivatives.hpp>
#include <clay/deform/surface_deformation.hpp>
#include <clay/surface/basis.hpp>

#include <benchmark/benchmark.h>

#include "frames.hpp"

#include <random>

using namespace clay::deform;

namespace {

using clay::bench::skewed_frame;

clay::surface::BSplineSurface bicubic_sheet(const Frame& f, int n = 13) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> bump(0.3, 0.7), wiggle(-0.02, 0.02);
  clay::surface::BSplineSurface s;
  s.u = clay::surface::clamped_uniform_basis(3, n);
  s.v = clay::surface::clamped_uniform_basis(3, n);
  s.points.resize(n * n, 3);
  s.weights = Eigen::VectorXd::Ones(n * n);
  const double step = 0.9 / (n - 1), shake = 0.26 / (n - 1);  // the 13 x 13 sheet's 0.02
  std::uniform_real_distribution<double> jiggle(-shake, shake);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      s.points.row(s.index(i, j)) =
          f.point(0.05 + step * i + (n == 13 ? wiggle(rng) : jiggle(rng)),
                  0.05 + step * j + (n == 13 ? wiggle(rng) : jiggle(rng)), bump(rng))
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

// Issue #41: the composed surface's Jacobian (composition_jacobian: every patch composed once
// with one channel per lattice point), against BM_ComposeExact of the same lattice and sheet in
// the same run, and the adjoint product C^T g (g: a gradient with respect to the composed
// control points). Arg: lattice (0 = (3, 3, 1), 1 = (2, 2, 2)).
void BM_CompositionJacobian(benchmark::State& state) {
  const BezierLattice l =
      lattice(state.range(0) == 0 ? std::array<int, 3>{3, 3, 1} : std::array<int, 3>{2, 2, 2});
  const auto s = bicubic_sheet(l.frame);
  CompositionJacobian j;
  for (auto _ : state) {
    j = composition_jacobian(l, s);
    benchmark::DoNotOptimize(j.matrix.valuePtr());
  }
  state.counters["control_points"] = static_cast<double>(j.matrix.rows());
  state.counters["nonzeros"] = static_cast<double>(j.matrix.nonZeros());
  state.SetLabel(state.range(0) == 0 ? "lattice (3,3,1)" : "lattice (2,2,2)");
}
BENCHMARK(BM_CompositionJacobian)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CompositionJacobianTransposeProduct(benchmark::State& state) {
  const BezierLattice l =
      lattice(state.range(0) == 0 ? std::array<int, 3>{3, 3, 1} : std::array<int, 3>{2, 2, 2});
  const CompositionJacobian j = composition_jacobian(l, bicubic_sheet(l.frame));
  const Eigen::MatrixXd g = Eigen::MatrixXd::Random(j.matrix.rows(), 3);
  Eigen::MatrixXd adjoint;
  for (auto _ : state) {
    adjoint = j.matrix.transpose() * g;
    benchmark::DoNotOptimize(adjoint.data());
  }
  state.SetLabel(state.range(0) == 0 ? "C^T g, lattice (3,3,1)" : "C^T g, lattice (2,2,2)");
}
BENCHMARK(BM_CompositionJacobianTransposeProduct)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// Issue #38: the exact composition against the light form of the same (3, 3, 1) lattice step
// (deform_surface with the default Budget: certified bicubic within 1e-4 of the size), in one
// run. Arguments: control points per direction of the sheet (13: 10 x 10 patches; 33: 30 x 30),
// 0 = exact, 1 = light. Counters: the result's net, the exact net (composed, or predicted for the
// light form) and the light form's certified bound.
void BM_ExactOrLight(benchmark::State& state) {
  const BezierLattice l = lattice({3, 3, 1});
  const auto s = bicubic_sheet(l.frame, static_cast<int>(state.range(0)));
  const bool light = state.range(1) == 1;
  SurfaceDeformationOptions options;
  if (light) options.budget = Budget{};
  SurfaceDeformationResult r;
  for (auto _ : state) {
    r = deform_surface(Deformation(l), s, options);
    benchmark::DoNotOptimize(r.surface.points.data());
  }
  const StepOutcome& o = r.report.steps.front();
  const double exact_points =
      light ? static_cast<double>(o.exact_size.control_points) : double(o.compose.control_points);
  state.counters["control_points"] = static_cast<double>(r.surface.points.rows());
  state.counters["exact_control_points"] = exact_points;
  state.counters["bound_mm"] = light ? o.bound_mm : 0.0;
  state.SetLabel(std::string(light ? "light form" : "exact") + ", sheet " +
                 std::to_string(state.range(0)) + " x " + std::to_string(state.range(0)));
}
BENCHMARK(BM_ExactOrLight)
    ->ArgsProduct({{13, 33}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
