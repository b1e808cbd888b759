#pragma once
/// Clayform Studio's kernel side (issue #23, docs/studio.md): the recipe as the single source of
/// truth, edited by commands, with a named history; and the server that puts it behind one
/// WebSocket on 127.0.0.1 (Boost.Beast), JSON for commands and binary frames for geometry.
///
/// Not installed: it lives with the command, like the viewer's server (clay/serve.hpp).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace clay::recipe {

class RunCache;  // clay/recipe/recipe.hpp

/// One studio document: the recipe's JSON text, the folder its imports are resolved in, and the
/// history of named edits (undo and redo move in it). Every edit replaces a value at a JSON path
/// of the recipe (keys joined by ".", list items as "[i]"; the path must exist, or, with
/// `create`, its parent must), so "Save recipe" writes what `clayform run` replays.
class StudioSession {
 public:
  /// A session on the recipe text (checked: clay::Error(Document) listing its problems).
  StudioSession(std::string text, std::filesystem::path base_dir, std::string name = "studio");
  ~StudioSession();
  StudioSession(StudioSession&&) noexcept;
  StudioSession& operator=(StudioSession&&) noexcept;

  /// Reads a recipe file (clay::Error(Io) when it cannot, Recipe for its problems).
  static StudioSession load(const std::filesystem::path& file);
  /// A recipe file as load does, or a STEP or IGES model (.step, .stp, .igs, .iges): a new recipe
  /// named STEM_studio, in the model's folder, whose "models" imports it whole (trimmed faces,
  /// solids, assemblies kept; the run's frames carry its trimmed mesh).
  static StudioSession open(const std::filesystem::path& file);

  /// The command's reply (JSON text) and the geometry frames that follow it (binary, see
  /// geometry_frames). Commands, as JSON objects with "op":
  /// - "hello": the recipe's name, its surfaces and curves, the history (every reply's history
  ///   has "restored" when the session continues an autosave, "autosave_problem" when the last
  ///   autosave failed);
  /// - "recipe": the current recipe text;
  /// - "edit" {path, value, label?, create?, group?, nets?} or {path, remove: true} or
  ///   {changes: [...], label?}: set or remove values, check and run the new recipe, one history
  ///   entry (edits with the same "group" in a row, a drag's updates, make one); a recipe the
  ///   edit breaks is refused and nothing changes; with "nets": false the reply has no frames (a
  ///   drag the page draws);
  /// - "undo", "redo": move in the history (and run);
  /// - "run": run the current recipe;
  /// - "save" {file}: write the current recipe text atomically, `file` a plain file name in the
  ///   recipe's folder;
  /// - "export" {folder, name?}: STEP, IGES and glTF of the final surfaces, read back and
  ///   checked, into `folder` (plain names joined by '/', inside the recipe's folder); `name` a
  ///   plain file name.
  /// A bad command gets {"op": "error", "category", "message"}: every field is read before
  /// anything changes, so the session is unchanged; nothing a command holds makes this throw,
  /// and every reply is valid UTF-8. `cancelled`, when given, is asked between the run's steps
  /// and inside its long loops (clay/cancel.hpp: an exact composition's patches, a refit's
  /// rounds, a model's faces, the files written); true ends the command with {"op": "error",
  /// "category": "cancelled"} and changes nothing (no history entry, no file). `progress`, when
  /// given, is called on the same thread with a JSON text {"op": "progress", "command",
  /// "doing" (the step being built, "PATH (KIND)", or an export's phase), "steps_done",
  /// "seconds" (since the command started)} each time the command starts something new.
  struct Reply {
    std::string json;
    std::vector<std::vector<std::uint8_t>> frames;
  };
  using Progress = std::function<void(const std::string& json)>;
  Reply handle(const std::string& command, const std::function<bool()>& cancelled = {},
               const Progress& progress = {});

  /// The largest command (bytes) and its deepest nesting of arrays and objects; beyond either a
  /// command is refused before it is parsed.
  static constexpr std::size_t command_bytes = 16u << 20;
  static constexpr int command_depth = 64;
  /// The history keeps its newest entries within this many bytes of recipe text by default
  /// (limit_history; the current entry and the one before it always stay, history_dropped()
  /// counts the others).
  static constexpr std::size_t history_bytes = 256u << 20;
  /// Entries an autosave keeps (the newest; the current one always).
  static constexpr std::size_t autosave_entries = 50;

  /// Where the studio autosaves a recipe named `name` of `recipe_folder`:
  /// NAME.studio-autosave.json beside it.
  static std::filesystem::path autosave_file(const std::filesystem::path& recipe_folder,
                                             const std::string& name);
  /// Autosaves the history into `file` from now on (atomically, written now, then after each
  /// change at most once a second; flush_autosave writes what is pending). clay::Error(Io) when
  /// it cannot be written now; a later failure does not fail the edit that caused it: the
  /// history in each reply says why ("autosave_problem"), and the next change tries again.
  void autosave_to(const std::filesystem::path& file);
  /// Writes a pending autosave now (the server calls it when a drag's updates stop).
  void flush_autosave();
  /// Continues the autosave `file` (written by autosave_to): its history and position replace
  /// this session's. Returns the number of entries. clay::Error(Document) naming the file when it
  /// is not an autosave or its current recipe has problems; Io when it cannot be read.
  std::size_t restore(const std::filesystem::path& file);
  /// Entries dropped from the start of the history to keep it within its limit.
  std::size_t history_dropped() const;
  /// Keeps the history within `bytes` of recipe text from now on (default history_bytes).
  void limit_history(std::size_t bytes);

  /// The current recipe text.
  const std::string& text() const;
  /// The session's name (the recipe file's stem; STEM_studio for a model).
  const std::string& name() const;
  /// Names of the history's entries, oldest first ("open", then each edit's label).
  std::vector<std::string> history() const;
  /// Index of the current entry in history().
  int position() const;
  /// The results kept between this session's runs (recipe::RunCache): an edit re-runs only the
  /// steps downstream of what it changed; its counts say how many were taken. Clearing it makes
  /// the next command run every step.
  std::shared_ptr<RunCache> run_cache() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One binary frame per final surface of a run (a model's trimmed mesh has a frame of its own,
/// {"kind": "mesh", "name", "vertices", "triangles"}: float64 positions and normals, then uint32
/// node indices, docs/studio.md): a 4-byte little-endian length N, N bytes of JSON
/// ({"kind": "net", "name", "degrees": [p, q], "counts": [nu, nv], "knots_u", "knots_v",
/// "rational"}), zero padding to a multiple of 8, then nu * nv * 3 float64 control points
/// (u-major, x y z) and nu * nv float64 weights, little-endian. The page evaluates the net.
std::vector<std::uint8_t> net_frame(const std::string& header_json,
                                    const std::vector<double>& points,
                                    const std::vector<double>& weights);

/// Settings of StudioServer.
struct StudioOptions {
  std::string host = "127.0.0.1";
  int port = 8770;                  ///< 0: any free port (see StudioServer::port)
  std::filesystem::path front_end;  ///< static files served at "/" (empty: none, 404)
  /// The session's secret (letters and digits, at least 16): every request must carry it, as
  /// ?token= or the cookie the first such request sets. Empty: 32 random hex digits.
  std::string token;
  int max_connections = 64;  ///< open connections; beyond, the oldest not yet upgraded closes
  int request_seconds = 10;  ///< a request's head and body must arrive within this
  std::size_t max_file_bytes = 64u << 20;     ///< largest static file served
  std::size_t max_queued_bytes = 512u << 20;  ///< replies a page has not read; beyond, it closes
};

/// The studio's server (Boost.Beast, asynchronous on one thread; the session's commands on a
/// worker of their own): static files at "/" and the WebSocket at "/ws". A security boundary
/// (docs/studio.md "Security"):
/// - every request needs the session's token (?token=TOKEN, or the cookie set when the page was
///   opened with it) and a Host of the server's own address; the upgrade also an Origin of
///   http://HOST:PORT (127.0.0.1 or localhost): otherwise 403, so neither another site's page
///   (DNS rebinding) nor another local user can read files or drive the kernel;
/// - only regular files under the front end's folder are served (no "..", no absolute or
///   symbolic-link escape, no device or FIFO, at most max_file_bytes);
/// - connections are capped (the oldest idle one makes room), a request must arrive within
///   request_seconds, a full descriptor table is waited out, and no exception or message ends
///   the server.
/// One page at a time holds the WebSocket: the newest (a reload, another tab) takes it over at
/// once, the older one is closed and a command it was running is cancelled at its next step.
/// Commands that arrive while one is being handled are coalesced: of several "edit" commands on
/// the same path only the newest is handled. {"op": "cancel"} (no reply of its own) cancels
/// every command received before it: the running one stops at its next check and answers
/// {"op": "error", "category": "cancelled"}. A command running over half a second sends its
/// progress lines (StudioSession::handle), each new one at most every quarter second, before
/// its reply.
class StudioServer {
 public:
  /// Binds the port (clay::Error(Io) when it cannot; InvalidArgument for a bad host, token or
  /// limit).
  StudioServer(StudioSession session, const StudioOptions& options = {});
  ~StudioServer();  ///< stops and joins
  StudioServer(const StudioServer&) = delete;
  StudioServer& operator=(const StudioServer&) = delete;

  int port() const noexcept;         ///< the bound port
  const std::string& token() const;  ///< the session's secret
  std::string url() const;           ///< "http://HOST:PORT/?token=TOKEN": the page to open
  void run();                        ///< serves in this thread until stop() (from another thread)
  void start();                      ///< serves in a thread of its own
  void stop();  ///< stops serving (and joins the thread of start); a running command is cancelled
  /// The session's current recipe text (between commands).
  std::string recipe_text() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clay::recipe
