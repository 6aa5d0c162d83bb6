// FormatProgress (server/cli_progress.hpp): the bar and the plain line, exactly.
#include "server/cli_progress.hpp"

#include <gtest/gtest.h>

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace cli_progress_test {
namespace {

TEST(CliProgressTest, TheBarShowsTheFractionTheCountsTheRateAndTheTimeLeft) {
  // A quarter done in 2 s: 6 s left; 3,000,000 rows at 1,500,000 a second.
  const ProgressSample quarter{0.25, 3000000};
  EXPECT_EQ(FormatProgress("explore", "rows", quarter, 2.0, false, 20),
            "explore [#####---------------]  25.0%  3.0M rows  1.5M rows/s  ETA 0:06");
  EXPECT_EQ(FormatProgress("explore", "rows", quarter, 2.0, true),
            "explore: 25.0% 3000000 rows 1500000 rows/s elapsed 2.0 s ETA 6 s");
  // Done: the time it took (1 min 15 s); before any progress the time left is unknown.
  EXPECT_EQ(FormatProgress("explore-merge", "B", {1.0, 12345}, 75.0, false, 10),
            "explore-merge [##########] 100.0%  12.3k B  165 B/s  in 1:15");
  EXPECT_EQ(FormatProgress("explore", "rows", {0.0, 0}, 0.5, false, 4),
            "explore [----]   0.0%  0 rows  0 rows/s  ETA ?");
  EXPECT_EQ(FormatProgress("explore", "rows", {0.0, 0}, 0.5, true),
            "explore: 0.0% 0 rows 0 rows/s elapsed 0.5 s ETA unknown");
  // No unit: an optimisation's starts report only a fraction. Over an hour: h:mm:ss.
  EXPECT_EQ(FormatProgress("optimize", "", {0.5, 0}, 10.0, true),
            "optimize: 50.0% elapsed 10.0 s ETA 10 s");
  EXPECT_EQ(FormatProgress("optimize", "", {0.5, 0}, 3725.0, false, 2),
            "optimize [#-]  50.0%  ETA 1:02:05");
}

TEST(CliProgressTest, ModesParseAndNothingElse) {
  ProgressMode mode = ProgressMode::kOff;
  EXPECT_TRUE(ParseProgressMode("lines", &mode));
  EXPECT_EQ(mode, ProgressMode::kLines);
  EXPECT_TRUE(ParseProgressMode("auto", &mode));
  EXPECT_EQ(mode, ProgressMode::kAuto);
  EXPECT_FALSE(ParseProgressMode("yes", &mode));
  EXPECT_FALSE(ParseProgressMode("", &mode));
  EXPECT_EQ(mode, ProgressMode::kAuto);  // unchanged by a refusal
}

}  // namespace
}  // namespace cli_progress_test
}  // namespace sweetspot::server
