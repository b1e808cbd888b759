// FFD throughput (issue #6): deformed points per second (items_per_second) for a tricubic Bézier
// lattice (4 x 4 x 4 control points) and a cubic B-spline lattice of 8 x 8 x 8 cells, on 1 and 4
// million points spread at random (uniform, random order: no coherence for the cell sort to
// exploit) in a skewed frame, one and two threads. "rows" is an N x 3 row-major matrix deformed
// into a reused one, "columns" three structure-of-arrays buffers. Wall time (UseRealTime).
// Direct manipulation (Hsu et al. §3) on the same cubic 8 x 8 x 8 B-spline lattice: a one-off
// manipulate() of 10 / 100 / 400 points (B, factorization, solve, pointwise check), and one drag
// step (DirectManipulator::move, factorization reused).
#include <clay/deform/direct_manipulation.hpp>
#include <clay/deform/frozen_lattice.hpp>

#include <benchmark/benchmark.h>

#include <random>
#include <vector>

using namespace clay::deform;

namespace {

Frame skewed_frame() {
  Frame f;
  f.origin = Eigen::Vector3d(-120.0, 35.0, 10.0);
  f.s = Eigen::Vector3d(300.0, 20.0, -10.0);
  f.t = Eigen::Vector3d(40.0, 180.0, 15.0);
  f.u = Eigen::Vector3d(-10.0, 25.0, 90.0);
  return f;
}

template <class Lattice>
Lattice displaced(Lattice lattice) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> c(-8.0, 8.0);
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    lattice.points.row(r) += Eigen::RowVector3d(c(rng), c(rng), c(rng));
  return lattice;
}

FrozenLattice frozen(bool bspline) {
  if (bspline) return FrozenLattice(displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8})));
  return FrozenLattice(displaced(make_bezier_lattice(skewed_frame(), {3, 3, 3})));
}

Points3 random_points(Eigen::Index n) {
  const Frame f = skewed_frame();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Points3 p(n, 3);
  for (Eigen::Index r = 0; r < n; ++r) p.row(r) = f.point(unit(rng), unit(rng), unit(rng)).transpose();
  return p;
}

// Arguments: points, threads, lattice (0 = Bézier 4x4x4, 1 = B-spline 8x8x8 cells).
void rows(benchmark::State& state) {
  const FrozenLattice lattice = frozen(state.range(2) != 0);
  const Points3 in = random_points(state.range(0));
  Points3 out(in.rows(), 3);
  const DeformOptions options{static_cast<int>(state.range(1))};
  for (auto _ : state) {
    deform_points(lattice, in, out, options);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetLabel(state.range(2) ? "bspline 8x8x8 cells cubic" : "bezier tricubic");
}

void columns(benchmark::State& state) {
  const FrozenLattice lattice = frozen(state.range(2) != 0);
  const Points3 p = random_points(state.range(0));
  const size_t n = static_cast<size_t>(p.rows());
  std::vector<double> x(n), y(n), z(n), ox(n), oy(n), oz(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = p(static_cast<Eigen::Index>(i), 0);
    y[i] = p(static_cast<Eigen::Index>(i), 1);
    z[i] = p(static_cast<Eigen::Index>(i), 2);
  }
  const DeformOptions options{static_cast<int>(state.range(1))};
  for (auto _ : state) {
    deform_points(lattice, PointColumns{x, y, z}, MutablePointColumns{ox, oy, oz}, options);
    benchmark::DoNotOptimize(ox.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
  state.SetLabel(state.range(2) ? "bspline 8x8x8 cells cubic" : "bezier tricubic");
}

void arguments(benchmark::internal::Benchmark* b) {
  b->ArgNames({"points", "threads", "bspline"});
  for (int lattice : {0, 1})
    for (int n : {1'000'000, 4'000'000})
      for (int threads : {1, 2}) b->Args({n, threads, lattice});
  b->UseRealTime()->Unit(benchmark::kMillisecond);
}

/// Points inside the lattice and targets 5 mm away from their images.
std::vector<PointMove> point_moves(const BSplineLattice& lattice, Eigen::Index n) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(0.05, 0.95), offset(-5.0, 5.0);
  std::vector<PointMove> moves;
  for (Eigen::Index r = 0; r < n; ++r) {
    const Eigen::Vector3d x = lattice.frame.point(unit(rng), unit(rng), unit(rng));
    moves.push_back({x, deform_point(lattice, x) + Eigen::Vector3d(offset(rng), offset(rng), offset(rng))});
  }
  return moves;
}

void manipulate_once(benchmark::State& state) {
  const BSplineLattice lattice = displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8}));
  const auto moves = point_moves(lattice, state.range(0));
  for (auto _ : state) {
    auto result = manipulate(lattice, moves);
    benchmark::DoNotOptimize(result.lattice.points.data());
  }
  state.SetLabel("bspline 8x8x8 cells cubic");
}

void manipulate_drag(benchmark::State& state) {
  const BSplineLattice lattice = displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8}));
  const auto moves = point_moves(lattice, state.range(0));
  Points3 points(state.range(0), 3), targets(state.range(0), 3);
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    points.row(r) = moves[static_cast<size_t>(r)].point.transpose();
    targets.row(r) = moves[static_cast<size_t>(r)].target.transpose();
  }
  const DirectManipulator<BSplineLattice> drag(lattice, points);
  for (auto _ : state) {
    auto result = drag.move(targets);
    benchmark::DoNotOptimize(result.lattice.points.data());
  }
  state.SetLabel("bspline 8x8x8 cells cubic");
}

}  // namespace

BENCHMARK(rows)->Apply(arguments);
BENCHMARK(columns)->Apply(arguments);
BENCHMARK(manipulate_once)->ArgName("points")->Arg(10)->Arg(100)->Arg(400)->Unit(benchmark::kMillisecond);
BENCHMARK(manipulate_drag)->ArgName("points")->Arg(10)->Arg(100)->Arg(400)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
