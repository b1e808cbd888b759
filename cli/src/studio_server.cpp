// Clayform Studio's server (clay/studio.hpp): the command's one HTTP stack (http/web_server.hpp:
// Boost.Beast on one I/O thread, the token, Host and Origin checks, the page's static files)
// with the studio's WebSocket, and the session's commands on one worker thread. It is a security
// boundary: a stylist leaves it running on a workstation (issue #36); no message, connection
// count or exception ends it.
#include "http/web_server.hpp"

#include <clay/error.hpp>
#include <clay/internal/fenv.hpp>
#include <clay/internal/json_reader.hpp>
#include <clay/studio.hpp>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

namespace clay::recipe {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Json = nlohmann::ordered_json;

namespace {

/// An edit's key for coalescing: its path, or its changes' paths joined; none for other
/// commands (or anything that is not a well-formed edit: the session answers those).
std::optional<std::string> edit_key(const std::string& text) {
  if (text.size() > StudioSession::command_bytes ||
      internal::nesting_too_deep(text, StudioSession::command_depth))
    return std::nullopt;
  const Json c = [&] {
    const internal::FpTrapsHeld traps_held;  // strtod's overflow on 1E99999 (StudioSession)
    return Json::parse(text, nullptr, false);
  }();
  if (!c.is_object()) return std::nullopt;
  const auto op = c.find("op");
  if (op == c.end() || !op->is_string() || *op != "edit") return std::nullopt;
  if (const auto path = c.find("path"); path != c.end())
    return path->is_string() ? std::optional(path->get<std::string>()) : std::nullopt;
  const auto changes = c.find("changes");
  if (changes == c.end() || !changes->is_array()) return std::nullopt;
  std::string key;
  for (const Json& change : *changes) {
    if (!change.is_object() || !change.contains("path") || !change.at("path").is_string())
      return std::nullopt;
    key += change.at("path").get<std::string>() + "\n";
  }
  return key;
}

/// True for the page's {"op": "cancel"}: answered by no reply of its own; the command it cancels
/// answers {"op": "error", "category": "cancelled"}.
bool is_cancel(const std::string& text) {
  if (text.size() > 256) return false;
  const Json c = [&] {
    const internal::FpTrapsHeld traps_held;
    return Json::parse(text, nullptr, false);
  }();
  return c.is_object() && c.size() == 1 && c.contains("op") && c.at("op") == "cancel";
}

/// How long a command runs before its progress lines go to the page, and how often they do.
constexpr auto progress_after = std::chrono::milliseconds(500);
constexpr auto progress_every = std::chrono::milliseconds(250);

}  // namespace

struct StudioServer::Impl {
  StudioSession session;
  StudioOptions options;
  std::optional<web::WebServer> web;
  std::thread thread;  // start()'s
  std::atomic<bool> stopping{false};

  struct Page;
  // I/O thread only: the page's socket.
  std::weak_ptr<Page> page;
  std::uint64_t pages = 0;  // pages that have held the socket

  // The session's worker: commands in order, a newer edit of a path replacing a waiting one.
  struct Job {
    std::string command;
    std::uint64_t page = 0;  // the page that sent it (its reply goes there, if it still holds it)
    std::optional<std::string> key;
    std::uint64_t seq = 0;  // in the order received
  };
  std::mutex jobs_mutex;
  std::condition_variable jobs_wake;
  std::deque<Job> jobs;
  bool worker_stop = false;
  std::thread worker;
  std::atomic<std::uint64_t> holder{0};  // the page that holds the socket (0: none)
  mutable std::mutex session_mutex;      // one command at a time on the session
  // The page's Cancel: every command received before it (seq <= cancel_through) stops at its
  // next check (clay/cancel.hpp) or is answered "cancelled" before it starts.
  std::uint64_t last_seq = 0;  // under jobs_mutex
  std::atomic<std::uint64_t> cancel_through{0};

  // The running command's latest progress line (StudioSession::Progress), sent to its page by
  // the I/O thread's timer once the command has run progress_after, each time it changes.
  struct Running {
    std::uint64_t page = 0;  // 0: nothing runs
    std::chrono::steady_clock::time_point since;
    std::string progress;
    bool sent = true;
  };
  std::mutex running_mutex;
  Running running;
  std::optional<asio::steady_timer> progress_timer;
  void watch_progress();

  explicit Impl(StudioSession s) : session(std::move(s)) {}

  void on_websocket(beast::tcp_stream stream, web::Request req);
  void take_over(const std::shared_ptr<Page>& newer);
  void submit(std::string command, std::uint64_t from);
  void work();
};

/// The page that holds the WebSocket: its reads go to the worker, the worker's replies come back
/// here in order; a page that stops reading is closed once max_queued_bytes wait for it.
struct StudioServer::Impl::Page : std::enable_shared_from_this<Page> {
  Impl& s;
  websocket::stream<beast::tcp_stream> ws;
  beast::flat_buffer buffer;
  std::deque<std::pair<bool, std::vector<std::uint8_t>>> out;  // (text, bytes)
  std::size_t queued = 0;
  bool writing = false, closed = false;
  std::uint64_t id = 0;

  Page(Impl& server, beast::tcp_stream stream) : s(server), ws(std::move(stream)) {}

  void accept(http::request<http::string_body> req) {
    beast::get_lowest_layer(ws).expires_never();  // the WebSocket's own timeouts from here
    ws.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws.read_message_max(StudioSession::command_bytes);
    ws.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close();
      self->s.take_over(self);
      self->read_next();
    });
  }

  void read_next() {
    ws.async_read(buffer, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->close();
      self->s.submit(beast::buffers_to_string(self->buffer.data()), self->id);
      self->buffer.consume(self->buffer.size());
      self->read_next();
    });
  }

  void send(StudioSession::Reply reply) {
    if (closed) return;
    queued += reply.json.size();
    out.emplace_back(true, std::vector<std::uint8_t>(reply.json.begin(), reply.json.end()));
    for (auto& frame : reply.frames) {
      queued += frame.size();
      out.emplace_back(false, std::move(frame));
    }
    if (queued > s.options.max_queued_bytes) return close();  // it does not read
    write_next();
  }

  void write_next() {
    if (writing || out.empty() || closed) return;
    writing = true;
    ws.text(out.front().first);
    ws.async_write(asio::buffer(out.front().second),
                   [self = shared_from_this()](beast::error_code ec, std::size_t) {
                     self->writing = false;
                     if (self->out.empty()) return;
                     self->queued -= self->out.front().second.size();
                     self->out.pop_front();
                     if (ec) return self->close();
                     self->write_next();
                   });
  }

  void close() {
    if (closed) return;
    forget();
    shut();
  }

  /// Closes with a reason its page shows ("another page took the studio session over"): a close
  /// frame when no write is under way (Beast allows one beside the pending read), else at once.
  void close_for(const char* reason) {
    if (closed) return;
    if (writing) return close();
    forget();
    ws.async_close(websocket::close_reason(websocket::close_code::going_away, reason),
                   [self = shared_from_this()](beast::error_code) { self->shut(); });
  }

 private:
  void forget() {
    closed = true;
    out.clear();
    queued = 0;
    if (s.holder == id) s.holder = 0;  // its running command is cancelled
  }
  void shut() {
    beast::error_code ignored;
    beast::get_lowest_layer(ws).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws).close();
  }
};

void StudioServer::Impl::on_websocket(beast::tcp_stream stream, web::Request req) {
  auto newer = std::make_shared<Page>(*this, std::move(stream));
  newer->accept(std::move(req));
}

void StudioServer::Impl::take_over(const std::shared_ptr<Page>& newer) {
  // One page edits the recipe at a time: the newest (a reload, another tab) takes over at once;
  // the older one's socket is closed (its page says so) and its waiting and running commands
  // are dropped and cancelled.
  if (auto older = page.lock(); older && older != newer)
    older->close_for("another page took the studio session over; reload to take it back");
  newer->id = ++pages;
  page = newer;
  holder = newer->id;
  std::lock_guard<std::mutex> lock(jobs_mutex);
  jobs.erase(
      std::remove_if(jobs.begin(), jobs.end(), [&](const Job& j) { return j.page != newer->id; }),
      jobs.end());
}

void StudioServer::Impl::submit(std::string command, std::uint64_t from) {
  if (is_cancel(command)) {
    std::lock_guard<std::mutex> lock(jobs_mutex);
    cancel_through = last_seq;
    return;
  }
  Job job{std::move(command), from, std::nullopt};
  job.key = edit_key(job.command);
  {
    std::lock_guard<std::mutex> lock(jobs_mutex);
    job.seq = ++last_seq;
    // A newer edit of a path replaces a waiting one in its place (a drag sends many; the kernel
    // answers the newest).
    bool replaced = false;
    if (job.key)
      for (Job& waiting : jobs)
        if (waiting.key == job.key) {
          waiting = std::move(job);
          replaced = true;
          break;
        }
    if (!replaced) jobs.push_back(std::move(job));
  }
  jobs_wake.notify_all();
}

void StudioServer::Impl::work() {
  while (true) {
    Job job;
    bool idle_after = false;
    {
      std::unique_lock<std::mutex> lock(jobs_mutex);
      jobs_wake.wait(lock, [&] { return worker_stop || !jobs.empty(); });
      if (worker_stop) return;
      job = std::move(jobs.front());
      jobs.pop_front();
      idle_after = jobs.empty();
    }
    if (job.page != holder) continue;  // its page is gone
    auto reply = std::make_shared<StudioSession::Reply>();
    {
      std::lock_guard<std::mutex> lock(running_mutex);
      running = {job.page, std::chrono::steady_clock::now(), "", true};
    }
    try {
      std::lock_guard<std::mutex> session_lock(session_mutex);
      *reply = session.handle(
          job.command,
          [this, from = job.page, seq = job.seq] {
            return stopping || holder != from || seq <= cancel_through;
          },
          [this](const std::string& line) {
            std::lock_guard<std::mutex> progress_lock(running_mutex);
            running.progress = line;
            running.sent = false;
          });
      if (idle_after) session.flush_autosave();  // a drag's updates have stopped
    } catch (const std::exception& e) {  // (handle answers everything; an autosave may fail)
      *reply = {Json{{"op", "error"}, {"category", "i/o"}, {"message", e.what()}}.dump(
                    -1, ' ', false, Json::error_handler_t::replace),
                {}};
    }
    {
      std::lock_guard<std::mutex> lock(running_mutex);
      running = {};
    }
    asio::post(web->io(), [this, reply, from = job.page] {
      if (auto p = page.lock(); p && p->id == from) p->send(std::move(*reply));
    });
  }
}

void StudioServer::Impl::watch_progress() {
  // On the I/O thread: a command running longer than progress_after has its newest progress
  // line sent (once per change), so a long export or a slow step shows what it is doing. A
  // line posted here is sent before the reply, which the worker posts after it finishes.
  progress_timer->expires_after(progress_every);
  progress_timer->async_wait([this](beast::error_code ec) {
    if (ec || stopping) return;  // (a timer left waiting would keep run() from returning)
    std::string line;
    std::uint64_t to = 0;
    {
      std::lock_guard<std::mutex> lock(running_mutex);
      if (running.page != 0 && !running.sent &&
          std::chrono::steady_clock::now() - running.since >= progress_after) {
        line = running.progress;
        to = running.page;
        running.sent = true;
      }
    }
    if (!line.empty())
      if (auto p = page.lock(); p && p->id == to) p->send({std::move(line), {}});
    watch_progress();
  });
}

StudioServer::StudioServer(StudioSession session, const StudioOptions& options)
    : impl_(std::make_unique<Impl>(std::move(session))) {
  impl_->options = options;
  if (options.max_queued_bytes == 0)
    throw Error(ErrorCategory::InvalidArgument, "studio: max_queued_bytes must be positive");
  web::WebOptions w;
  w.name = "the studio";
  w.command = "clayform studio";
  w.cookie = "clayform_studio";
  w.host = options.host;
  w.port = options.port;
  w.token = options.token;
  w.max_connections = options.max_connections;
  w.request_seconds = options.request_seconds;
  w.max_file_bytes = options.max_file_bytes;
  w.mounts = {{"/", options.front_end, "studio.html",
               options.front_end.empty()
                   ? "The studio's page is not built (scripts/viewer.sh builds it). The kernel's "
                     "WebSocket is at /ws (docs/studio.md).\n"
                   : ""}};
  impl_->web.emplace(std::move(w), [s = impl_.get()](beast::tcp_stream stream, web::Request req) {
    s->on_websocket(std::move(stream), std::move(req));
  });
}

StudioServer::~StudioServer() { stop(); }

int StudioServer::port() const noexcept { return impl_->web->port(); }

const std::string& StudioServer::token() const { return impl_->web->token(); }

std::string StudioServer::url() const { return impl_->web->url(); }

std::string StudioServer::recipe_text() const {
  std::lock_guard<std::mutex> lock(impl_->session_mutex);
  return impl_->session.text();
}

void StudioServer::run() {
  Impl& s = *impl_;
  {
    std::lock_guard<std::mutex> lock(s.jobs_mutex);
    s.worker_stop = false;
  }
  s.worker = std::thread([&s] { s.work(); });
  s.progress_timer.emplace(s.web->io());
  s.watch_progress();
  s.web->run();
  {
    std::lock_guard<std::mutex> lock(s.jobs_mutex);
    s.worker_stop = true;
  }
  s.jobs_wake.notify_all();
  s.worker.join();
  try {
    std::lock_guard<std::mutex> lock(s.session_mutex);
    s.session.flush_autosave();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "clayform studio: %s\n", e.what());
  }
}

void StudioServer::start() {
  impl_->thread = std::thread([this] { run(); });
}

void StudioServer::stop() {
  if (!impl_) return;
  impl_->stopping = true;
  asio::post(impl_->web->io(), [s = impl_.get()] {
    if (auto p = s->page.lock()) p->close();
    if (s->progress_timer) s->progress_timer->cancel();
  });
  impl_->web->stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

}  // namespace clay::recipe
