#include "api/explore/streams.hpp"

#include <string>
#include <utility>

#include "api/error_code.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

std::string CompactJsonText(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace

Response StreamedCsvAnswer(std::shared_ptr<Sweep> sweep, std::vector<ExploreColumn> columns,
                           core::Progress* progress) {
  Response streamed = Response::Text(200, std::string(), "text/csv");
  streamed.stream = [sweep, progress, columns](const ChunkSink& sink) {
    std::string header;
    AppendCsvHeader(columns, &header);
    if (!sink(header)) return false;
    const SweepOutcome outcome = RunSweep(*sweep, RowFormat::kCsv, columns, progress,
                                          [&](BlockRows& rows) { return sink(rows.text); });
    return !outcome.stopped && !outcome.cancelled && !outcome.failed;  // else truncated
  };
  return streamed;
}

Response StreamedNdjsonAnswer(std::shared_ptr<Sweep> sweep, std::vector<ExploreColumn> columns,
                              core::Progress* progress) {
  // With "columns", a row is the flat object of those columns.
  Response streamed = Response::Text(200, std::string(), "application/x-ndjson");
  streamed.stream = [sweep, progress, columns](const ChunkSink& sink) {
    const auto line = [&sink](const Json& value) { return sink(CompactJsonText(value) + "\n"); };
    const SweepOutcome outcome = RunSweep(*sweep, RowFormat::kNdjson, columns, progress,
                                          [&](BlockRows& rows) { return sink(rows.text); });
    if (outcome.stopped) return false;
    // A sweep that does not finish ends with an error line in place of the summary, and is
    // still incomplete (false): the server then ends the HTTP body without its last chunk and a
    // job keeps no result (docs/api.md, "A sweep that does not finish").
    if (outcome.failed || outcome.cancelled) {
      const ErrorCode code = outcome.failed ? ErrorCode::kUnavailable : ErrorCode::kCancelled;
      line({{"error",
             {{"code", ErrorCodeName(code)}, {"message", outcome.message}, {"field", nullptr}}}});
      return false;
    }
    return line({{"summary", outcome.summary}});
  };
  return streamed;
}

Response StreamedJsonAnswer(std::shared_ptr<Sweep> sweep, std::vector<ExploreColumn> columns,
                            core::Progress* progress) {
  Response streamed = Response::Text(200, std::string(), "application/json");
  streamed.stream = [sweep, progress, columns](const ChunkSink& sink) {
    std::string text = "{\"rows\":[";
    bool first = true;
    const SweepOutcome outcome =
        RunSweep(*sweep, RowFormat::kJson, columns, progress, [&](BlockRows& block) {
          for (const Json& row : block.rows) {
            if (!std::exchange(first, false)) text.push_back(',');
            text += CompactJsonText(row);
          }
          return sink(std::exchange(text, std::string()));
        });
    if (outcome.stopped || outcome.failed || outcome.cancelled) return false;
    return sink(text + "],\"summary\":" + CompactJsonText(outcome.summary) + "}");
  };
  return streamed;
}

}  // namespace sweetspot::api
