// The error codes of the contract's envelope {"code", "message", "field"}:
// one enum, each value with its name (as the JSON writes it) and its HTTP
// status. The names and statuses are part of the contract
// (../shared/docs/api-contract.md, "Errors"); docs/api.md lists them.
#pragma once

#include <array>
#include <optional>
#include <string_view>

namespace sweetspot::api {

/// Why a request was refused (or, for kInternalError, failed).
enum class ErrorCode {
  kInvalidJson,       ///< 400: the body is not JSON.
  kInvalidValue,      ///< 400: a value of the wrong type or outside its rule.
  kUnknownField,      ///< 400: a field the endpoint does not know.
  kMissingField,      ///< 400: a required field is absent.
  kUnauthorized,      ///< 401: a token is configured and the request lacks it.
  kTooBig,            ///< 413: a body, array, string or nesting over a configured limit.
  kNotFound,          ///< 404: no endpoint or no job at this path.
  kMethodNotAllowed,  ///< 405: the path exists for another method.
  kTimeout,           ///< 408: the request (or the work) ran out of time.
  kCancelled,         ///< 409: the work was cancelled.
  kNotReady,          ///< 409: a job's result was asked for before it finished.
  kInfeasible,        ///< 422: no design meets the constraints.
  kModelFailed,       ///< 422: a model ran and failed on this input.
  kTooBusy,           ///< 429: the queue is full; retry later.
  kInternalError,     ///< 500: an unexpected failure (the top-level handler only).
  kNotImplemented,    ///< 501: the feature is not built into this binary.
  kShuttingDown,      ///< 503: the server is stopping.
  kInterrupted,       ///< 503: a job's server died under it more than max_resumes times.
  kUnavailable,       ///< 503: the jobs database cannot be reached; retry later.
};

/// Every ErrorCode, in declaration order (for tables and tests).
inline constexpr std::array<ErrorCode, 19> kAllErrorCodes = {
    ErrorCode::kInvalidJson,    ErrorCode::kInvalidValue,     ErrorCode::kUnknownField,
    ErrorCode::kMissingField,   ErrorCode::kUnauthorized,     ErrorCode::kTooBig,
    ErrorCode::kNotFound,       ErrorCode::kMethodNotAllowed, ErrorCode::kTimeout,
    ErrorCode::kCancelled,      ErrorCode::kNotReady,         ErrorCode::kInfeasible,
    ErrorCode::kModelFailed,    ErrorCode::kTooBusy,          ErrorCode::kInternalError,
    ErrorCode::kNotImplemented, ErrorCode::kShuttingDown,     ErrorCode::kInterrupted,
    ErrorCode::kUnavailable,
};

/// The contract's name of `code` ("InvalidValue", "TooBig", ...).
std::string_view ErrorCodeName(ErrorCode code);

/// The HTTP status `code` is answered with. A few transport-level refusals
/// pass another status explicitly (411 without Content-Length, 431 for a
/// head over the limit, 503 TooBusy when the connection limit is reached,
/// 422 Timeout when a fit ran out of budget with a closest bat).
int ErrorCodeStatus(ErrorCode code);

/// The code named `name`, or nullopt for a name no code has.
std::optional<ErrorCode> ErrorCodeFromName(std::string_view name);

}  // namespace sweetspot::api
