#pragma once
// The command's one HTTP stack (issue #37: `clayform view` had a second static-file server,
// cpp-httplib, beside the studio's): Boost.Beast, asynchronous on one I/O thread as Beast's own
// server examples are. Both servers are security boundaries (issue #36, docs/studio.md
// "Security"), and the checks live here once:
// - every request carries the server's token (?token=TOKEN once, then the HttpOnly cookie that
//   answer sets) and a Host of the server's own address, else 403;
// - a request with an Origin, and every WebSocket upgrade, must come from the server's own page;
// - static files resolve under their mount's folder only: plain names, no link leading out,
//   regular files of a bounded size; GET and HEAD only;
// - connections are bounded (the oldest not yet answered goes) and timed; a full descriptor
//   table or a throwing handler does not end the server.
// Internal to the command (cli/): the studio adds its WebSocket through on_websocket.
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/status.hpp>
#include <boost/beast/http/string_body.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace clay::recipe::web {

namespace http = boost::beast::http;
using Request = http::request<http::string_body>;

/// A folder served under a target prefix.
struct Mount {
  std::string prefix;          ///< "/" or "/run/": the targets it answers (the longest matches)
  std::filesystem::path root;  ///< the folder; empty: nothing is served there (404)
  std::string index;           ///< the file answering the prefix itself ("index.html"); or none
  std::string missing_index;   ///< the 404 body when the index is missing (how to build it)
};

/// Settings of WebServer.
struct WebOptions {
  std::string name = "server";      ///< what the messages call it ("the studio", "the viewer")
  std::string command;              ///< the command that prints its address ("clayform studio")
  std::string cookie = "clayform";  ///< the token's cookie is COOKIE_PORT
  std::string host = "127.0.0.1";
  int port = 0;       ///< 0: any free port
  std::string token;  ///< 16 to 128 letters and digits; empty: 32 random hex digits
  std::vector<Mount> mounts;
  int max_connections = 64;  ///< open connections; beyond, the oldest not yet answered closes
  int request_seconds = 10;  ///< a request's head and body must arrive within this
  std::size_t max_file_bytes = 64u << 20;  ///< largest static file served
};

/// 32 hex digits from the kernel's random source (getrandom). Throws clay::Error(Io).
std::string random_token();

/// Equal strings, compared in a time that does not depend on where they first differ.
bool same_secret(std::string_view a, std::string_view b);

/// The value of `key` in a query string ("a=1&token=x"), or nothing.
std::optional<std::string_view> query_value(std::string_view query, std::string_view key);

/// The value of cookie `name` in a Cookie header ("a=1; name=x"), or nothing.
std::optional<std::string_view> cookie_value(std::string_view header, std::string_view name);

/// A static file under `root` (see the header's comment): HTTP status and body.
std::pair<http::status, std::string> read_static_file(const std::filesystem::path& root,
                                                      std::string_view path, std::size_t max_bytes);

/// The Content-Type of a file by its extension (application/octet-stream when unknown).
std::string content_type(std::string_view path);

/// A Beast HTTP server of static mounts, with an optional WebSocket at "/ws". Binds in the
/// constructor; serves in run() until stop().
class WebServer {
 public:
  /// Called on the I/O thread with an upgrade request to "/ws" that passed every check; owns
  /// the connection from then on. Empty: "/ws" answers 404.
  using OnWebSocket = std::function<void(boost::beast::tcp_stream, Request)>;

  /// Checks the options and binds (clay::Error: InvalidArgument naming the option, Io when the
  /// port cannot be had).
  explicit WebServer(WebOptions options, OnWebSocket on_websocket = {});
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const noexcept;               ///< the bound port
  const std::string& token() const;        ///< the token every request must carry
  std::string url() const;                 ///< "http://HOST:PORT/?token=TOKEN"
  boost::asio::io_context& io() noexcept;  ///< the I/O thread's context (post to it)
  void run();   ///< accepts and serves in this thread until stop(); handlers that throw are logged
  void stop();  ///< from any thread: closes the acceptor and every connection not upgraded

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clay::recipe::web
