#include "api/error_code.hpp"

namespace sweetspot::api {

std::string_view ErrorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidJson:
      return "InvalidJson";
    case ErrorCode::kInvalidValue:
      return "InvalidValue";
    case ErrorCode::kUnknownField:
      return "UnknownField";
    case ErrorCode::kMissingField:
      return "MissingField";
    case ErrorCode::kUnauthorized:
      return "Unauthorized";
    case ErrorCode::kTooBig:
      return "TooBig";
    case ErrorCode::kNotFound:
      return "NotFound";
    case ErrorCode::kMethodNotAllowed:
      return "MethodNotAllowed";
    case ErrorCode::kTimeout:
      return "Timeout";
    case ErrorCode::kCancelled:
      return "Cancelled";
    case ErrorCode::kNotReady:
      return "NotReady";
    case ErrorCode::kInfeasible:
      return "Infeasible";
    case ErrorCode::kModelFailed:
      return "ModelFailed";
    case ErrorCode::kTooBusy:
      return "TooBusy";
    case ErrorCode::kInternalError:
      return "InternalError";
    case ErrorCode::kNotImplemented:
      return "NotImplemented";
    case ErrorCode::kShuttingDown:
      return "ShuttingDown";
    case ErrorCode::kInterrupted:
      return "Interrupted";
    case ErrorCode::kUnavailable:
      return "Unavailable";
  }
  return "InternalError";
}

int ErrorCodeStatus(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidJson:
    case ErrorCode::kInvalidValue:
    case ErrorCode::kUnknownField:
    case ErrorCode::kMissingField:
      return 400;
    case ErrorCode::kUnauthorized:
      return 401;
    case ErrorCode::kTooBig:
      return 413;
    case ErrorCode::kNotFound:
      return 404;
    case ErrorCode::kMethodNotAllowed:
      return 405;
    case ErrorCode::kTimeout:
      return 408;
    case ErrorCode::kCancelled:
    case ErrorCode::kNotReady:
      return 409;
    case ErrorCode::kInfeasible:
    case ErrorCode::kModelFailed:
      return 422;
    case ErrorCode::kTooBusy:
      return 429;
    case ErrorCode::kInternalError:
      return 500;
    case ErrorCode::kNotImplemented:
      return 501;
    case ErrorCode::kShuttingDown:
    case ErrorCode::kInterrupted:
    case ErrorCode::kUnavailable:
      return 503;
  }
  return 500;
}

std::optional<ErrorCode> ErrorCodeFromName(std::string_view name) {
  for (const ErrorCode code : kAllErrorCodes) {
    if (ErrorCodeName(code) == name) return code;
  }
  return std::nullopt;
}

}  // namespace sweetspot::api
