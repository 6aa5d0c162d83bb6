// Faults on the wire: a client that disconnects mid-request and a client too
// slow to send its request. The server drops them and keeps serving others.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "server/server.hpp"
#include "tests/server/wire.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace faults_test {
namespace {

using sweetspot::testing::Connect;

class FaultsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerConfig config;
    config.port = 0;
    config.threads = 4;
    config.read_timeout_s = 1;  // the slow-client test waits past it
    config.access_log = false;
    config.jobs_db = kNoJobsDb;  // Jobs in memory: a shared default file would couple tests.
    server_ = std::make_unique<Server>(config);
    std::string error;
    ASSERT_TRUE(server_->Bind(&error)) << error;
    thread_ = std::thread([this] { server_->Run(); });
  }
  void TearDown() override {
    server_->Stop();
    thread_.join();
  }
  bool HealthOk() {
    httplib::Client client("127.0.0.1", server_->port());
    const auto res = client.Get("/health");
    return res && res->status == 200;
  }
  std::unique_ptr<Server> server_;
  std::thread thread_;
};

TEST_F(FaultsTest, ClientDisconnectingMidBodyIsDropped) {
  for (int i = 0; i < 20; ++i) {
    const int fd = Connect(server_->port());
    ASSERT_GE(fd, 0);
    const std::string head =
        "POST /v1/sweet-spot HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
        "Content-Length: 1000\r\n\r\n{\"bat\": {\"preset\"";
    ASSERT_EQ(send(fd, head.data(), head.size(), MSG_NOSIGNAL), static_cast<ssize_t>(head.size()));
    close(fd);  // 1000 bytes promised, 17 sent
  }
  EXPECT_TRUE(HealthOk());
}

TEST_F(FaultsTest, SlowClientIsTimedOutAndOthersAreServed) {
  const int fd = Connect(server_->port());
  ASSERT_GE(fd, 0);
  const std::string head = "POST /v1/sweet-spot HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\n";
  ASSERT_EQ(send(fd, head.data(), head.size(), MSG_NOSIGNAL), static_cast<ssize_t>(head.size()));
  // Others are served while it stalls.
  EXPECT_TRUE(HealthOk());
  // After its 1 s read timeout the server gives up on the body, answers 408
  // and closes the connection; 5 s bounds the wait.
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  const auto start = std::chrono::steady_clock::now();
  char buffer[4096];
  std::string answer;
  ssize_t n;
  while (answer.find("}\n") == std::string::npos && (n = recv(fd, buffer, sizeof buffer, 0)) > 0) {
    answer.append(buffer, static_cast<size_t>(n));
  }
  const double waited_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  close(fd);
  EXPECT_EQ(answer.substr(0, 12), "HTTP/1.1 408");
  EXPECT_NE(answer.find("read timeout"), std::string::npos) << answer;
  EXPECT_LT(waited_s, 4.0) << "the server waited past its read timeout";
  EXPECT_TRUE(HealthOk());
}

TEST_F(FaultsTest, GarbageRequestLineGetsAnErrorAndTheServerLives) {
  const int fd = Connect(server_->port());
  ASSERT_GE(fd, 0);
  const std::string junk = "\x16\x03\x01 not http at all\r\n\r\n";
  send(fd, junk.data(), junk.size(), MSG_NOSIGNAL);
  char buffer[1024];
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  const ssize_t n = recv(fd, buffer, sizeof buffer, 0);
  close(fd);
  if (n > 0) {
    EXPECT_EQ(std::string(buffer, 12).substr(0, 9), "HTTP/1.1 ");
  }
  EXPECT_TRUE(HealthOk());
}

}  // namespace
}  // namespace faults_test
}  // namespace sweetspot::server
