// The CLI's streamed `explore-merge` (NDJSON and CSV shards into the unsharded sweep's bytes,
// missing and repeated shards refused with exit 2 and named on stderr), `--progress` (a bar on
// stderr only when asked or on a terminal, stdout unchanged) and `threads` (the default thread
// count from the affinity mask: 1 under `taskset -c 0`).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

namespace sweetspot {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace cli_merge_test {
namespace {

struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

std::string Slurp(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A folder of its own, removed at the end.
class CliMergeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char folder[] = "/tmp/sweetspot-cli-merge-XXXXXX";
    ASSERT_NE(mkdtemp(folder), nullptr);
    dir_ = folder;
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  // Runs `prefix sweetspot args` through the shell, stdout and stderr into files.
  CliRun Cli(const std::string& args, const std::string& prefix = "") const {
    const std::string binary = std::string(SWEETSPOT_BINARY_DIR) + "/server/sweetspot";
    const std::string command = prefix + binary + " " + args + " >" + dir_ + "/out 2>" + dir_ +
                                "/err </dev/null";
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(dir_ + "/out"),
            Slurp(dir_ + "/err")};
  }

  // Writes the sweep's request in `format`.
  std::string Request(const std::string& format) const {
    const std::string file = dir_ + "/sweep-" + format + ".json";
    std::ofstream(file) << R"({"bat": {"preset": "paper-wood", "fill": {"material": "cork",
      "diameter_m": 0.0254, "depth_m": 0.254}}, "outputs": ["max_exit_speed", "properties"],
      "sampling": "sobol", "samples": 2001, "seed": 5,
      "parameters": [{"path": "fill.depth_m", "min": 0, "max": 0.3},
                     {"path": "ball.speed_mps", "min": 20, "max": 40}],
      "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                                {"output": "properties.mass_kg", "sense": "min"}]},
      "format": ")" << format << R"("})";
    return file;
  }

  // Runs the sweep as `count` shards; the files' names, space-separated, in `order`.
  std::string Shards(const std::string& request, const std::string& format, int count,
                     const std::vector<int>& order) const {
    std::string files;
    for (const int i : order) {
      const std::string file = dir_ + "/shard-" + std::to_string(i) + "." + format;
      const CliRun r = Cli("explore --shard " + std::to_string(i) + "/" + std::to_string(count) +
                        " " + request);
      EXPECT_EQ(r.exit_code, 0) << r.err;
      std::ofstream(file, std::ios::binary) << r.out;
      files += " " + file;
    }
    return files;
  }

  std::string dir_;
};

std::string Untimed(const std::string& ndjson) {
  return std::regex_replace(ndjson, std::regex("\"timing_s\":[-0-9.e+]+"), "\"timing_s\":T");
}

TEST_F(CliMergeTest, ShardsMergeIntoTheUnshardedBytesInNdjsonAndCsv) {
  for (const std::string format : {"ndjson", "csv"}) {
    const std::string request = Request(format);
    const CliRun whole = Cli("explore " + request);
    ASSERT_EQ(whole.exit_code, 0) << whole.err;
    const CliRun merged = Cli("explore-merge" + Shards(request, format, 4, {3, 1, 0, 2}));
    ASSERT_EQ(merged.exit_code, 0) << merged.err;
    EXPECT_EQ(merged.err, "");  // no progress in a pipe by default
    if (format == "csv") {
      EXPECT_EQ(merged.out, whole.out);  // byte for byte
    } else {
      // Byte for byte but the summary's one measured number (the shards' sum of times).
      EXPECT_EQ(Untimed(merged.out), Untimed(whole.out));
      EXPECT_NE(merged.out, Untimed(merged.out));
    }
    EXPECT_EQ(std::count(merged.out.begin(), merged.out.end(), '\n'), 2002);  // 2001 rows + 1
  }
}

TEST_F(CliMergeTest, MissingAndRepeatedShardsExitTwoNamingThemWithNothingOnStdout) {
  for (const std::string format : {"ndjson", "csv"}) {
    const std::string request = Request(format);
    CliRun r = Cli("explore-merge" + Shards(request, format, 4, {0, 2}));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err,
              "sweetspot explore-merge: the shards are incomplete: shards 1 and 3 of 4 missing (2 "
              "of 4 given)\n");
    r = Cli("explore-merge" + Shards(request, format, 4, {0, 1, 2, 3, 2}));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("shard-2." + format + ": repeats shard 2 of 4"), std::string::npos)
        << r.err;
  }
  const CliRun unreadable = Cli("explore-merge " + dir_ + "/no-such-shard.ndjson");
  EXPECT_EQ(unreadable.exit_code, 1);
  EXPECT_EQ(unreadable.err, "sweetspot explore-merge: cannot read " + dir_ + "/no-such-shard.ndjson\n");
}

TEST_F(CliMergeTest, ProgressGoesToStderrOnlyWhenAskedAndLeavesStdoutAlone) {
  const std::string request = Request("csv");
  const CliRun plain = Cli("explore " + request);
  const CliRun bar = Cli("--progress=on explore " + request);
  const CliRun lines = Cli("--progress lines explore " + request);
  ASSERT_EQ(plain.exit_code, 0);
  EXPECT_EQ(plain.err, "");  // a pipe: nothing by default
  EXPECT_EQ(bar.out, plain.out);
  EXPECT_EQ(lines.out, plain.out);
  // The final bar: full, the rows (2001 and the header line), the rate, then a line end.
  EXPECT_TRUE(std::regex_search(bar.err, std::regex("explore \\[#{30}\\] 100\\.0%  2002 rows  .* "
                                                    "rows/s  in 0:[0-9]{2}\x1b\\[K\n$")))
      << bar.err;
  EXPECT_TRUE(std::regex_search(lines.err, std::regex("^explore: 100\\.0% 2002 rows [0-9]+ "
                                                      "rows/s elapsed [0-9.]+ s ETA 0 s\n$")))
      << lines.err;
  const std::string files = Shards(Request("ndjson"), "ndjson", 2, {0, 1});
  const CliRun merged = Cli("explore-merge --progress=on" + files);
  EXPECT_EQ(merged.exit_code, 0);
  EXPECT_NE(merged.err.find("explore-merge [#"), std::string::npos) << merged.err;
  EXPECT_EQ(Cli("--progress=sometimes explore " + request).exit_code, 2);
  // auto on a terminal (util-linux's `script` gives the CLI a pseudo-terminal; stdout still
  // goes to a file): the bar, and the same rows.
  const std::string binary = std::string(SWEETSPOT_BINARY_DIR) + "/server/sweetspot";
  const std::string command = "script -qec '" + binary + " explore " + request + " >" + dir_ +
                              "/rows' /dev/null >" + dir_ + "/tty 2>&1 </dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  EXPECT_NE(Slurp(dir_ + "/tty").find("explore [###"), std::string::npos) << Slurp(dir_ + "/tty");
  EXPECT_EQ(Slurp(dir_ + "/rows"), plain.out);
}

TEST_F(CliMergeTest, ThreadsFollowTheAffinityMask) {
  const CliRun pinned = Cli("threads", "taskset -c 0 ");
  ASSERT_EQ(pinned.exit_code, 0) << pinned.err;
  const nlohmann::json report = nlohmann::json::parse(pinned.out);
  EXPECT_EQ(report["affinity_cpus"], 1);
  EXPECT_EQ(report["threads"], 1);
  const CliRun free = Cli("threads");
  EXPECT_GE(nlohmann::json::parse(free.out)["threads"].get<int>(), 1);
}

}  // namespace
}  // namespace cli_merge_test
}  // namespace sweetspot
