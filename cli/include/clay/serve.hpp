#pragma once
/// Serving a run to the browser viewer and taking pictures of it (issue #9): `clayform view` and
/// `clayform snapshot` (docs/recipe.md "Viewing a run"). The built front end (viewer/dist) is
/// served at `/`, the run folder (with its view/manifest.json, clay/recipe/view.hpp) under `/run/`.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace clay::recipe {

/// The built front end: the environment variable CLAYFORM_VIEWER_DIR when set and not empty, else
/// the folder compiled in (the source tree's viewer/dist).
std::filesystem::path viewer_dir();

/// Settings of ViewServer.
struct ServeOptions {
  std::string host = "127.0.0.1";
  int port = 8765;               ///< 0: any free port (see ViewServer::port)
  std::filesystem::path viewer;  ///< the built front end; empty: viewer_dir()
  /// Every request must carry it (?token=, or the cookie the first such answer sets): letters
  /// and digits, at least 16. Empty: 32 random hex digits.
  std::string token;
  std::size_t max_file_bytes = 1u << 30;  ///< largest file served (a dense run's mesh is large)
};

/// An HTTP server of one run folder, on the studio's HTTP stack (Boost.Beast, one I/O thread):
/// `/` and static files from the front end, `/run/...` from the run folder; content types by
/// extension (.bin application/octet-stream, .glb model/gltf-binary). A security boundary as the
/// studio is (docs/studio.md "Security"): the token, the server's own Host and, when a request
/// has one, its own Origin, else 403; files only under the two folders, by plain names (".."
/// and links leading out: 404). Binds in the constructor.
class ViewServer {
 public:
  /// Checks `run_dir`/view/manifest.json and the front end's index.html (clay::Error(Io) naming
  /// the fix when missing) and binds the port (clay::Error(Io) when it cannot).
  ViewServer(const std::filesystem::path& run_dir, const ServeOptions& options = {});
  ~ViewServer();  ///< stops and joins
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  int port() const noexcept;         ///< the bound port
  const std::string& token() const;  ///< the token every request must carry
  std::string url() const;           ///< "http://HOST:PORT/?token=TOKEN"
  void run();                        ///< serves in this thread until stop() (from another thread)
  void start();                      ///< serves in a thread of its own
  void stop();                       ///< stops serving (and joins the thread of start)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Settings of snapshot.
struct SnapshotOptions {
  int width = 1280;               ///< picture width in pixels [16, 8192]
  int height = 800;               ///< picture height in pixels [16, 8192]
  std::string mode = "shaded";    ///< shaded, zebra, gaussian, mean or deviation
  bool bare = false;              ///< the picture alone: no toolbar, no panels (?ui=0)
  std::vector<double> eye;        ///< direction from the model towards the eye, 3 numbers, finite
                                  ///< and not all 0; empty: the viewer's default view (?eye=x,y,z)
  std::vector<std::string> hide;  ///< surfaces (by name) not to show (?hide=a,b)
  std::string stage = "after";    ///< after, or before: the surfaces before their first
                                  ///< deformation step (?stage=before)
  std::filesystem::path viewer;   ///< the built front end; empty: viewer_dir()
  std::filesystem::path chromium = "/usr/bin/chromium";  ///< Debian's chromium
  int timeout_seconds = 60;                              ///< chromium is killed after this
};

/// A PNG picture of the viewer's page on the run folder: serves it on a free port of 127.0.0.1,
/// runs chromium headless (--screenshot, a temporary profile removed afterwards) on
/// `/?mode=MODE` (and eye, hide, stage when given), waits for it (killed after the timeout),
/// checks `png` was written. Throws clay::Error: InvalidArgument for a bad mode, size, eye or
/// stage, or a hidden surface the run does not have (naming the ones it has); Io when chromium is
/// missing (naming the Debian package), fails, times out or writes no picture.
void snapshot(const std::filesystem::path& run_dir, const std::filesystem::path& png,
              const SnapshotOptions& options = {});

}  // namespace clay::recipe
