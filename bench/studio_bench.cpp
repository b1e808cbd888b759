// Clayform Studio's drag step (issue #23) and stroke step (issue #40), kernel side, wall time
// (UseRealTime):
// - lattice_drag_step: one control point of a (3, 3, 1) Bézier lattice moved, the lattice frozen
//   again (FrozenLattice) and a 173 x 173 = 29,929-vertex tessellation of the parent deformed
//   pointwise: what a drag costs when the deformed tessellation is computed from the parent's
//   (the page does this itself in the studio; bench_style's drag is the style step's figure);
// - session_drag_step: what `clayform studio` does today for one drag update: the recipe edited,
//   checked and run whole (StudioSession::handle with "nets": false), for the car hood's crease
//   (style, exact and paper) and for a lattice composed exactly with the hood;
// - stroke_step: pointer-up to fitted curve for a design of 1, 20 and 40 hand-drawn strokes,
//   before and after the session kept its steps' results (recipe::RunCache).
#include <clay/deform/frozen_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/studio.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>
#include "hood.hpp"
#include "step_times.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

using namespace clay;
using Json = nlohmann::json;

namespace {

void lattice_drag_step(benchmark::State& state) {
  const auto grid = surface::linspace(0, 1, 173);
  const surface::Points3 parent = surface::evaluate_grid(bench::hood(), grid, grid);
  deform::Frame frame;
  frame.origin = Eigen::Vector3d(-660, -440, -60);
  frame.s = Eigen::Vector3d(1320, 0, 0);
  frame.t = Eigen::Vector3d(0, 880, 0);
  frame.u = Eigen::Vector3d(0, 0, 200);
  deform::BezierLattice lattice = deform::make_bezier_lattice(frame, {3, 3, 1});
  const Eigen::Index moved = lattice.index(2, 2, 1);
  const Eigen::RowVector3d rest = lattice.points.row(moved);
  surface::Points3 out(parent.rows(), 3);
  int step = 0;
  clay::bench::StepTimes times;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    lattice.points.row(moved) = rest + Eigen::RowVector3d(0, 0, 40 * std::sin(0.1 * step++));
    const deform::FrozenLattice frozen(lattice);
    deform::deform_points(frozen, parent, out, deform::DeformOptions{1});
    benchmark::DoNotOptimize(out.data());
    times.record(t0);
  }
  times.report(state);
  state.counters["vertices"] = static_cast<double>(parent.rows());
  state.SetItemsProcessed(state.iterations());
}

std::string read(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Arguments: 0 = the hood's crease target moved (the example: exact and paper styles), 1 = paper
// only, 3 = exact only, 2 = a (3, 3, 1) lattice composed exactly with the hood, one point moved.
void session_drag_step(benchmark::State& state) {
  const std::filesystem::path file =
      std::filesystem::path(CLAY_EXAMPLES_DIR) / "recipes" / "car_hood.json";
  Json doc = Json::parse(read(file));
  std::string path;
  if (state.range(0) == 1 || state.range(0) == 3) {
    const std::string other = state.range(0) == 1 ? "hood_exact" : "hood_paper";
    doc["surfaces"].erase(other);
    doc["exports"].erase(other);
  }
  if (state.range(0) == 2) {
    doc["deformations"]["lift"] =
        Json::array({{{"kind", "bezier_lattice"},
                      {"frame",
                       {{"origin", {-660, -440, -60}},
                        {"s", {1320, 0, 0}},
                        {"t", {0, 880, 0}},
                        {"u", {0, 0, 200}}}},
                      {"degrees", {3, 3, 1}},
                      {"moves", Json::array({{{"index", {2, 2, 1}}, {"by", {0, 0, 0}}}})}}});
    doc["surfaces"] = {
        {"hood", doc["surfaces"]["hood"]},
        {"hood_lifted", {{"deform", {{"surface", "hood"}, {"deformation", "lift"}}}}}};
    doc["exports"] = {{"hood", {{"surfaces", {"hood_lifted"}}}}};
    path = "deformations.lift[0].moves[0].by[2]";
  } else {
    path = "curves.crease.bspline.points[1][2]";
  }
  recipe::StudioSession session(doc.dump(), file.parent_path(), "car_hood");
  int step = 0;
  clay::bench::StepTimes times;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const double value =
        state.range(0) == 2 ? 40 * std::sin(0.1 * step) : 150 + 10 * std::sin(0.1 * step);
    ++step;
    const auto reply = session.handle(Json{
        {"op", "edit"},
        {"path", path},
        {"value", value},
        {"label", "drag"},
        {"group", "drag"},
        {"nets", false}}.dump());
    if (reply.json.find("\"op\":\"error\"") != std::string::npos) {
      state.SkipWithError(reply.json.c_str());
      break;
    }
    benchmark::DoNotOptimize(reply.json.data());
    times.record(t0);
  }
  times.report(state);
  const char* labels[] = {
      "car hood, crease target, exact and paper", "car hood, crease target, paper",
      "car hood, (3, 3, 1) lattice composed exactly", "car hood, crease target, exact"};
  state.SetLabel(labels[state.range(0)]);
}

// Issue #40: a style drag on the tank: the target "spine" made the B-spline it was fitted to (as
// the studio does at a curve's first drag), its middle control point moved up and down, each
// update an edit of that point ("nets": false): the style step and the lattice's light-form
// preview after it re-run, the strokes, the bound and the fill taken from the session's cache.
// `whole`: what such an update cost before issue #40, the edited recipe run whole (run_recipe:
// the fill, the style and the lattice's certified light fit).
void tank_style_drag(benchmark::State& state, const std::filesystem::path& file, Json doc,
                     bool whole) {
  const recipe::RunResult first =
      recipe::run_recipe(recipe::parse_recipe(doc.dump(), file.parent_path()));
  const surface::BSplineCurve& spine = first.curve("spine");
  Json points = Json::array();
  for (Eigen::Index k = 0; k < spine.points.rows(); ++k)
    points.push_back({spine.points(k, 0), spine.points(k, 1), spine.points(k, 2)});
  doc["strokes"].erase("spine");
  doc["curves"]["spine"] = {
      {"bspline",
       {{"degree", spine.basis.degree}, {"knots", spine.basis.knots}, {"points", points}}}};
  recipe::StudioSession session(doc.dump(), file.parent_path(), "tank");
  session.handle(Json{{"op", "run"}}.dump());
  const Eigen::Index middle = spine.points.rows() / 2;
  const std::string path = "curves.spine.bspline.points[" + std::to_string(middle) + "][2]";
  const double z0 = spine.points(middle, 2);
  int step = 0;
  clay::bench::StepTimes times;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const double value = z0 + 6 * std::sin(0.1 * ++step);
    if (whole) {
      doc["curves"]["spine"]["bspline"]["points"][static_cast<std::size_t>(middle)][2] = value;
      const auto r = recipe::run_recipe(recipe::parse_recipe(doc.dump(), file.parent_path()));
      benchmark::DoNotOptimize(r.surfaces.data());
      times.record(t0);
      continue;
    }
    const auto reply = session.handle(Json{
        {"op", "edit"},
        {"path", path},
        {"value", value},
        {"label", "drag"},
        {"group", "drag"},
        {"nets", false}}.dump());
    if (reply.json.find("\"op\":\"error\"") != std::string::npos) {
      state.SkipWithError(reply.json.c_str());
      break;
    }
    benchmark::DoNotOptimize(reply.json.data());
    times.record(t0);
  }
  times.report(state);
  state.SetLabel(whole ? "tank style drag, before: the recipe run whole"
                       : "tank style drag update: the target's middle control point, exact style");
}

// Issue #38 step 4: a drag of the tank's (3, 3, 1) lattice (examples/recipes/tank.json: fill,
// exact style, lattice whose exact form would have 727,065 control points, so its light form is
// used). Point [1, 1, 1] of "knees" moved each iteration. Arguments:
// 0 = before: what a drag update cost until then, the edited recipe run whole (run_recipe: the
//     fill, the style and the certified light fit);
// 1 = after: StudioSession::handle of the drag update ("nets": false): the fill and the style
//     taken from the last run, the light form one product of the lattice's points;
// 2 = the release ("nets": true): the style taken from the last run, the light form fitted and
//     certified;
// 3 = a drag of the style's target instead (tank_style_drag), 4 = the same run whole (before).
void tank_drag_step(benchmark::State& state) {
  const std::filesystem::path file =
      std::filesystem::path(CLAY_EXAMPLES_DIR) / "recipes" / "tank.json";
  const std::string text = read(file);
  Json doc = Json::parse(text);
  if (state.range(0) >= 3) return tank_style_drag(state, file, doc, state.range(0) == 4);
  Json& moves = doc["deformations"]["knees"][0]["moves"];
  std::size_t moved = 0;
  while (moves[moved]["index"] != Json::array({1, 1, 1})) ++moved;
  recipe::StudioSession session(text, file.parent_path(), "tank");
  session.handle(Json{{"op", "run"}}.dump());
  const std::string path = "deformations.knees[0].moves[" + std::to_string(moved) + "].by[2]";
  int step = 0;
  clay::bench::StepTimes times;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const double value = 8 + 6 * std::sin(0.1 * ++step);
    if (state.range(0) == 0) {
      moves[moved]["by"][2] = value;
      const auto r = recipe::run_recipe(recipe::parse_recipe(doc.dump(), file.parent_path()));
      benchmark::DoNotOptimize(r.surfaces.data());
    } else {
      const auto reply = session.handle(Json{
          {"op", "edit"},
          {"path", path},
          {"value", value},
          {"label", "drag"},
          {"group", "drag"},
          {"nets", state.range(0) == 2}}.dump());
      if (reply.json.find("\"op\":\"error\"") != std::string::npos) {
        state.SkipWithError(reply.json.c_str());
        break;
      }
      benchmark::DoNotOptimize(reply.json.data());
    }
    times.record(t0);
  }
  times.report(state);
  const char* labels[] = {"tank lattice drag, before: the recipe run whole",
                          "tank lattice drag update: style reused, light form one product",
                          "tank lattice release: style reused, light form fitted and certified"};
  state.SetLabel(labels[state.range(0)]);
}

/// A stroke drawn as a hand draws (issue #40): a section across a 600 mm panel on the plane
/// y = `y`, 120 points spaced unevenly (the pen slows at the ends), with correlated tremor (a
/// first-order autoregressive jitter, 0.12 mm, correlation 0.9 from point to point) normal to
/// the line. `seed` varies the tremor.
Json hand_stroke(double y, unsigned seed) {
  std::uint64_t state = 0x9e3779b97f4a7c15ull * (seed + 1);
  auto uniform = [&] {  // splitmix64, in [-1, 1)
    state += 0x9e3779b97f4a7c15ull;
    std::uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) / 4503599627370496.0 - 1.0;
  };
  Json points = Json::array();
  double tremor = 0;
  constexpr int n = 120;
  for (int k = 0; k < n; ++k) {
    const double s = 0.5 - 0.5 * std::cos(M_PI * k / (n - 1));  // slow at both ends
    const double x = -300 + 600 * s;
    tremor = 0.9 * tremor + 0.12 * std::sqrt(1 - 0.81) * 1.7 * uniform();
    const double z = 60 * std::sin(M_PI * s) + 8 * std::sin(3 * M_PI * s + 0.01 * y) + tremor;
    points.push_back({x, y, z});
  }
  return {{"points", points},
          {"plane", {{"origin", {0, y, 0}}, {"normal", {0, 1, 0}}}},
          {"tolerance_mm", 0.5}};
}

// The iterations of a stroke benchmark: the stroke at `path` (the k-th hand stroke, at
// y = -400 + 20 k) drawn again with a new tremor each time and timed as the page sends it, the
// "fit" (does it split at corners?) then the "edit" that puts it in the recipe with its nets;
// `untimed` runs before each.
void draw_again(benchmark::State& state, recipe::StudioSession& session, const std::string& path,
                int k, const std::function<void()>& untimed) {
  unsigned seed = 1000;
  clay::bench::StepTimes times;
  for (auto _ : state) {
    const Json stroke = hand_stroke(-400 + 20.0 * k, ++seed);
    untimed();
    const auto t0 = std::chrono::steady_clock::now();
    Json fit = {{"op", "fit"}};
    fit.update(stroke);
    const auto asked = session.handle(fit.dump());
    const auto reply = session.handle(
        Json{{"op", "edit"}, {"path", path}, {"value", stroke}, {"label", "stroke"}}.dump());
    times.record(t0);
    if (reply.json.find("\"op\":\"error\"") != std::string::npos ||
        asked.json.find("\"op\":\"error\"") != std::string::npos) {
      state.SkipWithError((asked.json + reply.json).c_str());
      break;
    }
    benchmark::DoNotOptimize(reply.json.data());
  }
  times.report(state);
}

// Issue #40: pointer-up to fitted curve in the studio, a design of N hand-drawn strokes
// (Arg 0: N = 1, 20 or 40), the last stroke drawn again each iteration (its tremor differs):
// the page's "fit" (does the stroke split at corners?) then the "edit" that puts it in the
// recipe, with its nets ("nets": true), as the page sends them. Arg 1: 0 = before, every step run
// again (the session's RunCache cleared before each edit: what every edit cost until then);
// 1 = after, the other strokes taken from the cache.
void stroke_step(benchmark::State& state) {
  const int strokes = static_cast<int>(state.range(0));
  const bool cached = state.range(1) == 1;
  Json doc = {{"format", "clayform.recipe"}, {"version", 1}, {"name", "strokes"}};
  for (int k = 0; k < strokes; ++k)
    doc["strokes"]["s" + std::to_string(k)] = hand_stroke(-400 + 20.0 * k, k);
  recipe::StudioSession session(doc.dump(), std::filesystem::temp_directory_path(), "strokes");
  session.handle(Json{{"op", "run"}}.dump());
  const std::string last = "strokes.s" + std::to_string(strokes - 1);
  draw_again(state, session, last, strokes - 1, [&] {
    if (!cached) session.run_cache()->clear();
  });
  state.SetLabel(std::to_string(strokes) + " strokes, " +
                 (cached ? "after: the other steps taken from the run cache"
                         : "before: every step run again"));
}

// Issue #40: a stroke drawn beside a styled scene (the design e2e's strokes 36-40 came after the
// fill and its exact style: 46 ms to the reply though the run took 3 ms). The tank (fill, exact
// style, lattice in its light form) with N hand-drawn strokes beside it (Arg: N = 1 or 20), the
// last drawn again each iteration: the page's "fit" and the "edit" with nets.
void styled_stroke_step(benchmark::State& state) {
  const std::filesystem::path file =
      std::filesystem::path(CLAY_EXAMPLES_DIR) / "recipes" / "tank.json";
  Json doc = Json::parse(read(file));
  const int strokes = static_cast<int>(state.range(0));
  for (int k = 0; k < strokes; ++k)
    doc["strokes"]["h" + std::to_string(k)] = hand_stroke(-400 + 20.0 * k, k);
  recipe::StudioSession session(doc.dump(), file.parent_path(), "tank");
  session.handle(Json{{"op", "run"}}.dump());
  const std::string last = "strokes.h" + std::to_string(strokes - 1);
  draw_again(state, session, last, strokes - 1, [] {});
  state.SetLabel(std::to_string(strokes) + " strokes beside the tank's styled fill and lattice");
}

}  // namespace

BENCHMARK(styled_stroke_step)->Arg(1)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(tank_drag_step)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(lattice_drag_step)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(stroke_step)
    ->ArgsProduct({{1, 20, 40}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(session_drag_step)
    ->Arg(0)
    ->Arg(3)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
