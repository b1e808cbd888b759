// FFD throughput (issue #6): deformed points per second (items_per_second) for a tricubic Bézier
// lattice (4 x 4 x 4 control points) and a cubic B-spline lattice of 8 x 8 x 8 cells, on 1 and 4
// million points spread at random (uniform, random order: no coherence for the cell sort to
// exploit) in a skewed frame, one and two threads. "rows" is an N x 3 row-major matrix deformed
// into a reused one, "columns" three structure-of-arrays buffers. Wall time (UseRealTime).
// Extended lattices (Coquillart): freezing and re-evaluating 100,000 points in a cylindrical
// lattice of 12 sectors x 2 rings x 2 layers (merged axis), one and two threads.
// "regular": Barr's twist (linear angle), bend and taper (quadratic profile) about a tilted axis,
// 1 million points of the same cloud, rows into a reused matrix.
// Direct manipulation (Hsu et al. §3) on the same cubic 8 x 8 x 8 B-spline lattice: a one-off
// manipulate() of 10 / 100 / 400 points (B, factorization, solve, pointwise check), and one drag
// step (DirectManipulator::move, factorization reused).
// Certified refit: a bicubic loft through four sections (about 160 mm) under a twist of 0.01
// rad/mm, fitted bicubic and certified to 1e-4 of its size (refit_deformed, default options).
#include <clay/deform/direct_manipulation.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/frozen_lattice.hpp>
#include <clay/deform/refit.hpp>
#include <clay/deform/regular.hpp>
#include <clay/surface/skin.hpp>

#include <benchmark/benchmark.h>

#include "frames.hpp"

#include <cmath>
#include <random>
#include <vector>

using namespace clay::deform;

namespace {

using clay::bench::skewed_frame;

template <class Lattice>
Lattice displaced(Lattice lattice) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> c(-8.0, 8.0);
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    lattice.points.row(r) += Eigen::RowVector3d(c(rng), c(rng), c(rng));
  return lattice;
}

FrozenLattice frozen(bool bspline) {
  if (bspline)
    return FrozenLattice(displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8})));
  return FrozenLattice(displaced(make_bezier_lattice(skewed_frame(), {3, 3, 3})));
}

Points3 random_points(Eigen::Index n) {
  const Frame f = skewed_frame();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Points3 p(n, 3);
  for (Eigen::Index r = 0; r < n; ++r)
    p.row(r) = f.point(unit(rng), unit(rng), unit(rng)).transpose();
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

CylinderSpec bench_cylinder() {
  CylinderSpec s;
  s.origin = Eigen::Vector3d(10.0, -20.0, 5.0);
  s.axis = Eigen::Vector3d(0.1, 0.2, 1.0);
  s.radius = 40;
  s.height = 60;
  s.sectors = 12;
  s.rings = 2;
  s.layers = 2;
  return s;
}

/// Points uniform in the cylinder (area-uniform radius), random order.
Points3 cylinder_points(const CylinderSpec& s, Eigen::Index n) {
  const Eigen::Vector3d e3 = s.axis.normalized();
  const Eigen::Vector3d e1 = (s.reference - s.reference.dot(e3) * e3).normalized(),
                        e2 = e3.cross(e1);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Points3 p(n, 3);
  for (Eigen::Index r = 0; r < n; ++r) {
    const double rho = s.radius * std::sqrt(unit(rng)), a = 6.283185307179586 * unit(rng);
    p.row(r) = (s.origin + s.height * unit(rng) * e3 + rho * (std::cos(a) * e1 + std::sin(a) * e2))
                   .transpose();
  }
  return p;
}

// Arguments: points, threads.
void extended_freeze(benchmark::State& state) {
  const ExtendedLattice lattice = make_cylindrical_lattice(bench_cylinder());
  const Points3 in = cylinder_points(bench_cylinder(), state.range(0));
  FreezeOptions options;
  options.threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    FrozenPoints f = freeze(lattice, in, options);
    benchmark::DoNotOptimize(f.points.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetLabel("cylindrical 12x2x2 chunks");
}

void extended_evaluate(benchmark::State& state) {
  ExtendedLattice lattice = make_cylindrical_lattice(bench_cylinder());
  const Points3 in = cylinder_points(bench_cylinder(), state.range(0));
  const FrozenPoints f = freeze(lattice, in);
  lattice.points = displaced(ExtendedLattice{lattice}).points;
  const DeformOptions options{static_cast<int>(state.range(1))};
  for (auto _ : state) {
    Points3 out = evaluate(lattice, f, options);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetLabel("cylindrical 12x2x2 chunks");
}

void extended_arguments(benchmark::internal::Benchmark* b) {
  b->ArgNames({"points", "threads"});
  for (int threads : {1, 2}) b->Args({100'000, threads});
  b->UseRealTime()->Unit(benchmark::kMillisecond);
}

// Arguments: points, threads, kind (0 = twist, 1 = bend, 2 = taper).
void regular(benchmark::State& state) {
  const AxisFrame frame{Eigen::Vector3d(30.0, 120.0, 50.0), Eigen::Vector3d(0.2, 1.0, 0.1),
                        Eigen::Vector3d(0.0, 0.0, 1.0)};
  const Twist twist{frame, {0.1, 0.01}};
  const Bend bend{frame, -60.0, 80.0, 10.0, 0.01};
  const Taper taper{frame, {1.0, 2e-3, -1e-5}};
  const Points3 in = random_points(state.range(0));
  Points3 out(in.rows(), 3);
  const DeformOptions options{static_cast<int>(state.range(1))};
  const auto kind = state.range(2);
  for (auto _ : state) {
    if (kind == 0)
      deform_points(twist, in, out, options);
    else if (kind == 1)
      deform_points(bend, in, out, options);
    else
      deform_points(taper, in, out, options);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetLabel(kind == 0 ? "twist" : (kind == 1 ? "bend" : "taper"));
}

void regular_arguments(benchmark::internal::Benchmark* b) {
  b->ArgNames({"points", "threads", "kind"});
  for (int kind : {0, 1, 2})
    for (int threads : {1, 2}) b->Args({1'000'000, threads, kind});
  b->UseRealTime()->Unit(benchmark::kMillisecond);
}

/// Points inside the lattice and targets 5 mm away from their images.
std::vector<PointMove> point_moves(const BSplineLattice& lattice, Eigen::Index n) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(0.05, 0.95), offset(-5.0, 5.0);
  std::vector<PointMove> moves;
  for (Eigen::Index r = 0; r < n; ++r) {
    const Eigen::Vector3d x = lattice.frame.point(unit(rng), unit(rng), unit(rng));
    moves.push_back(
        {x, deform_point(lattice, x) + Eigen::Vector3d(offset(rng), offset(rng), offset(rng))});
  }
  return moves;
}

void manipulate_once(benchmark::State& state) {
  const BSplineLattice lattice =
      displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8}));
  const auto moves = point_moves(lattice, state.range(0));
  for (auto _ : state) {
    auto result = manipulate(lattice, moves);
    benchmark::DoNotOptimize(result.lattice.points.data());
  }
  state.SetLabel("bspline 8x8x8 cells cubic");
}

void manipulate_drag(benchmark::State& state) {
  const BSplineLattice lattice =
      displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8}));
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

/// The refit test's loft: four cubic sections from z = 0 to 120 mm.
clay::surface::BSplineSurface twist_loft() {
  std::vector<clay::surface::BSplineCurve> sections;
  const double scales[] = {1.0, 0.8, 1.1, 0.9}, wobbles[] = {0, 6, -4, 3};
  for (int s = 0; s < 4; ++s) {
    Points3 p(6, 3);
    for (int i = 0; i < 6; ++i) {
      const double a = 0.6 * i;
      p.row(i) << scales[s] * 40 * std::cos(a),
          scales[s] * (25 + wobbles[s] * (i % 2)) * std::sin(a), 40.0 * s;
    }
    sections.push_back(clay::surface::make_curve(3, {0, 0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1, 1}, p));
  }
  return clay::surface::loft(sections).surface;
}

void refit_twist(benchmark::State& state) {
  const auto loft = twist_loft();
  const Twist twist{AxisFrame{}, {0.0, 0.01}};
  for (auto _ : state) {
    auto result = refit_deformed(twist, loft);
    benchmark::DoNotOptimize(result.surface.points.data());
    state.counters["bound_mm"] = result.report.certified_bound_mm;
    state.counters["tolerance_mm"] = result.report.tolerance_mm;
  }
  state.SetLabel("twisted loft, bicubic fit, 1e-4 of size");
}

}  // namespace

// Issue #41: the Jacobian of deformed points with respect to the lattice points (influence_matrix:
// deformed = B x lattice points) for 10^6 points, and the adjoint user's product B^T g (g: a
// gradient with respect to the deformed points, 10^6 x 3). Reference in the same run: deforming
// the same points once (rows, 1 thread). Arg: 0 = Bézier 4x4x4, 1 = B-spline 8x8x8 cells.
void jacobian_points(benchmark::State& state) {
  const bool bspline = state.range(0) == 1;
  const Points3 x = random_points(1000000);
  Eigen::SparseMatrix<double, Eigen::RowMajor> b;
  for (auto _ : state) {
    b = bspline ? influence_matrix(
                      displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8})), x)
                : influence_matrix(displaced(make_bezier_lattice(skewed_frame(), {3, 3, 3})), x);
    benchmark::DoNotOptimize(b.valuePtr());
  }
  state.counters["nonzeros"] = static_cast<double>(b.nonZeros());
  state.SetLabel(bspline ? "assembly, B-spline 8x8x8 cells" : "assembly, Bézier 4x4x4");
}
void jacobian_transpose_product(benchmark::State& state) {
  const bool bspline = state.range(0) == 1;
  const Points3 x = random_points(1000000);
  const auto b =
      bspline ? influence_matrix(
                    displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8})), x)
              : influence_matrix(displaced(make_bezier_lattice(skewed_frame(), {3, 3, 3})), x);
  const Eigen::MatrixXd g = Eigen::MatrixXd::Random(x.rows(), 3);
  Eigen::MatrixXd adjoint;
  for (auto _ : state) {
    adjoint = b.transpose() * g;
    benchmark::DoNotOptimize(adjoint.data());
  }
  state.SetLabel(bspline ? "B^T g, B-spline 8x8x8 cells" : "B^T g, Bézier 4x4x4");
}
// The same product without forming B (influence_transpose_product), from the points.
void jacobian_transpose_product_matrix_free(benchmark::State& state) {
  const bool bspline = state.range(0) == 1;
  const Points3 x = random_points(1000000);
  const Points3 g = Points3::Random(x.rows(), 3);
  const auto bezier = displaced(make_bezier_lattice(skewed_frame(), {3, 3, 3}));
  const auto cells = displaced(make_bspline_lattice(skewed_frame(), {3, 3, 3}, {8, 8, 8}));
  Points3 adjoint;
  for (auto _ : state) {
    adjoint = bspline ? influence_transpose_product(cells, x, g)
                      : influence_transpose_product(bezier, x, g);
    benchmark::DoNotOptimize(adjoint.data());
  }
  state.SetLabel(bspline ? "B^T g unformed, B-spline 8x8x8 cells" : "B^T g unformed, Bézier 4x4x4");
}
BENCHMARK(jacobian_points)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(jacobian_transpose_product_matrix_free)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(jacobian_transpose_product)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(refit_twist)->Unit(benchmark::kMillisecond);
BENCHMARK(rows)->Apply(arguments);
BENCHMARK(columns)->Apply(arguments);
BENCHMARK(extended_freeze)->Apply(extended_arguments);
BENCHMARK(extended_evaluate)->Apply(extended_arguments);
BENCHMARK(regular)->Apply(regular_arguments);
BENCHMARK(manipulate_once)
    ->ArgName("points")
    ->Arg(10)
    ->Arg(100)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(manipulate_drag)
    ->ArgName("points")
    ->Arg(10)
    ->Arg(100)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
