// The sweep engine of /v1/explore: a validated sweep (the template resolved once) and
// RunSweep, which evaluates its designs on up to `threads` threads and hands their rows on in
// index order, bit for bit the rows of a one-thread run.
//
// Per design, the engine applies only the swept values to the resolved template (a
// DesignBinder: ball, swing, cor, the three-segment shape, profile knots, material, wall and
// fill numbers) and recomputes only what they change: a sweep that leaves the bat alone
// computes its mass properties once. A design's row is written straight into its block's
// text when the columns and objectives are values the engine reads from the models' results
// (DirectColumns), and rendered as the JSON row otherwise. What the binder cannot bind (a
// swept path it does not know), and a design whose bound values fail a check, go through the
// JSON path (the design's JSON, parsed as /v1/sweet-spot parses it), so every row and error
// is the one that path gives; tests/api/explore_engine_test.cpp checks the two agree.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "api/explore/binder.hpp"
#include "api/explore/columns.hpp"
#include "api/explore/design.hpp"
#include "api/explore/shards.hpp"
#include "api/json_path.hpp"
#include "api/limits.hpp"
#include "api/router.hpp"
#include "api/thread_budget.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/explore/sampling.hpp"
#include "core/progress.hpp"
#include "core/scene/closed_form_designs.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::api {

/// A validated sweep: everything needed to evaluate its designs, owned, so a streamed answer
/// can run it after the handler has returned.
struct Sweep {
  nlohmann::json base;                     ///< The design template (bat + scene fields).
  std::vector<SweepParameter> parameters;  ///< The swept fields.
  core::SweepPlan plan;                    ///< Sampling, dimensions, seed.
  /// The plan's designs on demand (each worker evaluates from its own copy).
  std::optional<core::DesignSequence> designs;
  RowOutputs outputs;            ///< What each row reports.
  core::SceneOptions options;    ///< The models' settings.
  std::string exit_speed_model;  ///< The exit-speed model options.model resolves to (summary).
  std::string model_reason;      ///< Why that model ("requested", or "auto: ...").
  ApiLimits limits;              ///< The request limits (the JSON path's parser).
  std::vector<ParetoObjective> objectives;      ///< Pareto objectives (may be empty).
  core::Shard shard;                            ///< Which designs this run evaluates.
  std::uint64_t total = 0;                      ///< Designs in the whole sweep.
  nlohmann::json provenance;                    ///< The summary's provenance.
  std::chrono::steady_clock::time_point start;  ///< When the request arrived (timing_s).
  std::optional<DesignBinder> binder;           ///< Set when every swept path binds without JSON.
  /// "report_units": "imperial": a full row's output blocks carry their trade-unit fields
  /// (AddImperialToRow), and the summary says "report_units": "imperial". Rows of "columns"
  /// hold the columns named, whatever this says.
  bool imperial = false;
  int threads = 1;  ///< Threads to evaluate designs on (>= 1).
  /// Pareto objective values kept before they are first cut to their front (then at each
  /// 8-fold growth); tests lower it to exercise the cuts on small sweeps.
  std::size_t pareto_cut_min = 65536;
  ThreadBudget* budget = nullptr;  ///< Where threads beyond the first come from (or none).
};

/// A parsed /v1/explore request: the sweep, ready to run, and the answer's format.
struct ExploreRequest {
  std::shared_ptr<Sweep> sweep;        ///< The sweep (shared with a streamed answer).
  std::string format;                  ///< "json", "ndjson" or "csv".
  std::vector<ExploreColumn> columns;  ///< "columns" (csv: the default set when not given).
};

/// Parses and validates a /v1/explore body (api/handlers/explore.cpp); nullopt with the
/// error naming the field otherwise. Never throws.
std::optional<ExploreRequest> ParseExploreRequest(const nlohmann::json& body,
                                                  const Context& context, ApiError* error);

/// How a run writes its rows.
enum class RowFormat {
  kJson,    ///< JSON values, collected (BlockRows::rows).
  kNdjson,  ///< One JSON text line per row (BlockRows::text).
  kCsv,     ///< One RFC 4180 line per row (BlockRows::text), the values of `columns`.
};

/// The rows of consecutive designs, in index order.
struct BlockRows {
  std::vector<nlohmann::json> rows;  ///< kJson.
  std::string text;                  ///< kNdjson, kCsv.
  std::uint64_t count = 0;           ///< Rows in this block.
};

/// How a sweep ended.
struct SweepOutcome {
  bool cancelled = false;  ///< Progress::Cancel() (message says after how many designs).
  bool stopped = false;    ///< The row sink refused a block (a streaming client went away).
  /// An exception ended the sweep (out of memory: std::bad_alloc, or a thread that could not
  /// start), in any of its threads; message says which and after how many designs.
  bool failed = false;
  std::string message;     ///< Why it was cancelled or failed.
  nlohmann::json summary;  ///< Set when none of the three.
};

/// Evaluates the shard's designs on up to sweep.threads threads in blocks of consecutive
/// designs, handing each block to `emit` in index order (false from it stops the sweep),
/// and returns the summary. With `columns`, a row is the flat object (or CSV line) of
/// those columns. Never throws: an exception in any of its threads (std::bad_alloc) ends the
/// sweep with SweepOutcome::failed, after every thread it started has been joined.
SweepOutcome RunSweep(const Sweep& sweep, RowFormat format,
                      const std::vector<ExploreColumn>& columns, core::Progress* progress,
                      const std::function<bool(BlockRows&)>& emit);

}  // namespace sweetspot::api
