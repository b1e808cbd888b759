// Cost of find_self_intersection on cubic curves of 100 and 1000 knot spans: a helix (no
// self-intersection, turns 5 mm apart: the cost should grow like the number of spans), a planar
// spiral (no self-intersection, turns 2 mm apart, so the 1000-span one packs 63 turns and many
// more near pairs), a random planar zigzag (crossings everywhere) and a helix whose turns lie
// within the tolerance (near pairs everywhere).
#include <clay/surface/self_intersection.hpp>

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace clay::surface;

namespace {

/// Cubic B-spline, clamped uniform knots, `spans` spans, control point i at f(i / (count - 1)).
template <class F>
BSplineCurve cubic(int spans, F f) {
  const int count = spans + 3;
  Points3 p(count, 3);
  for (int i = 0; i < count; ++i) p.row(i) = f(double(i) / (count - 1)).transpose();
  return make_curve(3, clamped_uniform_basis(3, count).knots, p);
}

/// Archimedean spiral, 16 control points per turn, turns 2 mm apart, starting at radius 20 mm.
BSplineCurve spiral(int spans) {
  const double turns = (spans + 3) / 16.0;
  return cubic(spans, [turns](double s) {
    const double a = 2 * std::numbers::pi * turns * s;
    const double r = 20.0 + 2.0 * turns * s;
    return Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0);
  });
}

BSplineCurve zigzag(int spans) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coord(-100.0, 100.0);
  return cubic(spans, [&](double) { return Eigen::Vector3d(coord(rng), coord(rng), 0.0); });
}

/// Helix of radius 20, pitch 5 mm, 16 control points per turn.
BSplineCurve helix(int spans) {
  const double turns = (spans + 3) / 16.0;
  return cubic(spans, [turns](double s) {
    const double a = 2 * std::numbers::pi * turns * s;
    return Eigen::Vector3d(20 * std::cos(a), 20 * std::sin(a), 5.0 * turns * s);
  });
}

/// Helix of radius 20, pitch 1e-4 mm, 16 control points per turn: every turn within 1e-3 mm of
/// the next.
BSplineCurve flat_helix(int spans) {
  const double turns = (spans + 3) / 16.0;
  return cubic(spans, [turns](double s) {
    const double a = 2 * std::numbers::pi * turns * s;
    return Eigen::Vector3d(20 * std::cos(a), 20 * std::sin(a), 1e-4 * turns * s);
  });
}

void run(benchmark::State& state, const BSplineCurve& c, double tolerance) {
  for (auto _ : state) {
    auto x = find_self_intersection(c, tolerance);
    benchmark::DoNotOptimize(x);
  }
  state.counters["found"] = find_self_intersection(c, tolerance).has_value() ? 1 : 0;
  state.counters["spans"] = static_cast<double>(c.basis.count() - 3);
}

void self_intersection_helix(benchmark::State& state) {
  run(state, helix(static_cast<int>(state.range(0))), 1e-5);
}
void self_intersection_spiral(benchmark::State& state) {
  run(state, spiral(static_cast<int>(state.range(0))), 1e-5);
}
void self_intersection_zigzag(benchmark::State& state) {
  run(state, zigzag(static_cast<int>(state.range(0))), 1e-5);
}
void self_intersection_flat_helix(benchmark::State& state) {
  run(state, flat_helix(static_cast<int>(state.range(0))), 1e-3);
}

}  // namespace

BENCHMARK(self_intersection_helix)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(self_intersection_spiral)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(self_intersection_zigzag)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(self_intersection_flat_helix)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
