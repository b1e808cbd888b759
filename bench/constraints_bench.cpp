// Constraint solve plus DOF / redundancy diagnosis (one clay::constraints::solve call, which
// builds the model, substitutes, solves and diagnoses) from a start perturbed by ±1 mm:
//   staircase: a chain of N segments, each with its own two end points, coincident joints,
//              alternating horizontal/vertical, a length each, first point fixed (DOF 0);
//   zigzag:    the same chain with ±60° angles between neighbours instead of H/V (DOF 1);
//   rectangles: R independent rectangles (8 points, 4 coincident, 2 H, 2 V, width, height,
//              one corner fixed; DOF 0).
//   loose staircase: the staircase with its last 1-10 vertical constraints removed (1-10 DOF);
//   free end:  one line, fixed start, length 10, end drawn at (0.02, 10.5) (DOF 1; issue #18).
// Targets (issue #3): 1,000-segment chains < 50 ms, 3,000 < 200 ms, 750 rectangles < 30 ms.
#include <clay/constraints.hpp>

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstddef>
#include <numbers>
#include <random>
#include <stdexcept>

using namespace clay::constraints;
using clay::sketch::Sketch;

namespace {

struct Case {
  Sketch sketch;
  std::vector<Constraint> constraints;
};

/// A chain through `corners` (exact), each segment with its own end points perturbed by ±1.
Case chain(const std::vector<Eigen::Vector2d>& corners, std::mt19937& rng) {
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  Case c;
  const auto plane = c.sketch.add_plane({});
  std::vector<PointId> ends;
  for (size_t k = 0; k + 1 < corners.size(); ++k) {
    const PointId a =
        c.sketch.add_point(plane, corners[k] + Eigen::Vector2d(jitter(rng), jitter(rng)));
    const PointId b =
        c.sketch.add_point(plane, corners[k + 1] + Eigen::Vector2d(jitter(rng), jitter(rng)));
    c.sketch.add_line(a, b);
    if (k > 0) c.constraints.push_back(coincident(ends.back(), a));
    ends.push_back(b);
    c.constraints.push_back(distance(a, b, (corners[k + 1] - corners[k]).norm()));
  }
  c.constraints.push_back(fixed(PointId{0}));
  return c;
}

Case staircase(int n) {
  std::mt19937 rng(7);
  std::vector<Eigen::Vector2d> corners{{0, 0}};
  for (int k = 0; k < n; ++k) {
    const double length = 10 + k % 3;
    corners.push_back(corners.back() +
                      (k % 2 == 0 ? Eigen::Vector2d(length, 0) : Eigen::Vector2d(0, length)));
  }
  Case c = chain(corners, rng);
  for (int k = 0; k < n; ++k)
    c.constraints.push_back(k % 2 == 0 ? horizontal(EntityId{k}) : vertical(EntityId{k}));
  return c;
}

/// The staircase with its last `free` vertical constraints removed: `free` degrees of freedom
/// (issue #18: under-constrained sketches, the normal state while a stylist draws).
Case loose_staircase(int n, int free) {
  Case c = staircase(n);
  const size_t first_hv =
      c.constraints.size() - static_cast<size_t>(n);  // H/V appended last, by segment
  for (int k = n - 1, removed = 0; k >= 0 && removed < free; --k)
    if (k % 2 == 1) {
      c.constraints.erase(c.constraints.begin() +
                          static_cast<std::ptrdiff_t>(first_hv + static_cast<size_t>(k)));
      ++removed;
    }
  return c;
}

/// One line with a fixed start and a length of 10, its end drawn at (0.02, 10.5): 1 DOF.
Case free_end_line() {
  Case c;
  const auto plane = c.sketch.add_plane({});
  const PointId a = c.sketch.add_point(plane, {0, 0}), b = c.sketch.add_point(plane, {0.02, 10.5});
  c.sketch.add_line(a, b);
  c.constraints = {fixed(a), distance(a, b, 10)};
  return c;
}

Case zigzag(int n) {
  std::mt19937 rng(11);
  std::vector<Eigen::Vector2d> corners{{0, 0}};
  for (int k = 0; k < n; ++k) {
    const double a = (k % 2 == 0 ? 30.0 : -30.0) * std::numbers::pi / 180;
    corners.push_back(corners.back() + (10 + k % 3) * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  Case c = chain(corners, rng);
  for (int k = 0; k + 1 < n; ++k) c.constraints.push_back(angle(EntityId{k}, EntityId{k + 1}, 60));
  return c;
}

Case rectangles(int r) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  Case c;
  const auto plane = c.sketch.add_plane({});
  for (int k = 0; k < r; ++k) {
    const Eigen::Vector2d o(60.0 * (k % 50), 40.0 * (k / 50));
    const double w = 30 + k % 7, h = 20 + k % 5;
    const Eigen::Vector2d q[4] = {o, o + Eigen::Vector2d(w, 0), o + Eigen::Vector2d(w, h),
                                  o + Eigen::Vector2d(0, h)};
    std::vector<PointId> p;
    std::vector<EntityId> side;
    for (int s = 0; s < 4; ++s) {
      p.push_back(c.sketch.add_point(plane, q[s] + Eigen::Vector2d(jitter(rng), jitter(rng))));
      p.push_back(
          c.sketch.add_point(plane, q[(s + 1) % 4] + Eigen::Vector2d(jitter(rng), jitter(rng))));
      side.push_back(
          c.sketch.add_line(p[static_cast<size_t>(2 * s)], p[static_cast<size_t>(2 * s + 1)]));
    }
    for (int s = 0; s < 4; ++s)
      c.constraints.push_back(
          coincident(p[static_cast<size_t>(2 * s + 1)], p[static_cast<size_t>((2 * s + 2) % 8)]));
    c.constraints.push_back(horizontal(side[0]));
    c.constraints.push_back(vertical(side[1]));
    c.constraints.push_back(horizontal(side[2]));
    c.constraints.push_back(vertical(side[3]));
    c.constraints.push_back(distance(p[0], p[1], w));
    c.constraints.push_back(distance(p[2], p[3], h));
    c.constraints.push_back(fixed(p[0]));
  }
  return c;
}

void run(benchmark::State& state, const Case& c, int expected_dof) {
  SolveReport last;
  for (auto _ : state) {
    SolveResult r = solve(c.sketch, c.constraints);
    benchmark::DoNotOptimize(r.sketch.points.data());
    last = std::move(r.report);
  }
  state.counters["iterations"] =
      last.summary.iterations;  // also when it fails: the figure to compare
  if (!last.summary.converged() || last.degrees_of_freedom != expected_dof)
    state.SkipWithError(("not solved as expected: " + last.summary.brief()).c_str());
  state.counters["equations"] = last.equations;
  state.counters["dof"] = last.degrees_of_freedom;
  state.counters["iterations"] = last.summary.iterations;
  state.counters["solve_ms"] = 1e3 * last.solve_seconds;
  state.counters["diagnose_ms"] = 1e3 * last.diagnose_seconds;
}

void staircase_chain(benchmark::State& state) {
  run(state, staircase(static_cast<int>(state.range(0))), 0);
}
void zigzag_chain(benchmark::State& state) {
  run(state, zigzag(static_cast<int>(state.range(0))), 1);
}
void loose_staircase_chain(benchmark::State& state) {
  run(state, loose_staircase(static_cast<int>(state.range(0)), static_cast<int>(state.range(1))),
      static_cast<int>(state.range(1)));
}
void free_end(benchmark::State& state) { run(state, free_end_line(), 1); }
void independent_rectangles(benchmark::State& state) {
  run(state, rectangles(static_cast<int>(state.range(0))), 0);
}

}  // namespace

BENCHMARK(staircase_chain)->Arg(10)->Arg(100)->Arg(1000)->Arg(3000)->Unit(benchmark::kMillisecond);
BENCHMARK(zigzag_chain)->Arg(10)->Arg(100)->Arg(1000)->Arg(3000)->Unit(benchmark::kMillisecond);
BENCHMARK(loose_staircase_chain)
    ->Args({10, 1})
    ->Args({100, 5})
    ->Args({1000, 1})
    ->Args({1000, 10})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(free_end)->Unit(benchmark::kMicrosecond);
BENCHMARK(independent_rectangles)
    ->Arg(10)
    ->Arg(100)
    ->Arg(750)
    ->Arg(1000)
    ->Arg(3000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
