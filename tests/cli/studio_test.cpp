// Clayform Studio's kernel side (clay/studio.hpp): a recipe under edits with a history, its
// geometry frames against an independent replay of the recipe, and the WebSocket server's
// origin checks and coalescing, through a Boost.Beast client.
#include <catch2/catch.hpp>

#include <clay/occt/model_exchange.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/studio.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include "studio_client.hpp"

#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace clay::recipe;
namespace fs = std::filesystem;
using Json = nlohmann::json;
using Catch::Matchers::Contains;

namespace {

const fs::path sail_file = fs::path(CLAY_EXAMPLES_DIR) / "recipes" / "sail.json";
const std::string billow = "deformations.shape[1].moves[0].by[1]";

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The header and the doubles of a net frame, decoded by the documented layout.
struct Net {
  Json header;
  std::vector<double> points, weights;
};
Net decode(const std::vector<std::uint8_t>& frame) {
  REQUIRE(frame.size() >= 8);
  std::uint32_t length = 0;
  for (int k = 0; k < 4; ++k)
    length |= std::uint32_t(frame[static_cast<std::size_t>(k)]) << (8 * k);
  Net net;
  net.header = Json::parse(std::string(frame.begin() + 4, frame.begin() + 4 + length));
  const std::size_t start = (4 + length + 7) / 8 * 8;
  if (net.header.at("kind") == "deviation") {  // rows x cols distances, in `points`
    const std::size_t count =
        net.header.at("rows").get<std::size_t>() * net.header.at("cols").get<std::size_t>();
    REQUIRE(frame.size() == start + count * sizeof(double));
    net.points.resize(count);
    std::memcpy(net.points.data(), frame.data() + start, count * sizeof(double));
    return net;
  }
  const std::size_t n =
      net.header.at("kind") == "curve"
          ? net.header.at("knots").size() - net.header.at("degree").get<std::size_t>() - 1
          : net.header.at("counts")[0].get<std::size_t>() *
                net.header.at("counts")[1].get<std::size_t>();
  REQUIRE(frame.size() == start + 4 * n * sizeof(double));
  net.points.resize(3 * n);
  net.weights.resize(n);
  std::memcpy(net.points.data(), frame.data() + start, 3 * n * sizeof(double));
  std::memcpy(net.weights.data(), frame.data() + start + 3 * n * sizeof(double),
              n * sizeof(double));
  return net;
}

/// The frame's net equals the surface bit for bit.
bool same(const Net& net, const clay::surface::BSplineSurface& s) {
  return net.header.at("knots_u").get<std::vector<double>>() == s.u.knots &&
         net.header.at("knots_v").get<std::vector<double>>() == s.v.knots &&
         std::memcmp(net.points.data(), s.points.data(), net.points.size() * sizeof(double)) == 0 &&
         std::memcmp(net.weights.data(), s.weights.data(), net.weights.size() * sizeof(double)) ==
             0;
}

/// The frame's curve equals the curve bit for bit.
bool same(const Net& net, const clay::surface::BSplineCurve& c) {
  return net.header.at("knots").get<std::vector<double>>() == c.basis.knots &&
         net.header.at("degree") == c.basis.degree &&
         std::memcmp(net.points.data(), c.points.data(), net.points.size() * sizeof(double)) == 0 &&
         std::memcmp(net.weights.data(), c.weights.data(), net.weights.size() * sizeof(double)) ==
             0;
}

/// A mesh frame's JSON header and where its numbers start.
std::pair<Json, std::size_t> mesh_header(const std::vector<std::uint8_t>& frame) {
  std::uint32_t length = 0;
  for (int k = 0; k < 4; ++k)
    length |= std::uint32_t(frame[static_cast<std::size_t>(k)]) << (8 * k);
  return {Json::parse(std::string(frame.begin() + 4, frame.begin() + 4 + length)),
          (4 + length + 7) / 8 * 8};
}

/// The frames of a reply, decoded, by name (the parents before their steps left out).
std::map<std::string, Net> frames_by_name(const StudioSession::Reply& reply) {
  std::map<std::string, Net> out;
  for (const auto& f : reply.frames) {
    Net net = decode(f);
    if (!net.header.contains("before") && net.header.at("kind") != "deviation")
      out[net.header.at("name")] = std::move(net);
  }
  return out;
}

}  // namespace

TEST_CASE("studio session: edits, undo, redo and save replay to identical control points",
          "[studio]") {
  // The session works on a copy in a folder of its own: a save writes into the recipe's folder.
  const fs::path dir = fs::path(CLAY_TEST_OUTPUT_DIR) / "studio";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(sail_file, dir / "sail.json");
  StudioSession session = StudioSession::load(dir / "sail.json");
  const Json hello = Json::parse(session.handle(R"({"op": "hello"})").json);
  CHECK(hello.at("recipe") == "sail");
  CHECK(hello.at("surfaces") == Json::array({"sail"}));

  // An edit: the billow's first move from 300 to 500 mm. The frame's net is the sail of the
  // edited recipe as run_recipe computes it on its own.
  const auto edited = session.handle(
      Json{{"op", "edit"}, {"path", billow}, {"value", 500}, {"label", "billow 500"}}.dump());
  INFO(edited.json);
  const Json reply = Json::parse(edited.json);
  REQUIRE(reply.at("op") == "edit");
  Json doc = Json::parse(read(sail_file));
  doc["deformations"]["shape"][1]["moves"][0]["by"][1] = 500;
  const auto replay = run_recipe(parse_recipe(doc.dump(), sail_file.parent_path(), "sail"));
  // One frame per final surface (first), one per named curve of the run, then the deformed
  // surface's parent before its first step, then its deviation map.
  REQUIRE(edited.frames.size() == 3 + replay.curves.size());
  CHECK(same(decode(edited.frames[0]), replay.surface("sail")));
  CHECK(decode(edited.frames.back()).header.at("kind") == "deviation");
  const Net before = decode(edited.frames[edited.frames.size() - 2]);
  CHECK(before.header.at("before") == true);
  CHECK(same(before, replay.stages.front().before));
  CHECK(reply.at("befores") == Json::array({"sail"}));
  const auto nets = frames_by_name(edited);
  for (const auto& [name, curve] : replay.curves) {
    INFO("curve " << name);
    REQUIRE(nets.count(name) == 1);
    CHECK(nets.at(name).header.at("kind") == "curve");
    CHECK(same(nets.at(name), curve));
  }
  CHECK(reply.at("curves").size() == replay.curves.size());
  CHECK(session.history() == std::vector<std::string>{"open", "billow 500"});

  // Undo gives the original sail, redo the edited one again. Only what changed is sent again
  // (the sail and its deviation map); the curves and the sail's parent, as the page holds them
  // already, are named under "kept" (issue #40: a reply's size does not grow with the scene).
  const auto undone = session.handle(R"({"op": "undo"})");
  REQUIRE(undone.frames.size() == 2);
  const auto original = run_recipe(load_recipe(sail_file));
  CHECK(same(decode(undone.frames[0]), original.surface("sail")));
  CHECK(decode(undone.frames[1]).header.at("kind") == "deviation");
  const Json undone_reply = Json::parse(undone.json);
  CHECK(undone_reply.at("surfaces") == Json::array({"sail"}));
  CHECK(undone_reply.at("befores").empty());
  CHECK(undone_reply.at("curves").empty());
  CHECK(undone_reply.at("kept").at("befores") == Json::array({"sail"}));
  CHECK(undone_reply.at("kept").at("curves").size() == replay.curves.size());
  CHECK(undone_reply.at("kept").at("surfaces").empty());
  // "run" (what a new page sends) sends everything again.
  CHECK(session.handle(R"({"op": "run"})").frames.size() == 3 + replay.curves.size());
  CHECK(session.position() == 0);
  const auto redone = session.handle(R"({"op": "redo"})");
  CHECK(same(decode(redone.frames[0]), replay.surface("sail")));

  // Save, and replay the saved file as `clayform run` does: identical control points.
  const fs::path saved = dir / "sail_edited.json";
  const Json ok =
      Json::parse(session.handle(Json{{"op", "save"}, {"file", "sail_edited.json"}}.dump()).json);
  CHECK(ok.at("op") == "saved");
  CHECK(same(decode(redone.frames[0]), run_recipe(load_recipe(saved)).surface("sail")));

  // A drag's updates share a group: one entry, holding the last update; undo goes back past it.
  for (int v : {200, 250, 275})
    session.handle(Json{
        {"op", "edit"},
        {"path", billow},
        {"value", v},
        {"label", "drag billow"},
        {"group",
         "drag 1"}}.dump());
  CHECK(session.history() == std::vector<std::string>{"open", "billow 500", "drag billow"});
  // "nets": false (a drag the page draws itself): the run's figures and the history, no frames.
  const auto quiet = session.handle(Json{
      {"op", "edit"},
      {"path", billow},
      {"value", 275},
      {"label", "drag billow"},
      {"group", "drag 1"},
      {"nets", false}}.dump());
  CHECK(quiet.frames.empty());
  CHECK(Json::parse(quiet.json).at("nets") == false);
  CHECK(Json::parse(quiet.json).at("steps").size() == replay.steps.size());
  CHECK(Json::parse(session.text())["deformations"]["shape"][1]["moves"][0]["by"][1] == 275);
  session.handle(R"({"op": "undo"})");
  CHECK(Json::parse(session.text())["deformations"]["shape"][1]["moves"][0]["by"][1] == 500);
  // An edit after an undo drops the redo tail.
  session.handle(R"({"op": "undo"})");
  session.handle(
      Json{{"op", "edit"}, {"path", billow}, {"value", 100}, {"label", "billow 100"}}.dump());
  CHECK(session.history() == std::vector<std::string>{"open", "billow 100"});
}

TEST_CASE("studio session: bad commands are refused and change nothing", "[studio]") {
  StudioSession session = StudioSession::load(sail_file);
  const std::string before = session.text();
  auto error = [&](const std::string& command) {
    const Json r = Json::parse(session.handle(command).json);
    CHECK(r.at("op") == "error");
    return r.at("message").get<std::string>();
  };
  CHECK_THAT(error("not json"), Contains("not valid JSON"));
  CHECK_THAT(error(R"({"op": "fly"})"), Contains("unknown op \"fly\""));
  CHECK_THAT(error(R"({"op": "edit", "path": "deformations.nope", "value": 1})"),
             Contains("no \"deformations.nope\"") && Contains("create"));
  CHECK_THAT(error(R"({"op": "edit", "path": "a..b", "value": 1})"), Contains("empty key"));
  // A value the recipe refuses (a negative curve tolerance): the run's error, nothing changes.
  CHECK_THAT(
      error(R"({"op": "edit", "path": "deformations.shape[0].curve_tolerance", "value": -1})"),
      Contains("curve_tolerance"));
  CHECK_THAT(error(R"({"op": "undo"})"), Contains("nothing to undo"));
  // Created levels are object keys, even all-digit ones: JSON pointer would read "8888888889" as
  // a list index and grow a list of 8.9e9 entries (a fuzz finding). The recipe then refuses the
  // unknown key, and nothing changes.
  CHECK_THAT(error(R"({"op": "edit", "path": "extra.8888888889.x", "value": 1, "create": true})"),
             Contains("extra"));
  // A list index cannot be created: the list is sent whole.
  CHECK_THAT(error(R"({"op": "edit", "path": "extra[4000000000]", "value": 1, "create": true})"),
             Contains("no list at [4000000000]") && Contains("whole list"));
  CHECK(session.text() == before);
  CHECK(session.history().size() == 1);
  // create: a new key under an existing object.
  const Json created = Json::parse(
      session
          .handle(
              R"({"op": "edit", "path": "description", "value": "drawn in the studio", "create": true})")
          .json);
  CHECK(created.at("op") == "edit");
  CHECK(Json::parse(session.text()).at("description") == "drawn in the studio");
}

TEST_CASE("studio session: \"fit\" says how a stroke splits at its corners", "[studio]") {
  StudioSession session = StudioSession::load(sail_file);
  const std::string before = session.text();
  // A 100 x 60 rectangle drawn once round from the middle of its bottom side, every 3 mm.
  Json points = Json::array();
  const std::array<std::array<double, 2>, 6> path = {
      {{50, 0}, {100, 0}, {100, 60}, {0, 60}, {0, 0}, {50, 0}}};
  for (std::size_t leg = 0; leg + 1 < path.size(); ++leg) {
    const double dx = path[leg + 1][0] - path[leg][0], dy = path[leg + 1][1] - path[leg][1];
    const int steps = static_cast<int>(std::lround(std::hypot(dx, dy) / 3));
    for (int k = 0; k < steps; ++k)
      points.push_back({path[leg][0] + dx * k / steps, path[leg][1] + dy * k / steps, 0.0});
  }
  points.push_back({50.0, 0.0, 0.0});
  const Json fit = Json::parse(
      session.handle(Json{{"op", "fit"}, {"points", points}, {"tolerance_mm", 0.5}}.dump()).json);
  INFO(fit.dump());
  CHECK(fit.at("op") == "fit");
  CHECK(fit.at("pieces") == 4);
  CHECK(fit.at("corners").size() == 4);
  CHECK(fit.at("closed") == true);
  CHECK(fit.at("converged") == true);
  // with the recipe's "pieces": 4 the run gives curves NAME.1 .. NAME.4
  const Json edited =
      Json::parse(session
                      .handle(Json{
                          {"op", "edit"},
                          {"path", "strokes.frame"},
                          {"value", {{"points", points}, {"tolerance_mm", 0.5}, {"pieces", 4}}},
                          {"create",
                           true}}.dump())
                      .json);
  INFO(edited.dump());
  REQUIRE(edited.at("op") == "edit");
  for (const char* c : {"frame.1", "frame.2", "frame.3", "frame.4"})
    CHECK(std::find(edited.at("curves").begin(), edited.at("curves").end(), c) !=
          edited.at("curves").end());
  // A smooth arc on a plane: one piece.
  Json arc = Json::array();
  for (int k = 0; k <= 40; ++k)
    arc.push_back({100 * std::cos(k * 0.03), 100 * std::sin(k * 0.03), 5.0});
  const Json one =
      Json::parse(session
                      .handle(Json{{"op", "fit"},
                                   {"points", arc},
                                   {"plane", {{"origin", {0, 0, 5}}, {"normal", {0, 0, 1}}}}}
                                  .dump())
                      .json);
  CHECK(one.at("pieces") == 1);
  CHECK(one.at("closed") == false);
  // Bad input: named, and nothing changes.
  const std::string text = session.text();
  auto error = [&](const Json& command) {
    const Json r = Json::parse(session.handle(command.dump()).json);
    CHECK(r.at("op") == "error");
    return r.at("message").get<std::string>();
  };
  // Each problem with its path in the command, as the recipe checker words them.
  CHECK_THAT(error({{"op", "fit"}}), Contains("points: missing"));
  CHECK_THAT(error({{"op", "fit"}, {"points", {{0, 0, 0}, {1, "a", 0}}}}),
             Contains("points[1][1]: expected a number"));
  CHECK_THAT(error({{"op", "fit"}, {"points", arc}, {"tolerance_mm", "fine"}}),
             Contains("tolerance_mm: expected a number"));
  CHECK_THAT(error({{"op", "fit"}, {"points", arc}, {"tolerance_mm", -1}}),
             Contains("tolerance_mm: -1 is out of range"));
  // The key issue #37 renamed is named with its new name, not ignored (a page sending the old
  // key would otherwise get the default tolerance without a word).
  CHECK_THAT(error({{"op", "fit"}, {"points", arc}, {"tolerance", 0.5}}),
             Contains("\"tolerance\" was renamed \"tolerance_mm\"") &&
                 Contains("write \"tolerance_mm\": 0.5 instead"));
  CHECK_THAT(error({{"op", "fit"}, {"points", arc}, {"radius", 0.5}}),
             Contains("unknown key \"radius\""));
  CHECK_THAT(error({{"op", "fit"}, {"points", arc}, {"corner_angle", 200}}),
             Contains("corner_angle: 200 is out of range"));
  Json many = Json::array();
  for (int k = 0; k <= 10000; ++k) many.push_back({0.01 * k, 0.0, 0.0});
  CHECK_THAT(error({{"op", "fit"}, {"points", many}}), Contains("at most 10000"));
  CHECK_THAT(error({{"op", "fit"}, {"points", arc}, {"plane", {{"origin", {0, 0}}}}}),
             Contains("plane.origin: expected [x, y, z]") && Contains("plane.x_axis: missing"));
  // a plane whose axes are not orthonormal: the stroke's own check names it
  CHECK_THAT(
      error({{"op", "fit"},
             {"points", arc},
             {"plane", {{"origin", {0, 0, 0}}, {"x_axis", {1, 0, 0}}, {"y_axis", {1, 1, 0}}}}}),
      Contains("plane"));
  CHECK(session.text() == text);
  CHECK(before != text);
}

TEST_CASE("studio session: each run sends the deviation map of a surface its lattice deforms",
          "[studio]") {
  StudioSession session = StudioSession::load(sail_file);
  const auto ran = session.handle(R"({"op": "run"})");
  const Json reply = Json::parse(ran.json);
  REQUIRE(reply.at("deviations") == Json::array({"sail"}));
  // The frame: rows x cols distances from the sail to its last step's pointwise deformation of
  // the surface before it, at the same fractions of their domains (an independent replay's).
  const RunResult replay = run_recipe(load_recipe(sail_file));
  const Stage* last = nullptr;
  for (const Stage& st : replay.stages)
    if (st.surface == "sail") last = &st;
  REQUIRE(last);
  REQUIRE(last->map);
  bool found = false;
  for (const auto& f : ran.frames) {
    const auto [header, start] = mesh_header(f);
    if (header.at("kind") != "deviation") continue;
    found = true;
    const int rows = header.at("rows"), cols = header.at("cols");
    REQUIRE(f.size() == start + static_cast<std::size_t>(rows * cols) * sizeof(double));
    const auto& s = replay.surface("sail");
    const auto [u0, u1] = s.u.domain();
    const auto [v0, v1] = s.v.domain();
    const auto [a0, a1] = last->before.u.domain();
    const auto [b0, b1] = last->before.v.domain();
    double largest = 0;
    for (int i = 0; i < rows; i += 5)
      for (int j = 0; j < cols; j += 5) {
        double value = 0;
        std::memcpy(&value, f.data() + start + static_cast<std::size_t>(i * cols + j) * 8, 8);
        const double fu = double(i) / (rows - 1), fv = double(j) / (cols - 1);
        const Eigen::Vector3d p =
            clay::surface::evaluate(s, u0 + fu * (u1 - u0), v0 + fv * (v1 - v0));
        const Eigen::Vector3d q = last->map(
            clay::surface::evaluate(last->before, a0 + fu * (a1 - a0), b0 + fv * (b1 - b0)));
        CHECK(value == Approx((p - q).norm()).margin(1e-9));
        largest = std::max(largest, value);
      }
    CHECK(header.at("max").get<double>() >= largest);
    // The sail's lattice step is its certified bicubic light form (the exact one is above the
    // budget): the map shows that form's error, within its certified tolerance.
    const auto light = std::find_if(replay.steps.begin(), replay.steps.end(), [](const auto& st) {
      return st.path == "surfaces.sail.steps[1]";
    });
    REQUIRE(light != replay.steps.end());
    double tolerance = -1;
    for (const auto& [key, value] : light->figures)
      if (key == "tolerance_mm") tolerance = std::get<double>(value);
    CHECK(header.at("max").get<double>() > 0);
    CHECK(header.at("max").get<double>() <= tolerance);
  }
  CHECK(found);
}

TEST_CASE(
    "studio session: a stroke drawn into an empty recipe, a fill in one entry, removal, export",
    "[studio]") {
  const fs::path dir = fs::path(CLAY_TEST_OUTPUT_DIR) / "studio_draw";
  fs::remove_all(dir);
  fs::create_directories(dir);
  StudioSession session(R"({"format": "clayform.recipe", "version": 1, "name": "drawn"})", dir,
                        "drawn");
  // Four strokes, edges of a 100 x 60 mm patch (the first one bowed), each a new key of
  // "strokes", which the empty recipe does not have yet.
  auto along = [](std::array<double, 2> a, std::array<double, 2> b, double bow) {
    Json points = Json::array();
    for (int k = 0; k <= 20; ++k) {
      const double t = k / 20.0;
      points.push_back(
          {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]) - bow * 4 * t * (1 - t), 0.0});
    }
    return points;
  };
  const std::vector<std::pair<std::string, Json>> edges = {{"e0", along({0, 0}, {100, 0}, 8)},
                                                           {"e1", along({100, 0}, {100, 60}, 0)},
                                                           {"e2", along({100, 60}, {0, 60}, 0)},
                                                           {"e3", along({0, 60}, {0, 0}, 0)}};
  Json expected = Json::parse(session.text());
  for (const auto& [name, points] : edges) {
    const Json stroke = {{"points", points}, {"tolerance_mm", 0.01}, {"closing_ratio", 0}};
    const auto r = session.handle(Json{
        {"op", "edit"},
        {"path", "strokes." + name},
        {"value", stroke},
        {"create", true},
        {"label", "stroke " + name}}.dump());
    INFO(r.json);
    REQUIRE(Json::parse(r.json).at("op") == "edit");
    expected["strokes"][name] = stroke;
    const auto replay = run_recipe(parse_recipe(expected.dump(), dir, "drawn"));
    const auto nets = frames_by_name(r);
    REQUIRE(nets.count(name) == 1);
    CHECK(same(nets.at(name), replay.curve(name)));
  }
  // A fill and its report in one history entry with a stroke removed and put back: "changes".
  const Json fill = {{"fill", {{"curves", {"e0", "e1", "e2", "e3"}}}}};
  const auto filled = session.handle(
      Json{{"op", "edit"},
           {"label", "fill"},
           {"changes",
            {{{"path", "surfaces.patch"}, {"value", fill}, {"create", true}},
             {{"path", "strokes.e3"}, {"remove", true}},
             {{"path", "strokes.e3"}, {"value", expected["strokes"]["e3"]}, {"create", true}}}}}
          .dump());
  INFO(filled.json);
  REQUIRE(Json::parse(filled.json).at("op") == "edit");
  expected["surfaces"]["patch"] = fill;
  const auto replay = run_recipe(parse_recipe(expected.dump(), dir, "drawn"));
  CHECK(same(frames_by_name(filled).at("patch"), replay.surface("patch")));
  CHECK(session.history().back() == "fill");
  CHECK(session.history().size() == 6);
  // Removing what a surface is built from breaks the recipe: refused, nothing changes.
  const std::string before = session.text();
  const Json refused =
      Json::parse(session.handle(R"({"op": "edit", "path": "strokes.e1", "remove": true})").json);
  CHECK(refused.at("op") == "error");
  CHECK_THAT(refused.at("message").get<std::string>(), Contains("e1"));
  CHECK(session.text() == before);
  CHECK_THAT(
      Json::parse(session.handle(R"({"op": "edit", "path": "strokes.nope", "remove": true})").json)
          .at("message")
          .get<std::string>(),
      Contains("no such entry"));
  // Export: STEP, IGES and glTF of the final surfaces, read back and checked, beside the recipe.
  const Json exported =
      Json::parse(session.handle(R"({"op": "export", "folder": "out", "name": "patch"})").json);
  INFO(exported.dump());
  REQUIRE(exported.at("op") == "exported");
  CHECK(exported.at("valid") == true);
  CHECK(exported.at("read_back_identical") == true);
  for (const char* f : {"patch.step", "patch.igs", "patch.glb", "report.json"})
    CHECK(fs::exists(dir / "out" / f));
  CHECK(exported.at("profile") == "opencascade");
  CHECK(exported.at("bounds_mm") == Json::array({0.0}));  // the fill is exact, and conforms
  // Export for a receiver: class A takes the bicubic patch as it is; an unknown profile is
  // refused before anything runs, naming the profiles.
  const Json class_a = Json::parse(
      session
          .handle(R"({"op": "export", "folder": "out_a", "name": "patch", "profile": "class_a"})")
          .json);
  CHECK(class_a.at("profile") == "class_a");
  CHECK(class_a.at("valid") == true);
  const Json unknown = Json::parse(
      session.handle(R"({"op": "export", "folder": "out_b", "profile": "alias"})").json);
  CHECK(unknown.at("op") == "error");
  CHECK_THAT(unknown.at("message").get<std::string>(), Contains("class_a, bicubic"));
  CHECK_FALSE(fs::exists(dir / "out_b"));
}

TEST_CASE("studio session: a STEP model opened whole, meshed, deformed by a lattice, exported",
          "[studio]") {
  const fs::path model_file = fs::path(CLAY_EXAMPLES_DIR) / "models" / "block.step";
  const fs::path dir = fs::path(CLAY_TEST_OUTPUT_DIR) / "studio_model";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(model_file, dir / "block.step");
  StudioSession session = StudioSession::open(dir / "block.step");
  const Json recipe = Json::parse(session.text());
  CHECK(recipe.at("name") == "block_studio");
  CHECK(recipe.at("models").at("block").at("import") == "block.step");
  // The run's mesh frame: the model's trimmed faces as brep::tessellate meshes the file read on
  // its own, node for node.
  const auto ran = session.handle(R"({"op": "run"})");
  INFO(ran.json);
  REQUIRE(Json::parse(ran.json).at("models") == Json::array({"block"}));
  REQUIRE(ran.frames.size() == 1);
  const auto [header, start] = mesh_header(ran.frames[0]);
  const auto& frame = ran.frames[0];
  const auto mesh = clay::brep::tessellate(clay::brep::read_model(model_file).model);
  REQUIRE(header.at("vertices") == mesh.positions.size());
  REQUIRE(header.at("triangles") == mesh.triangles.size());
  const std::size_t n = mesh.positions.size();
  REQUIRE(frame.size() == start + 68 * n + 12 * mesh.triangles.size());
  std::vector<double> positions(3 * n);
  std::memcpy(positions.data(), frame.data() + start, positions.size() * sizeof(double));
  for (std::size_t k = 0; k < n; ++k)
    for (int e = 0; e < 3; ++e)
      REQUIRE(positions[3 * k + static_cast<std::size_t>(e)] == mesh.positions[k][e]);
  // A lattice around the block, its top raised 5 mm: the model is deformed (its mesh's top too).
  Eigen::Vector3d lo = mesh.positions.front(), hi = lo;
  for (const auto& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d size = hi - lo, origin = lo - 0.05 * size;
  Json moves = Json::array();
  for (int i = 0; i <= 1; ++i)
    for (int j = 0; j <= 1; ++j) moves.push_back({{"index", {i, j, 1}}, {"by", {0, 0, 5}}});
  const Json lattice = {{"kind", "bezier_lattice"},
                        {"frame",
                         {{"origin", {origin.x(), origin.y(), origin.z()}},
                          {"s", {1.1 * size.x(), 0, 0}},
                          {"t", {0, 1.1 * size.y(), 0}},
                          {"u", {0, 0, 1.1 * size.z()}}}},
                        {"degrees", {1, 1, 1}},
                        {"moves", moves}};
  const auto lifted = session.handle(
      Json{{"op", "edit"},
           {"label", "lattice on block"},
           {"changes",
            {{{"path", "deformations.lift"}, {"value", Json::array({lattice})}, {"create", true}},
             {{"path", "models.block.deformation"}, {"value", "lift"}, {"create", true}}}}}
          .dump());
  INFO(lifted.json);
  REQUIRE(Json::parse(lifted.json).at("op") == "edit");
  REQUIRE(lifted.frames.size() == 1);
  // Only positions changed (exact composition keeps each face's (u, v) and loops), so the frame
  // is the faces' nets, not a mesh: evaluated at the first mesh's nodes' (u, v), they give the
  // nodes raised by the lattice's closed form (the top corners moved 5 mm up: z + 5 w, where w is
  // the node's height in the lattice's frame).
  const auto [h2, start2] = mesh_header(lifted.frames[0]);
  REQUIRE(h2.at("kind") == "model_nets");
  REQUIRE(h2.at("faces").size() == header.at("faces").get<std::size_t>());
  std::vector<clay::surface::BSplineSurface> faces;
  std::size_t offset = start2;
  for (const Json& f : h2.at("faces")) {
    const auto nu = f.at("counts")[0].get<Eigen::Index>(),
               nv = f.at("counts")[1].get<Eigen::Index>();
    clay::surface::Points3 points(nu * nv, 3);
    Eigen::VectorXd weights(nu * nv);
    std::memcpy(points.data(), lifted.frames[0].data() + offset,
                static_cast<std::size_t>(points.size()) * sizeof(double));
    offset += static_cast<std::size_t>(points.size()) * sizeof(double);
    std::memcpy(weights.data(), lifted.frames[0].data() + offset,
                static_cast<std::size_t>(weights.size()) * sizeof(double));
    offset += static_cast<std::size_t>(weights.size()) * sizeof(double);
    faces.push_back(clay::surface::make_surface(
        {f.at("degrees")[0].get<int>(), f.at("knots_u").get<std::vector<double>>()},
        {f.at("degrees")[1].get<int>(), f.at("knots_v").get<std::vector<double>>()},
        std::move(points), std::move(weights)));
  }
  REQUIRE(offset == lifted.frames[0].size());
  // The first mesh's (u, v) and faces, read from its frame after the positions and normals.
  const std::size_t m = mesh.triangles.size();
  double worst = 0, top = -1e300;
  for (std::size_t k = 0; k < n; ++k) {
    double uv[2];
    std::uint32_t face = 0;
    std::memcpy(uv, frame.data() + start + 48 * n + 16 * k, sizeof uv);
    std::memcpy(&face, frame.data() + start + 64 * n + 12 * m + 4 * k, sizeof face);
    REQUIRE(face == static_cast<std::uint32_t>(mesh.node_face[k]));
    REQUIRE(uv[0] == mesh.uv[k].x());
    const Eigen::Vector3d p = mesh.positions[k];
    const Eigen::Vector3d expected =
        p + Eigen::Vector3d(0, 0, 5 * (p.z() - origin.z()) / (1.1 * size.z()));
    const Eigen::Vector3d got = clay::surface::evaluate(faces[face], uv[0], uv[1]);
    worst = std::max(worst, (got - expected).norm());
    top = std::max(top, got.z());
  }
  CHECK(worst < 1e-9 * size.norm());
  // the top face at w = 1/1.1 of the lattice's height, raised by that fraction of 5 mm
  CHECK(top == Approx(hi.z() + 5 * (hi.z() - origin.z()) / (1.1 * size.z())).epsilon(1e-9));
  // A "run" (what a new page sends) gives the whole mesh again, of the lifted block.
  const auto again = session.handle(R"({"op": "run"})");
  REQUIRE(again.frames.size() == 1);
  CHECK(mesh_header(again.frames[0]).first.at("kind") == "mesh");
  // Export: the deformed model's STEP, IGES and glTF, read back and checked.
  const Json exported = Json::parse(session.handle(R"({"op": "export", "folder": "out"})").json);
  INFO(exported.dump());
  REQUIRE(exported.at("op") == "exported");
  CHECK(exported.at("valid") == true);
  for (const char* f : {"block.step", "block.igs", "block.glb"}) CHECK(fs::exists(dir / "out" / f));
  // Export for a bicubic receiver: the model's faces too (the planes were degree 1), read back
  // from the written STEP.
  const Json bicubic = Json::parse(
      session.handle(R"({"op": "export", "folder": "out_bicubic", "profile": "bicubic"})").json);
  INFO(bicubic.dump());
  REQUIRE(bicubic.at("op") == "exported");
  CHECK(bicubic.at("valid") == true);
  CHECK(bicubic.at("profile") == "bicubic");
  const auto written = clay::brep::read_model(dir / "out_bicubic" / "block.step").model;
  int bicubic_faces = 0;
  for (const auto& face : clay::brep::flattened(written).faces) {
    CHECK(face.surface.u.degree == 3);
    CHECK(face.surface.v.degree == 3);
    ++bicubic_faces;
  }
  CHECK(bicubic_faces == 17);
  int lowest = 25;
  for (const auto& face :
       clay::brep::flattened(clay::brep::read_model(dir / "out" / "block.step").model).faces)
    lowest = std::min({lowest, face.surface.u.degree, face.surface.v.degree});
  CHECK(lowest == 1);
}

namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

using Client = clay::test::StudioClient;

}  // namespace

TEST_CASE(
    "studio session: progress names each step built, and a cancel changes nothing and keeps its "
    "steps",
    "[studio]") {
  const fs::path dir = fs::path(CLAY_TEST_OUTPUT_DIR) / "studio_cancel";
  fs::remove_all(dir);
  fs::create_directories(dir);
  StudioSession session(read(sail_file), dir, "sail");
  std::vector<Json> lines;
  const auto progress = [&](const std::string& line) { lines.push_back(Json::parse(line)); };
  // Cancelled once two steps have started: it stops before the third, and says so.
  const std::string before = session.text();
  const Json cancelled = Json::parse(
      session.handle(R"({"op": "run"})", [&] { return lines.size() >= 2; }, progress).json);
  INFO(cancelled.dump());
  CHECK(cancelled.at("op") == "error");
  CHECK(cancelled.at("category") == "cancelled");
  CHECK_THAT(cancelled.at("message").get<std::string>(), Contains("cancelled in a recipe's steps"));
  REQUIRE(lines.size() == 2);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    CHECK(lines[k].at("op") == "progress");
    CHECK(lines[k].at("command") == "run");
    CHECK(lines[k].at("steps_done") == k);
    CHECK(lines[k].at("seconds").get<double>() >= 0);
  }
  CHECK(lines[0].at("doing") == "curves.luff (line)");
  CHECK(lines[1].at("doing") == "curves.foot (bspline)");
  CHECK(session.text() == before);
  CHECK(session.history().size() == 1);
  // Run whole: a line per step built, none for the two the cancelled run finished (the cache).
  lines.clear();
  const Json whole = Json::parse(session.handle(R"({"op": "run"})", {}, progress).json);
  REQUIRE(whole.at("op") == "run");
  std::size_t reused = 0;
  for (const Json& step : whole.at("steps")) reused += step.value("reused", false) ? 1 : 0;
  CHECK(reused == 2);
  CHECK(lines.size() == whole.at("steps").size() - reused);
  CHECK(lines.back().at("steps_done") == whole.at("steps").size() - 1);

  // An export cancelled while it writes leaves no file behind; the next one writes them all.
  lines.clear();
  const auto writing = [&] {
    return !lines.empty() && lines.back().at("doing") == "writing the files and reading them back";
  };
  const Json stopped = Json::parse(
      session.handle(R"({"op": "export", "folder": "out", "name": "sail"})", writing, progress)
          .json);
  INFO(stopped.dump());
  CHECK(stopped.at("category") == "cancelled");
  CHECK_THAT(stopped.at("message").get<std::string>(), Contains("writing a recipe's files"));
  std::vector<std::string> left;
  if (fs::exists(dir / "out"))
    for (const auto& entry : fs::recursive_directory_iterator(dir / "out"))
      left.push_back(entry.path().string());
  CHECK(left.empty());
  lines.clear();
  const Json exported = Json::parse(
      session.handle(R"({"op": "export", "folder": "out", "name": "sail"})", {}, progress).json);
  REQUIRE(exported.at("op") == "exported");
  CHECK(exported.at("valid") == true);
  CHECK(fs::exists(dir / "out" / "sail.step"));
  CHECK(lines.back().at("doing") == "writing the files and reading them back");
}

TEST_CASE("studio server: its own page's origin talks, any other is refused", "[studio]") {
  StudioOptions options;
  options.port = 0;
  StudioServer server(StudioSession::load(sail_file), options);
  server.start();
  const int port = server.port();
  {
    Client client(port, "http://127.0.0.1:" + std::to_string(port), server.token());
    client.send(R"({"op": "hello"})");
    const auto [text, body] = client.receive();
    CHECK(text);
    CHECK(Json::parse(body).at("recipe") == "sail");
    // While the page holds its socket: another site's page (or a DNS-rebound name) cannot open
    // one (403 at the upgrade), answered at once, not after the page closes.
    for (const std::string& origin :
         {std::string("http://evil.example"), "http://127.0.0.1:" + std::to_string(port + 1),
          std::string("null")}) {
      INFO("origin " << origin);
      try {
        Client refused(port, origin, server.token());
        FAIL("the upgrade was accepted");
      } catch (const beast::system_error& e) {
        CHECK(e.code() == websocket::error::upgrade_declined);
      }
    }
    client.send(R"({"op": "recipe"})");
    CHECK(Json::parse(client.receive().second).at("op") == "recipe");
    client.ws.close(websocket::close_code::normal);
  }
  // The server goes on serving its own page after refusing. A second page of its own (a
  // reload, another tab) takes the socket over; the first one's connection is closed.
  Client again(port, "http://localhost:" + std::to_string(port), server.token());
  again.send(R"({"op": "recipe"})");
  CHECK(Json::parse(again.receive().second).at("op") == "recipe");
  Client newer(port, "http://127.0.0.1:" + std::to_string(port), server.token());
  newer.send(R"({"op": "hello"})");
  CHECK(Json::parse(newer.receive().second).at("op") == "hello");
  CHECK_THROWS(again.receive());
  newer.ws.close(websocket::close_code::normal);
  server.stop();
}

TEST_CASE("studio server: a burst of edits of one path is answered for the newest", "[studio]") {
  StudioOptions options;
  options.port = 0;
  StudioServer server(StudioSession::load(sail_file), options);
  server.start();
  Client client(server.port(), "http://127.0.0.1:" + std::to_string(server.port()), server.token());
  const int burst = 12;
  for (int k = 1; k <= burst; ++k)
    client.send(
        Json{{"op", "edit"}, {"path", billow}, {"value", 20 * k}, {"label", "drag"}}.dump());
  client.send(R"({"op": "hello"})");
  int edits = 0;
  std::string last_net;
  while (true) {
    const auto [text, body] = client.receive();
    if (!text) {
      const Net net = decode(std::vector<std::uint8_t>(body.begin(), body.end()));
      if (net.header.at("kind") == "net" && !net.header.contains("before")) last_net = body;
      continue;
    }
    const Json r = Json::parse(body);
    if (r.at("op") == "progress") continue;  // (a loaded machine's edit may run half a second)
    if (r.at("op") == "hello") {
      CHECK(r.at("history").at("entries").size() == static_cast<std::size_t>(edits + 1));
      break;
    }
    REQUIRE(r.at("op") == "edit");
    ++edits;
  }
  INFO(edits << " of " << burst << " edits answered");
  CHECK(edits >= 1);
  CHECK(edits <= burst);
  // Whatever was coalesced, the newest value is what the recipe holds and the last net shows.
  CHECK(Json::parse(server.recipe_text())["deformations"]["shape"][1]["moves"][0]["by"][1] ==
        20 * burst);
  Json doc = Json::parse(read(sail_file));
  doc["deformations"]["shape"][1]["moves"][0]["by"][1] = 20 * burst;
  const auto replay = run_recipe(parse_recipe(doc.dump(), sail_file.parent_path(), "sail"));
  CHECK(same(decode(std::vector<std::uint8_t>(last_net.begin(), last_net.end())),
             replay.surface("sail")));
  client.ws.close(websocket::close_code::normal);
  server.stop();
}

TEST_CASE("studio server: a long run sends its progress and stops at the page's cancel",
          "[studio]") {
  // The fender (46 s in a Release build) is still running when its first progress line comes.
  const fs::path fender = fs::path(CLAY_EXAMPLES_DIR) / "recipes" / "fender.json";
  StudioOptions options;
  options.port = 0;
  StudioServer server(StudioSession::load(fender), options);
  server.start();
  Client client(server.port(), "http://127.0.0.1:" + std::to_string(server.port()), server.token());
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  const auto sent = Clock::now();
  client.send(R"({"op": "run"})");
  auto next_text = [&] {
    while (true) {
      const auto [text, body] = client.receive();
      if (text) return Json::parse(body);
    }
  };
  const Json line = next_text();
  const double first_line = since(sent);
  INFO(line.dump() << " after " << first_line << " s");
  REQUIRE(line.at("op") == "progress");
  CHECK(line.at("command") == "run");
  CHECK(first_line >= 0.5);  // a command under half a second sends none
  CHECK_THAT(line.at("doing").get<std::string>(), Contains(" ("));
  const auto cancel = Clock::now();
  client.send(R"({"op": "cancel"})");
  Json reply = next_text();
  int lines_after = 0;
  for (; reply.at("op") == "progress"; reply = next_text()) ++lines_after;
  const double stopped = since(cancel);
  INFO(reply.dump() << "; " << lines_after << " progress lines after the cancel; stopped after "
                    << stopped << " s");
  CHECK(reply.at("op") == "error");
  CHECK(reply.at("category") == "cancelled");
  CHECK(stopped < 60);  // (a sanitized build on a loaded 2-core machine: a step's longest loop)
  // Nothing changed, and the server answers the next command.
  client.send(R"({"op": "hello"})");
  const Json hello = client.reply();
  CHECK(hello.at("op") == "hello");
  CHECK(hello.at("history").at("entries").size() == 1);
  client.ws.close(websocket::close_code::normal);
  server.stop();
}
