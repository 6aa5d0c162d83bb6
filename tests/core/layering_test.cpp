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
      // not our wrappers such as "core/numerics/nlopt_search.hpp".
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

// The folders of a layer, lowest first: a file may include its own folder and the folders
// before it, never one after it. Shared by core and api; a new folder must be placed here
// (an unplaced folder fails the test, so the map in docs/architecture.md stays complete).
const std::vector<std::string> kCoreFolders = {
    "core",  // the foundation: refusal, summary, units, version, progress, number format
    "core/numerics",  "core/bat",        "core/ball",  "core/flight",   "core/flexible",
    "core/collision", "core/sweet_spot", "core/scene", "core/optimize", "core/explore"};
const std::vector<std::string> kApiFolders = {
    "api",  // JSON reading and rendering, limits, errors, the route types
    "api/outputs", "api/explore", "api/handlers"};

// Rank of a "core/..." or "api/..." header or file's folder in `folders`; -1 when unplaced.
int FolderRank(const std::vector<std::string>& folders, const std::string& path) {
  const std::string folder = fs::path(path).parent_path().generic_string();
  for (std::size_t i = 0; i < folders.size(); ++i) {
    if (folders[i] == folder) return static_cast<int>(i);
  }
  return -1;
}

// The quoted path of an #include line ("core/bat/bat.hpp"), or "" for <...> includes.
std::string QuotedPath(const std::string& line) {
  const auto open = line.find('"');
  if (open == std::string::npos) return "";
  const auto close = line.find('"', open + 1);
  return close == std::string::npos ? "" : line.substr(open + 1, close - open - 1);
}

void ExpectNoUpwardInclude(const std::string& layer, const std::vector<std::string>& folders) {
  const std::string root = fs::path(SWEETSPOT_SOURCE_DIR).generic_string() + "/";
  for (const auto& inc : IncludesUnder(layer)) {
    const std::string file = fs::path(inc.file).generic_string().substr(root.size());
    const int own = FolderRank(folders, file);
    EXPECT_GE(own, 0) << file << ": its folder is not placed in the layering test's map";
    const std::string header = QuotedPath(inc.header);
    if (header.rfind(layer + "/", 0) != 0) continue;
    const int included = FolderRank(folders, header);
    EXPECT_GE(included, 0) << file << " includes " << header << ", an unplaced folder";
    EXPECT_LE(included, own) << file << " includes " << header << " from a folder above its own";
  }
}

TEST(LayeringTest, NoCoreFolderIncludesOneAboveIt) { ExpectNoUpwardInclude("core", kCoreFolders); }

TEST(LayeringTest, NoApiFolderIncludesOneAboveIt) { ExpectNoUpwardInclude("api", kApiFolders); }

}  // namespace
