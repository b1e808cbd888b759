#pragma once
// Raw HTTP over a plain socket to 127.0.0.1: the servers' tests (studio, view) speak bytes, as
// an attacker would, with no HTTP library between them and the server.
#include <catch2/catch.hpp>

#include <chrono>
#include <cstdint>
#include <string>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

namespace clay::test {

/// 127.0.0.1:port as a socket address.
inline sockaddr_in loopback(int port) {
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_port = htons(static_cast<std::uint16_t>(port));
  at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return at;
}

/// A socket connected to 127.0.0.1:port, or -1 when nothing listens there.
inline int try_connect(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  REQUIRE(fd >= 0);
  const sockaddr_in at = loopback(port);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&at), sizeof at) == 0) return fd;
  ::close(fd);
  return -1;
}

/// A TCP connection to 127.0.0.1:port (a plain socket: the test speaks raw bytes).
inline int connect_to(int port) {
  const int fd = try_connect(port);
  REQUIRE(fd >= 0);
  return fd;
}

/// Whether anything listens on 127.0.0.1:port.
inline bool can_connect(int port) {
  const int fd = try_connect(port);
  if (fd >= 0) ::close(fd);
  return fd >= 0;
}

/// Sends `request` as it is and reads the answer until the server closes, or its head when it
/// is a 101 (an upgrade stays open), within `seconds` (then whatever came).
inline std::string raw_http(int port, const std::string& request, int seconds = 15) {
  const int fd = connect_to(port);
  timeval tv{seconds, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string answer;
  char buffer[65536];
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  while (std::chrono::steady_clock::now() < deadline && answer.size() < (4u << 20)) {
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    answer.append(buffer, static_cast<std::size_t>(n));
    if (answer.rfind("HTTP/1.1 101", 0) == 0 && answer.find("\r\n\r\n") != std::string::npos) break;
  }
  ::close(fd);
  return answer;
}

/// The status code of an HTTP answer (0 when there is none: the server closed without one).
inline int status_of(const std::string& answer) {
  if (answer.rfind("HTTP/1.", 0) != 0 || answer.size() < 12) return 0;
  return std::stoi(answer.substr(9, 3));
}

/// GET `target` with the given header lines ("Host: ...\r\n").
inline std::string get(int port, const std::string& target, const std::string& headers) {
  return raw_http(port, "GET " + target + " HTTP/1.1\r\n" + headers + "\r\n");
}

/// The body of an answer (after its head).
inline std::string body_of(const std::string& answer) {
  const std::size_t at = answer.find("\r\n\r\n");
  return at == std::string::npos ? "" : answer.substr(at + 4);
}

/// A header's value in an answer's head ("" when absent).
inline std::string header_of(const std::string& answer, const std::string& name) {
  const std::string head = answer.substr(0, answer.find("\r\n\r\n"));
  const std::size_t at = head.find("\r\n" + name + ": ");
  if (at == std::string::npos) return "";
  const std::size_t start = at + 4 + name.size();
  return head.substr(start, head.find("\r\n", start) - start);
}

}  // namespace clay::test
