// The frame of a timed solve (core/numerics/timing_book.hpp): TimedSolve and TimedRequest fill
// the time, the timings and the models used however the body ends, and let no exception out.
#include "core/numerics/timing_book.hpp"

#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace timing_book_test {
namespace {

struct FakeResult {
  Summary summary;
  std::vector<ModelTiming> timings;
  int value = 0;
};

TEST(TimingBookTest, AddsPerModelInFirstUseOrder) {
  TimingBook book;
  book.Add("hertz", 0.5, 1);
  book.Add("mass_properties", 0.25, 1);
  book.Add("hertz", 0.5, 2);
  ASSERT_EQ(book.timings().size(), 2u);
  EXPECT_EQ(book.timings()[0].model, "hertz");
  EXPECT_EQ(book.timings()[0].time_s, 1.0);
  EXPECT_EQ(book.timings()[0].calls, 3);
  EXPECT_EQ(book.Models(), (std::vector<std::string>{"hertz", "mass_properties"}));
}

TEST(TimingBookTest, TimedSolveStartsAsInvalidInputAndTimesTheBody) {
  const FakeResult refused = TimedSolve<FakeResult>(
      [](FakeResult& out) { out.summary.message = "x = -1: must be positive"; });
  EXPECT_EQ(refused.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(refused.summary.message, "x = -1: must be positive");
  EXPECT_GE(refused.summary.solve_time_s, 0.0);
  const FakeResult solved = TimedSolve<FakeResult>([](FakeResult& out) {
    out.value = 7;
    out.summary.termination = Termination::kConverged;
  });
  EXPECT_EQ(solved.value, 7);
  EXPECT_EQ(solved.summary.termination, Termination::kConverged);
}

TEST(TimingBookTest, TimedSolveTurnsAnExceptionIntoAFailure) {
  const FakeResult out = TimedSolve<FakeResult>([](FakeResult& r) {
    r.value = 3;
    throw std::runtime_error("bad");
  });
  EXPECT_EQ(out.value, 3);  // what the body filled before it threw is kept
  EXPECT_EQ(out.summary.termination, Termination::kFailure);
  EXPECT_EQ(out.summary.message, "internal error: bad");
  EXPECT_GE(out.summary.solve_time_s, 0.0);
}

TEST(TimingBookTest, TimedRequestReportsTheBookAlsoWhenTheBodyThrows) {
  const FakeResult out = TimedRequest<FakeResult>("scene", [](FakeResult&, TimingBook& book) {
    book.Add("mass_properties", 0.0, 1);
    book.Add("rigid_pivot", 0.0, 2);
    throw 1;
  });
  EXPECT_EQ(out.summary.backend, "scene");
  EXPECT_EQ(out.summary.termination, Termination::kFailure);
  EXPECT_EQ(out.summary.message, "internal error");
  EXPECT_EQ(out.summary.models_used, (std::vector<std::string>{"mass_properties", "rigid_pivot"}));
  ASSERT_EQ(out.timings.size(), 2u);
  EXPECT_EQ(out.timings[1].calls, 2);
  EXPECT_GE(out.summary.solve_time_s, 0.0);
}

}  // namespace
}  // namespace timing_book_test
}  // namespace sweetspot::core
