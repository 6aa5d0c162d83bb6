#include "api/error_code.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "api/json_reader.hpp"
#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace error_code_test {
namespace {

// The contract's names and statuses (../shared/docs/api-contract.md, "Errors",
// plus the codes the server and jobs document in docs/api.md).
const std::map<std::string, int>& ContractStatuses() {
  static const std::map<std::string, int> statuses = {
      {"InvalidJson", 400},   {"InvalidValue", 400},     {"UnknownField", 400},
      {"MissingField", 400},  {"TooBig", 413},           {"NotFound", 404},
      {"MethodNotAllowed", 405}, {"Timeout", 408},       {"Cancelled", 409},
      {"NotReady", 409},      {"Infeasible", 422},       {"ModelFailed", 422},
      {"TooBusy", 429},       {"InternalError", 500},    {"NotImplemented", 501},
      {"ShuttingDown", 503},  {"Interrupted", 503},      {"Unavailable", 503},
      {"Unauthorized", 401},
  };
  return statuses;
}

TEST(ErrorCodeTest, EveryCodeHasAUniqueNameItsContractStatusAndRoundTrips) {
  std::set<std::string> names;
  for (const ErrorCode code : kAllErrorCodes) {
    const std::string name(ErrorCodeName(code));
    EXPECT_TRUE(names.insert(name).second) << "duplicate name " << name;
    const int status = ErrorCodeStatus(code);
    EXPECT_GE(status, 400) << name;
    EXPECT_LT(status, 600) << name;
    ASSERT_TRUE(ContractStatuses().count(name)) << name << " is not in the contract's table";
    EXPECT_EQ(status, ContractStatuses().at(name)) << name;
    const auto back = ErrorCodeFromName(name);
    ASSERT_TRUE(back.has_value()) << name;
    EXPECT_EQ(*back, code) << name;
  }
  // Every name of the table has an enum value.
  EXPECT_EQ(names.size(), ContractStatuses().size());
}

TEST(ErrorCodeTest, OnlyTheServerErrorsAre5xx) {
  for (const ErrorCode code : kAllErrorCodes) {
    const bool server_side = code == ErrorCode::kInternalError ||
                             code == ErrorCode::kNotImplemented ||
                             code == ErrorCode::kShuttingDown ||
                             code == ErrorCode::kInterrupted || code == ErrorCode::kUnavailable;
    EXPECT_EQ(ErrorCodeStatus(code) >= 500, server_side) << ErrorCodeName(code);
  }
}

TEST(ErrorCodeTest, UnknownNamesHaveNoCode) {
  EXPECT_FALSE(ErrorCodeFromName("").has_value());
  EXPECT_FALSE(ErrorCodeFromName("invalidvalue").has_value());  // Names are case-sensitive.
  EXPECT_FALSE(ErrorCodeFromName("Infeasible ").has_value());
}

TEST(ErrorCodeTest, TheEnvelopeWritesTheName) {
  const Response response = ErrorResponse(413, ErrorCode::kTooBig, "too big", "bat");
  EXPECT_EQ(response.status, 413);
  EXPECT_EQ(response.body.at("code"), "TooBig");
  EXPECT_EQ(response.body.at("field"), "bat");
  ApiError error;
  SetError(&error, ErrorCode::kTooBig, "variants", nullptr, "has 3 variants");
  EXPECT_EQ(error.status, 413);  // SetError takes the code's status.
  const Response from_error = ToResponse(error);
  EXPECT_EQ(from_error.body.at("code"), "TooBig");
  EXPECT_EQ(from_error.body.at("message"), "variants has 3 variants");
}

}  // namespace
}  // namespace error_code_test
}  // namespace sweetspot::api
