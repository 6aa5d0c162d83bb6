// Test helpers for the attack tests (attack_test.cpp, attack_soak_test.cpp): raw requests
// from a chosen loopback address, one whole exchange, a process's resident memory, and the
// requests the attacks and the probes send.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "tests/server/wire.hpp"

namespace sweetspot::testing {

/// A blocking TCP connection to 127.0.0.1:port from the loopback address `source`
/// (e.g. "127.0.0.2": another client to the server's per-address limits), or -1. A positive
/// `receive_buffer` sets SO_RCVBUF first (a small window: the server cannot send much
/// to a client that does not read).
inline int ConnectFrom(int port, const char* source, int receive_buffer = 0) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (receive_buffer > 0) {
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  }
  sockaddr_in local{};
  local.sin_family = AF_INET;
  inet_pton(AF_INET, source, &local.sin_addr);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (bind(fd, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0 ||
      connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    close(fd);
    return -1;
  }
  const int yes = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  return fd;
}

/// Sends `raw` on a new connection and reads until the server closes it or `timeout_s`
/// passes: everything it answered ("" when it could not connect).
inline std::string Exchange(int port, const std::string& raw, double timeout_s = 10.0) {
  const int fd = Connect(port);
  if (fd < 0) return "";
  SendAll(fd, raw);
  const ReadResult read = ReadFor(fd, timeout_s, [](const std::string&) { return false; });
  close(fd);
  return read.bytes;
}

/// The status of the first answer in `bytes` ("HTTP/1.1 413 ..." gives 413), or 0.
inline int StatusOf(const std::string& bytes) {
  if (bytes.rfind("HTTP/1.1 ", 0) != 0 || bytes.size() < 12) return 0;
  return std::atoi(bytes.substr(9, 3).c_str());
}

/// How many answers `bytes` holds (status lines at the start of a line).
inline int AnswersIn(const std::string& bytes) {
  int n = 0;
  for (std::size_t at = bytes.find("HTTP/1.1 "); at != std::string::npos;
       at = bytes.find("HTTP/1.1 ", at + 1)) {
    if (at == 0 || bytes[at - 1] == '\n') ++n;
  }
  return n;
}

/// The body of the first answer in `bytes` (after its blank line).
inline std::string BodyOf(const std::string& bytes) {
  const std::size_t at = bytes.find("\r\n\r\n");
  return at == std::string::npos ? "" : bytes.substr(at + 4);
}

/// Resident memory of process `pid`, in bytes (VmRSS), or -1.
inline long long ResidentBytes(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atoll(line.c_str() + 6) * 1024;
  }
  return -1;
}

/// A /v1/sweet-spot request that runs 10,000 flexible impacts, one per point of its exit-speed
/// curve: about 40 s of one core in Release (docs/benchmarks.md: 3.6-3.8 ms per flexible
/// impact), far longer than any test waits, and it polls its cancel flag between points.
inline const char* kLongFlexibleCurve =
    R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["exit_speed_curve"],
        "options": {"model": "flexible", "curve_samples": 10000}})";

/// A raw POST of `body` to `path` (Connection: close).
inline std::string RawPost(const std::string& path, const std::string& body,
                           const std::string& extra_headers = "") {
  return "POST " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n" +
         extra_headers + "Content-Length: " + std::to_string(body.size()) +
         "\r\nConnection: close\r\n\r\n" + body;
}

}  // namespace sweetspot::testing
