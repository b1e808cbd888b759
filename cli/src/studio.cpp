// Clayform Studio's kernel side (clay/studio.hpp): the session (a recipe under edits with a
// history) and its server (Boost.Beast, Debian's libboost-dev: cpp-httplib 0.11 has no
// WebSocket, and Beast is the well-kept header-only HTTP/WebSocket library Debian ships).
#include <clay/brep/exchange.hpp>
#include <clay/error.hpp>
#include <clay/internal/files.hpp>
#include <clay/internal/json_reader.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/studio.hpp>
#include <clay/surface/evaluate.hpp>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <fstream>
#include <functional>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

namespace clay::recipe {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

/// "a.b[2].c" -> JSON pointer "/a/b/2/c"; clay::Error(InvalidArgument) for a malformed path.
Json::json_pointer pointer_of(const std::string& path) {
  std::string out;
  std::size_t i = 0;
  bool expect_key = true;
  while (i < path.size()) {
    if (path[i] == '[') {
      const std::size_t close = path.find(']', i);
      const std::string index = close == std::string::npos ? "" : path.substr(i + 1, close - i - 1);
      if (index.empty() || !std::all_of(index.begin(), index.end(), ::isdigit))
        throw Error(ErrorCategory::InvalidArgument,
                    "studio: path \"" + path + "\" has a malformed list index; write items as [i]");
      out += "/" + index;
      i = close + 1;
      expect_key = false;
    } else if (path[i] == '.') {
      if (expect_key)
        throw Error(ErrorCategory::InvalidArgument,
                    "studio: path \"" + path + "\" has an empty key");
      ++i;
      expect_key = true;
    } else {
      const std::size_t end = path.find_first_of(".[", i);
      std::string key = path.substr(i, end == std::string::npos ? std::string::npos : end - i);
      // JSON pointer escapes: ~ as ~0, / as ~1.
      std::string escaped;
      for (char c : key) escaped += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
      out += "/" + escaped;
      i = end == std::string::npos ? path.size() : end;
      expect_key = false;
    }
  }
  if (out.empty() || expect_key)
    throw Error(ErrorCategory::InvalidArgument,
                "studio: path \"" + path + "\" is empty or ends with \".\"");
  return Json::json_pointer(out);
}

/// Applies one change of an "edit" to the recipe document: {path, value, create?} sets a value
/// (the path must exist, or with create its parent object), {path, remove: true} removes a key
/// or a list item. `first_path` gets the first change's path (the default history label).
void apply_change(Json& doc, const Json& change, std::string& first_path) {
  if (!change.is_object() || !change.contains("path") || !change.at("path").is_string())
    throw Error(ErrorCategory::InvalidArgument,
                "studio: \"edit\" needs \"path\" (a JSON path of the recipe) and \"value\" "
                "(or \"remove\": true)");
  const std::string path = change.at("path");
  if (first_path.empty()) first_path = path;
  const Json::json_pointer ptr = pointer_of(path);
  const bool exists = doc.contains(ptr);
  if (change.value("remove", false)) {
    if (!exists)
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: cannot remove \"" + path + "\": the recipe has no such entry");
    Json& parent = doc.at(ptr.parent_pointer());
    if (parent.is_array())
      parent.erase(static_cast<std::size_t>(std::stoul(ptr.back())));
    else
      parent.erase(ptr.back());
    return;
  }
  if (!change.contains("value"))
    throw Error(ErrorCategory::InvalidArgument,
                "studio: the change of \"" + path + "\" has no \"value\" (or \"remove\": true)");
  if (!exists) {
    if (!change.value("create", false))
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: the recipe has no \"" + path + "\"; to add it, send \"create\": true");
    // Created keys hang from an object: the nearest existing entry above must be one (the
    // missing ones between, e.g. "strokes" of a recipe without strokes, are made objects).
    Json::json_pointer above = ptr.parent_pointer();
    while (!above.empty() && !doc.contains(above)) above = above.parent_pointer();
    if (!doc.at(above).is_object())
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: cannot create \"" + path + "\": \"" + above.to_string() +
                      "\" is not an object; a list item is changed by its index");
  }
  doc[ptr] = change.at("value");
}

}  // namespace

namespace {

/// A frame of `body_bytes` after its prefix: the 4-byte little-endian length of the JSON header,
/// the header, zero padding to a multiple of 8. Returns the frame and where the body starts.
/// (Sized once and filled with memcpy: GCC 12 misreads insert() of chars into bytes as an
/// overflow at -O3.)
std::pair<std::vector<std::uint8_t>, std::size_t> frame_with_header(const std::string& header_json,
                                                                    std::size_t body_bytes) {
  const std::size_t padded = (4 + header_json.size() + 7) / 8 * 8;
  std::vector<std::uint8_t> out(padded + body_bytes, 0);
  const auto length = static_cast<std::uint32_t>(header_json.size());
  for (int k = 0; k < 4; ++k)
    out[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(length >> (8 * k));
  std::memcpy(out.data() + 4, header_json.data(), header_json.size());
  return {std::move(out), padded};
}

}  // namespace

std::vector<std::uint8_t> net_frame(const std::string& header_json,
                                    const std::vector<double>& points,
                                    const std::vector<double>& weights) {
  auto [out, at] =
      frame_with_header(header_json, (points.size() + weights.size()) * sizeof(double));
  // x86-64: little-endian; an empty list (a deviation map has no weights) copies nothing (memcpy
  // may not be handed its null data)
  if (!points.empty()) std::memcpy(out.data() + at, points.data(), points.size() * sizeof(double));
  if (!weights.empty())
    std::memcpy(out.data() + at + points.size() * sizeof(double), weights.data(),
                weights.size() * sizeof(double));
  return out;
}

namespace {

/// A model's frame: the length and JSON header as in net_frame ({"kind": "mesh", "name",
/// "vertices": n, "triangles": m, "faces"}), then n * 3 float64 positions, n * 3 float64 unit
/// normals, n * 2 float64 (u, v) on each node's face, m * 3 uint32 node indices and n uint32
/// face indices, little-endian. The (u, v) and faces let the page move the nodes itself when only
/// the faces' control points change (model_nets_frame).
std::vector<std::uint8_t> mesh_frame(const std::string& header_json, const brep::ModelMesh& mesh) {
  const std::size_t n = mesh.positions.size(), m = mesh.triangles.size();
  auto [out, start] = frame_with_header(
      header_json, (2 * n * 3 + 2 * n) * sizeof(double) + (m * 3 + n) * sizeof(std::uint32_t));
  std::uint8_t* at = out.data() + start;
  for (const auto* list : {&mesh.positions, &mesh.normals})
    for (const Eigen::Vector3d& p : *list) {
      std::memcpy(at, p.data(), 3 * sizeof(double));
      at += 3 * sizeof(double);
    }
  for (const Eigen::Vector2d& uv : mesh.uv) {
    std::memcpy(at, uv.data(), 2 * sizeof(double));
    at += 2 * sizeof(double);
  }
  auto put = [&](int index) {
    const auto value = static_cast<std::uint32_t>(index);
    std::memcpy(at, &value, sizeof value);
    at += sizeof value;
  };
  for (const auto& t : mesh.triangles)
    for (int corner : t) put(corner);
  for (int face : mesh.node_face) put(face);
  return out;
}

/// A model's faces as nets, one frame: the header {"kind": "model_nets", "name", "faces": [{
/// "degrees", "counts", "knots_u", "knots_v", "rational", "reversed"}, ...]}, then each face's
/// points (3 float64 each) and weights in turn. Sent instead of a mesh when the model's topology
/// is that of the mesh the page holds: the page evaluates each node at its (u, v).
std::vector<std::uint8_t> model_nets_frame(const std::string& name, const brep::Model& model) {
  Json faces = Json::array();
  std::size_t doubles = 0;
  for (const brep::Face& f : model.faces) {
    const surface::BSplineSurface& s = f.surface;
    faces.push_back({{"degrees", {s.u.degree, s.v.degree}},
                     {"counts", {s.u.count(), s.v.count()}},
                     {"knots_u", s.u.knots},
                     {"knots_v", s.v.knots},
                     {"rational", s.is_rational()},
                     {"reversed", f.reversed}});
    doubles += static_cast<std::size_t>(s.points.size() + s.weights.size());
  }
  const Json header = {{"kind", "model_nets"}, {"name", name}, {"faces", faces}};
  auto [out, start] = frame_with_header(header.dump(), doubles * sizeof(double));
  std::uint8_t* at = out.data() + start;
  for (const brep::Face& f : model.faces) {
    const surface::BSplineSurface& s = f.surface;
    std::memcpy(at, s.points.data(), static_cast<std::size_t>(s.points.size()) * sizeof(double));
    at += static_cast<std::size_t>(s.points.size()) * sizeof(double);
    std::memcpy(at, s.weights.data(), static_cast<std::size_t>(s.weights.size()) * sizeof(double));
    at += static_cast<std::size_t>(s.weights.size()) * sizeof(double);
  }
  return out;
}

/// The viewer's deviation map (docs/viewer.md) of a surface: on a rows x cols grid evenly over
/// its domain, the distance from the surface to its last stage's pointwise deformation of the
/// surface before it, at the same fractions of that surface's domain (exact composition: rounding;
/// a refit: its error). A frame {"kind": "deviation", "name", "step", "rows", "cols", "max"}
/// then rows * cols float64, row (u) by row.
std::vector<std::uint8_t> deviation_frame(const std::string& name, const surface::BSplineSurface& s,
                                          const Stage& stage, int rows, int cols) {
  // The same fractions of both domains, the last one each domain's end exactly.
  auto fractions = [](const surface::BSplineBasis& basis, int n) {
    const auto [first, last] = basis.domain();
    std::vector<double> t(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k)
      t[static_cast<std::size_t>(k)] = k == n - 1 ? last : first + (last - first) * k / (n - 1);
    return t;
  };
  const surface::Points3 after =
      surface::evaluate_grid(s, fractions(s.u, rows), fractions(s.v, cols));
  const surface::Points3 before = surface::evaluate_grid(
      stage.before, fractions(stage.before.u, rows), fractions(stage.before.v, cols));
  std::vector<double> values(static_cast<std::size_t>(after.rows()));
  double worst = 0;
  for (Eigen::Index k = 0; k < after.rows(); ++k) {
    const Eigen::Vector3d q = stage.map(before.row(k).transpose());
    const double d = (after.row(k).transpose() - q).norm();
    values[static_cast<std::size_t>(k)] = d;
    worst = std::max(worst, d);
  }
  const Json header = {{"kind", "deviation"}, {"name", name}, {"step", stage.step},
                       {"rows", rows},        {"cols", cols}, {"max", worst}};
  return net_frame(header.dump(), values, {});
}

/// What a model's mesh depends on besides its faces' control points: the faces, their domains,
/// sides and loops (edges used, senses, pcurves bit for bit). Exact composition keeps (u, v), so
/// a deformed model keeps its key and its mesh's nodes stay at their (u, v) (FNV-1a, 64 bits).
std::uint64_t topology_key(const brep::Model& model) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* data, std::size_t bytes) {
    const auto* b = static_cast<const std::uint8_t*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ull;
  };
  auto mix_value = [&](auto x) { mix(&x, sizeof x); };
  mix_value(model.faces.size());
  for (const brep::Face& f : model.faces) {
    const auto [u0, u1] = f.surface.u.domain();
    const auto [v0, v1] = f.surface.v.domain();
    for (double d : {u0, u1, v0, v1}) mix_value(d);
    mix_value(f.reversed);
    mix_value(f.loops.size());
    for (const brep::Loop& loop : f.loops) {
      mix_value(loop.coedges.size());
      for (const brep::Coedge& c : loop.coedges) {
        mix_value(c.edge);
        mix_value(c.same_sense);
        mix(c.pcurve.basis.knots.data(), c.pcurve.basis.knots.size() * sizeof(double));
        mix(c.pcurve.points.data(),
            static_cast<std::size_t>(c.pcurve.points.size()) * sizeof(double));
        mix(c.pcurve.weights.data(),
            static_cast<std::size_t>(c.pcurve.weights.size()) * sizeof(double));
      }
    }
  }
  return h;
}

/// The "fit" op: the stroke {points, plane?, tolerance?, corner_angle?} fitted as a recipe stroke
/// with "pieces" would be (fit_stroke, split where it turns by more than corner_angle), and how:
/// the page asks before it writes the stroke, so a stroke with corners becomes one with "pieces".
/// Read by the shared path-aware reader, with a recipe stroke's limits; every problem is named.
Json fit_reply(const Json& command) {
  const internal::Json c = internal::Json::parse(command.dump());
  internal::JsonReader r;
  r.limit_note = "a recipe stroke's limit: draw it as several strokes";
  sketch::Stroke stroke;
  if (const auto* pts = r.member(c, "", "points", true, "the drawn points [[x, y, z], ...]"))
    if (auto p = r.points(*pts, "points", 2, 10000)) stroke.points = std::move(*p);
  if (const auto* pl = r.member(c, "", "plane", false, "");
      pl && r.object(*pl, "plane", {"origin", "normal", "x_axis", "y_axis"},
                     "a plane {origin, normal, x_axis?} or {origin, x_axis, y_axis}")) {
    auto vec = [&](const char* key, bool required) -> std::optional<Eigen::Vector3d> {
      const auto* v = r.member(*pl, "plane", key, required, "[x, y, z]");
      return v ? r.vec3(*v, internal::key_path("plane", key)) : std::nullopt;
    };
    const auto origin = vec("origin", true);
    if (pl->contains("normal")) {
      const auto normal = vec("normal", true);
      const auto x = pl->contains("x_axis") ? vec("x_axis", true) : std::nullopt;
      if (origin && normal) stroke.plane = sketch::make_plane(*origin, *normal, x);
    } else {
      const auto x = vec("x_axis", true), y = vec("y_axis", true);
      if (origin && x && y) stroke.plane = sketch::SketchPlane{*origin, *x, *y};
    }
  }
  sketch::FitOptions options;
  options.tolerance =
      r.number_or(c, "", "tolerance", options.tolerance, internal::Range{0, 1e6, true});
  options.corner_angle = r.number_or(c, "", "corner_angle", options.corner_angle,
                                     internal::Range{0, 180, true, false});
  if (!r.problems.empty()) {
    std::string list;
    for (const auto& p : r.problems) list += (list.empty() ? "" : "; ") + p.path + ": " + p.message;
    throw Error(ErrorCategory::InvalidArgument, "studio: \"fit\": " + list);
  }
  sketch::validate(stroke, "the fit's stroke");
  const sketch::StrokeFit fit = sketch::fit_stroke(stroke, options);
  return {{"op", "fit"},
          {"pieces", fit.curves.size()},
          {"corners", fit.corners},
          {"closed", fit.closed},
          {"max_deviation_mm", fit.max_deviation_mm},
          {"corner_angle", options.corner_angle},
          {"converged", fit.summary.converged()}};
}

}  // namespace

struct StudioSession::Impl {
  fs::path base_dir;
  std::string name;
  std::vector<std::pair<std::string, std::string>> history;  // (label, recipe text)
  std::vector<std::string> groups;  // per entry: the "group" of the edits it holds ("" none)
  int position = 0;
  /// Per model, the topology key of the mesh last sent (topology_key): while it holds, runs send
  /// the model's nets only. "hello" and "run" (what a new page sends first) forget them.
  mutable std::map<std::string, std::uint64_t> meshed;

  const std::string& text() const { return history[static_cast<std::size_t>(position)].second; }

  /// A file or folder the page names, relative to the recipe's folder.
  fs::path resolve(const std::string& relative) const {
    const fs::path p(relative);
    return p.is_absolute() ? p : base_dir / p;
  }

  /// A run of the recipe text, and the surfaces a picture of it shows (final_surfaces).
  struct Run {
    RunResult result;
    std::vector<std::string> shown;
  };
  Run run(const std::string& recipe_text) const {
    const Recipe recipe = parse_recipe(recipe_text, base_dir, name);
    return {run_recipe(recipe), final_surfaces(recipe)};
  }

  Json history_json() const {
    Json h = Json::array();
    for (const auto& [label, t] : history) h.push_back(label);
    return Json{{"entries", h}, {"position", position}};
  }

  /// The reply of a run: its report figures per step, the history and the recipe text; then a
  /// net frame per final surface, a curve frame per named curve, and a net frame per deformed
  /// final surface's parent before its first step. Without `nets` (a drag update the page draws
  /// itself), no frames: the figures and the history only.
  Reply ran(const std::string& op, const Run& run, bool nets = true) const {
    const RunResult& result = run.result;
    Reply reply;
    Json steps = Json::array();
    for (const auto& s : result.steps) {
      Json figures = Json::object();
      for (const auto& [k, v] : s.figures)
        std::visit([&, key = k](const auto& x) { figures[key] = x; }, v);
      steps.push_back({{"path", s.path},
                       {"kind", s.kind},
                       {"seconds", s.seconds},
                       {"warning", s.warning},
                       {"message", s.message},
                       {"figures", figures}});
    }
    auto push_net = [&](const std::string& n, const surface::BSplineSurface& s, bool before) {
      Json header = {{"kind", "net"},
                     {"name", n},
                     {"degrees", {s.u.degree, s.v.degree}},
                     {"counts", {s.u.count(), s.v.count()}},
                     {"knots_u", s.u.knots},
                     {"knots_v", s.v.knots},
                     {"rational", s.is_rational()}};
      if (before) header["before"] = true;
      std::vector<double> points(s.points.data(), s.points.data() + s.points.size());
      std::vector<double> weights(s.weights.data(), s.weights.data() + s.weights.size());
      reply.frames.push_back(net_frame(header.dump(), points, weights));
    };
    // A drag update the page draws itself ("nets": false) gets no frames: none are made.
    const std::vector<std::string> none;
    const std::vector<std::string>& shown = nets ? run.shown : none;
    Json surfaces = Json::array();
    for (const std::string& n : shown) {
      push_net(n, result.surface(n), false);
      surfaces.push_back(n);
    }
    // Every named curve too (fitted strokes, sketch entities, bounds and targets): the page
    // draws them from their nets and picks them by name.
    Json curves = Json::array();
    for (const auto& [n, c] : result.curves) {
      if (!nets) break;
      const Json header = {{"kind", "curve"},
                           {"name", n},
                           {"degree", c.basis.degree},
                           {"knots", c.basis.knots},
                           {"rational", c.is_rational()}};
      std::vector<double> points(c.points.data(), c.points.data() + c.points.size());
      std::vector<double> weights(c.weights.data(), c.weights.data() + c.weights.size());
      reply.frames.push_back(net_frame(header.dump(), points, weights));
      curves.push_back(n);
    }
    // A deformed surface's parent before its first step (the page's before/after view, and
    // what a lattice drag is checked against).
    Json befores = Json::array();
    for (const std::string& n : shown) {
      const auto stage = std::find_if(result.stages.begin(), result.stages.end(),
                                      [&](const Stage& st) { return st.surface == n; });
      if (stage == result.stages.end()) continue;
      push_net(n, stage->before, true);
      befores.push_back(n);
    }
    // The deviation map of each shown surface whose last step deforms space point by point (a
    // lattice, taper, twist or bend; a style step moves control points and has none).
    Json deviations = Json::array();
    for (const std::string& n : shown) {
      const auto stage = std::find_if(result.stages.rbegin(), result.stages.rend(),
                                      [&](const Stage& st) { return st.surface == n; });
      if (stage == result.stages.rend() || !stage->map) continue;
      reply.frames.push_back(deviation_frame(n, result.surface(n), *stage, 41, 41));
      deviations.push_back(n);
    }
    // Whole models (a recipe's "models", a STEP file opened in the studio): their trimmed faces
    // as a triangle mesh when the page has none of this topology yet, else only the faces' nets
    // (a lattice moved: the mesh's nodes keep their (u, v), the page evaluates them there).
    Json models = Json::array();
    if (nets)
      for (const ModelRunResult& m : result.models) {
        const std::uint64_t key = topology_key(m.model);
        if (const auto it = meshed.find(m.name); it != meshed.end() && it->second == key) {
          reply.frames.push_back(model_nets_frame(m.name, m.model));
        } else {
          const brep::ModelMesh mesh = brep::tessellate(m.model);
          const Json header = {{"kind", "mesh"},
                               {"name", m.name},
                               {"vertices", mesh.positions.size()},
                               {"triangles", mesh.triangles.size()},
                               {"faces", m.model.faces.size()}};
          reply.frames.push_back(mesh_frame(header.dump(), mesh));
          meshed[m.name] = key;
        }
        models.push_back(m.name);
      }
    Json out = {{"op", op},       {"recipe", result.recipe},   {"seconds", result.seconds},
                {"steps", steps}, {"history", history_json()}, {"text", text()}};
    if (nets) {
      out["surfaces"] = surfaces;
      out["curves"] = curves;
      out["befores"] = befores;
      out["models"] = models;
      out["deviations"] = deviations;
    } else {
      out["nets"] = false;
    }
    reply.json = out.dump();
    return reply;
  }
};

StudioSession::StudioSession(std::string text, fs::path base_dir, std::string name)
    : impl_(std::make_unique<Impl>()) {
  impl_->base_dir = std::move(base_dir);
  impl_->name = std::move(name);
  parse_recipe(text, impl_->base_dir, impl_->name);  // throws Recipe listing the problems
  impl_->history.emplace_back("open", std::move(text));
  impl_->groups.emplace_back();
}

StudioSession::~StudioSession() = default;
StudioSession::StudioSession(StudioSession&&) noexcept = default;
StudioSession& StudioSession::operator=(StudioSession&&) noexcept = default;

StudioSession StudioSession::load(const fs::path& file) {
  return StudioSession(internal::read_text(file, "recipe"), file.parent_path(),
                       file.stem().string());
}

StudioSession StudioSession::open(const fs::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (extension != ".step" && extension != ".stp" && extension != ".igs" && extension != ".iges")
    return load(file);
  if (!fs::exists(file))
    throw Error(ErrorCategory::Io,
                "studio: cannot read \"" + file.string() + "\": no such file; check the path");
  // A model: a recipe beside it importing it whole, named after it (saved as STEM_studio.json).
  std::string name;
  for (char ch : file.stem().string())
    name += std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' ? ch : '_';
  name = name.substr(0, 50);
  const Json recipe = {
      {"format", "clayform.recipe"},
      {"version", 1},
      {"name", name + "_studio"},
      {"description", "Opened in Clayform Studio from " + file.filename().string()},
      {"models", {{name, {{"import", file.filename().string()}}}}}};
  return StudioSession(recipe.dump(1), file.parent_path(), name + "_studio");
}

const std::string& StudioSession::text() const { return impl_->text(); }

std::vector<std::string> StudioSession::history() const {
  std::vector<std::string> out;
  for (const auto& [label, t] : impl_->history) out.push_back(label);
  return out;
}

int StudioSession::position() const { return impl_->position; }

StudioSession::Reply StudioSession::handle(const std::string& command) {
  Impl& s = *impl_;
  try {
    const Json c = Json::parse(command);
    if (!c.is_object() || !c.contains("op") || !c.at("op").is_string())
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: a command is a JSON object with \"op\" (hello, recipe, edit, undo, "
                  "redo, run, save, export, fit)");
    const std::string op = c.at("op");
    if (op == "hello") {
      s.meshed.clear();  // a new page holds no mesh yet
      const Recipe r = parse_recipe(s.text(), s.base_dir, s.name);
      return {Json{{"op", "hello"},
                   {"recipe", r.name()},
                   {"surfaces", final_surfaces(r)},
                   {"deformations", r.deformation_names()},
                   {"history", s.history_json()}}
                  .dump(),
              {}};
    }
    if (op == "recipe") return {Json{{"op", "recipe"}, {"text", s.text()}}.dump(), {}};
    if (op == "fit") return {fit_reply(c).dump(), {}};
    if (op == "run") {
      s.meshed.clear();  // "run" sends everything: the page may hold nothing (a new page)
      return s.ran("run", s.run(s.text()));
    }
    if (op == "undo" || op == "redo") {
      const int to = s.position + (op == "undo" ? -1 : 1);
      if (to < 0 || to >= static_cast<int>(s.history.size()))
        throw Error(ErrorCategory::InvalidArgument, "studio: nothing to " + op +
                                                        " (history position " +
                                                        std::to_string(s.position) + " of " +
                                                        std::to_string(s.history.size()) + ")");
      const Impl::Run result = s.run(s.history[static_cast<std::size_t>(to)].second);
      s.position = to;
      return s.ran(op, result);
    }
    if (op == "edit") {
      // One change ({path, value, create?} or {path, remove: true}) or several ("changes": an
      // array of them), applied in order as one entry of the history.
      Json changes = Json::array();
      if (c.contains("changes")) {
        if (!c.at("changes").is_array() || c.at("changes").empty())
          throw Error(ErrorCategory::InvalidArgument,
                      "studio: \"changes\" must be a non-empty array of {path, value} or "
                      "{path, remove: true}");
        changes = c.at("changes");
      } else {
        changes.push_back(c);
      }
      Json doc = Json::parse(s.text());
      std::string first_path;
      for (const Json& change : changes) apply_change(doc, change, first_path);
      std::string next = doc.dump(1);
      const Impl::Run result = s.run(next);  // a recipe the edit breaks throws: nothing changes
      // The updates of one drag share a "group": the latest replaces the entry an earlier one
      // made, so the drag is one step of the history.
      const std::string group = c.value("group", "");
      const auto at = static_cast<std::size_t>(s.position);
      if (!group.empty() && at + 1 == s.history.size() && s.groups[at] == group) {
        s.history[at].second = std::move(next);
        return s.ran("edit", result, c.value("nets", true));
      }
      s.history.resize(at + 1);  // an edit drops the redo tail
      s.groups.resize(at + 1);
      s.history.emplace_back(c.value("label", "edit " + first_path), std::move(next));
      s.groups.push_back(group);
      s.position = static_cast<int>(s.history.size()) - 1;
      return s.ran("edit", result, c.value("nets", true));
    }
    if (op == "export") {
      // The final surfaces, as STEP, IGES and glTF (write_outputs: read back and checked),
      // with the run's report, into a folder (relative to the recipe's).
      if (!c.contains("folder") || !c.at("folder").is_string() ||
          c.at("folder").get<std::string>().empty())
        throw Error(ErrorCategory::InvalidArgument,
                    "studio: \"export\" needs \"folder\" (relative to the recipe's folder)");
      const fs::path folder = s.resolve(c.at("folder").get<std::string>());
      Impl::Run run = s.run(s.text());
      if (run.shown.empty() && run.result.models.empty())
        throw Error(ErrorCategory::InvalidArgument,
                    "studio: the recipe has no surface or model to export yet; build one first");
      run.result.exports.clear();
      if (!run.shown.empty()) {
        ExportResult e;
        e.name = c.value("name", run.result.recipe);
        e.formats = {"step", "iges", "glb"};
        for (const std::string& n : run.shown) {
          e.surface_names.push_back(n);
          e.surfaces.push_back(run.result.surface(n));
        }
        run.result.exports.push_back(std::move(e));
      }
      write_outputs(run.result, folder);  // the models' files too (NAME.step, .igs, .glb)
      Json files = Json::array();
      bool valid = true, identical = true;
      for (const ExportResult& x : run.result.exports) {
        for (const std::string& f : x.files) files.push_back(f);
        valid = valid && x.valid;
        identical = identical && x.read_back_identical;
      }
      for (const ModelRunResult& m : run.result.models) {
        for (const std::string& f : m.files) files.push_back(f);
        valid = valid && m.valid;
      }
      return {Json{{"op", "exported"},
                   {"folder", folder.string()},
                   {"files", files},
                   {"valid", valid},
                   {"read_back_identical", identical}}
                  .dump(),
              {}};
    }
    if (op == "save") {
      if (!c.contains("file") || !c.at("file").is_string())
        throw Error(ErrorCategory::InvalidArgument, "studio: \"save\" needs \"file\"");
      const fs::path file = s.resolve(c.at("file").get<std::string>());
      const fs::path tmp = file.string() + ".clayform-tmp";
      {
        std::ofstream out(tmp, std::ios::binary);
        out << s.text();
        if (!out)
          throw Error(ErrorCategory::Io,
                      "studio: cannot write \"" + tmp.string() + "\"; check the folder");
      }
      std::error_code ec;
      fs::rename(tmp, file, ec);
      if (ec)
        throw Error(ErrorCategory::Io,
                    "studio: cannot move the recipe to \"" + file.string() + "\": " + ec.message());
      return {Json{{"op", "saved"}, {"file", file.string()}}.dump(), {}};
    }
    throw Error(ErrorCategory::InvalidArgument,
                "studio: unknown op \"" + op +
                    "\"; the ops: hello, recipe, edit, undo, redo, run, save, export, fit");
  } catch (const Error& e) {
    return {Json{{"op", "error"},
                 {"category", std::string(to_string(e.category()))},
                 {"message", recipe_wording(e.message())}}
                .dump(),
            {}};
  } catch (const Json::exception& e) {
    return {Json{{"op", "error"},
                 {"category", "invalid argument"},
                 {"message", std::string("studio: the command is not valid JSON: ") + e.what()}}
                .dump(),
            {}};
  }
}

// ---- the server -----------------------------------------------------------------------------

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

struct StudioServer::Impl {
  StudioSession session;
  StudioOptions options;
  asio::io_context accept_io;  // the acceptor's
  tcp::acceptor acceptor{accept_io};
  int port = 0;
  std::thread thread;
  mutable std::mutex session_mutex;  // one command at a time on the session

  /// One accepted connection, served on a thread of its own (with its own io_context for the
  /// WebSocket's asynchronous reads and writes), so the page's open socket does not hold up
  /// another request (a file, a refused upgrade).
  struct Connection {
    asio::io_context io;
    tcp::socket socket{io};
    std::thread thread;
    std::atomic<bool> done{false};
  };
  std::mutex mutex;  // guards connections, socket_owner, stopping
  std::list<std::unique_ptr<Connection>> connections;
  Connection* socket_owner = nullptr;  // the connection of the page that holds the WebSocket
  std::condition_variable released;    // socket_owner became nullptr
  bool stopping = false;

  /// Joins the threads of finished connections (mutex held).
  void reap() {
    for (auto it = connections.begin(); it != connections.end();) {
      if ((*it)->done) {
        (*it)->thread.join();
        it = connections.erase(it);
      } else {
        ++it;
      }
    }
  }

  explicit Impl(StudioSession s) : session(std::move(s)) {}

  /// Host must be the server's own address and Origin its page: a page from elsewhere (DNS
  /// rebinding, another site) cannot open the socket.
  bool allowed(const http::request<http::string_body>& req) const {
    const std::string p = std::to_string(port);
    const std::string host(req[http::field::host]);
    const std::string origin(req[http::field::origin]);
    const bool host_ok =
        host == "127.0.0.1:" + p || host == "localhost:" + p || host == options.host + ":" + p;
    const bool origin_ok = origin == "http://127.0.0.1:" + p || origin == "http://localhost:" + p ||
                           origin == "http://" + options.host + ":" + p;
    return host_ok && origin_ok;
  }

  http::response<http::string_body> plain(const http::request<http::string_body>& req,
                                          http::status status, const std::string& body) const {
    http::response<http::string_body> res{status, req.version()};
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.keep_alive(false);
    res.body() = body;
    res.prepare_payload();
    return res;
  }

  void serve_file(tcp::socket& socket, const http::request<http::string_body>& req) const {
    std::string target(req.target());
    if (const auto q = target.find('?'); q != std::string::npos) target.resize(q);
    if (target == "/") target = "/studio.html";
    if (target.find("..") != std::string::npos) {
      http::write(socket, plain(req, http::status::bad_request, "a path with \"..\" is refused\n"));
      return;
    }
    const fs::path file =
        options.front_end.empty() ? fs::path() : options.front_end / target.substr(1);
    std::ifstream in(file, std::ios::binary);
    if (file.empty() || !in) {
      http::write(socket,
                  plain(req, http::status::not_found,
                        target == "/studio.html"
                            ? "The studio's page is not built yet (issue #23). The kernel's "
                              "WebSocket is at /ws: JSON commands hello, recipe, edit, undo, "
                              "redo, run, save (docs/studio.md).\n"
                            : "not found: " + target + "\n"));
      return;
    }
    std::ostringstream body;
    body << in.rdbuf();
    static const std::map<std::string, std::string> types = {{".html", "text/html; charset=utf-8"},
                                                             {".js", "text/javascript"},
                                                             {".css", "text/css"},
                                                             {".json", "application/json"},
                                                             {".png", "image/png"}};
    const auto t = types.find(file.extension().string());
    http::response<http::string_body> res{http::status::ok, req.version()};
    res.set(http::field::content_type, t == types.end() ? "application/octet-stream" : t->second);
    res.keep_alive(false);
    res.body() = body.str();
    res.prepare_payload();
    http::write(socket, res);
  }

  /// Queues a command; an edit replaces a queued edit of the same path in its place (a drag
  /// sends many; the kernel answers the newest).
  static void enqueue(std::deque<std::string>& queue, std::string command) {
    // An edit's key: its path, or its changes' paths joined.
    auto edit_path = [](const std::string& text) -> std::optional<std::string> {
      const Json c = Json::parse(text, nullptr, false);
      if (!c.is_object() || c.value("op", "") != "edit") return std::nullopt;
      if (c.contains("path") && c.at("path").is_string()) return c.at("path").get<std::string>();
      if (!c.contains("changes") || !c.at("changes").is_array()) return std::nullopt;
      std::string key;
      for (const Json& change : c.at("changes")) {
        if (!change.is_object() || !change.contains("path") || !change.at("path").is_string())
          return std::nullopt;
        key += change.at("path").get<std::string>() + "\n";
      }
      return key;
    };
    if (const auto path = edit_path(command))
      for (std::string& queued : queue)
        if (edit_path(queued) == path) {
          queued = std::move(command);
          return;
        }
    queue.push_back(std::move(command));
  }

  /// One WebSocket client, until it closes. Reads and writes run here, as asynchronous
  /// operations on this thread; the commands run on a worker, one at a time. Commands that
  /// arrive while one runs wait in a queue where a newer edit of a path replaces an older one:
  /// at most one drag update is being computed, and the newest wins.
  void converse(websocket::stream<tcp::socket&>& ws, asio::io_context& io) {
    std::mutex queue_mutex;
    std::condition_variable wake;
    std::deque<std::string> queue;
    bool closed = false;
    std::deque<std::pair<bool, std::vector<std::uint8_t>>> out;  // (text, bytes)
    bool writing = false;
    beast::flat_buffer buffer;
    io.restart();
    std::function<void()> write_next = [&] {
      if (writing || out.empty()) return;
      writing = true;
      ws.text(out.front().first);
      ws.async_write(asio::buffer(out.front().second), [&](beast::error_code ec, std::size_t) {
        writing = false;
        out.pop_front();
        if (!ec) write_next();
      });
    };
    std::function<void()> read_next = [&] {
      ws.async_read(buffer, [&](beast::error_code ec, std::size_t) {
        {
          std::lock_guard<std::mutex> lock(queue_mutex);
          if (ec)
            closed = true;
          else
            enqueue(queue, beast::buffers_to_string(buffer.data()));
        }
        wake.notify_all();
        buffer.consume(buffer.size());
        if (!ec) read_next();
      });
    };
    std::thread worker([&] {
      while (true) {
        std::string command;
        {
          std::unique_lock<std::mutex> lock(queue_mutex);
          wake.wait(lock, [&] { return closed || !queue.empty(); });
          if (closed) return;
          command = std::move(queue.front());
          queue.pop_front();
        }
        auto reply = std::make_shared<StudioSession::Reply>();
        {
          std::lock_guard<std::mutex> lock(session_mutex);
          *reply = session.handle(command);
        }
        asio::post(io, [&, reply] {
          out.emplace_back(true, std::vector<std::uint8_t>(reply->json.begin(), reply->json.end()));
          for (auto& frame : reply->frames) out.emplace_back(false, std::move(frame));
          write_next();
        });
      }
    });
    read_next();
    io.run();  // until the client closes (or stop() shuts the socket) and the writes are done
    {
      std::lock_guard<std::mutex> lock(queue_mutex);
      closed = true;
    }
    wake.notify_all();
    worker.join();
    // What the worker posted after the reads ended runs now, while everything it refers to
    // lives (the writes fail at once on the closed socket).
    io.restart();
    io.run();
  }

  void handle_connection(Connection& connection) {
    tcp::socket& socket = connection.socket;
    asio::io_context& io = connection.io;
    beast::flat_buffer buffer;
    http::request<http::string_body> req;
    http::read(socket, buffer, req);
    if (!websocket::is_upgrade(req)) {
      serve_file(socket, req);
      return;
    }
    if (std::string(req.target()) != "/ws") {
      http::write(socket, plain(req, http::status::not_found, "the studio's socket is /ws\n"));
      return;
    }
    if (!allowed(req)) {
      http::write(socket, plain(req, http::status::forbidden,
                                "refused: the studio's socket takes its own page only (Host and "
                                "Origin must be this server's address)\n"));
      return;
    }
    {
      // One page edits the recipe at a time: the newest (a reload, another tab) takes over, the
      // older one's socket is closed (its page says so). A command still running there is
      // waited for.
      std::unique_lock<std::mutex> lock(mutex);
      if (socket_owner) {
        boost::system::error_code ignored;
        socket_owner->socket.shutdown(tcp::socket::shutdown_both, ignored);
        if (!released.wait_for(lock, std::chrono::seconds(30),
                               [&] { return socket_owner == nullptr; })) {
          http::write(socket, plain(req, http::status::conflict,
                                    "the studio's other page is still busy with a command; "
                                    "try again when it has finished\n"));
          return;
        }
      }
      socket_owner = &connection;
    }
    struct Release {
      Impl& s;
      ~Release() {
        {
          std::lock_guard<std::mutex> lock(s.mutex);
          s.socket_owner = nullptr;
        }
        s.released.notify_all();
      }
    } release{*this};
    websocket::stream<tcp::socket&> ws(socket);
    ws.read_message_max(64 << 20);
    ws.accept(req);
    converse(ws, io);
  }
};

StudioServer::StudioServer(StudioSession session, const StudioOptions& options)
    : impl_(std::make_unique<Impl>(std::move(session))) {
  impl_->options = options;
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(options.host, ec);
  if (ec)
    throw Error(ErrorCategory::InvalidArgument,
                "studio: host \"" + options.host + "\" is not an address; give e.g. 127.0.0.1");
  const tcp::endpoint at(address, static_cast<unsigned short>(options.port));
  impl_->acceptor.open(at.protocol(), ec);
  if (!ec) impl_->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) impl_->acceptor.bind(at, ec);
  if (!ec) impl_->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    throw Error(ErrorCategory::Io, "studio: cannot listen on " + options.host + ":" +
                                       std::to_string(options.port) + ": " + ec.message() +
                                       "; choose another --port (0 for any free one)");
  impl_->port = impl_->acceptor.local_endpoint().port();
}

StudioServer::~StudioServer() { stop(); }

int StudioServer::port() const noexcept { return impl_->port; }

std::string StudioServer::url() const {
  return "http://" + impl_->options.host + ":" + std::to_string(impl_->port) + "/";
}

std::string StudioServer::recipe_text() const {
  std::lock_guard<std::mutex> lock(impl_->session_mutex);
  return impl_->session.text();
}

void StudioServer::run() {
  Impl& s = *impl_;
  while (true) {
    auto connection = std::make_unique<Impl::Connection>();
    boost::system::error_code ec;
    s.acceptor.accept(connection->socket, ec);
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.stopping) break;
    s.reap();
    if (ec) continue;
    // A reply is a JSON frame and then its binary frames, written one after another: with
    // Nagle's algorithm each small write after the first waits for the page's (delayed, up to
    // 40 ms) ACK of the one before. Interactive traffic goes out at once.
    connection->socket.set_option(tcp::no_delay(true), ec);
    Impl::Connection* c = connection.get();
    c->thread = std::thread([&s, c] {
      try {
        s.handle_connection(*c);
      } catch (const std::exception&) {
        // A client that goes away mid-message ends its connection, not the server.
      }
      boost::system::error_code ignored;
      c->socket.shutdown(tcp::socket::shutdown_both, ignored);
      c->socket.close(ignored);
      c->done = true;
    });
    s.connections.push_back(std::move(connection));
  }
  // Stopping: stop() has shut every connection's socket; their threads end.
  std::list<std::unique_ptr<Impl::Connection>> open;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    open.swap(s.connections);
  }
  for (auto& c : open) c->thread.join();
}

void StudioServer::start() {
  impl_->thread = std::thread([this] { run(); });
}

void StudioServer::stop() {
  if (!impl_) return;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    if (impl_->stopping && !impl_->thread.joinable()) return;
    impl_->stopping = true;
    boost::system::error_code ec;
    for (auto& c : impl_->connections) c->socket.shutdown(tcp::socket::shutdown_both, ec);
  }
  // A blocking accept wakes for a connection only: make one (run() then sees `stopping`).
  if (impl_->thread.joinable()) {
    boost::system::error_code ec;
    asio::io_context io;
    tcp::socket poke(io);
    poke.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"),
                               static_cast<unsigned short>(impl_->port)),
                 ec);
    impl_->thread.join();
  }
  boost::system::error_code ec;
  impl_->acceptor.close(ec);
}

}  // namespace clay::recipe
