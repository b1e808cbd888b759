// Clayform Studio's session (clay/studio.hpp): a recipe under edits with a named history, one
// handler per op. Every command is read whole before anything changes; every reply is valid
// UTF-8 JSON whatever the command held; files are written only inside the recipe's folder.
#include "frames/frames.hpp"

#include <clay/cancel.hpp>
#include <clay/deform/receiver.hpp>
#include <clay/error.hpp>
#include <clay/internal/fenv.hpp>
#include <clay/internal/files.hpp>
#include <clay/internal/json_reader.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/recipe/document.hpp>
#include <clay/recipe/path.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/studio.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string_view>

namespace clay::recipe {

namespace fs = std::filesystem;
// Ordered: an edit keeps the document's key order (sorted keys put a surface before the one it
// is made from, which the recipe refuses: 5 of the 12 examples could not be edited, issue #36).
using Json = nlohmann::ordered_json;

namespace {

/// Every reply's text: invalid UTF-8 (a command's bytes quoted in a message) is replaced, not
/// thrown (a throw there ended the server, issue #36).
std::string reply_text(const Json& reply) {
  return reply.dump(-1, ' ', false, Json::error_handler_t::replace);
}

/// A command's optional field of one JSON type, read before anything changes: absent gives
/// `fallback`, another type is an error naming the field and the type it needs.
template <class T>
T field(const Json& command, const char* op, const char* key, T fallback, const char* type) {
  const auto it = command.find(key);
  if (it == command.end()) return fallback;
  const bool ok = std::is_same_v<T, bool>          ? it->is_boolean()
                  : std::is_same_v<T, std::string> ? it->is_string()
                                                   : it->is_number();
  if (!ok)
    throw Error(ErrorCategory::InvalidArgument, std::string("studio: \"") + op + "\": \"" + key +
                                                    "\" must be " + type + ", not " +
                                                    internal::found(*it));
  return it->get<T>();
}

/// A recipe path as a JSON pointer, and which of its tokens were list indices ([i]) rather than
/// keys: a key may be all digits ("a.2"), and only the path tells the two apart.
struct RecipePath {
  Json::json_pointer pointer;
  std::vector<bool> is_index;  ///< per token, from the first
};

/// "a.b[2].c" -> JSON pointer "/a/b/2/c" (the grammar is recipe::parse_path's, shared with the
/// sweeps); clay::Error(InvalidArgument) for a malformed path.
RecipePath pointer_of(const std::string& path) {
  std::vector<PathStep> steps;
  try {
    steps = parse_path(path);
  } catch (const Error& e) {
    throw Error(e.category(), "studio: " + e.message());
  }
  RecipePath out;
  std::string pointer;
  for (const PathStep& step : steps) {
    if (const auto* key = std::get_if<std::string>(&step)) {
      // JSON pointer escapes: ~ as ~0, / as ~1.
      pointer += "/";
      for (char c : *key) pointer += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
      out.is_index.push_back(false);
    } else {
      pointer += "/" + std::to_string(std::get<std::size_t>(step));
      out.is_index.push_back(true);
    }
  }
  out.pointer = Json::json_pointer(pointer);
  return out;
}

/// The number of tokens of a JSON pointer.
std::size_t depth_of(Json::json_pointer p) {
  std::size_t n = 0;
  for (; !p.empty(); p.pop_back()) ++n;
  return n;
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
  const bool remove = field<bool>(change, "edit", "remove", false, "true or false");
  const bool create = field<bool>(change, "edit", "create", false, "true or false");
  const RecipePath parsed = pointer_of(path);
  const Json::json_pointer& ptr = parsed.pointer;
  const bool exists = doc.contains(ptr);
  if (remove) {
    if (!exists)
      throw Error(ErrorCategory::InvalidArgument, "studio: cannot remove \"" +
                                                      internal::clip_utf8(path, 120) +
                                                      "\": the recipe has no such entry");
    Json& parent = doc.at(ptr.parent_pointer());
    if (parent.is_array())
      parent.erase(static_cast<std::size_t>(std::stoul(ptr.back())));
    else
      parent.erase(ptr.back());
    return;
  }
  if (!change.contains("value"))
    throw Error(ErrorCategory::InvalidArgument, "studio: the change of \"" +
                                                    internal::clip_utf8(path, 120) +
                                                    "\" has no \"value\" (or \"remove\": true)");
  if (exists) {
    doc.at(ptr) = change.at("value");
    return;
  }
  if (!create)
    throw Error(ErrorCategory::InvalidArgument, "studio: the recipe has no \"" +
                                                    internal::clip_utf8(path, 120) +
                                                    "\"; to add it, send \"create\": true");
  // Created keys hang from an object: the nearest existing entry above must be one, and the
  // missing ones between (e.g. "strokes" of a recipe without strokes) are made objects. They are
  // walked here as object keys: JSON pointer's own creation would read a digit key ("a.123456789")
  // as a list index and grow a list to that length (a fuzzed edit asked for 8.9e9 entries).
  Json::json_pointer above = ptr.parent_pointer();
  while (!above.empty() && !doc.contains(above)) above = above.parent_pointer();
  if (!doc.at(above).is_object())
    throw Error(ErrorCategory::InvalidArgument,
                "studio: cannot create \"" + internal::clip_utf8(path, 120) + "\": \"" +
                    internal::clip_utf8(above.to_string(), 120) +
                    "\" is not an object; a list item is changed by its index");
  std::vector<std::string> missing;
  for (Json::json_pointer p = ptr; p != above; p.pop_back()) missing.push_back(p.back());
  const std::size_t first_missing = depth_of(above);
  for (std::size_t k = first_missing; k < parsed.is_index.size(); ++k)
    if (parsed.is_index[k])
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: cannot create \"" + internal::clip_utf8(path, 120) +
                      "\": it has no list at [" +
                      internal::clip_utf8(missing[missing.size() - 1 - (k - first_missing)], 24) +
                      "]; send the whole list as the value of its key");
  Json* node = &doc.at(above);
  for (auto key = missing.rbegin(); key != missing.rend(); ++key) node = &(*node)[*key];
  *node = change.at("value");
}

}  // namespace

namespace {

/// The "fit" op: the stroke {points, plane?, tolerance?, corner_angle?} fitted as a recipe stroke
/// with "pieces" would be (fit_stroke, split where it turns by more than corner_angle), and how:
/// the page asks before it writes the stroke, so a stroke with corners becomes one with "pieces".
/// Read by the shared path-aware reader, with a recipe stroke's limits; every problem is named.
/// Fitted through the session's `cache`: the edit that writes the stroke takes this fit.
Json fit_reply(const Json& command, recipe::RunCache& cache) {
  const internal::Json& c = command;
  internal::JsonReader r;
  r.limit_note = "a recipe stroke's limit: draw it as several strokes";
  r.object(c, "", {"op", "points", "plane", "tolerance_mm", "corner_angle"},
           "a fit {points, plane?, tolerance_mm?, corner_angle?}",
           {{"tolerance", "tolerance_mm", "in millimetres"}});
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
  options.tolerance_mm =
      r.number_or(c, "", "tolerance_mm", options.tolerance_mm, internal::Range{0, 1e6, true});
  options.corner_angle = r.number_or(c, "", "corner_angle", options.corner_angle,
                                     internal::Range{0, 180, true, false});
  if (!r.problems.empty()) {
    std::string list;
    for (const auto& p : r.problems) list += (list.empty() ? "" : "; ") + p.path + ": " + p.message;
    throw Error(ErrorCategory::InvalidArgument, "studio: \"fit\": " + list);
  }
  sketch::validate(stroke, "the fit's stroke");
  const sketch::StrokeFit fit = cache.fit_stroke(stroke, options);
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
  struct Entry {
    std::string label;
    std::string text;   // the recipe text
    std::string group;  // the "group" of the edits it holds ("" none)
    /// The edit's changes that make `text` from the entry before it (a group's, in order), or
    /// null: the autosave writes these instead of the text, so its size follows the edits, not
    /// the number of entries times the recipe (issue #40).
    Json changes = nullptr;
  };
  /// recipe::check's limit of a recipe's text, which an edit's document is checked without.
  static constexpr std::size_t recipe_bytes = 64u << 20;
  /// A group's changes past which its entry is autosaved as its text again.
  static constexpr std::size_t group_changes_kept = 256;
  std::vector<Entry> history;
  int position = 0;
  /// Counts the changes of the current text (an edit, an undo, a redo, a restore): an edit's
  /// reply carries its changes from `revision - 1` instead of the whole text, and the page,
  /// holding that revision, applies them (issue #40: the text grew every reply with the recipe).
  std::uint64_t revision = 0;
  std::size_t dropped = 0;  // oldest entries dropped to keep the history within history_limit
  std::size_t history_limit = history_bytes;
  /// Per model, the topology key of the mesh last sent (topology_key): while it holds, runs send
  /// the model's nets only. "hello" and "run" (what a new page sends first) forget them.
  mutable std::map<std::string, std::uint64_t> meshed;
  /// Per frame ("net NAME", "before NAME", "curve NAME"; "deviation NAME" keyed by the two nets
  /// it is made from), the frame_key last sent: a run's reply sends only what changed and names
  /// the rest under "kept", so a stroke's reply stays the size of the stroke however many
  /// surfaces, styles and curves the page shows (issue #40). Forgotten with `meshed`.
  mutable std::map<std::string, std::uint64_t> sent;
  // The last run and the recipe text it ran: what the next edit of deformations alone reuses.
  mutable std::shared_ptr<const RunResult> last_run;
  mutable std::string last_text;
  mutable std::shared_ptr<const Json> last_doc;  // last_text parsed, when an edit had it so
  // Every step's result kept between runs (issue #40): an edit re-runs only the steps
  // downstream of what it changed; undo, redo and a restored autosave meet their steps again.
  std::shared_ptr<RunCache> cache = std::make_shared<RunCache>();
  fs::path autosave;  // empty: none
  std::chrono::steady_clock::time_point autosaved{};
  bool autosave_pending = false;
  Json restored;                 // what restore() read ({entries, file}), in the history
  std::string autosave_problem;  // why the last autosave failed ("" when it did not)

  const std::string& text() const { return history[static_cast<std::size_t>(position)].text; }

  // The command being handled, for its progress lines (handle() sets them).
  struct Doing {
    std::string op;
    StudioSession::Progress progress;
    std::chrono::steady_clock::time_point since;
    int steps_done = 0;
  };
  mutable Doing doing;

  /// Tells the progress callback what the command does now: {"op": "progress", "command",
  /// "doing" (a step's path and kind, or a phase of an export), "steps_done", "seconds"}.
  void tell(const std::string& what) const {
    if (!doing.progress) return;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - doing.since).count();
    doing.progress(reply_text(Json{{"op", "progress"},
                                   {"command", doing.op},
                                   {"doing", what},
                                   {"steps_done", doing.steps_done},
                                   {"seconds", seconds}}));
  }

  /// A run of the recipe text, and the surfaces a picture of it shows (final_surfaces). A
  /// cancelled command ends at the next step.
  struct Run {
    std::shared_ptr<RunResult> result;
    std::vector<std::string> shown;
  };
  /// Runs the recipe text; `changed` (the deformations an edit changed, and nothing else) lets
  /// the run take every other surface from the last run, and `preview` (a drag update) lets a
  /// lattice's light form be the one product of its linear map (RunOptions).
  Run run(const std::string& recipe_text, const std::function<bool()>& cancelled,
          const std::optional<std::vector<std::string>>& changed = std::nullopt,
          bool preview = false, const std::string& profile = "",
          std::shared_ptr<const Json> parsed = nullptr) const {
    // An edit's document is checked as it is: its text, printed from it, need not be parsed.
    const Recipe recipe = parsed ? parse_recipe_document(parsed, base_dir, name)
                                 : parse_recipe(recipe_text, base_dir, name);
    RunOptions options;
    options.profile = profile;  // the export's receiver, for the deformed models
    options.cache = cache;
    // (A cancel stops the run inside its long steps too: handle() opened a CancelScope.)
    options.progress = [this](const StepReport&) { ++doing.steps_done; };
    options.starting = [this](const std::string& path, const std::string& kind) {
      tell(path + " (" + kind + ")");
    };
    if (changed && last_run) {
      options.previous = last_run;
      options.changed_deformations = *changed;
      options.preview = preview;
    } else if (preview && last_run) {
      // A drag of something else (a style's target curve): the lattice steps after it preview
      // on their last light forms too; what is unchanged comes from the cache.
      options.previous = last_run;
      options.take_from_previous = false;
      options.preview = true;
    }
    if (cancelled && cancelled()) throw Cancelled{"the studio's command"};
    Run out{std::make_shared<RunResult>(run_recipe(recipe, options)), final_surfaces(recipe)};
    last_run = out.result;
    last_text = recipe_text;
    last_doc = std::move(parsed);
    return out;
  }

  /// The deformations whose definitions differ between the last run's recipe and `next`, when
  /// nothing else differs (then the run may take every other surface from the last run).
  /// Compared section by section in place: a stroke's edit of a long recipe copies nothing.
  std::optional<std::vector<std::string>> changed_deformations(const Json& after) const {
    if (!last_run) return std::nullopt;
    if (!last_doc) last_doc = std::make_shared<const Json>(Json::parse(last_text));
    const Json& before = *last_doc;
    if (!before.is_object() || !after.is_object()) return std::nullopt;
    for (const auto& [key, value] : before.items())
      if (key != "deformations" && (!after.contains(key) || after.at(key) != value))
        return std::nullopt;
    for (const auto& [key, value] : after.items())
      if (key != "deformations" && !before.contains(key)) return std::nullopt;
    const Json none = Json::object();
    const Json& a = before.contains("deformations") ? before.at("deformations") : none;
    const Json& b = after.contains("deformations") ? after.at("deformations") : none;
    if (!a.is_object() || !b.is_object()) return std::nullopt;
    std::vector<std::string> changed;
    for (const auto& [key, value] : a.items())
      if (!b.contains(key) || b.at(key) != value) changed.push_back(key);
    for (const auto& [key, value] : b.items())
      if (!a.contains(key)) changed.push_back(key);
    return changed;
  }

  Json history_json() const {
    Json h = Json::array();
    for (const Entry& e : history) h.push_back(e.label);
    Json out{{"entries", h}, {"position", position}, {"dropped", dropped}};
    if (!autosave_problem.empty()) out["autosave_problem"] = autosave_problem;
    if (!restored.is_null()) out["restored"] = restored;
    return out;
  }

  /// Appends an entry after the current one (dropping the redo tail), then drops the oldest
  /// entries while the texts exceed history_limit (the current one and one before it stay).
  void push(Entry entry) {
    history.resize(static_cast<std::size_t>(position) + 1);
    history.push_back(std::move(entry));
    position = static_cast<int>(history.size()) - 1;
    std::size_t bytes = 0;
    for (const Entry& e : history) bytes += e.text.size() + e.label.size();
    while (bytes > history_limit && position > 1) {
      bytes -= history.front().text.size() + history.front().label.size();
      history.erase(history.begin());
      --position;
      ++dropped;
    }
    save_soon();
  }

  /// The history changed: autosave it now, unless the last autosave is under a second old (a
  /// drag's updates); then flush_autosave (the server calls it when idle) writes it.
  void save_soon() {
    if (autosave.empty()) return;
    autosave_pending = true;
    if (std::chrono::steady_clock::now() - autosaved <= std::chrono::seconds(1)) return;
    // The edit is done whatever the disk says: a failed autosave is reported with the history
    // (and tried again at the next change), not turned into the edit's error.
    try {
      flush_autosave();
      autosave_problem.clear();
    } catch (const Error& e) {
      autosave_problem = e.message();
    }
  }

  /// Writes the autosave (atomically): the newest autosave_entries entries of the history and
  /// the position in them.
  void flush_autosave() {
    if (autosave.empty() || !autosave_pending) return;
    const std::size_t from =
        history.size() > autosave_entries ? history.size() - autosave_entries : 0;
    const std::size_t current = static_cast<std::size_t>(position);
    const std::size_t first = std::min(from, current);
    Json entries = Json::array();
    for (std::size_t k = first; k < history.size(); ++k) {
      const Entry& e = history[k];
      Json entry = {{"label", e.label}, {"group", e.group}};
      if (k > first && e.changes.is_array())
        entry["changes"] = e.changes;  // made from the entry before it on restoring
      else
        entry["text"] = e.text;
      entries.push_back(std::move(entry));
    }
    const Json doc = {{"format", "clayform.studio-autosave"},
                      {"version", 2},
                      {"recipe", name},
                      {"position", current - first},
                      {"history", entries}};
    internal::write_atomically(autosave, reply_text(doc), "studio's autosave");
    autosaved = std::chrono::steady_clock::now();
    autosave_pending = false;
  }

  /// The reply of a run: its report figures per step, the history and the recipe text; then a
  /// net frame per final surface, a curve frame per named curve, and a net frame per deformed
  /// final surface's parent before its first step, each only when it differs from the one last
  /// sent (the others named under "kept"). Without `nets` (a drag update the page draws
  /// itself), no frames: the figures and the history only. With `changes` (an edit's), the
  /// reply carries them and the revision they apply to instead of the recipe's whole text.
  Reply ran(const std::string& op, const Run& run, bool nets = true,
            const Json* changes = nullptr) const {
    const RunResult& result = *run.result;
    Reply reply;
    // What the page will hold once it has this reply, made aside and kept only when the whole
    // reply is made: an exception part-way would otherwise mark frames sent that never left.
    std::map<std::string, std::uint64_t> sending = sent;
    std::map<std::string, std::uint64_t> meshing = meshed;
    const Json steps = Json::parse(step_reports_json(result.steps));  // as report.json has them
    Json kept = {{"surfaces", Json::array()},
                 {"curves", Json::array()},
                 {"befores", Json::array()},
                 {"deviations", Json::array()},
                 {"models", Json::array()}};
    // Sends `frame` unless the page holds it already; true when sent.
    auto send = [&](const std::string& key, std::vector<std::uint8_t> frame) {
      const std::uint64_t content = frame_key(frame);
      if (const auto it = sending.find(key); it != sending.end() && it->second == content)
        return false;
      sending[key] = content;
      reply.frames.push_back(std::move(frame));
      return true;
    };
    std::map<std::string, std::uint64_t> net_keys;  // "net NAME", "before NAME": for deviations
    auto net_header = [](const std::string& n, const surface::BSplineSurface& s) {
      return Json{{"kind", "net"},
                  {"name", n},
                  {"degrees", {s.u.degree, s.v.degree}},
                  {"counts", {s.u.count(), s.v.count()}},
                  {"knots_u", s.u.knots},
                  {"knots_v", s.v.knots},
                  {"rational", s.is_rational()}};
    };
    auto net_of = [](const surface::BSplineSurface& s) {
      return std::pair{std::vector<double>(s.points.data(), s.points.data() + s.points.size()),
                       std::vector<double>(s.weights.data(), s.weights.data() + s.weights.size())};
    };
    auto surface_key = [&](const surface::BSplineSurface& s) {
      const auto [points, weights] = net_of(s);
      return frame_key(net_frame(net_header("", s).dump(), points, weights));
    };
    auto push_net = [&](const std::string& n, const surface::BSplineSurface& s, bool before) {
      Json header = net_header(n, s);
      if (before) header["before"] = true;
      const auto [points, weights] = net_of(s);
      const std::string key = (before ? "before " : "net ") + n;
      std::vector<std::uint8_t> frame = net_frame(header.dump(), points, weights);
      net_keys[key] = frame_key(frame);
      return send(key, std::move(frame));
    };
    // A drag update the page draws itself ("nets": false) gets no frames: none are made.
    const std::vector<std::string> none;
    const std::vector<std::string>& shown = nets ? run.shown : none;
    Json surfaces = Json::array();
    for (const std::string& n : shown)
      (push_net(n, result.surface(n), false) ? surfaces : kept["surfaces"]).push_back(n);
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
      const bool fresh = send("curve " + n, net_frame(header.dump(), points, weights));
      (fresh ? curves : kept["curves"]).push_back(n);
    }
    // A deformed surface's parent before its first step (the page's before/after view, and
    // what a lattice drag is checked against).
    Json befores = Json::array();
    for (const std::string& n : shown) {
      const auto stage = std::find_if(result.stages.begin(), result.stages.end(),
                                      [&](const Stage& st) { return st.surface == n; });
      if (stage == result.stages.end()) continue;
      (push_net(n, stage->before, true) ? befores : kept["befores"]).push_back(n);
    }
    // The deviation map of each shown surface whose last step deforms space point by point (a
    // lattice, taper, twist or bend; a style step moves control points and has none).
    Json deviations = Json::array();
    for (const std::string& n : shown) {
      const auto stage = std::find_if(result.stages.rbegin(), result.stages.rend(),
                                      [&](const Stage& st) { return st.surface == n; });
      if (stage == result.stages.rend() || !stage->map) continue;
      // Made from the surface and the one before its last step: the same two nets, the same
      // map (41 x 41 evaluations spared).
      const std::uint64_t made_from =
          net_keys["net " + n] * 1099511628211ull ^ surface_key(stage->before);
      const std::string key = "deviation " + n;
      if (const auto it = sending.find(key); it != sending.end() && it->second == made_from) {
        kept["deviations"].push_back(n);
        continue;
      }
      sending[key] = made_from;
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
        if (const auto it = meshing.find(m.name); it != meshing.end() && it->second == key) {
          if (!send("model " + m.name, model_nets_frame(m.name, m.model))) {
            kept["models"].push_back(m.name);
            continue;
          }
        } else {
          const brep::ModelMesh mesh = brep::tessellate(m.model);
          const Json header = {{"kind", "mesh"},
                               {"name", m.name},
                               {"vertices", mesh.positions.size()},
                               {"triangles", mesh.triangles.size()},
                               {"faces", m.model.faces.size()}};
          reply.frames.push_back(mesh_frame(header.dump(), mesh));
          meshing[m.name] = key;
          sending.erase("model " + m.name);  // the mesh holds the nets it was made on
        }
        models.push_back(m.name);
      }
    Json out = {{"op", op},       {"recipe", result.recipe},   {"seconds", result.seconds},
                {"steps", steps}, {"history", history_json()}, {"revision", revision}};
    // Each model's volume before and after its stack, and what a "keep" corrected: the lattice
    // panel shows them (a drag that keeps the volume says so, with the correction's size).
    Json figures = Json::object();
    for (const ModelRunResult& m : result.models) {
      Json corrected = Json::array();
      for (const ModelRunResult::Kept& k : m.kept)
        corrected.push_back({{"step", k.step},
                             {"properties", k.properties},
                             {"newton_steps", k.iterations},
                             {"largest_correction_mm", k.largest_correction_mm}});
      figures[m.name] = {{"volume_before_mm3", m.report.volume_before_mm3},
                         {"volume_after_mm3", m.report.volume_after_mm3},
                         {"kept", corrected}};
    }
    out["model_figures"] = figures;
    if (changes) {
      out["changes"] = *changes;
      out["from_revision"] = revision - 1;
    } else {
      out["text"] = text();
    }
    if (nets) {
      out["surfaces"] = surfaces;
      out["curves"] = curves;
      out["befores"] = befores;
      out["models"] = models;
      out["deviations"] = deviations;
      out["kept"] = kept;
    } else {
      out["nets"] = false;
    }
    reply.json = reply_text(out);
    sent = std::move(sending);
    meshed = std::move(meshing);
    return reply;
  }

  // The ops, one handler each, all of one signature (the table kOps below names them).
  using Cancel = std::function<bool()>;

  Reply hello(const Json&, const Cancel&) {
    meshed.clear();  // a new page holds no mesh yet
    sent.clear();
    const Recipe r = parse_recipe(text(), base_dir, name);
    Json out = {{"op", "hello"},
                {"recipe", r.name()},
                {"surfaces", final_surfaces(r)},
                {"deformations", r.deformation_names()},
                {"history", history_json()}};
    return {reply_text(out), {}};
  }

  Reply recipe_text(const Json&, const Cancel&) {
    return {reply_text(Json{{"op", "recipe"}, {"text", text()}, {"revision", revision}}), {}};
  }

  Reply fit(const Json& c, const Cancel&) { return {reply_text(fit_reply(c, *cache)), {}}; }

  Reply run_all(const Json&, const Cancel& cancelled) {
    meshed.clear();  // "run" sends everything: the page may hold nothing (a new page)
    sent.clear();
    return ran("run", run(text(), cancelled));
  }

  Reply undo(const Json&, const Cancel& cancelled) { return undo_redo("undo", cancelled); }
  Reply redo(const Json&, const Cancel& cancelled) { return undo_redo("redo", cancelled); }

  Reply undo_redo(const std::string& op, const Cancel& cancelled) {
    const int to = position + (op == "undo" ? -1 : 1);
    if (to < 0 || to >= static_cast<int>(history.size()))
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: nothing to " + op + " (history position " + std::to_string(position) +
                      " of " + std::to_string(history.size()) + ")");
    const Run result = run(history[static_cast<std::size_t>(to)].text, cancelled);
    position = to;
    ++revision;
    save_soon();
    return ran(op, result);
  }

  /// "edit": one change ({path, value, create?} or {path, remove: true}) or several ("changes":
  /// an array of them), applied in order as one entry of the history. Every field is read
  /// before the history changes (a wrong-typed "nets" was answered with an error but applied).
  Reply edit(const Json& c, const Cancel& cancelled) {
    const std::string group = field<std::string>(c, "edit", "group", "", "a string");
    const bool nets = field<bool>(c, "edit", "nets", true, "true or false");
    const std::optional<std::string> label =
        c.contains("label") ? std::optional(field<std::string>(c, "edit", "label", "", "a string"))
                            : std::nullopt;
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
    // The text as the last run parsed it, when it is the current one (a copy costs less than a
    // parse of a long recipe's text).
    Json doc = last_doc && last_text == text() ? *last_doc : Json::parse(text());
    std::string first_path;
    for (const Json& change : changes) apply_change(doc, change, first_path);
    std::string next = doc.dump(1, ' ', false, Json::error_handler_t::replace);
    if (next.size() > recipe_bytes)
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: the edit makes the recipe " + std::to_string(next.size()) +
                      " bytes, over the recipe limit of " + std::to_string(recipe_bytes) +
                      " (64 MiB); nothing changed");
    // A recipe the edit breaks throws: nothing changes. An edit of deformations alone reruns
    // only what they touch; a drag update (no nets) previews a lattice's light form.
    const auto changed = changed_deformations(doc);
    const Run result =
        run(next, cancelled, changed, !nets, "", std::make_shared<const Json>(std::move(doc)));
    ++revision;
    const Json applied = changes;  // the reply's: the page applies them to the text it holds
    // The updates of one drag share a "group": the latest replaces the entry an earlier one
    // made, so the drag is one step of the history.
    const auto at = static_cast<std::size_t>(position);
    if (!group.empty() && at + 1 == history.size() && history[at].group == group) {
      history[at].text = std::move(next);
      Json& kept_changes = history[at].changes;
      for (const Json& change : changes) {
        if (!kept_changes.is_array()) break;
        kept_changes.push_back(change);
      }
      if (kept_changes.is_array() && kept_changes.size() > group_changes_kept)
        kept_changes = nullptr;
      save_soon();
    } else {
      push({label.value_or("edit " + first_path), std::move(next), group, std::move(changes)});
    }
    return ran("edit", result, nets, &applied);
  }

  /// "export" {folder, name?, profile?}: the final surfaces as STEP, IGES and glTF
  /// (write_outputs: read back and checked), made to conform to the receiver profile (default
  /// "opencascade"; recipe::conform_export), with the run's report and the models' files (their
  /// deformed faces written for the same profile), into a folder inside the recipe's.
  Reply export_files(const Json& c, const Cancel& cancelled) {
    if (!c.contains("folder") || !c.at("folder").is_string())
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: \"export\" needs \"folder\" (a folder inside the recipe's, e.g. "
                  "\"out\")");
    const fs::path folder = internal::path_under(
        base_dir, c.at("folder").get_ref<const std::string&>(), "studio: the export's folder");
    const std::string export_name = field<std::string>(c, "export", "name", "", "a string");
    if (c.contains("name")) internal::check_file_name(export_name, "studio: the export's name");
    const std::string profile =
        field<std::string>(c, "export", "profile", "opencascade", "a receiver profile name");
    deform::receiver_profile(profile);  // an unknown name fails before the run
    // The deformed models are written for the profile too (their faces fitted with their edges).
    Run run = this->run(text(), cancelled, std::nullopt, false, profile);
    if (run.shown.empty() && run.result->models.empty())
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: the recipe has no surface or model to export yet; build one first");
    run.result->exports.clear();
    if (!run.shown.empty()) {
      ExportResult e;
      e.name = export_name.empty() ? run.result->recipe : export_name;
      e.formats = {"step", "iges", "glb"};
      e.surface_names = run.shown;
      e.profile = profile;
      tell("fitting the surfaces for the receiver (" + profile + ")");
      conform_export(e, parse_recipe(text(), base_dir, name), *run.result);
      run.result->exports.push_back(std::move(e));
    }
    tell("writing the files and reading them back");
    write_outputs(*run.result, folder);  // checks every file name it writes
    Json files = Json::array();
    bool valid = true, identical = true;
    for (const ExportResult& x : run.result->exports) {
      for (const std::string& f : x.files) files.push_back(f);
      valid = valid && x.valid;
      identical = identical && x.read_back_identical;
    }
    for (const ModelRunResult& m : run.result->models) {
      for (const std::string& f : m.files) files.push_back(f);
      valid = valid && m.valid;
    }
    Json bounds = Json::array();  // per surface, mm from the all-exact recipe (null: unbounded)
    for (const ExportResult& x : run.result->exports)
      for (double b : x.bounds_mm) bounds.push_back(std::isfinite(b) ? Json(b) : Json(nullptr));
    return {reply_text(Json{{"op", "exported"},
                            {"folder", folder.string()},
                            {"profile", profile},
                            {"bounds_mm", bounds},
                            {"files", files},
                            {"valid", valid},
                            {"read_back_identical", identical}}),
            {}};
  }

  /// "save" {file}: the current recipe text, written atomically as a plain file name in the
  /// recipe's folder.
  Reply save(const Json& c, const Cancel&) {
    if (!c.contains("file") || !c.at("file").is_string())
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: \"save\" needs \"file\" (a file name in the recipe's folder)");
    const std::string& file_name = c.at("file").get_ref<const std::string&>();
    internal::check_file_name(file_name, "studio: the file to save");
    const fs::path file = base_dir / file_name;
    internal::write_atomically(file, text(), "recipe");
    return {reply_text(Json{{"op", "saved"}, {"file", file.string()}}), {}};
  }

  struct Op {
    std::string_view name;
    Reply (Impl::*reply)(const Json&, const Cancel&);
  };
  static constexpr Op kOps[] = {
      {"hello", &Impl::hello}, {"recipe", &Impl::recipe_text},  {"edit", &Impl::edit},
      {"undo", &Impl::undo},   {"redo", &Impl::redo},           {"run", &Impl::run_all},
      {"save", &Impl::save},   {"export", &Impl::export_files}, {"fit", &Impl::fit},
  };
  /// "hello, recipe, edit, ...": the ops, for the messages that list them.
  static std::string op_names() {
    std::string names;
    for (const Op& op : kOps) names += (names.empty() ? "" : ", ") + std::string(op.name);
    return names;
  }

  Reply handle(const std::string& command, const Cancel& cancelled,
               const StudioSession::Progress& progress) {
    // Read whole and bounded before parsing: nlohmann's parser recursed a command nested
    // 1,000,000 levels deep until the stack overflowed.
    if (command.size() > command_bytes)
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: a command of " + std::to_string(command.size()) +
                      " bytes is over the limit of " + std::to_string(command_bytes) +
                      "; send smaller edits");
    if (const auto deep = internal::nesting_too_deep(command, command_depth))
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: the command nests arrays and objects deeper than " +
                      std::to_string(command_depth) + " levels (at byte " +
                      std::to_string(deep->at) + "); a recipe needs at most 8");
    // strtod raises overflow on a literal such as 1E99999 (as C requires): a host that traps
    // it (the Debug tests, the fuzzer) died of the number the checks exist to refuse.
    const Json c = [&] {
      const internal::FpTrapsHeld traps_held;
      return Json::parse(command);
    }();
    if (!c.is_object() || !c.contains("op") || !c.at("op").is_string())
      throw Error(ErrorCategory::InvalidArgument,
                  "studio: a command is a JSON object with \"op\" (" + op_names() + ")");
    const std::string op = c.at("op");
    const auto handler = std::find_if(std::begin(kOps), std::end(kOps),
                                      [&](const Op& known) { return known.name == op; });
    if (handler == std::end(kOps))
      throw Error(
          ErrorCategory::InvalidArgument,
          "studio: unknown op \"" + internal::clip_utf8(op, 40) + "\"; the ops: " + op_names());
    // The command's long loops ask `cancelled` too (clay/cancel.hpp), not only its steps.
    const CancelScope scope(cancelled);
    doing = {op, progress, std::chrono::steady_clock::now(), 0};
    struct Done {
      Doing& d;
      ~Done() { d = {}; }
    } done{doing};
    return (this->*handler->reply)(c, cancelled);
  }
};

namespace {

StudioSession::Reply error_reply(const std::string& category, const std::string& message) {
  return {reply_text(Json{{"op", "error"}, {"category", category}, {"message", message}}), {}};
}

}  // namespace

StudioSession::StudioSession(std::string text, fs::path base_dir, std::string name)
    : impl_(std::make_unique<Impl>()) {
  impl_->base_dir = std::move(base_dir);
  impl_->name = std::move(name);
  parse_recipe(text, impl_->base_dir, impl_->name);  // throws Recipe listing the problems
  impl_->history.push_back({"open", std::move(text), ""});
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
  return StudioSession(recipe.dump(1, ' ', false, Json::error_handler_t::replace),
                       file.parent_path(), name + "_studio");
}

const std::string& StudioSession::text() const { return impl_->text(); }

const std::string& StudioSession::name() const { return impl_->name; }

std::vector<std::string> StudioSession::history() const {
  std::vector<std::string> out;
  for (const auto& e : impl_->history) out.push_back(e.label);
  return out;
}

int StudioSession::position() const { return impl_->position; }

std::size_t StudioSession::history_dropped() const { return impl_->dropped; }

std::shared_ptr<RunCache> StudioSession::run_cache() const { return impl_->cache; }

void StudioSession::limit_history(std::size_t bytes) { impl_->history_limit = bytes; }

fs::path StudioSession::autosave_file(const fs::path& recipe_folder, const std::string& name) {
  return recipe_folder / (name + ".studio-autosave.json");
}

void StudioSession::autosave_to(const fs::path& file) {
  impl_->autosave = file;
  impl_->autosave_pending = true;
  impl_->flush_autosave();
}

void StudioSession::flush_autosave() { impl_->flush_autosave(); }

std::size_t StudioSession::restore(const fs::path& file) {
  const std::string text = internal::read_text(file, "studio's autosave");
  auto bad = [&](const std::string& why) {
    return Error(ErrorCategory::Document, "the studio's autosave \"" + file.string() + "\" " + why +
                                              "; start without it (--fresh) or remove it");
  };
  if (internal::nesting_too_deep(text, 64)) throw bad("nests too deep");
  const Json doc = [&] {
    const internal::FpTrapsHeld traps_held;  // strtod's overflow, as in handle()
    return Json::parse(text, nullptr, false);
  }();
  if (!doc.is_object() || doc.value("format", Json()) != "clayform.studio-autosave" ||
      !doc.contains("history") || !doc.at("history").is_array() || doc.at("history").empty() ||
      !doc.contains("position") || !doc.at("position").is_number_unsigned() ||
      doc.at("position").get<std::size_t>() >= doc.at("history").size())
    throw bad("is not a studio autosave (format, history, position)");
  std::vector<Impl::Entry> entries;
  for (const Json& e : doc.at("history")) {
    const bool whole = e.is_object() && e.contains("text") && e.at("text").is_string();
    const bool changes =
        e.is_object() && e.contains("changes") && e.at("changes").is_array() && !entries.empty();
    if (!e.is_object() || !e.contains("label") || !e.at("label").is_string() ||
        (!whole && !changes) || (e.contains("group") && !e.at("group").is_string()))
      throw bad("has an entry without a label and a text (or the changes from the one before)");
    if (whole) {
      entries.push_back({e.at("label"), e.at("text"), e.value("group", "")});
      continue;
    }
    // Version 2: the entry's edit replayed on the entry before it, as edit() made it.
    Json recipe = Json::parse(entries.back().text, nullptr, false);
    std::string first_path;
    try {
      if (recipe.is_discarded()) throw bad("has an entry whose text is not JSON");
      for (const Json& change : e.at("changes")) apply_change(recipe, change, first_path);
    } catch (const Error& error) {
      throw bad("has an entry whose changes do not apply (" + error.message() + ")");
    }
    entries.push_back({e.at("label"), recipe.dump(1, ' ', false, Json::error_handler_t::replace),
                       e.value("group", ""), e.at("changes")});
  }
  const std::size_t position = doc.at("position");
  parse_recipe(entries[position].text, impl_->base_dir, impl_->name);  // its problems, named
  impl_->history = std::move(entries);
  impl_->position = static_cast<int>(position);
  ++impl_->revision;
  impl_->restored = {{"entries", impl_->history.size()}, {"file", file.filename().string()}};
  return impl_->history.size();
}

StudioSession::Reply StudioSession::handle(const std::string& command,
                                           const std::function<bool()>& cancelled,
                                           const Progress& progress) {
  // Nothing escapes: a command that throws anything is answered with an error and changes
  // nothing (an exception escaping a connection's handler ended the server, issue #36).
  try {
    return impl_->handle(command, cancelled, progress);
  } catch (const Cancelled& c) {
    return error_reply("cancelled", "studio: the command was cancelled in " + c.where +
                                        " (the page's Cancel, a newer page taking the session "
                                        "over, or the server stopping); nothing changed");
  } catch (const Error& e) {
    return error_reply(std::string(to_string(e.category())), recipe_wording(e.message()));
  } catch (const Json::parse_error& e) {
    return error_reply("invalid argument",
                       std::string("studio: the command is not valid JSON: ") + e.what());
  } catch (const Json::exception& e) {  // a path's list index too large, and the like
    return error_reply("invalid argument",
                       std::string("studio: the command was refused: ") + e.what());
  } catch (const std::bad_alloc&) {
    return error_reply("internal error",
                       "studio: out of memory while handling the command; "
                       "nothing changed");
  } catch (const std::exception& e) {
    return error_reply("invalid argument", std::string("studio: the command was refused: ") +
                                               internal::clip_utf8(e.what(), 200));
  }
}

}  // namespace clay::recipe
