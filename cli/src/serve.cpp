// `clayform view` and `clayform snapshot`: the run folder and the built front end over HTTP
// (the command's one HTTP stack, http/web_server.hpp), and headless chromium for pictures.
#include "http/web_server.hpp"

#include <clay/error.hpp>
#include <clay/serve.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace clay::recipe {

namespace fs = std::filesystem;

fs::path viewer_dir() {
  if (const char* env = std::getenv("CLAYFORM_VIEWER_DIR"); env && *env) return env;
#ifdef CLAYFORM_VIEWER_DIR
  return CLAYFORM_VIEWER_DIR;
#else
  return "viewer/dist";
#endif
}

struct ViewServer::Impl {
  std::optional<web::WebServer> server;
  std::thread thread;
};

ViewServer::ViewServer(const fs::path& run_dir, const ServeOptions& options)
    : impl_(std::make_unique<Impl>()) {
  const fs::path viewer = options.viewer.empty() ? viewer_dir() : options.viewer;
  if (!fs::is_regular_file(run_dir / "view" / "manifest.json"))
    throw Error(
        ErrorCategory::Io,
        "no view data in \"" + run_dir.string() +
            "\" (view/manifest.json is missing); give "
            "the --out folder of `clayform run` or `clayform deform`, or run the recipe again");
  if (!fs::is_regular_file(viewer / "index.html"))
    throw Error(ErrorCategory::Io,
                "no viewer build at \"" + viewer.string() +
                    "\" (index.html is missing); build it "
                    "with scripts/viewer.sh (or `npm ci && npm run build` in viewer/), or set "
                    "CLAYFORM_VIEWER_DIR to a built viewer's folder");
  // The studio's server, without a socket: the same token, Host and Origin checks, and files
  // only under the two folders.
  web::WebOptions w;
  w.name = "the viewer";
  w.command = "clayform view";
  w.cookie = "clayform_view";
  w.host = options.host;
  w.port = options.port;
  w.token = options.token;
  w.max_file_bytes = options.max_file_bytes;
  w.mounts = {{"/run/", fs::absolute(run_dir).lexically_normal(), "", ""},
              {"/", fs::absolute(viewer).lexically_normal(), "index.html", ""}};
  impl_->server.emplace(std::move(w));
}

ViewServer::~ViewServer() { stop(); }

int ViewServer::port() const noexcept { return impl_->server->port(); }

const std::string& ViewServer::token() const { return impl_->server->token(); }

std::string ViewServer::url() const { return impl_->server->url(); }

void ViewServer::run() { impl_->server->run(); }

void ViewServer::start() {
  if (impl_->thread.joinable()) return;
  impl_->thread = std::thread([this] { impl_->server->run(); });
}

void ViewServer::stop() {
  impl_->server->stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

namespace {

/// The last `lines` lines of a text file, for an error message.
std::string tail_of(const fs::path& file, int lines) {
  std::ifstream in(file);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) all.push_back(line);
  std::string out;
  for (std::size_t k = all.size() > static_cast<std::size_t>(lines)
                           ? all.size() - static_cast<std::size_t>(lines)
                           : 0;
       k < all.size(); ++k)
    out += "\n  " + all[k];
  return out;
}

/// A temporary folder (removed by its destructor, with whatever chromium left in it).
struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "clayform-chromium-XXXXXX").string();
    if (!::mkdtemp(pattern.data()))
      throw Error(ErrorCategory::Io, "cannot create a temporary folder in \"" +
                                         fs::temp_directory_path().string() +
                                         "\": " + std::strerror(errno));
    path = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    for (int attempt = 0; attempt < 5;
         ++attempt) {  // a chromium helper may still be writing its profile
      fs::remove_all(path, ec);
      if (!ec && !fs::exists(path, ec)) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

}  // namespace

void snapshot(const fs::path& run_dir, const fs::path& png, const SnapshotOptions& options) {
  static const std::array<const char*, 5> modes{"shaded", "zebra", "gaussian", "mean", "deviation"};
  if (std::find(modes.begin(), modes.end(), options.mode) == modes.end())
    throw Error(ErrorCategory::InvalidArgument,
                "snapshot: unknown mode '" + options.mode +
                    "'; give shaded, zebra, gaussian, mean or deviation");
  if (options.width < 16 || options.width > 8192 || options.height < 16 || options.height > 8192)
    throw Error(ErrorCategory::InvalidArgument,
                "snapshot: picture size " + std::to_string(options.width) + " x " +
                    std::to_string(options.height) + " is out of range; give 16..8192 pixels");
  if (png.empty())
    throw Error(ErrorCategory::InvalidArgument, "snapshot: give the picture to write (--png FILE)");
  if (!options.eye.empty() &&
      (options.eye.size() != 3 ||
       !std::all_of(options.eye.begin(), options.eye.end(),
                    [](double x) { return std::isfinite(x); }) ||
       std::all_of(options.eye.begin(), options.eye.end(), [](double x) { return x == 0; })))
    throw Error(ErrorCategory::InvalidArgument,
                "snapshot: the eye direction must be 3 finite numbers, not all 0 (--eye X Y Z)");
  if (options.stage != "after" && options.stage != "before")
    throw Error(ErrorCategory::InvalidArgument,
                "snapshot: unknown stage '" + options.stage + "'; give after or before");
  // The surfaces to hide must be the run's: the names of the manifest's "surfaces" (written by
  // write_outputs). Recipe names are identifiers, safe in a URL.
  std::string query = "?mode=" + options.mode + (options.bare ? "&ui=0" : "");
  if (!options.hide.empty()) {
    std::ifstream in(run_dir / "view" / "manifest.json", std::ios::binary);
    const nlohmann::json manifest = nlohmann::json::parse(in, nullptr, false);
    std::vector<std::string> surfaces;
    if (manifest.is_object() && manifest.contains("surfaces") && manifest["surfaces"].is_array())
      for (const nlohmann::json& surface : manifest["surfaces"])
        if (surface.is_object() && surface.contains("name") && surface["name"].is_string())
          surfaces.push_back(surface["name"].get<std::string>());
    std::string names, unknown;
    for (const std::string& name : surfaces) names += (names.empty() ? "" : ", ") + name;
    for (const std::string& h : options.hide) {
      const bool plain = !h.empty() && std::all_of(h.begin(), h.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
      });
      if (!plain || std::find(surfaces.begin(), surfaces.end(), h) == surfaces.end())
        unknown += (unknown.empty() ? "" : ", ") + ("'" + h + "'");
    }
    if (in && !unknown.empty())  // (no manifest: the view server below says what is missing)
      throw Error(ErrorCategory::InvalidArgument, "snapshot: no surface " + unknown + " in " +
                                                      run_dir.string() +
                                                      " to hide; its surfaces are " + names);
    query += "&hide=";
    for (std::size_t k = 0; k < options.hide.size(); ++k) query += (k ? "," : "") + options.hide[k];
  }
  if (!options.eye.empty()) {
    char eye[96];
    std::snprintf(eye, sizeof eye, "&eye=%.9g,%.9g,%.9g", options.eye[0], options.eye[1],
                  options.eye[2]);
    query += eye;
  }
  if (options.stage == "before") query += "&stage=before";
  if (::access(options.chromium.c_str(), X_OK) != 0)
    throw Error(ErrorCategory::Io,
                "snapshot needs chromium at \"" + options.chromium.string() +
                    "\", which is missing; install Debian's package: apt-get install chromium");
  ServeOptions so;
  so.port = 0;
  so.viewer = options.viewer;
  ViewServer server(run_dir, so);  // checks the view data and the front end first

  const fs::path out = fs::absolute(png).lexically_normal();
  std::error_code ec;
  fs::remove(out, ec);  // so that a picture found afterwards is this run's
  if (out.has_parent_path()) fs::create_directories(out.parent_path(), ec);
  server.start();
  TempDir profile;
  const fs::path log = profile.path / "chromium.log";
  std::vector<std::string> args{
      options.chromium.string(),
      "--headless",
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--no-first-run",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
      "--hide-scrollbars",
      "--user-data-dir=" + (profile.path / "profile").string(),
      "--window-size=" + std::to_string(options.width) + "," + std::to_string(options.height),
      "--virtual-time-budget=10000",
      "--screenshot=" + out.string(),
      server.url() + "&" + query.substr(1)};  // url() ends with ?token=
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // The environment, with HOME in the temporary folder (chromium's wrapper and crash handler write
  // there).
  std::vector<std::string> env;
  for (char** e = environ; e && *e; ++e)
    if (std::strncmp(*e, "HOME=", 5) != 0) env.emplace_back(*e);
  env.push_back("HOME=" + profile.path.string());
  std::vector<char*> envp;
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attr;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_init(&attr);
  posix_spawnattr_setpgroup(&attr,
                            0);  // its own process group: a timeout kills every helper process
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  pid_t pid = 0;
  const int spawned = ::posix_spawn(&pid, argv[0], &actions, &attr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (spawned != 0)
    throw Error(ErrorCategory::Io, "cannot start \"" + options.chromium.string() +
                                       "\": " + std::strerror(spawned) +
                                       "; install Debian's package: apt-get install chromium");
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(options.timeout_seconds);
  int status = 0;
  bool timed_out = false;
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR)
      throw Error(ErrorCategory::Io, std::string("waiting for chromium: ") + std::strerror(errno));
    if (std::chrono::steady_clock::now() > deadline) {
      timed_out = true;
      ::kill(-pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::kill(-pid, SIGKILL);  // helper processes left behind by the browser, if any
  server.stop();
  if (timed_out)
    throw Error(ErrorCategory::Io, "chromium did not finish within " +
                                       std::to_string(options.timeout_seconds) +
                                       " s; it was stopped. Its last output:" + tail_of(log, 8));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error(ErrorCategory::Io,
                "chromium failed (" +
                    (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                       : "signal " + std::to_string(WTERMSIG(status))) +
                    "). Its last output:" + tail_of(log, 8));
  if (!fs::is_regular_file(out, ec) || fs::file_size(out, ec) == 0)
    throw Error(ErrorCategory::Io, "chromium wrote no picture at \"" + out.string() +
                                       "\". Its last output:" + tail_of(log, 8));
}

}  // namespace clay::recipe
