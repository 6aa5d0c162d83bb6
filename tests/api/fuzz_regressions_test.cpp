// Replays the fuzzing inputs through the fuzz targets' own entry points
// (fuzz/entry_points.hpp) in the normal build: every crash input kept in
// fuzz/regressions/<target>/, and the seed corpora in fuzz/corpus/<target>/.
// A file named "pending-*" is a known bug in code this suite's owners may not
// edit yet: while it still fails, its test is skipped with the problem (so the
// suite passes); once fixed, the skip message says to rename it.
#include "fuzz/entry_points.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

namespace sweetspot::fuzz {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace fuzz_regressions_test {
namespace {

namespace fs = std::filesystem;

// The files of directory `dir`/<target> for every target, as (target, path).
std::vector<std::pair<const Target*, fs::path>> Inputs(const fs::path& dir) {
  std::vector<std::pair<const Target*, fs::path>> inputs;
  for (const Target& target : Targets()) {
    const fs::path target_dir = dir / target.name;
    if (!fs::is_directory(target_dir)) continue;
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(target_dir)) {
      if (entry.is_regular_file()) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (auto& file : files) inputs.emplace_back(&target, std::move(file));
  }
  return inputs;
}

// The bytes of `path`.
std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// What is wrong with `input` through `target`, "" if nothing (strict: a
// deliberate 500 counts). An escaping exception counts as wrong.
std::string Replay(const Target& target, const std::string& input) {
  try {
    const Verdict verdict = target.run(input);
    return verdict.problem.empty() ? verdict.note : verdict.problem;
  } catch (const std::exception& e) {
    return std::string("exception escaped the handler: ") + e.what();
  } catch (...) {
    return "a non-standard exception escaped the handler";
  }
}

const fs::path kFuzzDir = fs::path(SWEETSPOT_SOURCE_DIR) / "fuzz";

// True for a known, not yet fixed bug ("pending-<what>").
bool IsPending(const fs::path& path) { return path.filename().string().rfind("pending-", 0) == 0; }

TEST(FuzzRegressionsTest, EveryKeptCrashInputIsHandled) {
  const auto inputs = Inputs(kFuzzDir / "regressions");
  ASSERT_FALSE(inputs.empty()) << "no files under " << kFuzzDir / "regressions";
  for (const auto& [target, path] : inputs) {
    if (IsPending(path)) continue;
    EXPECT_EQ(Replay(*target, ReadFile(path)), "")
        << "fuzz/regressions/" << target->name << "/" << path.filename().string();
  }
}

TEST(FuzzRegressionsTest, PendingBugsAreListed) {
  std::string report;
  for (const auto& [target, path] : Inputs(kFuzzDir / "regressions")) {
    if (!IsPending(path)) continue;
    const std::string problem = Replay(*target, ReadFile(path));
    const std::string where = std::string(target->name) + "/" + path.filename().string();
    report += problem.empty() ? "\n  now passes (drop the \"pending-\" prefix): " + where
                              : "\n  still open: " + where + ": " + problem;
  }
  if (!report.empty()) {
    GTEST_SKIP() << "known bugs awaiting a fix outside fuzz/ (fuzz/README.md):" << report;
  }
}

TEST(FuzzRegressionsTest, EverySeedIsHandledCleanly) {
  const auto inputs = Inputs(kFuzzDir / "corpus");
  ASSERT_GT(inputs.size(), 100u) << "the seed corpora under " << kFuzzDir / "corpus";
  for (const auto& [target, path] : inputs) {
    EXPECT_EQ(Replay(*target, ReadFile(path)), "")
        << "fuzz/corpus/" << target->name << "/" << path.filename().string();
  }
}

TEST(FuzzRegressionsTest, TheDispatchTargetReachesEveryPostRoute) {
  std::set<std::string> fuzzed;
  for (const FuzzRoute& route : PostRoutes()) fuzzed.insert(route.path);
  for (const api::Route& route : api::Routes()) {
    if (route.method == "POST") {
      EXPECT_EQ(fuzzed.count(route.path), 1u) << route.path << ": add it to fuzz::PostRoutes()";
    }
  }
  std::set<char> keys;
  for (const FuzzRoute& route : PostRoutes()) keys.insert(route.key);
  EXPECT_EQ(keys.size(), PostRoutes().size()) << "selector bytes must differ";
  EXPECT_EQ(keys.count(kRawKey), 0u);
}

TEST(FuzzRegressionsTest, EveryTargetHasSeeds) {
  for (const Target& target : Targets()) {
    const fs::path dir = kFuzzDir / "corpus" / target.name;
    EXPECT_TRUE(fs::is_directory(dir) && !fs::is_empty(dir)) << dir;
  }
}

}  // namespace
}  // namespace fuzz_regressions_test
}  // namespace sweetspot::fuzz
