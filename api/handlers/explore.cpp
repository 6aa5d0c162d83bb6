// POST /v1/explore: design sweeps for pipelines. Parameters are numeric fields
// of the request's bat or scene, addressed by path; designs come from a grid,
// a Latin hypercube or a Sobol sequence; each design is one row (failed
// designs are rows with an error, never fatal to the sweep); shards split a
// sweep deterministically (design i belongs to shard i mod count). The request is parsed by
// explore_request.cpp (ParseExploreRequest), each swept parameter by explore_parameters.cpp.
#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "api/explore/engine.hpp"
#include "api/explore/flight_sweep.hpp"
#include "api/explore/streams.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/memory_reserve.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

}  // namespace

Response HandleExplore(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response failure;
  // Not ParseRequest: "report_units" is this endpoint's own field (ParseExploreRequest).
  const std::optional<Json> body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  // A sweep of batted-ball launches ("flight" instead of a bat): api/explore/flight_sweep.hpp.
  if (IsFlightSweep(*body)) return HandleFlightSweep(*body, context);
  ApiError error;
  const auto parsed = ParseExploreRequest(*body, context, &error);
  if (!parsed) return ToResponse(error);
  if (context.validate_only) return ValidRequest();
  // The sweep's timing_s, in its summary, counts from the request's arrival.
  const std::shared_ptr<Sweep>& sweep = parsed->sweep;
  sweep->start = start;
  const std::vector<ExploreColumn> columns = parsed->columns;
  // csv and ndjson are streamed (the sweep runs while the server writes), and so is json for
  // a job's result (api/explore/streams.hpp).
  if (parsed->format == "csv") return StreamedCsvAnswer(sweep, columns, context.progress);
  if (parsed->format == "ndjson") return StreamedNdjsonAnswer(sweep, columns, context.progress);
  if (context.stream_json) return StreamedJsonAnswer(sweep, columns, context.progress);
  Json rows = Json::array();
  const SweepOutcome outcome =
      RunSweep(*sweep, RowFormat::kJson, columns, context.progress, [&](BlockRows& block) {
        for (Json& row : block.rows) rows.push_back(std::move(row));
        return true;
      });
  if (outcome.failed) {
    rows = Json();  // the memory back before the answer is made
    RestoreMemoryReserve();
    return ErrorResponse(503, ErrorCode::kUnavailable,
                         outcome.message +
                             "; retry later, or ask for \"format\": \"ndjson\" or \"csv\" "
                             "(streamed)");
  }
  if (outcome.cancelled) return ErrorResponse(409, ErrorCode::kCancelled, outcome.message);
  return {200, {{"rows", std::move(rows)}, {"summary", outcome.summary}}};
}

}  // namespace sweetspot::api
