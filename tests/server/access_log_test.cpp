#include "server/access_log.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace access_log_test {
namespace {

TEST(AccessLogTest, LineHasTheRequestAndNoErrorWhenNoneWasCaught) {
  const std::string line =
      AccessLogLine({"POST", "/v1/sweet-spot", "/v1/sweet-spot", 200, 0.25, 57, ""});
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const auto json = nlohmann::json::parse(line);
  EXPECT_EQ(json.at("method"), "POST");
  EXPECT_EQ(json.at("path"), "/v1/sweet-spot");
  EXPECT_EQ(json.at("route"), "/v1/sweet-spot");
  EXPECT_EQ(json.at("status"), 200);
  EXPECT_DOUBLE_EQ(json.at("duration_s").get<double>(), 0.25);
  EXPECT_EQ(json.at("bytes_in"), 57);
  EXPECT_FALSE(json.contains("error"));
}

TEST(AccessLogTest, CaughtExceptionTextIsInTheLine) {
  const std::string line =
      AccessLogLine({"GET", "/metrics", "/metrics", 500, 0.001, 0, "store exploded \"x\"\n"});
  EXPECT_EQ(line.find('\n'), std::string::npos);  // Escaped: still one line.
  const auto json = nlohmann::json::parse(line);
  EXPECT_EQ(json.at("status"), 500);
  EXPECT_EQ(json.at("error"), "store exploded \"x\"\n");
}

TEST(AccessLogTest, InvalidUtf8InTheTextStillGivesJson) {
  const std::string line = AccessLogLine({"GET", "/x", "unrouted", 500, 0.0, 0, "bad \xff byte"});
  const auto json = nlohmann::json::parse(line);
  EXPECT_EQ(json.at("error"), "bad \xEF\xBF\xBD byte");  // U+FFFD replaces the byte.
}

}  // namespace
}  // namespace access_log_test
}  // namespace sweetspot::server
