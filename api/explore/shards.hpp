// The shards of a /v1/explore sweep, put back together: a sweep run as N
// shards (N jobs, a Slurm array, a Kubernetes indexed Job) gives N NDJSON
// outputs; MergeExploreShards checks they are the complete, disjoint shards of
// one sweep and returns the NDJSON of the whole sweep, equal row for row and in
// its summary (but timing_s) to the unsharded sweep's. Also the Pareto helpers
// the sweep and the merge share.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "core/explore/sampling.hpp"

namespace sweetspot::api {

/// A Pareto objective of a sweep: a dotted path into a row and its sense.
struct ParetoObjective {
  std::string output;               ///< As written, e.g. "max_exit_speed.exit_speed_mps".
  std::vector<std::string> tokens;  ///< The path split ("parameters.<path>" keeps <path> whole).
  core::Sense sense = core::Sense::kMaximize;  ///< Maximised or minimised.
};

/// Splits an objective's output path into tokens: "parameters.<path>" names a
/// swept parameter (whose path may hold dots); anything else splits at dots.
std::vector<std::string> ObjectiveTokens(const std::string& output);

/// The value at `tokens` in `row` (object keys, or decimal array indices), or
/// nullptr when there is none. Never throws.
const nlohmann::json* FindAt(const nlohmann::json& row, const std::vector<std::string>& tokens);

/// The objectives as a summary lists them: [{"output", "sense"}].
nlohmann::json ObjectivesToJson(const std::vector<ParetoObjective>& objectives);

/// Adds to a sweep's summary how many feasible designs have their max_exit_speed clamped to an
/// end of the bat ("max_exit_speed_at_bat_end": {"beyond_tip", "before_knob"}) and a warning
/// saying so, when any has; nothing otherwise. The merge of shards sums the counts.
void AddEndPlacements(std::uint64_t beyond_tip, std::uint64_t before_knob, nlohmann::json* summary);

/// One shard's NDJSON output and where it came from (for messages).
struct ShardOutput {
  std::string name;  ///< A file name, or any label.
  std::string text;  ///< The whole NDJSON output: rows, then the summary line.
};

/// What MergeExploreShards gives.
struct MergedSweep {
  bool ok = false;     ///< False: `error` says which shard and why.
  std::string ndjson;  ///< The whole sweep: rows in index order, then its summary line.
  std::string error;   ///< Why the shards do not merge.
};

/// Merges the shards of one sweep. They must all carry the same provenance
/// (the sweep's input hash: explore hashes the request without its shard,
/// format, columns and report_units), the same shard count, designs_total and
/// report_units (the summary's, absent for SI), and between them every
/// shard index exactly once, each with all its rows (indices i with
/// i mod count = its index, each once) and no error line. The summary is the
/// unsharded sweep's: totals and failures summed, shard {0, 1}, the Pareto
/// front over all rows, timing_s the sum of the shards' (CPU-like). Rows may be the flat rows
/// of "columns" (with index, and the Pareto objectives' paths as keys). Never throws.
/// The texts in memory: MergeShardStreams (api/explore/merge_stream.hpp) over them, which
/// also takes CSV shards and is what `sweetspot explore-merge` runs on files.
MergedSweep MergeExploreShards(const std::vector<ShardOutput>& shards);

}  // namespace sweetspot::api
