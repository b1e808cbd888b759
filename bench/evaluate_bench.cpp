// Grid evaluation throughput of a bicubic surface of 20 x 20 Bézier patches (23 x 23 control
// points): clay::surface::evaluate_grid against OpenCASCADE's Geom_BSplineSurface::D0 called per
// point, on the same grid, polynomial and rational. Reported as items_per_second = points/s.
#include <clay/surface/evaluate.hpp>

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "occt_reference.hpp"

using namespace clay::surface;

namespace {

BSplineSurface bicubic_20x20(bool rational) {
  BSplineBasis b = clamped_uniform_basis(3, 23);
  Points3 p(23 * 23, 3);
  Eigen::VectorXd w = Eigen::VectorXd::Ones(23 * 23);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> jitter(-5.0, 5.0), weight(0.5, 2.0);
  for (int i = 0; i < 23; ++i)
    for (int j = 0; j < 23; ++j) {
      p.row(i * 23 + j) << 50.0 * i + jitter(rng), 50.0 * j + jitter(rng),
          30.0 * std::sin(0.4 * i) * std::cos(0.3 * j);
      if (rational) w[i * 23 + j] = weight(rng);
    }
  return make_surface(b, b, p, w);
}

void grid_clayform(benchmark::State& state) {
  const BSplineSurface s = bicubic_20x20(state.range(1) != 0);
  const auto us = linspace(0, 1, static_cast<int>(state.range(0)));
  const auto vs = us;
  for (auto _ : state) {
    Points3 g = evaluate_grid(s, us, vs);
    benchmark::DoNotOptimize(g.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(us.size() * vs.size()));
}

void grid_occt_d0(benchmark::State& state) {
  const BSplineSurface s = bicubic_20x20(state.range(1) != 0);
  const occt_reference::GridEvaluator occt(s);
  const auto us = linspace(0, 1, static_cast<int>(state.range(0)));
  const auto vs = us;
  for (auto _ : state) {
    Points3 g = occt.evaluate_grid(us, vs);
    benchmark::DoNotOptimize(g.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(us.size() * vs.size()));
}

/// 4096 scattered parameter pairs (no grid reuse possible).
std::pair<std::vector<double>, std::vector<double>> scattered() {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> us(4096), vs(4096);
  for (size_t k = 0; k < us.size(); ++k) us[k] = unit(rng), vs[k] = unit(rng);
  return {us, vs};
}

void point_clayform(benchmark::State& state) {
  const BSplineSurface s = bicubic_20x20(state.range(0) != 0);
  const auto [us, vs] = scattered();
  for (auto _ : state) {
    for (size_t k = 0; k < us.size(); ++k) benchmark::DoNotOptimize(evaluate(s, us[k], vs[k]));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(us.size()));
}

void point_occt_d0(benchmark::State& state) {
  const BSplineSurface s = bicubic_20x20(state.range(0) != 0);
  const occt_reference::GridEvaluator occt(s);
  const auto [us, vs] = scattered();
  for (auto _ : state) {
    for (size_t k = 0; k < us.size(); ++k) benchmark::DoNotOptimize(occt.evaluate(us[k], vs[k]));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(us.size()));
}

}  // namespace

// Arguments: grid side (points per direction), rational (0/1).
BENCHMARK(grid_clayform)->Args({201, 0})->Args({201, 1})->Args({1001, 0})->Args({1001, 1});
BENCHMARK(grid_occt_d0)->Args({201, 0})->Args({201, 1})->Args({1001, 0})->Args({1001, 1});
BENCHMARK(point_clayform)->Arg(0)->Arg(1);
BENCHMARK(point_occt_d0)->Arg(0)->Arg(1);

BENCHMARK_MAIN();
