// Clayform Studio's drag step (issue #23), kernel side, wall time (UseRealTime):
// - lattice_drag_step: one control point of a (3, 3, 1) Bézier lattice moved, the lattice frozen
//   again (FrozenLattice) and a 173 x 173 = 29,929-vertex tessellation of the parent deformed
//   pointwise: what a drag costs when the deformed tessellation is computed from the parent's
//   (the page does this itself in the studio; bench_style's drag is the style step's figure);
// - session_drag_step: what `clayform studio` does today for one drag update: the recipe edited,
//   checked and run whole (StudioSession::handle with "nets": false), for the car hood's crease
//   (style, exact and paper) and for a lattice composed exactly with the hood.
#include <clay/deform/frozen_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/studio.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>
#include "hood.hpp"
#include "step_times.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
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

// Issue #38 step 4: a drag of the tank's (3, 3, 1) lattice (examples/recipes/tank.json: fill,
// exact style, lattice whose exact form would have 727,065 control points, so its light form is
// used). Point [1, 1, 1] of "knees" moved each iteration. Arguments:
// 0 = before: what a drag update cost until then, the edited recipe run whole (run_recipe: the
//     fill, the style and the certified light fit);
// 1 = after: StudioSession::handle of the drag update ("nets": false): the fill and the style
//     taken from the last run, the light form one product of the lattice's points;
// 2 = the release ("nets": true): the style taken from the last run, the light form fitted and
//     certified.
void tank_drag_step(benchmark::State& state) {
  const std::filesystem::path file =
      std::filesystem::path(CLAY_EXAMPLES_DIR) / "recipes" / "tank.json";
  const std::string text = read(file);
  Json doc = Json::parse(text);
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

}  // namespace

BENCHMARK(tank_drag_step)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(lattice_drag_step)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(session_drag_step)
    ->Arg(0)
    ->Arg(3)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
