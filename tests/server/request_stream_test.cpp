// The connection loop hands a request's framing and the body its classify hook parsed to
// the answer (RequestStream): the server's scene bodies are parsed once (issue 33, item 4).
#include "server/request_stream.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "server/connection_loop.hpp"
#include "tests/server/wire.hpp"

namespace sweetspot::server {
namespace request_stream_test {
namespace {

// A non-blocking listening socket on 127.0.0.1 (any port); *port gets it.
int ListenOnLoopback(int* port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      ::listen(fd, 16) != 0) {
    return -1;
  }
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  *port = ntohs(addr.sin_port);
  return fd;
}

// What the serve hook saw of one request.
struct Seen {
  std::mutex mutex;
  int requests = 0;
  int classified = 0;
  std::string body;
  std::uint64_t content_length = 0;
  bool framed = false;
  nlohmann::json* parsed = nullptr;  // the object classify made (compared by address)
  nlohmann::json* made = nullptr;
};

TEST(RequestStreamTest, TheBodyClassifyParsedReachesTheAnswerAndTheFramingIsKnown) {
  int port = 0;
  const int listen_fd = ListenOnLoopback(&port);
  ASSERT_GE(listen_fd, 0);
  Seen seen;
  ConnectionLoopOptions options;
  options.light_workers = 2;
  options.compute_workers = 1;
  ConnectionLoopHooks hooks;
  // Parses the body (as the server's does for a scene that names an iterative model) and
  // sends the light request on: the answer must get this very object.
  hooks.classify = [&seen](std::string_view, std::string_view path, std::string_view body,
                           std::shared_ptr<nlohmann::json>* parsed) {
    if (path == "/parse") {
      *parsed = std::make_shared<nlohmann::json>(nlohmann::json::parse(body));
      std::lock_guard<std::mutex> lock(seen.mutex);
      seen.made = parsed->get();
      ++seen.classified;
    }
    return path == "/compute" ? Pool::kCompute : Pool::kLight;
  };
  hooks.serve = [&seen](RequestStream& stream, bool, bool*) {
    {
      std::lock_guard<std::mutex> lock(seen.mutex);
      ++seen.requests;
      seen.body = std::string(stream.body());
      seen.content_length = stream.content_length();
      seen.framed = stream.framed();
      seen.parsed = stream.parsed_body().get();
      EXPECT_EQ(RequestStream::Current(), &stream);
    }
    static constexpr char kAnswer[] = "HTTP/1.1 200 OK\r\nContent-Length: 2\r\n\r\nok";
    stream.write(kAnswer, sizeof kAnswer - 1);
    return true;
  };
  hooks.error_body = [](int, api::ErrorCode, const std::string&) { return std::string("{}\n"); };
  ConnectionLoop loop(listen_fd, options, std::move(hooks));
  std::thread runner([&loop] { loop.Run(); });

  const int fd = testing::Connect(port);
  ASSERT_GE(fd, 0);
  const auto exchange = [fd](const std::string& request) {
    testing::SendAll(fd, request);
    return testing::ReadFor(fd, 5.0,
                            [](const std::string& bytes) {
                              return bytes.size() >= 40 &&
                                     bytes.compare(bytes.size() - 2, 2, "ok") == 0;
                            })
        .bytes;
  };
  // Parsed by classify: the answer holds the same object; the body and its length are known.
  const std::string body = R"({"outputs": ["vibration_node"]})";
  EXPECT_NE(exchange("POST /parse HTTP/1.1\r\nHost: x\r\nContent-Length: " +
                     std::to_string(body.size()) + "\r\n\r\n" + body)
                .find("200 OK"),
            std::string::npos);
  {
    std::lock_guard<std::mutex> lock(seen.mutex);
    EXPECT_EQ(seen.classified, 1);
    EXPECT_TRUE(seen.framed);
    EXPECT_EQ(seen.body, body);
    EXPECT_EQ(seen.content_length, body.size());
    ASSERT_NE(seen.parsed, nullptr);
    EXPECT_EQ(seen.parsed, seen.made);
  }
  // The next request on the same connection, not parsed by classify: nothing carried over.
  EXPECT_NE(
      exchange("POST /other HTTP/1.1\r\nHost: x\r\nContent-Length: 2\r\n\r\n{}").find("200 OK"),
      std::string::npos);
  {
    std::lock_guard<std::mutex> lock(seen.mutex);
    EXPECT_EQ(seen.requests, 2);
    EXPECT_EQ(seen.body, "{}");
    EXPECT_EQ(seen.parsed, nullptr);
  }
  close(fd);
  loop.Stop();
  runner.join();
}

}  // namespace
}  // namespace request_stream_test
}  // namespace sweetspot::server
