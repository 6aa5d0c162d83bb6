// The layers point one way (server -> api -> core): scans the #include lines
// of the sources so a wrong-way include fails the build's tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Include {
  std::string file;
  std::string header;
};

std::vector<Include> IncludesUnder(const std::string& folder) {
  std::vector<Include> out;
  const fs::path root = fs::path(SWEETSPOT_SOURCE_DIR) / folder;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const auto ext = entry.path().extension();
    if (ext != ".hpp" && ext != ".cpp" && ext != ".in") continue;
    std::ifstream in(entry.path());
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("#include", 0) == 0) out.push_back({entry.path().string(), line});
    }
  }
  return out;
}

bool Mentions(const std::string& line, const char* what) {
  return line.find(what) != std::string::npos;
}

TEST(LayeringTest, CoreIncludesNeitherJsonNorHttpNorUpperLayers) {
  const auto includes = IncludesUnder("core");
  ASSERT_FALSE(includes.empty());
  for (const auto& inc : includes) {
    EXPECT_FALSE(Mentions(inc.header, "httplib")) << inc.file;
    EXPECT_FALSE(Mentions(inc.header, "nlohmann")) << inc.file;
    EXPECT_FALSE(Mentions(inc.header, "\"api/")) << inc.file;
    EXPECT_FALSE(Mentions(inc.header, "\"server/")) << inc.file;
  }
}

TEST(LayeringTest, SolverHeadersStayInCoreSources) {
  for (const char* folder : {"core", "api", "server"}) {
    for (const auto& inc : IncludesUnder(folder)) {
      // The libraries' own headers (<nlopt.hpp>, <coin/IpTNLP.hpp>, <IpIpoptApplication.hpp>),
      // not our wrappers such as "core/optimize/nlopt_search.hpp".
      const bool solver = Mentions(inc.header, "<nlopt") || Mentions(inc.header, "<Ip") ||
                          Mentions(inc.header, "<coin/") || Mentions(inc.header, "\"Ip");
      if (!solver) continue;
      EXPECT_EQ(std::string(folder), "core") << inc.file << ": " << inc.header;
      EXPECT_EQ(fs::path(inc.file).extension(), ".cpp") << inc.file << ": " << inc.header;
    }
  }
}

TEST(LayeringTest, ApiNeverIncludesHttplibOrServer) {
  for (const auto& inc : IncludesUnder("api")) {
    EXPECT_FALSE(Mentions(inc.header, "httplib")) << inc.file;
    EXPECT_FALSE(Mentions(inc.header, "\"server/")) << inc.file;
  }
}

}  // namespace
