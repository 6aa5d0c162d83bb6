// POST /v1/explore with a "flight" template (api/explore/flight_sweep.hpp): launches swept on a
// grid, each row the flight POST /v1/flight gives for the same launch (bit for bit), the same
// bytes on one thread or four, refused designs as rows, and the refusals naming the field.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace flight_sweep_test {
namespace {

Response Explore(const std::string& body, const Context& context = Context{}) {
  return Dispatch({"POST", "/v1/explore", body}, context);
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> Cells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      cells.push_back(cell);
      cell.clear();
    } else {
      cell.push_back(c);
    }
  }
  cells.push_back(cell);
  return cells;
}

constexpr const char* kGrid = R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
    "environment": {"temperature_f": 80}},
  "parameters": [{"path": "launch.exit_speed_mph", "min": 90, "max": 110, "count": 3},
                 {"path": "launch.launch_angle_deg", "min": 20, "max": 28, "count": 2}],
  "format": "csv"})";

TEST(FlightSweepTest, GridRowsAreTheFlightsOfTheFlightEndpoint) {
  const Response r = Explore(kGrid);
  ASSERT_EQ(r.status, 200) << r.body.dump() << r.text;
  EXPECT_EQ(r.content_type, "text/csv");
  const std::vector<std::string> lines = Lines(r.text);
  ASSERT_EQ(lines.size(), 7u);
  const std::vector<std::string> header = Cells(lines[0]);
  EXPECT_EQ(header[0], "index");
  EXPECT_EQ(header[1], "parameters.launch.exit_speed_mph");
  EXPECT_EQ(header[2], "parameters.launch.launch_angle_deg");
  EXPECT_EQ(header[3], "termination");
  EXPECT_EQ(header[4], "distance_m");
  EXPECT_EQ(header.back(), "message");
  // Design 5 is the grid's last point: 110 mph at 28°. The same flight at /v1/flight.
  const std::vector<std::string> last = Cells(lines[6]);
  ASSERT_EQ(last.size(), header.size());
  EXPECT_EQ(last[0], "5");
  EXPECT_EQ(last[1], "110");
  EXPECT_EQ(last[2], "28");
  EXPECT_EQ(last[3], "landed");
  const Response one = Dispatch({"POST", "/v1/flight",
                                 R"({"launch": {"exit_speed_mph": 110, "launch_angle_deg": 28},
                                     "environment": {"temperature_f": 80}})"},
                                Context{});
  ASSERT_EQ(one.status, 200);
  // Shortest round-trip text: the same double.
  EXPECT_EQ(std::stod(last[4]), one.body["distance_m"].get<double>());
  EXPECT_EQ(std::stod(last[5]), one.body["hang_time_s"].get<double>());
  EXPECT_EQ(last.back(), "");  // landed: no message
}

TEST(FlightSweepTest, JsonRowsAndSummary) {
  std::string body = kGrid;
  body.replace(body.find(R"("format": "csv")"), 15, R"("format": "json")");
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 6u);
  EXPECT_EQ(r.body["rows"][0]["parameters"]["launch.exit_speed_mph"], 90.0);
  EXPECT_EQ(r.body["rows"][0]["parameters"]["launch.launch_angle_deg"], 20.0);
  EXPECT_TRUE(r.body["rows"][0]["flight"].contains("distance_m"));
  EXPECT_EQ(r.body["summary"]["designs"], 6);
  EXPECT_EQ(r.body["summary"]["landed"], 6);
  EXPECT_EQ(r.body["summary"]["models_used"][0], "flight:nathan-2016");
}

// 5000 designs on one thread and on four: the same bytes (rows in design order).
TEST(FlightSweepTest, ThreadsGiveTheSameBytes) {
  const std::string body = R"({"flight": {"launch": {"exit_speed_mps": 40, "launch_angle_deg": 25}},
      "parameters": [{"path": "launch.exit_speed_mps", "min": 20, "max": 55, "count": 100},
                     {"path": "environment.wind.speed_mph", "min": 0, "max": 20, "count": 50}],
      "format": "csv"})";
  Context one;
  Context four;
  four.explore_threads = 4;
  const Response a = Explore(body, one);
  const Response b = Explore(body, four);
  ASSERT_EQ(a.status, 200);
  ASSERT_EQ(b.status, 200);
  EXPECT_EQ(Lines(a.text).size(), 5001u);
  EXPECT_EQ(a.text, b.text);
}

// A design core refuses (a launch angle over 90°) is a row with its message; the others fly.
TEST(FlightSweepTest, ARefusedDesignIsARow) {
  const Response r = Explore(R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
      "parameters": [{"path": "launch.launch_angle_deg", "min": 80, "max": 100, "count": 3}],
      "format": "csv"})");
  ASSERT_EQ(r.status, 200);
  const std::vector<std::string> lines = Lines(r.text);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(Cells(lines[1])[2], "landed");
  EXPECT_EQ(Cells(lines[2])[2], "landed");
  const std::vector<std::string> refused = Cells(lines[3]);
  EXPECT_EQ(refused[2], "invalid_input");
  EXPECT_EQ(refused[3], "");
  EXPECT_NE(refused.back().find("launch.launch_angle_deg"), std::string::npos) << lines[3];
}

// Launches that never come down (a custom lift holds them up to max_flight_time_s = 600 s,
// thousands of steps each): a block's budget of 1,024,000 steps bounds the work; later launches
// of the block fly with the 10-step minimum and say why. The same rows on 1 and 2 threads.
TEST(FlightSweepTest, LaunchesThatNeverLandStopAtTheBlocksStepBudget) {
  const std::string body = R"({"flight": {"launch": {"exit_speed_mps": 20, "launch_angle_deg": 0,
        "backspin_rpm": 10000, "sidespin_rpm": 0},
      "aero": {"model": "custom", "cd0": 0, "cd_spin_per_krpm": 0, "lift_law": "linear",
               "cl_per_spin_factor": 10, "spin_decay_s": 1e6},
      "options": {"max_flight_time_s": 600}},
    "parameters": [{"path": "launch.exit_speed_mps", "min": 5, "max": 20, "count": 300}],
    "format": "csv"})";
  Context two;
  two.explore_threads = 2;
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(Explore(body, two).text, r.text);
  const std::vector<std::string> lines = Lines(r.text);
  ASSERT_EQ(lines.size(), 301u);
  long long steps = 0;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = Cells(lines[i]);
    EXPECT_NE(row[2], "landed") << lines[i];
    steps += std::stoll(row[row.size() - 2]);
  }
  // Accepted steps only (the budget also counts rejected ones): at most the budget plus the
  // 10-step minimum of each later launch.
  EXPECT_LE(steps, 1024000 + 10 * 300);
  const std::vector<std::string> last = Cells(lines.back());
  EXPECT_EQ(last[2], "step_limit");
  EXPECT_EQ(last.back(),
            "the integrator took max_steps = 10 steps before the ball landed (the sweep's budget "
            "of 1024000 integrator steps per block of 1024 launches was spent by the block's "
            "launches before it)");
}

// "launches" instead of "launch": the list flown as given, a row per launch in its order, each
// the row /v1/flight's "launches" gives (bit for bit).
TEST(FlightSweepTest, AListOfLaunchesIsFlownAsGiven) {
  const std::string launches = R"([{"exit_speed_mph": 104.2, "launch_angle_deg": 27},
      {"exit_speed_mph": 88, "launch_angle_deg": 12, "spray_angle_deg": -20, "batter_hand": "left"},
      {"exit_speed_mph": 100, "launch_angle_deg": -20, "backspin_rpm": -500, "sidespin_rpm": 0}])";
  const Response r = Explore(R"({"flight": {"launches": )" + launches + R"(},
      "format": "csv"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const std::vector<std::string> lines = Lines(r.text);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(Cells(lines[0])[1], "termination");  // no parameters columns
  const Response flights =
      Dispatch({"POST", "/v1/flight", R"({"launches": )" + launches + "}"}, Context{});
  ASSERT_EQ(flights.status, 200) << flights.body.dump();
  for (int i = 0; i < 3; ++i) {
    const std::vector<std::string> row = Cells(lines[1 + i]);
    EXPECT_EQ(row[1], "landed");
    EXPECT_EQ(std::stod(row[2]), flights.body["flights"][i]["distance_m"].get<double>()) << i;
  }
  const Response json = Explore(R"({"flight": {"launches": )" + launches + "}}");
  ASSERT_EQ(json.status, 200);
  EXPECT_EQ(json.body["rows"].size(), 3u);
  EXPECT_FALSE(json.body["rows"][0].contains("parameters"));
  // A list takes no parameters; a launch out of range refuses the request, as /v1/flight does.
  EXPECT_EQ(Explore(R"({"flight": {"launches": )" + launches +
                    R"(}, "parameters": [{"path": "launch.exit_speed_mph", "min": 1, "max": 2}]})")
                .body["field"],
            "parameters");
  Context small;
  small.limits.max_samples = 2;
  const Response too_many = Explore(R"({"flight": {"launches": )" + launches + "}}", small);
  EXPECT_EQ(too_many.status, 413);
  EXPECT_EQ(too_many.body["field"], "flight.launches");
  EXPECT_EQ(too_many.body["message"],
            "flight.launches: has 3 launches, over the limit max_samples = 2");
  EXPECT_EQ(Explore(R"({"flight": {"launches": [{"exit_speed_mph": 100, "launch_angle_deg": 28},
                {"exit_speed_mph": 100, "launch_angle_deg": 120}]}})")
                .body["field"],
            "flight.launches[1].launch_angle_deg");
}

struct Bad {
  const char* body;
  const char* field;
  int status;
};

TEST(FlightSweepTest, RefusalsNameTheField) {
  const Bad cases[] = {
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
          "parameters": [{"path": "launch.spin", "min": 0, "max": 1}]})",
       "parameters[0].path", 400},
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 120}},
          "parameters": [{"path": "launch.exit_speed_mph", "min": 90, "max": 100}]})",
       "flight.launch.launch_angle_deg", 400},
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
          "parameters": [{"path": "launch.backspin_rpm", "min": 0, "max": 3000}]})",
       "flight.launch", 400},
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
          "parameters": [{"path": "launch.exit_speed_mph", "min": 90, "max": 100},
                         {"path": "launch.exit_speed_mps", "min": 40, "max": 45}]})",
       "parameters[1].path", 400},
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
          "parameters": [{"path": "launch.exit_speed_mph", "min": 90, "max": 100, "count": 1000},
                         {"path": "launch.launch_angle_deg", "min": 0, "max": 50, "count": 1000}]})",
       "parameters", 413},
      // 90,000 rows of JSON (~90 MB) are over max_response_bytes (64 MiB): csv streams.
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
          "parameters": [{"path": "launch.exit_speed_mph", "min": 90, "max": 100, "count": 300},
                         {"path": "launch.launch_angle_deg", "min": 0, "max": 50, "count": 300}]})",
       "format", 413},
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
          "parameters": [{"path": "launch.exit_speed_mph", "min": 90, "max": 100}],
          "format": "ndjson"})",
       "format", 400},
      {R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
                      "outputs": ["trajectory"]},
          "parameters": [{"path": "launch.exit_speed_mph", "min": 90, "max": 100}]})",
       "flight.outputs", 400},
  };
  for (const Bad& c : cases) {
    const Response r = Explore(c.body);
    EXPECT_EQ(r.status, c.status) << c.body << "\n" << r.body.dump();
    EXPECT_EQ(r.body["field"], c.field) << r.body.dump();
  }
  // The template's refusal is named under "flight." with the value as written.
  const Response angle = Explore(cases[1].body);
  EXPECT_EQ(angle.body["message"].get<std::string>().rfind("flight.launch.launch_angle_deg", 0),
            0u)
      << angle.body.dump();
}

}  // namespace
}  // namespace flight_sweep_test
}  // namespace sweetspot::api
