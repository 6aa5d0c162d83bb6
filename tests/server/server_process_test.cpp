// Starts the real sweetspot-server executable on 127.0.0.1 with an ephemeral
// port, talks HTTP to it and stops it with a signal.
#include <httplib.h>
#include <fstream>
#include <iterator>
#include <string>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/server/server_process.hpp"

namespace sweetspot {
namespace {

TEST(ServerProcessTest, HealthOverHttpThenCleanStopOnSigterm) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start()) << server.log();
  httplib::Client client("127.0.0.1", server.port());
  const auto res = client.Get("/health");
  ASSERT_TRUE(res) << httplib::to_string(res.error());
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/json");
  EXPECT_EQ(nlohmann::json::parse(res->body), nlohmann::json({{"status", "ok"}}));
  EXPECT_EQ(server.Stop(SIGTERM), 0);
  const std::string log = server.log();
  EXPECT_NE(log.find("\"path\":\"/health\""), std::string::npos) << log;
  EXPECT_NE(log.find("received SIGTERM"), std::string::npos) << log;
  EXPECT_NE(log.find("stopped"), std::string::npos) << log;
}

TEST(ServerProcessTest, SigintAlsoStopsCleanly) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start({"--threads", "2"})) << server.log();
  EXPECT_EQ(server.Stop(SIGINT), 0);
  EXPECT_NE(server.log().find("with 2 threads"), std::string::npos);
}

TEST(ServerProcessTest, BadFlagExitsWithStatus2AndNamesIt) {
  testing::ServerProcess server;
  EXPECT_FALSE(server.Start({"--threads", "0"}));
  EXPECT_NE(server.log().find("option --threads = \"0\": must be an integer in [1, 1024]"),
            std::string::npos)
      << server.log();
}

}  // namespace
}  // namespace sweetspot

namespace sweetspot {
namespace {

// The server's environment as the kernel holds it (after its own exec).
std::string EnvironmentOf(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/environ", std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (char& c : text) {
    if (c == '\0') c = '\n';
  }
  return "\n" + text;
}

TEST(ServerProcessTest, RunsWithALargerMallocCacheUnlessTheOperatorSetsTunables) {
  if (std::getenv("GLIBC_TUNABLES") != nullptr) GTEST_SKIP() << "GLIBC_TUNABLES set here";
  {
    testing::ServerProcess server;
    ASSERT_TRUE(server.Start()) << server.log();
    EXPECT_NE(EnvironmentOf(server.pid()).find("\nGLIBC_TUNABLES=glibc.malloc.tcache_count=64\n"),
              std::string::npos);
    httplib::Client client("127.0.0.1", server.port());
    const auto res = client.Get("/health");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200);
    EXPECT_EQ(server.Stop(), 0);
  }
  {
    testing::ServerProcess server;
    server.SetEnvironment("GLIBC_TUNABLES", "");
    ASSERT_TRUE(server.Start()) << server.log();
    EXPECT_NE(EnvironmentOf(server.pid()).find("\nGLIBC_TUNABLES=\n"), std::string::npos);
    EXPECT_EQ(server.Stop(), 0);
  }
}

}  // namespace
}  // namespace sweetspot
