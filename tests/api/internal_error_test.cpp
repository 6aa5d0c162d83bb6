// The top-level handler: an exception escaping a handler becomes a 500
// InternalError whose body has no details, and whose caught text is kept in
// Response::internal_error for the server's and the CLI's log.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace internal_error_test {
namespace {

// GET /metrics calls Context::metrics_text: a context whose metrics throw
// stands in for any handler that throws.
Response MetricsThatThrow(std::function<std::string()> metrics_text) {
  Context context;
  context.metrics_text = std::move(metrics_text);
  return Dispatch({"GET", "/metrics", ""}, context);
}

TEST(InternalErrorTest, CaughtTextIsKeptForTheLogAndNotSent) {
  const Response response = MetricsThatThrow(
      []() -> std::string { throw std::runtime_error("metrics store exploded at row 42"); });
  EXPECT_EQ(response.status, 500);
  EXPECT_EQ(response.body.at("code"), "InternalError");
  EXPECT_EQ(response.body.at("message"), "internal error");
  EXPECT_TRUE(response.body.at("field").is_null());
  EXPECT_EQ(response.internal_error, "metrics store exploded at row 42");
  EXPECT_EQ(response.body.dump().find("exploded"), std::string::npos);
}

TEST(InternalErrorTest, NonStandardExceptionsAreNamedAsSuch) {
  const Response response = MetricsThatThrow([]() -> std::string { throw 7; });
  EXPECT_EQ(response.status, 500);
  EXPECT_EQ(response.internal_error, "an exception not derived from std::exception");
}

TEST(InternalErrorTest, AnAnswerWithoutAnExceptionHasNoInternalError) {
  const Response response = MetricsThatThrow([] { return std::string("m 1\n"); });
  EXPECT_EQ(response.status, 200);
  EXPECT_TRUE(response.internal_error.empty());
  const Response missing = Dispatch({"GET", "/no/such/path", ""}, Context{});
  EXPECT_EQ(missing.status, 404);
  EXPECT_TRUE(missing.internal_error.empty());
}

}  // namespace
}  // namespace internal_error_test
}  // namespace sweetspot::api
