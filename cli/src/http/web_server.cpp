// The command's one HTTP stack (web_server.hpp): Boost.Beast, asynchronous on one I/O thread.
#include "web_server.hpp"

#include <clay/error.hpp>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket/rfc6455.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <list>
#include <map>

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

namespace clay::recipe::web {

namespace fs = std::filesystem;
namespace asio = boost::asio;
namespace beast = boost::beast;
using tcp = asio::ip::tcp;

namespace {

/// Beast's string_view (Boost's) as the standard one.
std::string_view view(beast::string_view v) { return {v.data(), v.size()}; }

}  // namespace

/// 32 hex digits from the kernel's random source (getrandom): the session's secret.
std::string random_token() {
  unsigned char bytes[16];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw Error(ErrorCategory::Io,
                  "no random bytes for the server's token (getrandom failed); give one "
                  "with --token");
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
    return {http::status::payload_too_large, "the file is larger than the server serves\n"};
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

std::string content_type(std::string_view path) {
  static const std::map<std::string, std::string, std::less<>> types = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".txt", "text/plain; charset=utf-8"},
      {".png", "image/png"},
      {".svg", "image/svg+xml"},
      {".wasm", "application/wasm"},
      {".glb", "model/gltf-binary"}};  // .bin, .step, .igs: application/octet-stream
  const auto t = types.find(fs::path(path).extension().string());
  return t == types.end() ? "application/octet-stream" : t->second;
}

struct WebServer::Impl {
  WebOptions options;
  OnWebSocket on_websocket;
  std::string token, cookie_name;
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  asio::steady_timer retry{io};  // accepting again after a full descriptor table
  int port = 0;
  std::atomic<bool> stopping{false};

  struct Http;
  // I/O thread only: connections not (yet) answered or upgraded, oldest first.
  std::list<std::weak_ptr<Http>> open_requests;

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

  /// The mount answering `path`: the longest prefix that matches, or none.
  const Mount* mount_of(std::string_view path) const {
    const Mount* best = nullptr;
    for (const Mount& m : options.mounts)
      if (path.substr(0, m.prefix.size()) == m.prefix &&
          (!best || m.prefix.size() > best->prefix.size()))
        best = &m;
    return best;
  }

  static http::response<http::string_body> plain(const Request& req, http::status status,
                                                 std::string body) {
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
  void close_all();
};

/// One connection until its request is answered (or handed to on_websocket).
struct WebServer::Impl::Http : std::enable_shared_from_this<Http> {
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
    Request req = parser->release();
    const std::string target(req.target());
    const std::size_t q = target.find('?');
    const std::string path = target.substr(0, q);
    const std::string query = q == std::string::npos ? "" : target.substr(q + 1);
    // The checks come before anything is served: the server's own Host, its token.
    if (!s.host_ok(view(req[http::field::host]))) {
      reply(plain(req, http::status::forbidden,
                  "refused: " + s.options.name +
                      " answers requests to its own address only (Host must be 127.0.0.1:" +
                      std::to_string(s.port) + ")\n"));
      return;
    }
    const auto given = query_value(query, "token");
    const auto kept = cookie_value(view(req[http::field::cookie]), s.cookie_name);
    const bool token_ok =
        (given && same_secret(*given, s.token)) || (kept && same_secret(*kept, s.token));
    if (!token_ok) {
      reply(plain(
          req, http::status::forbidden,
          "refused: open the address `" + s.options.command + "` printed, with its ?token=\n"));
      return;
    }
    const std::string_view origin = view(req[http::field::origin]);
    if (beast::websocket::is_upgrade(req)) {
      if (path != "/ws" || !s.on_websocket) {
        reply(plain(req, http::status::not_found,
                    s.on_websocket ? "the socket is /ws\n" : "no socket here\n"));
        return;
      }
      if (!s.origin_ok(origin)) {
        reply(plain(req, http::status::forbidden,
                    "refused: the socket takes its own page only (Origin must be this "
                    "server's address)\n"));
        return;
      }
      done = true;  // on_websocket's connection now
      s.open_requests.erase(slot);
      s.on_websocket(std::move(stream), std::move(req));
      return;
    }
    if (!origin.empty() && !s.origin_ok(origin)) {
      reply(plain(req, http::status::forbidden, "refused: another site's page\n"));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      reply(plain(req, http::status::method_not_allowed, s.options.name + " serves GET only\n"));
      return;
    }
    const Mount* mount = s.mount_of(path);
    if (!mount) {
      reply(plain(req, http::status::not_found, "not found\n"));
      return;
    }
    const bool index = path == mount->prefix;
    const std::string file = "/" + (index ? mount->index : path.substr(mount->prefix.size()));
    auto [status, body] = read_static_file(mount->root, file, s.options.max_file_bytes);
    if (status != http::status::ok) {
      reply(plain(req, status,
                  index && !mount->missing_index.empty() ? mount->missing_index : std::move(body)));
      return;
    }
    http::response<http::string_body> res{http::status::ok, req.version()};
    res.set(http::field::content_type, content_type(file));
    res.set(http::field::cache_control, "no-store");  // a run folder is rewritten by the next run
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
};

void WebServer::Impl::accept_next() {
  acceptor.async_accept(
      io, [this](beast::error_code ec, tcp::socket socket) { on_accept(ec, std::move(socket)); });
}

void WebServer::Impl::on_accept(beast::error_code ec, tcp::socket socket) {
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
  // A studio reply is a JSON frame and then its binary frames, written one after another: with
  // Nagle's algorithm each small write after the first waits for the page's delayed ACK.
  beast::error_code ignored;
  socket.set_option(tcp::no_delay(true), ignored);
  auto connection = std::make_shared<Http>(*this, std::move(socket));
  open_requests.push_back(connection);
  connection->slot = std::prev(open_requests.end());
  connection->start();
  accept_next();
}

void WebServer::Impl::close_all() {
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
}

WebServer::WebServer(WebOptions options, OnWebSocket on_websocket)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  const std::string who = options.name + ": ";
  if (options.max_connections < 2 || options.request_seconds < 1 || options.max_file_bytes == 0)
    throw Error(ErrorCategory::InvalidArgument,
                who +
                    "max_connections must be at least 2, request_seconds at least 1, and the "
                    "byte limits positive");
  if (options.port < 0 || options.port > 65535)
    throw Error(ErrorCategory::InvalidArgument,
                who + "port " + std::to_string(options.port) +
                    " is out of range; give 0..65535 (0: any free port)");
  s.token = options.token.empty() ? random_token() : options.token;
  if (s.token.size() < 16 || s.token.size() > 128 ||
      !std::all_of(s.token.begin(), s.token.end(),
                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)); }))
    throw Error(ErrorCategory::InvalidArgument,
                who +
                    "the token must be 16 to 128 letters and digits (or empty for a random "
                    "one)");
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(options.host, ec);
  if (ec)
    throw Error(ErrorCategory::InvalidArgument,
                who + "host \"" + options.host + "\" is not an address; give e.g. 127.0.0.1");
  const tcp::endpoint at(address, static_cast<unsigned short>(options.port));
  s.acceptor.open(at.protocol(), ec);
  if (!ec) s.acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(at, ec);
  if (!ec) s.acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    throw Error(ErrorCategory::Io, who + "cannot listen on " + options.host + ":" +
                                       std::to_string(options.port) + ": " + ec.message() +
                                       "; choose another --port (0 for any free one)");
  s.port = s.acceptor.local_endpoint().port();
  // Cookies are not told apart by port: two servers on one machine keep a cookie each.
  s.cookie_name = options.cookie + "_" + std::to_string(s.port);
  s.options = std::move(options);
  s.on_websocket = std::move(on_websocket);
}

WebServer::~WebServer() = default;

int WebServer::port() const noexcept { return impl_->port; }

const std::string& WebServer::token() const { return impl_->token; }

std::string WebServer::url() const {
  return "http://" + impl_->options.host + ":" + std::to_string(impl_->port) +
         "/?token=" + impl_->token;
}

asio::io_context& WebServer::io() noexcept { return impl_->io; }

void WebServer::run() {
  impl_->accept_next();
  // A handler that throws (it should not: each answers its own errors) ends that handler, not
  // the server: run() goes on with the others.
  while (true) {
    try {
      impl_->io.run();
      break;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "clayform: %s: a connection failed: %s\n", impl_->options.name.c_str(),
                   e.what());
    }
  }
}

void WebServer::stop() {
  impl_->stopping = true;
  asio::post(impl_->io, [s = impl_.get()] { s->close_all(); });
}

}  // namespace clay::recipe::web
