// The Server class in-process: limits and error envelopes over real HTTP on
// 127.0.0.1 with an ephemeral port.
#include "server/server.hpp"

#include <httplib.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <thread>

namespace sweetspot::server {
namespace {

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerConfig config;
    config.port = 0;
    config.threads = 4;
    config.max_body_bytes = 1024;
    config.access_log = false;
    server_ = std::make_unique<Server>(config);
    std::string error;
    ASSERT_TRUE(server_->Bind(&error)) << error;
    thread_ = std::thread([this] { server_->Run(); });
  }
  void TearDown() override {
    server_->Stop();
    thread_.join();
  }
  httplib::Client Client() { return httplib::Client("127.0.0.1", server_->port()); }

  std::unique_ptr<Server> server_;
  std::thread thread_;
};

TEST_F(ServerTest, UnknownPathIsJson404) {
  auto client = Client();
  const auto res = client.Get("/v1/nowhere");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 404);
  const auto body = nlohmann::json::parse(res->body);
  EXPECT_EQ(body["code"], "NotFound");
}

TEST_F(ServerTest, BodyOverLimitIs413TooBig) {
  auto client = Client();
  const auto res = client.Post("/health", std::string(4096, 'x'), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 413);
  const auto body = nlohmann::json::parse(res->body);
  EXPECT_EQ(body["code"], "TooBig");
}

TEST_F(ServerTest, ChunkedBodyIsRefused) {
  // Chunked bodies bypass the payload limit in cpp-httplib 0.11.4 (pitfalls.md).
  auto client = Client();
  const auto res = client.Post(
      "/health",
      [](size_t offset, httplib::DataSink& sink) {
        if (offset < 8192) {
          const std::string chunk(1024, 'x');
          sink.write(chunk.data(), chunk.size());
        } else {
          sink.done();
        }
        return true;
      },
      "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 411);
  EXPECT_EQ(nlohmann::json::parse(res->body)["field"], "Transfer-Encoding");
}

TEST_F(ServerTest, ManyKeepAliveRequestsFromSeveralThreads) {
  std::vector<std::thread> clients;
  std::atomic<int> ok{0};
  for (int t = 0; t < 4; ++t) {
    clients.emplace_back([&] {
      auto client = Client();
      client.set_keep_alive(true);
      for (int i = 0; i < 50; ++i) {
        const auto res = client.Get("/health");
        if (res && res->status == 200) ++ok;
      }
    });
  }
  for (auto& c : clients) c.join();
  EXPECT_EQ(ok.load(), 200);
}

TEST(ServerBindTest, PortInUseIsReported) {
  ServerConfig config;
  config.port = 0;
  config.access_log = false;
  Server first(config);
  std::string error;
  ASSERT_TRUE(first.Bind(&error));
  config.port = first.port();
  Server second(config);
  EXPECT_FALSE(second.Bind(&error));
  EXPECT_NE(error.find("cannot bind 127.0.0.1:" + std::to_string(config.port)), std::string::npos);
}

}  // namespace
}  // namespace sweetspot::server
