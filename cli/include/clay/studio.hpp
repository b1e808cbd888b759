#pragma once
/// Clayform Studio's kernel side (issue #23, docs/studio.md): the recipe as the single source of
/// truth, edited by commands, with a named history; and the server that puts it behind one
/// WebSocket on 127.0.0.1 (Boost.Beast), JSON for commands and binary frames for geometry.
///
/// Not installed: it lives with the command, like the viewer's server (clay/serve.hpp).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace clay::recipe {

/// One studio document: the recipe's JSON text, the folder its imports are resolved in, and the
/// history of named edits (undo and redo move in it). Every edit replaces a value at a JSON path
/// of the recipe (keys joined by ".", list items as "[i]"; the path must exist, or, with
/// `create`, its parent must), so "Save recipe" writes what `clayform run` replays.
class StudioSession {
 public:
  /// A session on the recipe text (checked: clay::Error(Recipe) listing its problems).
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
  /// - "hello": the recipe's name, its surfaces and curves, the history;
  /// - "recipe": the current recipe text;
  /// - "edit" {path, value, label, create?} or {path, remove: true} or {changes: [...], label}:
  ///   set or remove values, check and run the new recipe, one history entry (edits with the
  ///   same "group" in a row, a drag's updates, make one); a recipe the edit breaks is refused
  ///   and nothing changes; with "nets": false the reply has no frames (a drag the page draws);
  /// - "undo", "redo": move in the history (and run);
  /// - "run": run the current recipe;
  /// - "save" {file}: write the current recipe text (atomically; relative to the recipe's folder);
  /// - "export" {folder, name?}: STEP, IGES and glTF of the final surfaces, read back and checked.
  /// A bad command gets {"op": "error", "message": ...}; the session is unchanged.
  struct Reply {
    std::string json;
    std::vector<std::vector<std::uint8_t>> frames;
  };
  Reply handle(const std::string& command);

  /// The current recipe text.
  const std::string& text() const;
  /// Names of the history's entries, oldest first ("open", then each edit's label).
  std::vector<std::string> history() const;
  /// Index of the current entry in history().
  int position() const;

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
};

/// The studio's server (Boost.Beast): static files at "/" and the WebSocket at "/ws". The
/// upgrade is refused (403) unless its Host is the server's own address and its Origin is
/// http://HOST:PORT (127.0.0.1 or localhost), so another site's page cannot drive the kernel.
/// Each connection is served on a thread of its own; one page at a time holds the WebSocket (the
/// newest, a reload or another tab, takes it over and the older one is closed). Commands that
/// arrive while one is being handled are coalesced: of several "edit" commands on the same path
/// only the newest is handled.
class StudioServer {
 public:
  /// Binds the port (clay::Error(Io) when it cannot).
  StudioServer(StudioSession session, const StudioOptions& options = {});
  ~StudioServer();  ///< stops and joins
  StudioServer(const StudioServer&) = delete;
  StudioServer& operator=(const StudioServer&) = delete;

  int port() const noexcept;  ///< the bound port
  std::string url() const;    ///< "http://HOST:PORT/"
  void run();                 ///< serves in this thread until stop() (from another thread)
  void start();               ///< serves in a thread of its own
  void stop();                ///< stops serving (and joins the thread of start)
  /// The session's current recipe text (between commands).
  std::string recipe_text() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clay::recipe
