#pragma once
// A WebSocket client of `clayform studio` for the tests (Boost.Beast): the page's socket with
// the session's token and an Origin of the test's choosing, raw text and binary frames.
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <utility>

namespace clay::test {

struct StudioClient {
  boost::asio::io_context io;
  boost::beast::websocket::stream<boost::asio::ip::tcp::socket> ws{io};

  /// Connects to 127.0.0.1:port (Host 127.0.0.1:port) with `origin` and `token`; throws
  /// boost::beast::system_error (upgrade_declined) when the server refuses.
  StudioClient(int port, const std::string& origin, const std::string& token) {
    namespace websocket = boost::beast::websocket;
    boost::asio::ip::tcp::resolver resolver(io);
    boost::asio::connect(ws.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
    ws.set_option(websocket::stream_base::decorator([origin](websocket::request_type& req) {
      req.set(boost::beast::http::field::origin, origin);
    }));
    ws.read_message_max(256u << 20);
    ws.handshake("127.0.0.1:" + std::to_string(port), "/ws?token=" + token);
  }
  /// Sends `bytes` as a text frame, or a binary one.
  void send(const std::string& bytes, bool text = true) {
    ws.text(text);
    ws.write(boost::asio::buffer(bytes));
  }
  /// The next message: (is text, bytes).
  std::pair<bool, std::string> receive() {
    boost::beast::flat_buffer buffer;
    ws.read(buffer);
    return {ws.got_text(), boost::beast::buffers_to_string(buffer.data())};
  }
  /// The next JSON reply (binary frames and progress lines skipped).
  nlohmann::ordered_json reply() {
    while (true) {
      auto [text, bytes] = receive();
      if (!text) continue;
      auto r = nlohmann::ordered_json::parse(bytes);
      if (r.value("op", "") != "progress") return r;
    }
  }
};

}  // namespace clay::test
