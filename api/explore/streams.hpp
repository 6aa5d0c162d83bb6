// /v1/explore's streamed answers (Response::stream): the sweep runs while the server writes,
// or while a job service stores, so each owns copies of everything it uses; a sink that
// refuses (a client gone, a job stopped) stops the sweep.
#pragma once

#include <memory>
#include <vector>

#include "api/explore/columns.hpp"
#include "api/explore/engine.hpp"
#include "api/response.hpp"
#include "core/progress.hpp"

namespace sweetspot::api {

/// text/csv: the header row, then the rows block by block as they are evaluated. Only rows: the
/// summary is in the json and ndjson answers (docs/api.md). A stopped sweep is cut short and
/// reports itself unfinished (false).
Response StreamedCsvAnswer(std::shared_ptr<Sweep> sweep, std::vector<ExploreColumn> columns,
                           core::Progress* progress);

/// application/x-ndjson: the rows block by block, then the summary line, or an {"error"} line
/// when the sweep was cancelled or ran out of memory (then the stream still reports itself
/// unfinished: false).
Response StreamedNdjsonAnswer(std::shared_ptr<Sweep> sweep, std::vector<ExploreColumn> columns,
                              core::Progress* progress);

/// application/json, for a job's result (Context::stream_json): the bytes Json::dump gives the
/// whole {"rows": [...], "summary": {...}} answer ("rows" before "summary", compact), a block of
/// rows at a time, never the whole answer in memory. A sweep cancelled or out of memory stops
/// it (false): a job keeps no incomplete answer.
Response StreamedJsonAnswer(std::shared_ptr<Sweep> sweep, std::vector<ExploreColumn> columns,
                            core::Progress* progress);

}  // namespace sweetspot::api
