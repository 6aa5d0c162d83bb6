// http::AppendJson writes exactly what http::Serialize (nlohmann's dump) writes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "server/server_http.hpp"

namespace sweetspot::server::http {
namespace {

std::string Appended(const nlohmann::json& value) {
  std::string out = "x";
  AppendJson(value, &out);
  return out.substr(1);
}

TEST(AppendJsonTest, WritesWhatSerializeWrites) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  nlohmann::json values = nlohmann::json::array(
      {nullptr, true, false, 0, -1, 7, std::numeric_limits<std::int64_t>::min(),
       std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::uint64_t>::max(), 0u,
       0.0, -0.0, 1.5, 1e-300, 1e300, 23.23759724121471, 1.39688433693434e-13, 2.4242e-05, nan,
       inf, -inf, 5e-324, 1e21, 123456789012345680.0, "", "plain text", "quote \" and \\",
       "tab\tnewline\n\x01\x1f\x7f", "caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80",
       "bad \xff\xfe utf-8 \xc3", nlohmann::json::object(), nlohmann::json::array(),
       nlohmann::json::binary({1, 2, 3})});
  values.push_back({{"b", 1}, {"a", {{"z", nullptr}, {"\xc3\xa9", "x"}}}, {"bad\xff", 2}});
  for (const auto& value : values) {
    EXPECT_EQ(Appended(value), Serialize(value)) << Serialize(value);
  }
  EXPECT_EQ(Appended(values), Serialize(values));
}

}  // namespace
}  // namespace sweetspot::server::http
