// Runs that keep their steps' results for the next run (RunCache, issue #40): an edit re-runs only
// the steps downstream of what it changed. On the tank example (six strokes, a projected bound,
// a fill, an exact style, a lattice in its light form) and small recipes; every result checked
// bit for bit against a whole run of the same recipe without a cache.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/recipe/document.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/studio.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "bspline_target.hpp"

using namespace clay::recipe;
namespace fs = std::filesystem;
namespace surface = clay::surface;
using Json = nlohmann::json;

namespace {

const fs::path tank_file = fs::path(CLAY_EXAMPLES_DIR) / "recipes" / "tank.json";

Json tank() {
  std::ifstream in(tank_file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return Json::parse(text.str());
}

RunResult run(const Json& doc, std::shared_ptr<RunCache> cache = {}) {
  RunOptions options;
  options.cache = std::move(cache);
  return run_recipe(parse_recipe(doc.dump(), tank_file.parent_path(), "tank"), options);
}

/// The same figures, a NaN (a style step's net_change when no net convergence is asked for)
/// equal to a NaN.
bool same_figures(const StepReport& a, const StepReport& b) {
  if (a.figures.size() != b.figures.size()) return false;
  for (std::size_t f = 0; f < a.figures.size(); ++f) {
    const auto& [name_a, x] = a.figures[f];
    const auto& [name_b, y] = b.figures[f];
    const bool both_nan = std::holds_alternative<double>(x) && std::holds_alternative<double>(y) &&
                          std::isnan(std::get<double>(x)) && std::isnan(std::get<double>(y));
    if (name_a != name_b || !(x == y || both_nan)) return false;
  }
  return true;
}

/// Every curve and surface of `a` equal to `b`'s bit for bit, in the same order.
void require_identical(const RunResult& a, const RunResult& b) {
  REQUIRE(a.curves.size() == b.curves.size());
  for (std::size_t k = 0; k < a.curves.size(); ++k) {
    INFO("curve " << a.curves[k].first);
    CHECK(a.curves[k].first == b.curves[k].first);
    CHECK(surface::identical(a.curves[k].second, b.curves[k].second));
  }
  REQUIRE(a.surfaces.size() == b.surfaces.size());
  for (std::size_t k = 0; k < a.surfaces.size(); ++k) {
    INFO("surface " << a.surfaces[k].first);
    CHECK(a.surfaces[k].first == b.surfaces[k].first);
    CHECK(surface::identical(a.surfaces[k].second, b.surfaces[k].second));
  }
  REQUIRE(a.steps.size() == b.steps.size());
  for (std::size_t k = 0; k < a.steps.size(); ++k) {
    CHECK(a.steps[k].path == b.steps[k].path);
    CHECK(same_figures(a.steps[k], b.steps[k]));
  }
  CHECK(a.bounds == b.bounds);
  CHECK(a.stages.size() == b.stages.size());
}

/// The paths of the steps a run did (not taken from the cache), exports aside.
std::set<std::string> built(const RunResult& r) {
  std::set<std::string> out;
  for (const StepReport& s : r.steps)
    if (!s.reused && s.path.rfind("exports.", 0) != 0) out.insert(s.path);
  return out;
}

/// The tank's steps, by what each needs: strokes (6), the projected bound, the fill and the two
/// deformed surfaces with their stacks' steps.
const std::set<std::string> tank_steps{
    "strokes.left",          "strokes.rear",   "strokes.right",
    "strokes.front",         "strokes.spine",  "strokes.bound_drawn",
    "curves.bound",          "surfaces.panel", "surfaces.styled.steps[0]",
    "surfaces.tank.steps[0]"};

}  // namespace

TEST_CASE("run_recipe with a cache: the second run takes every step, bit for bit",
          "[recipe][cache][release-only]") {
  const RunResult whole = run(tank());
  const auto cache = std::make_shared<RunCache>();
  const RunResult first = run(tank(), cache);
  require_identical(first, whole);
  CHECK(built(first) == tank_steps);
  // Ten steps kept: six strokes, the bound, the panel, the styled and the lattice surfaces.
  CHECK(cache->counts().kept == 10);
  CHECK(cache->counts().reused == 0);
  CHECK(cache->counts().entries == 10);

  const RunResult second = run(tank(), cache);
  require_identical(second, whole);
  CHECK(built(second).empty());
  CHECK(cache->counts().reused == 10);
  for (const StepReport& s : second.steps)
    if (s.path.rfind("exports.", 0) != 0) CHECK(s.reused);
  // The report says which steps were taken (require_identical compared their figures).
  CHECK(report_json(second).find("\"reused\"") != std::string::npos);
  CHECK(report_json(whole).find("\"reused\"") == std::string::npos);

  cache->clear();
  CHECK(cache->counts().entries == 0);
  CHECK(cache->counts().bytes == 0);
  CHECK(built(run(tank(), cache)) == tank_steps);
}

TEST_CASE("run_recipe with a cache: an edit re-runs only the steps downstream of it",
          "[recipe][cache][release-only]") {
  const auto cache = std::make_shared<RunCache>();
  (void)run(tank(), cache);

  SECTION("the target stroke: the style and the lattice after it") {
    Json edited = tank();
    for (Json& p : edited["strokes"]["spine"]["points"]) p[2] = p[2].get<double>() + 2.0;
    const RunResult r = run(edited, cache);
    require_identical(r, run(edited));
    CHECK(built(r) == std::set<std::string>{"strokes.spine", "surfaces.styled.steps[0]",
                                            "surfaces.tank.steps[0]"});
  }
  SECTION("the lattice: only the lattice step") {
    Json edited = tank();
    for (Json& m : edited["deformations"]["knees"][0]["moves"])
      if (m["index"] == Json::array({1, 1, 1})) m["by"][2] = m["by"][2].get<double>() + 5.0;
    const RunResult r = run(edited, cache);
    require_identical(r, run(edited));
    CHECK(built(r) == std::set<std::string>{"surfaces.tank.steps[0]"});
  }
  SECTION("a boundary stroke: the fill, the bound projected on it and everything after") {
    Json edited = tank();
    edited["strokes"]["left"]["points"][5][2] =
        edited["strokes"]["left"]["points"][5][2].get<double>() + 1.0;
    const RunResult r = run(edited, cache);
    require_identical(r, run(edited));
    CHECK(built(r) == std::set<std::string>{"strokes.left", "surfaces.panel", "curves.bound",
                                            "surfaces.styled.steps[0]", "surfaces.tank.steps[0]"});
  }
  SECTION("the composition: every surface, no stroke") {
    Json edited = tank();
    edited["composition"] = {{"relative_tolerance", 5e-5}};
    const RunResult r = run(edited, cache);
    require_identical(r, run(edited));
    CHECK(built(r) == std::set<std::string>{"surfaces.panel", "curves.bound",
                                            "surfaces.styled.steps[0]", "surfaces.tank.steps[0]"});
  }
  SECTION("an edit undone: everything from the cache again") {
    Json edited = tank();
    edited["strokes"]["spine"]["tolerance_mm"] = 0.2;
    (void)run(edited, cache);
    CHECK(built(run(tank(), cache)).empty());
  }
}

TEST_CASE("run_recipe with a cache: a stack's first steps are taken when a later one changed",
          "[recipe][cache]") {
  // The sail: a fill, then the stack "shape" of an exact style and a lattice. A sweep or an edit
  // of the lattice's moves (issue #40: a sweep whose variants share a prefix computes it once)
  // takes the style from the cache and runs the lattice alone; an edit of the style runs both.
  std::ifstream in(tank_file.parent_path() / "sail.json", std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const Json sail = Json::parse(text.str());
  const auto cache = std::make_shared<RunCache>();
  const RunResult first = run(sail, cache);
  require_identical(first, run(sail));
  CHECK(built(first).count("surfaces.sail.steps[0]") == 1);
  CHECK(built(first).count("surfaces.sail.steps[1]") == 1);
  for (const double lift : {150.0, 0.0, -80.0}) {
    INFO("the billow's first move by " << lift << " mm");
    Json edited = sail;
    edited["deformations"]["shape"][1]["moves"][0]["by"][1] = lift;
    const RunResult r = run(edited, cache);
    require_identical(r, run(edited));
    CHECK(built(r) == std::set<std::string>{"surfaces.sail.steps[1]"});
  }
  Json restyled = sail;
  restyled["deformations"]["shape"][0]["curve_tolerance"] = 0.02;
  const RunResult r = run(restyled, cache);
  require_identical(r, run(restyled));
  CHECK(built(r) == std::set<std::string>{"surfaces.sail.steps[0]", "surfaces.sail.steps[1]"});
}

TEST_CASE("run_recipe with a cache: a sketch and the curves built on it", "[recipe][cache]") {
  // A stroke on the plane z = 0 taken into a sketch whose start point is fixed, a line beside it
  // and a band skinned through both (a curve may not use a sketch's, defined after it): editing
  // the line rebuilds the line and the band; editing the stroke rebuilds it, the sketch and the
  // band.
  auto recipe = [](double lift, double line_end) {
    Json doc = Json::parse(R"({"format": "clayform.recipe", "version": 1,
      "strokes": {"st": {"points": [[0, 0, 0], [10, 1, 0], [20, 3, 0], [30, 2, 0], [40, 0, 0]],
                         "plane": {"origin": [0, 0, 0], "normal": [0, 0, 1]}}},
      "curves": {"edge": {"line": {"from": [0, 0, 0], "to": [40, 0, 0]}}},
      "sketches": {"s": {"plane": {"origin": [0, 0, 0], "x_axis": [1, 0, 0], "y_axis": [0, 1, 0]},
        "points": {}, "entities": {"f": {"curve": "st"}},
        "constraints": [{"type": "fixed", "point": "f.start"}]}},
      "surfaces": {"band": {"skin": {"sections": ["s.f", "edge"], "degree": 1}}}})");
    doc["strokes"]["st"]["points"][2][1] = 3 + lift;
    doc["curves"]["edge"]["line"]["to"][0] = line_end;
    return doc;
  };
  const auto cache = std::make_shared<RunCache>();
  const RunResult first = run(recipe(0, 40), cache);
  require_identical(first, run(recipe(0, 40)));
  CHECK(built(first) ==
        std::set<std::string>{"strokes.st", "curves.edge", "sketches.s", "surfaces.band"});
  const RunResult line_moved = run(recipe(0, 45), cache);
  require_identical(line_moved, run(recipe(0, 45)));
  CHECK(built(line_moved) == std::set<std::string>{"curves.edge", "surfaces.band"});
  const RunResult stroke_moved = run(recipe(0.5, 45), cache);
  require_identical(stroke_moved, run(recipe(0.5, 45)));
  CHECK(built(stroke_moved) == std::set<std::string>{"strokes.st", "sketches.s", "surfaces.band"});
}

TEST_CASE("run_recipe with a cache: beyond its capacity the least recently used go first",
          "[recipe][cache]") {
  // 40 KB holds the strokes' fits and the bound (a few KB each) but not the surfaces with their
  // stages (the lattice's light net alone is larger): they are dropped, never wrong.
  const auto cache = std::make_shared<RunCache>(40 * 1024);
  const RunResult whole = run(tank());
  require_identical(run(tank(), cache), whole);
  const RunCache::Counts after_first = cache->counts();
  CHECK(after_first.bytes <= 40 * 1024);
  CHECK(after_first.entries < 10);
  const RunResult again = run(tank(), cache);
  require_identical(again, whole);
  const std::set<std::string> rebuilt = built(again);
  CHECK(!rebuilt.empty());
  CHECK(rebuilt.size() < tank_steps.size());
  CHECK(cache->counts().bytes <= 40 * 1024);
}

TEST_CASE("run_recipe with a cache: an imported file that changes is read again",
          "[recipe][cache]") {
  const fs::path dir = fs::path(CLAY_TEST_OUTPUT_DIR) / "run_cache_import";
  fs::create_directories(dir);
  const fs::path models = fs::path(CLAY_EXAMPLES_DIR) / "models";
  fs::copy_file(models / "block.step", dir / "part.step", fs::copy_options::overwrite_existing);
  const std::string text = R"({"format": "clayform.recipe", "version": 1,
    "surfaces": {"d": {"import": {"file": "part.step"}}}})";
  const auto cache = std::make_shared<RunCache>();
  auto run_here = [&](std::shared_ptr<RunCache> c) {
    RunOptions options;
    options.cache = std::move(c);
    return run_recipe(parse_recipe(text, dir), options);
  };
  (void)run_here(cache);
  CHECK(built(run_here(cache)).empty());
  // Another file under the same name (a different size): read again, as a run without a cache.
  fs::copy_file(models / "g2_block.step", dir / "part.step", fs::copy_options::overwrite_existing);
  const RunResult changed = run_here(cache);
  CHECK(built(changed) == std::set<std::string>{"surfaces.d"});
  require_identical(changed, run_here(nullptr));
}

TEST_CASE("studio session: a new stroke is fitted alone, the rest taken from the session's cache",
          "[recipe][cache][studio]") {
  StudioSession session(tank().dump(), tank_file.parent_path(), "tank");
  REQUIRE(Json::parse(session.handle(R"({"op": "run"})").json).at("op") == "run");
  const auto cache = session.run_cache();
  REQUIRE(cache);
  CHECK(cache->counts().kept == 10);
  // A stroke drawn beside the panel: its fit is the one step the edit runs.
  const Json stroke = {{"points", {{0, 300, 0}, {100, 302, 4}, {200, 301, 9}, {300, 300, 11}}},
                       {"tolerance_mm", 0.5}};
  const Json reply = Json::parse(
      session
          .handle(
              Json{{"op", "edit"}, {"path", "strokes.extra"}, {"value", stroke}, {"create", true}}
                  .dump())
          .json);
  INFO(reply.dump().substr(0, 400));
  REQUIRE(reply.at("op") == "edit");
  std::set<std::string> ran;
  for (const Json& step : reply.at("steps"))
    if (!step.value("reused", false) &&
        step.at("path").get<std::string>().rfind("exports.", 0) != 0)
      ran.insert(step.at("path").get<std::string>());
  CHECK(ran == std::set<std::string>{"strokes.extra"});
  CHECK(cache->counts().reused == 10);
  // Undo meets every step in the cache again.
  const Json undone = Json::parse(session.handle(R"({"op": "undo"})").json);
  for (const Json& step : undone.at("steps"))
    if (step.at("path").get<std::string>().rfind("exports.", 0) != 0)
      CHECK(step.value("reused", false));
}

TEST_CASE(
    "studio session: a stroke the page asked about is fitted once, for the question and "
    "the edit that writes it",
    "[recipe][cache][studio]") {
  // The page asks "fit" (at 50 degrees, to find corners) and then writes the stroke: the run
  // takes the question's fit (RunCache::fit_stroke) when the stroke has no corners, whose fit at
  // the recipe's 180 degrees is the same computation. Checked bit for bit against a run without
  // a cache. A stroke with a corner written without "pieces" is fitted again, unsplit; written
  // with them, its fit is the question's.
  const std::string text = R"({"format": "clayform.recipe", "version": 1})";
  const Json smooth = {
      {"points",
       {{0, 0, 0}, {40, 9, 1}, {80, 14, 3}, {120, 12, 4}, {160, 5, 4}, {200, -3, 5}, {240, -6, 7}}},
      {"tolerance_mm", 0.5}};
  const Json cornered = {{"points",
                          {{0, 0, 0},
                           {25, 1, 0},
                           {50, 0, 0},
                           {75, 1, 0},
                           {100, 0, 0},
                           {101, 25, 0},
                           {100, 50, 0},
                           {101, 75, 0},
                           {100, 100, 0}}},
                         {"tolerance_mm", 0.5}};
  Json in_pieces = cornered;
  in_pieces["pieces"] = 2;
  for (const auto& [name, stroke, pieces, reused] :
       {std::tuple{"smooth", smooth, 1, 1LL}, std::tuple{"cornered", cornered, 2, 0LL},
        std::tuple{"cornered, written in pieces", in_pieces, 2, 1LL}}) {
    INFO(name);
    StudioSession session(text, fs::path(CLAY_TEST_OUTPUT_DIR), "fit_once");
    Json ask = stroke;
    ask.erase("pieces");
    ask["op"] = "fit";
    const Json fit = Json::parse(session.handle(ask.dump()).json);
    REQUIRE(fit.at("op") == "fit");
    CHECK(fit.at("pieces") == pieces);
    const Json reply = Json::parse(
        session
            .handle(Json{{"op", "edit"}, {"path", "strokes.s"}, {"value", stroke}, {"create", true}}
                        .dump())
            .json);
    REQUIRE(reply.at("op") == "edit");
    CHECK(session.run_cache()->counts().fits_reused == reused);
    Json doc = Json::parse(text);
    doc["strokes"]["s"] = stroke;
    const RunResult fresh = run_recipe(parse_recipe(doc.dump(), fs::path(CLAY_TEST_OUTPUT_DIR)));
    const RunResult in_session =
        run_recipe(parse_recipe(session.text(), fs::path(CLAY_TEST_OUTPUT_DIR)));
    REQUIRE(fresh.curves.size() == static_cast<std::size_t>(stroke.value("pieces", 1)));
    RunOptions cached;
    cached.cache = session.run_cache();
    const RunResult from_cache =
        run_recipe(parse_recipe(session.text(), fs::path(CLAY_TEST_OUTPUT_DIR)), cached);
    require_identical(from_cache, fresh);
    require_identical(in_session, fresh);
  }
}

TEST_CASE(
    "studio session: dragging a style's target previews the lattice after it, the release "
    "certifies",
    "[recipe][cache][studio][release-only]") {
  // Issue #40: a drag of the tank's target curve re-ran the lattice's certified light fit on
  // every update (740 ms); now the update previews it on its last knots, as a lattice drag does,
  // and the release fits and certifies it: what a whole run of the saved recipe gives.
  Json doc = tank();
  const RunResult first = run(doc);
  const surface::BSplineCurve& spine = first.curve("spine");
  doc = with_bspline_curve(doc, "spine", spine);
  StudioSession session(doc.dump(), tank_file.parent_path(), "tank");
  REQUIRE(Json::parse(session.handle(R"({"op": "run"})").json).at("op") == "run");
  const Eigen::Index middle = spine.points.rows() / 2;
  const std::string path = "curves.spine.bspline.points[" + std::to_string(middle) + "][2]";
  auto drag = [&](double z, bool nets) {
    const Json r = Json::parse(
        session
            .handle(Json{
                {"op", "edit"}, {"path", path}, {"value", z}, {"group", "drag"}, {"nets", nets}}
                        .dump())
            .json);
    REQUIRE(r.at("op") == "edit");
    std::map<std::string, Json> steps;
    for (const Json& s : r.at("steps")) steps[s.at("path").get<std::string>()] = s;
    return steps;
  };
  const double z0 = spine.points(middle, 2);
  for (double dz : {2.0, 4.0}) {
    auto steps = drag(z0 + dz, false);
    CHECK(steps.at("strokes.left").value("reused", false));  // from the cache
    CHECK(steps.at("surfaces.panel").value("reused", false));
    CHECK_FALSE(steps.at("surfaces.styled.steps[0]").value("reused", false));
    CHECK(steps.at("surfaces.tank.steps[0]").at("figures").at("preview") == true);
    CHECK(steps.at("surfaces.tank.steps[0]").at("figures").at("certified") == false);
  }
  auto released = drag(z0 + 4.0, true);
  const Json& figures = released.at("surfaces.tank.steps[0]").at("figures");
  CHECK_FALSE(figures.contains("preview"));
  CHECK(figures.at("certified") == true);
  const RunResult whole = run_recipe(parse_recipe(session.text(), tank_file.parent_path(), "tank"));
  for (const StepReport& s : whole.steps)
    if (s.path == "surfaces.tank.steps[0]")
      for (const auto& [key, value] : s.figures)
        if (key == "max_deviation_mm")
          CHECK(figures.at(key).get<double>() == std::get<double>(value));
}

TEST_CASE("parse_recipe_document: a document held parsed runs as its text does",
          "[recipe][cache][release-only]") {
  // The studio checks its edited document without printing and parsing it (issue #40): the
  // same recipe, the same cache keys, bit for bit what the text gives.
  const std::string text = tank().dump();
  const auto document =
      std::make_shared<const nlohmann::ordered_json>(nlohmann::ordered_json::parse(text));
  const auto cache = std::make_shared<RunCache>();
  RunOptions options;
  options.cache = cache;
  const RunResult held =
      run_recipe(parse_recipe_document(document, tank_file.parent_path(), "tank"), options);
  require_identical(held, run(tank()));
  CHECK(built(held) == tank_steps);
  // The text's run meets every step the document's run kept: the keys are the same.
  CHECK(built(run(tank(), cache)).empty());
  CHECK(cache->counts().reused == 10);

  SECTION("its problems are the text's, in one error") {
    nlohmann::ordered_json bad = *document;
    bad["surfaces"]["panel"]["fill"]["curvs"] = 1;
    bad["strokes"]["left"]["tolerance_mm"] = -1;
    std::string from_text;
    try {
      (void)parse_recipe(bad.dump(), tank_file.parent_path());
    } catch (const clay::Error& e) {
      from_text = e.message();
    }
    REQUIRE(from_text.find("the recipe has 2 problems:") != std::string::npos);
    try {
      (void)parse_recipe_document(std::make_shared<const nlohmann::ordered_json>(bad),
                                  tank_file.parent_path());
      FAIL("a document with two problems was accepted");
    } catch (const clay::Error& e) {
      CHECK(e.category() == clay::ErrorCategory::Document);
      CHECK(e.message() == from_text);
    }
  }
  SECTION("a document nested deeper than a text may be is refused by its section") {
    nlohmann::ordered_json deep = *document;
    nlohmann::ordered_json* node = &deep["notes"];
    for (int k = 0; k < 70; ++k) node = &(*node)["x"];
    *node = 1;
    try {
      (void)parse_recipe_document(std::make_shared<const nlohmann::ordered_json>(deep));
      FAIL("a document nested 70 deep was accepted");
    } catch (const clay::Error& e) {
      CHECK(e.category() == clay::ErrorCategory::Document);
      CHECK_THAT(e.message(), Catch::Contains("notes: arrays and objects nest deeper than 64"));
    }
  }
  SECTION("a null document is named") {
    CHECK_THROWS_MATCHES(parse_recipe_document(nullptr), clay::Error,
                         Catch::Matchers::Predicate<clay::Error>([](const clay::Error& e) {
                           return e.category() == clay::ErrorCategory::InvalidArgument &&
                                  e.message().find("the document is null") != std::string::npos;
                         }));
  }
}

TEST_CASE("studio session: an edit's reply carries its changes and revisions, not the text",
          "[recipe][studio][release-only]") {
  // Issue #40: the reply of every edit held the recipe's whole text, which grew with the design.
  // Now it holds the edit's changes and the revision they apply to; the text held at that
  // revision, changed by them (here by JSON pointers, independently of the session), is the
  // session's new text. Runs, undos and redos still carry the text.
  StudioSession session(tank().dump(), tank_file.parent_path(), "tank");
  const Json ran = Json::parse(session.handle(R"({"op": "run"})").json);
  REQUIRE(ran.at("op") == "run");
  const auto revision = ran.at("revision").get<std::uint64_t>();
  Json held = Json::parse(ran.at("text").get<std::string>());
  const Json changes =
      Json::array({{{"path", "strokes.extra"},
                    {"value", {{"points", {{0, 300, 0}, {100, 302, 4}, {200, 301, 9}}}}},
                    {"create", true}},
                   {{"path", "strokes.left.tolerance_mm"}, {"value", 0.4}}});
  const Json edited =
      Json::parse(session.handle(Json{{"op", "edit"}, {"changes", changes}}.dump()).json);
  REQUIRE(edited.at("op") == "edit");
  CHECK_FALSE(edited.contains("text"));
  CHECK(edited.at("from_revision") == revision);
  CHECK(edited.at("revision") == revision + 1);
  CHECK(edited.at("changes") == changes);
  held["/strokes/extra"_json_pointer] = changes[0]["value"];
  held["/strokes/left/tolerance_mm"_json_pointer] = 0.4;
  CHECK(held == Json::parse(session.text()));
  // A refused edit changes nothing: no revision is spent.
  const Json refused = Json::parse(
      session.handle(R"({"op": "edit", "path": "strokes.left.tolerance_mm", "value": -1})").json);
  CHECK(refused.at("op") == "error");
  const Json undone = Json::parse(session.handle(R"({"op": "undo"})").json);
  CHECK(undone.at("revision") == revision + 2);
  CHECK(Json::parse(undone.at("text").get<std::string>()) ==
        Json::parse(ran.at("text").get<std::string>()));
  const Json asked = Json::parse(session.handle(R"({"op": "recipe"})").json);
  CHECK(asked.at("revision") == revision + 2);
  CHECK(asked.at("text") == session.text());
}
