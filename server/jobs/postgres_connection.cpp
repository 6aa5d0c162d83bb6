#include "server/jobs/postgres_connection.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "api/json_reader.hpp"
#include "server/jobs/job_common.hpp"

namespace sweetspot::server::pg {

void IgnoreNotice(void*, const char*) {}

std::string Message(const char* text) {
  std::string out = text != nullptr ? text : "";
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out.empty() ? "unknown error" : out;
}

std::string Text(const PGresult* result, int row, int column) {
  return PQgetisnull(result, row, column) ? std::string() : PQgetvalue(result, row, column);
}

double Number(const PGresult* result, int row, int column) {
  return std::strtod(PQgetvalue(result, row, column), nullptr);
}

std::optional<double> OptionalNumber(const PGresult* result, int row, int column) {
  if (PQgetisnull(result, row, column)) return std::nullopt;
  return Number(result, row, column);
}

bool Execute(PGconn* connection, const std::string& sql, const std::vector<Param>& params,
             PgResult* out, std::string* error, const BinaryParts& binary) {
  std::vector<const char*> values;
  std::vector<int> lengths;
  std::vector<int> formats;
  values.reserve(params.size() + 1);
  for (const Param& param : params) values.push_back(param ? param->c_str() : nullptr);
  if (binary.index > 0) {
    values.resize(std::max<std::size_t>(values.size(), static_cast<std::size_t>(binary.index)));
    lengths.assign(values.size(), 0);
    formats.assign(values.size(), 0);
    values[binary.index - 1] = binary.binary.data();
    lengths[binary.index - 1] = static_cast<int>(binary.binary.size());
    formats[binary.index - 1] = 1;
  }
  const bool plain = params.empty() && binary.index == 0 && !binary.binary_result;
  PgResult result(
      plain
          ? PQexec(connection, sql.c_str())
          : PQexecParams(connection, sql.c_str(), static_cast<int>(values.size()), nullptr,
                         values.data(), lengths.empty() ? nullptr : lengths.data(),
                         formats.empty() ? nullptr : formats.data(), binary.binary_result ? 1 : 0),
      &PQclear);
  const ExecStatusType status = result ? PQresultStatus(result.get()) : PGRES_FATAL_ERROR;
  if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) {
    *error = Message(result ? PQresultErrorMessage(result.get()) : PQerrorMessage(connection));
    return false;
  }
  if (out != nullptr) *out = std::move(result);
  return true;
}

std::string Decimal(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

std::string LeaseOwner() {
  char host[256] = "unknown";
  gethostname(host, sizeof(host) - 1);
  std::mt19937_64 random = SeededEngine();
  char tail[32];
  std::snprintf(tail, sizeof(tail), "%016llx", static_cast<unsigned long long>(random()));
  return std::string(host) + ":" + std::to_string(getpid()) + ":" + tail;
}

api::Response Unavailable() {
  return api::ToResponse(api::ApiError{503, api::ErrorCode::kUnavailable,
                                       "the jobs database cannot be reached; retry later", ""});
}

}  // namespace sweetspot::server::pg
