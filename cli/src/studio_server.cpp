// Clayform Studio's server (clay/studio.hpp): Boost.Beast (Debian's libboost-dev: cpp-httplib 0.11
// has no WebSocket, and Beast is the well-kept header-only HTTP/WebSocket library Debian ships),
// asynchronous on one I/O thread as Beast's own server examples are, with the session's commands
// on one worker thread. It is a security boundary: a stylist leaves it running on a workstation
// (issue #36). Every request is checked for the session's token and the server's own Host before
// anything is read or served; static files resolve under the front end's folder only; no message,
// connection count or exception ends it.
#include <clay/error.hpp>
#include <clay/internal/fenv.hpp>
#include <clay/internal/files.hpp>
#include <clay/internal/json_reader.hpp>
#include <clay/studio.hpp>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

namespace clay::recipe {

namespace fs = std::filesystem;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Json = nlohmann::ordered_json;

namespace {

/// Beast's string_view (Boost's) as the standard one.
std::string_view view(beast::string_view v) { return {v.data(), v.size()}; }

/// 32 hex digits from the kernel's random source (getrandom): the session's secret.
std::string random_token() {
  unsigned char bytes[16];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw Error(ErrorCategory::Io,
                  "studio: no random bytes for the session's token (getrandom "
                  "failed); give one with --token");
    got += static_cast<std::size_t>(n);
  }
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned char b : bytes) {
    out += hex[b >> 4];
    out += hex[b & 15];
  }
  return out;
}

/// Equal strings, compared in a time that does not depend on where they first differ.
bool same_secret(std::string_view a, std::string_view b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t k = 0; k < a.size(); ++k)
    diff |= static_cast<unsigned char>(a[k] ^ (k < b.size() ? b[k] : 0));
  return diff == 0;
}

/// The value of `key` in a query string ("a=1&token=x"), or nothing.
std::optional<std::string_view> query_value(std::string_view query, std::string_view key) {
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view item = query.substr(0, amp);
    if (item.size() > key.size() && item.substr(0, key.size()) == key && item[key.size()] == '=')
      return item.substr(key.size() + 1);
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return std::nullopt;
}

/// The value of cookie `name` in a Cookie header ("a=1; name=x"), or nothing.
std::optional<std::string_view> cookie_value(std::string_view header, std::string_view name) {
  while (!header.empty()) {
    while (!header.empty() && header.front() == ' ') header.remove_prefix(1);
    const std::size_t semi = header.find(';');
    const std::string_view item = header.substr(0, semi);
    if (item.size() > name.size() && item.substr(0, name.size()) == name &&
        item[name.size()] == '=')
      return item.substr(name.size() + 1);
    if (semi == std::string_view::npos) break;
    header.remove_prefix(semi + 1);
  }
  return std::nullopt;
}

/// A static file of the front end: a target path of plain names (letters, digits, '.', '_', '-';
/// no segment empty or starting with '.') that resolves under `root` (a symbolic link inside may
/// not lead out), a regular file (opened without following a link and without blocking, so a
/// device or a FIFO is refused before it is read) of at most `max_bytes`. HTTP status and body.
std::pair<http::status, std::string> read_static_file(const fs::path& root, std::string_view path,
                                                      std::size_t max_bytes) {
  if (root.empty() || path.size() < 2 || path.front() != '/' || path.size() > 512)
    return {http::status::not_found, "not found\n"};
  std::string_view rest = path.substr(1);
  fs::path file = root;
  while (true) {
    const std::size_t slash = rest.find('/');
    const std::string_view segment = rest.substr(0, slash);
    const bool plain =
        !segment.empty() && segment.front() != '.' &&
        std::all_of(segment.begin(), segment.end(), [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
        });
    if (!plain) return {http::status::not_found, "not found\n"};
    file /= std::string(segment);
    if (slash == std::string_view::npos) break;
    rest.remove_prefix(slash + 1);
  }
  std::error_code ec;
  const fs::path base = fs::canonical(root, ec);
  const fs::path resolved = fs::canonical(file, ec);
  if (ec) return {http::status::not_found, "not found\n"};
  const auto [b, r] = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
  if (b != base.end()) return {http::status::not_found, "not found\n"};
  const int fd = ::open(resolved.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return {http::status::not_found, "not found\n"};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return {http::status::not_found, "not found\n"};
  }
  if (static_cast<std::size_t>(st.st_size) > max_bytes) {
    ::close(fd);
    return {http::status::payload_too_large, "the file is larger than the studio serves\n"};
  }
  std::string body(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t done = 0;
  while (done < body.size()) {
    const ssize_t n = ::read(fd, body.data() + done, body.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
  body.resize(done);
  return {http::status::ok, std::move(body)};
}

std::string content_type(const std::string& path) {
  static const std::map<std::string, std::string> types = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".png", "image/png"},
      {".svg", "image/svg+xml"},
      {".wasm", "application/wasm"}};
  const auto t = types.find(fs::path(path).extension().string());
  return t == types.end() ? "application/octet-stream" : t->second;
}

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

}  // namespace

struct StudioServer::Impl {
  StudioSession session;
  StudioOptions options;
  std::string token, cookie_name;
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  asio::steady_timer retry{io};  // accepting again after a full descriptor table
  int port = 0;
  std::thread thread;  // start()'s
  std::atomic<bool> stopping{false};

  struct Http;
  struct Page;
  // I/O thread only: connections not (yet) upgraded, oldest first, and the page's socket.
  std::list<std::weak_ptr<Http>> open_requests;
  std::weak_ptr<Page> page;
  std::uint64_t pages = 0;  // pages that have held the socket

  // The session's worker: commands in order, a newer edit of a path replacing a waiting one.
  struct Job {
    std::string command;
    std::uint64_t page = 0;  // the page that sent it (its reply goes there, if it still holds it)
    std::optional<std::string> key;
  };
  std::mutex jobs_mutex;
  std::condition_variable jobs_wake;
  std::deque<Job> jobs;
  bool worker_stop = false;
  std::thread worker;
  std::atomic<std::uint64_t> holder{0};  // the page that holds the socket (0: none)
  mutable std::mutex session_mutex;      // one command at a time on the session

  explicit Impl(StudioSession s) : session(std::move(s)) {}

  /// Host must be the server's own address: a page of another name (DNS rebinding) is refused.
  bool host_ok(std::string_view host) const {
    const std::string p = ":" + std::to_string(port);
    return host == "127.0.0.1" + p || host == "localhost" + p || host == options.host + p;
  }
  bool origin_ok(std::string_view origin) const {
    const std::string p = ":" + std::to_string(port);
    return origin == "http://127.0.0.1" + p || origin == "http://localhost" + p ||
           origin == "http://" + options.host + p;
  }

  template <class Body>
  static http::response<http::string_body> plain(const http::request<Body>& req,
                                                 http::status status, std::string body) {
    http::response<http::string_body> res{status, req.version()};
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.set(http::field::cache_control, "no-store");
    res.keep_alive(false);
    res.body() = std::move(body);
    res.prepare_payload();
    return res;
  }

  void accept_next();
  void on_accept(beast::error_code ec, tcp::socket socket);
  void take_over(const std::shared_ptr<Page>& newer);
  void submit(std::string command, std::uint64_t from);
  void work();
  void close_all();
};

/// One connection until its request is answered (or upgraded to the page's WebSocket).
struct StudioServer::Impl::Http : std::enable_shared_from_this<Http> {
  Impl& s;
  beast::tcp_stream stream;
  beast::flat_buffer buffer;
  std::optional<http::request_parser<http::string_body>> parser;
  std::list<std::weak_ptr<Http>>::iterator slot;
  bool done = false;

  Http(Impl& server, tcp::socket socket) : s(server), stream(std::move(socket)) {}

  void start() {
    parser.emplace();
    parser->header_limit(16 * 1024);
    parser->body_limit(64 * 1024);  // a GET has none; the upgrade none
    stream.expires_after(std::chrono::seconds(s.options.request_seconds));
    http::async_read(
        stream, buffer, *parser,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  /// Closes the connection (and leaves the list of open requests).
  void close() {
    if (done) return;
    done = true;
    s.open_requests.erase(slot);
    beast::error_code ignored;
    stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream.close();
  }

  template <class Response>
  void reply(Response&& response) {
    auto res = std::make_shared<std::decay_t<Response>>(std::forward<Response>(response));
    stream.expires_after(std::chrono::seconds(s.options.request_seconds));
    http::async_write(
        stream, *res,
        [self = shared_from_this(), res](beast::error_code, std::size_t) { self->close(); });
  }

  void on_read(beast::error_code ec) {
    if (ec) {
      close();
      return;
    }
    http::request<http::string_body> req = parser->release();
    const std::string target(req.target());
    const std::size_t q = target.find('?');
    const std::string path = target.substr(0, q);
    const std::string query = q == std::string::npos ? "" : target.substr(q + 1);
    // The checks come before anything is served: the server's own Host, the session's token.
    if (!s.host_ok(view(req[http::field::host]))) {
      reply(plain(req, http::status::forbidden,
                  "refused: the studio answers requests to its own address only (Host must be "
                  "127.0.0.1:" +
                      std::to_string(s.port) + ")\n"));
      return;
    }
    const auto given = query_value(query, "token");
    const auto kept = cookie_value(view(req[http::field::cookie]), s.cookie_name);
    const bool token_ok =
        (given && same_secret(*given, s.token)) || (kept && same_secret(*kept, s.token));
    if (!token_ok) {
      reply(plain(req, http::status::forbidden,
                  "refused: open the address `clayform studio` printed, with its ?token=\n"));
      return;
    }
    const std::string_view origin = view(req[http::field::origin]);
    if (websocket::is_upgrade(req)) {
      if (path != "/ws") {
        reply(plain(req, http::status::not_found, "the studio's socket is /ws\n"));
        return;
      }
      if (!s.origin_ok(origin)) {
        reply(plain(req, http::status::forbidden,
                    "refused: the studio's socket takes its own page only (Origin must be this "
                    "server's address)\n"));
        return;
      }
      upgrade(std::move(req));
      return;
    }
    if (!origin.empty() && !s.origin_ok(origin)) {
      reply(plain(req, http::status::forbidden, "refused: another site's page\n"));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      reply(plain(req, http::status::method_not_allowed, "the studio serves GET only\n"));
      return;
    }
    const std::string file = path == "/" ? "/studio.html" : path;
    auto [status, body] = read_static_file(s.options.front_end, file, s.options.max_file_bytes);
    if (status != http::status::ok) {
      reply(plain(req, status,
                  file == "/studio.html" && s.options.front_end.empty()
                      ? "The studio's page is not built (scripts/viewer.sh builds it). The "
                        "kernel's WebSocket is at /ws (docs/studio.md).\n"
                      : std::move(body)));
      return;
    }
    http::response<http::string_body> res{http::status::ok, req.version()};
    res.set(http::field::content_type, content_type(file));
    res.set(http::field::cache_control, "no-store");
    res.set("X-Content-Type-Options", "nosniff");
    if (given)  // the page was opened with its token: later requests carry it as a cookie
      res.set(http::field::set_cookie,
              s.cookie_name + "=" + s.token + "; Path=/; HttpOnly; SameSite=Strict");
    res.keep_alive(false);
    if (req.method() == http::verb::head)
      res.content_length(body.size());
    else
      res.body() = std::move(body);
    if (req.method() != http::verb::head) res.prepare_payload();
    reply(std::move(res));
  }

  void upgrade(http::request<http::string_body> req);
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

void StudioServer::Impl::Http::upgrade(http::request<http::string_body> req) {
  done = true;  // the page's connection now
  s.open_requests.erase(slot);
  auto holder_page = std::make_shared<Page>(s, std::move(stream));
  holder_page->accept(std::move(req));
}

void StudioServer::Impl::accept_next() {
  acceptor.async_accept(
      io, [this](beast::error_code ec, tcp::socket socket) { on_accept(ec, std::move(socket)); });
}

void StudioServer::Impl::on_accept(beast::error_code ec, tcp::socket socket) {
  if (stopping || ec == asio::error::operation_aborted) return;
  if (ec) {
    // A full descriptor table (EMFILE, ENFILE) or the like: make room by closing the oldest
    // request not yet answered, and accept again shortly, instead of ending the server.
    if (!open_requests.empty())
      if (auto oldest = open_requests.front().lock()) oldest->close();
    retry.expires_after(std::chrono::milliseconds(50));
    retry.async_wait([this](beast::error_code wait) {
      if (!wait && !stopping) accept_next();
    });
    return;
  }
  // Room for the newest: the oldest connections that have not sent a whole request yet go (idle
  // ones were each holding a thread and a descriptor until the table was full).
  while (static_cast<int>(open_requests.size()) >= options.max_connections - 1) {
    auto oldest = open_requests.front().lock();
    if (!oldest) {
      open_requests.pop_front();
      continue;
    }
    oldest->close();
  }
  // A reply is a JSON frame and then its binary frames, written one after another: with
  // Nagle's algorithm each small write after the first waits for the page's delayed ACK.
  beast::error_code ignored;
  socket.set_option(tcp::no_delay(true), ignored);
  auto connection = std::make_shared<Http>(*this, std::move(socket));
  open_requests.push_back(connection);
  connection->slot = std::prev(open_requests.end());
  connection->start();
  accept_next();
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
  Job job{std::move(command), from, std::nullopt};
  job.key = edit_key(job.command);
  {
    std::lock_guard<std::mutex> lock(jobs_mutex);
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
    try {
      std::lock_guard<std::mutex> lock(session_mutex);
      *reply = session.handle(job.command,
                              [this, from = job.page] { return stopping || holder != from; });
      if (idle_after) session.flush_autosave();  // a drag's updates have stopped
    } catch (const std::exception& e) {  // (handle answers everything; an autosave may fail)
      *reply = {Json{{"op", "error"}, {"category", "i/o"}, {"message", e.what()}}.dump(
                    -1, ' ', false, Json::error_handler_t::replace),
                {}};
    }
    asio::post(io, [this, reply, from = job.page] {
      if (auto p = page.lock(); p && p->id == from) p->send(std::move(*reply));
    });
  }
}

void StudioServer::Impl::close_all() {
  beast::error_code ignored;
  acceptor.close(ignored);
  retry.cancel();
  while (!open_requests.empty()) {
    auto oldest = open_requests.front().lock();
    if (!oldest) {
      open_requests.pop_front();
      continue;
    }
    oldest->close();
  }
  if (auto p = page.lock()) p->close();
}

StudioServer::StudioServer(StudioSession session, const StudioOptions& options)
    : impl_(std::make_unique<Impl>(std::move(session))) {
  impl_->options = options;
  if (options.max_connections < 2 || options.request_seconds < 1 || options.max_file_bytes == 0 ||
      options.max_queued_bytes == 0)
    throw Error(ErrorCategory::InvalidArgument,
                "studio: max_connections must be at least 2, request_seconds at least 1, and the "
                "byte limits positive");
  impl_->token = options.token.empty() ? random_token() : options.token;
  if (impl_->token.size() < 16 || impl_->token.size() > 128 ||
      !std::all_of(impl_->token.begin(), impl_->token.end(),
                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)); }))
    throw Error(ErrorCategory::InvalidArgument,
                "studio: the token must be 16 to 128 letters and digits (or empty for a random "
                "one)");
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
  // Cookies are not told apart by port: two studios on one machine keep a cookie each.
  impl_->cookie_name = "clayform_studio_" + std::to_string(impl_->port);
}

StudioServer::~StudioServer() { stop(); }

int StudioServer::port() const noexcept { return impl_->port; }

const std::string& StudioServer::token() const { return impl_->token; }

std::string StudioServer::url() const {
  return "http://" + impl_->options.host + ":" + std::to_string(impl_->port) +
         "/?token=" + impl_->token;
}

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
  s.accept_next();
  // A handler that throws (it should not: each answers its own errors) ends that handler, not
  // the server: run() goes on with the others.
  while (true) {
    try {
      s.io.run();
      break;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "clayform studio: a connection failed: %s\n", e.what());
    }
  }
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
  asio::post(impl_->io, [s = impl_.get()] { s->close_all(); });
  if (impl_->thread.joinable()) impl_->thread.join();
}

}  // namespace clay::recipe
