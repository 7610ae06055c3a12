#pragma once
// A tiny test-only HTTP/1.1 and WebSocket client over plain loopback sockets: one request per
// connection (the server answers with Connection: close), and the first text frame of a stream.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace orthoflow::ui::test {

struct HttpResponse {
  int status = 0;  // 0: no answer
  std::string head;
  std::string body;
};

/// A connected socket to 127.0.0.1:port with a 10 s receive timeout; -1 on failure.
inline int connect_loopback(std::uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  timeval timeout{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

inline bool send_all(int fd, const std::string& bytes) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

/// Reads until "\r\n\r\n"; returns the head and leaves what followed in @p rest.
inline std::string read_head(int fd, std::string& rest) {
  std::string data;
  char buf[4096];
  while (data.find("\r\n\r\n") == std::string::npos) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    data.append(buf, static_cast<std::size_t>(n));
  }
  const std::size_t end = data.find("\r\n\r\n");
  if (end == std::string::npos) return data;
  rest = data.substr(end + 4);
  return data.substr(0, end + 4);
}

inline int status_of(const std::string& head) {
  return head.size() > 12 && head.compare(0, 5, "HTTP/") == 0 ? std::stoi(head.substr(9, 3)) : 0;
}

/// Sends one request (Host: 127.0.0.1:port unless @p headers names one) and reads the answer.
inline HttpResponse http(std::uint16_t port, const std::string& method, const std::string& target,
                         const std::vector<std::pair<std::string, std::string>>& headers = {},
                         const std::string& body = "", bool default_host = true) {
  HttpResponse r;
  const int fd = connect_loopback(port);
  if (fd < 0) return r;
  std::string request = method + " " + target + " HTTP/1.1\r\n";
  if (default_host) request += "Host: 127.0.0.1:" + std::to_string(port) + "\r\n";
  for (const auto& [name, value] : headers) request += name + ": " + value + "\r\n";
  if (!body.empty() || method == "POST")
    request += "Content-Length: " + std::to_string(body.size()) + "\r\n";
  request += "Connection: close\r\n\r\n" + body;
  if (send_all(fd, request)) {
    r.head = read_head(fd, r.body);
    r.status = status_of(r.head);
    char buf[4096];
    for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;)
      r.body.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return r;
}

/// A JSON POST.
inline HttpResponse post_json(std::uint16_t port, const std::string& path, const std::string& body,
                              std::vector<std::pair<std::string, std::string>> headers = {}) {
  headers.emplace_back("Content-Type", "application/json");
  return http(port, "POST", path, headers, body);
}

/// The WebSocket upgrade of @p target; on 101, the payload of the first text frame in @p frame.
inline HttpResponse websocket_first_frame(
    std::uint16_t port, const std::string& target, std::string& frame,
    const std::vector<std::pair<std::string, std::string>>& headers = {}) {
  HttpResponse r;
  const int fd = connect_loopback(port);
  if (fd < 0) return r;
  std::string request =
      "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
      "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n";
  for (const auto& [name, value] : headers) request += name + ": " + value + "\r\n";
  std::string data;
  if (send_all(fd, request + "\r\n")) {
    r.head = read_head(fd, data);
    r.status = status_of(r.head);
  }
  char buf[65536];
  auto need = [&](std::size_t n) {
    while (data.size() < n) {
      const ssize_t got = ::recv(fd, buf, sizeof buf, 0);
      if (got <= 0) return false;
      data.append(buf, static_cast<std::size_t>(got));
    }
    return true;
  };
  // RFC 6455 5.2: the server's frames are unmasked; 7-bit, 16-bit or 64-bit payload length.
  if (r.status == 101 && need(2) && (static_cast<unsigned char>(data[0]) & 0x0F) == 1) {
    std::size_t length = static_cast<unsigned char>(data[1]) & 0x7F, header = 2;
    const std::size_t ext = length == 126 ? 2 : length == 127 ? 8 : 0;
    if (need(2 + ext)) {
      if (ext > 0) length = 0;
      for (std::size_t i = 0; i < ext; ++i)
        length = (length << 8) | static_cast<unsigned char>(data[2 + i]);
      header += ext;
      if (need(header + length)) frame = data.substr(header, length);
    }
  } else if (r.status != 101) {
    r.body = data;
    for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;)
      r.body.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return r;
}

}  // namespace orthoflow::ui::test
