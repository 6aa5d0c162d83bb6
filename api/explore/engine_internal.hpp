// The sweep engine's internals shared by its two files: the plan of a run, a worker's
// reusable state, a block of designs and its evaluation (engine_rows.cpp: a design's row, JSON,
// template-filled or direct); engine.cpp runs the blocks on threads (RunSweep). Internal to
// api/explore/.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "api/explore/direct_columns.hpp"
#include "api/explore/engine.hpp"
#include "core/scene/closed_form_designs.hpp"

namespace sweetspot::api::explore_run {

using Json = nlohmann::json;
using explore_direct::DirectAccessor;
using explore_direct::JsonValueMemo;

struct RunPlan {
  const Sweep* sweep = nullptr;
  std::uint64_t memory_failures = 0;  // MemoryFailures() when the run started
  RowFormat format = RowFormat::kJson;
  const std::vector<ExploreColumn>* columns = nullptr;
  std::vector<DirectAccessor> column_accessors;     // when `direct`
  std::vector<DirectAccessor> objective_accessors;  // when `direct`
  bool direct = false;  // feasible bound rows are written without a JSON row
  // Direct rows, and full rows filled in a worker's template, whose designs go the lean path
  // first (core::ClosedFormDesigns): the scene outputs only max_exit_speed by a closed form,
  // and no collision efficiency.
  bool lean = false;
  // kNdjson direct rows: the columns in the order of the JSON object's keys (sorted, each path
  // once), each with its key's text ("\"path\":").
  std::vector<std::pair<std::size_t, std::string>> ndjson_keys;
  bool imperial = false;    // some direct column reads the imperial properties
  bool row_twins = false;   // full rows carry the trade-unit fields (report_units imperial)
  bool json_twins = false;  // JSON rows get them before columns and objectives read them
  std::uint64_t in_shard = 0;

  // The design index of the shard's k-th design.
  std::uint64_t DesignIndex(std::uint64_t k) const {
    return sweep->shard.index + k * sweep->shard.count;
  }
};

// One block's rows and what the summary needs from them.
struct BlockResult {
  BlockRows rows;
  std::uint64_t failed = 0;
  // Feasible designs whose max_exit_speed lies beyond the tip / before the knob (clamped).
  std::uint64_t beyond_tip = 0, before_knob = 0;
  std::vector<std::vector<double>> objective_values;
  std::vector<std::uint64_t> indices;
  bool cancelled = false;  // stopped early: Progress::Cancel()
};

// A worker's reusable state.
struct Worker {
  std::optional<core::Scene> scene;             // the binder's scene, bound design after design
  std::optional<core::DesignSequence> designs;  // the sweep's, with this worker's position
  DesignOutcome outcome;  // the last bound design's, refilled design after design
  std::optional<core::SceneEvaluator> evaluator;  // the sweep's options, validated once
  // Full rows of bound designs: the first feasible row, kept as a template whose leaves are
  // overwritten design after design (no JSON tree built per row), when every leaf is a value
  // the engine reads directly.
  bool template_tried = false;
  std::optional<Json> row_template;
  std::vector<std::pair<Json*, DirectAccessor>> leaves;
  // The lean path (plan.lean): its evaluator and the last design's numbers.
  std::optional<core::ClosedFormDesigns> lean;
  core::ClosedFormDesign lean_design;
  std::string_view lean_model_name;       // core::CollisionModelName of lean's model
  std::vector<CsvNumberMemo> csv_memos;   // per CSV column: the text of its last number
  std::vector<JsonValueMemo> json_memos;  // per NDJSON column: the text of its last value
  // The template's NDJSON text cut at its leaves (CompileTemplateText): the text before each
  // leaf with the leaf's index in `leaves`, in the order DumpRow writes them, then the tail.
  std::vector<std::pair<std::string, std::size_t>> template_pieces;
  std::string template_tail;
  std::vector<JsonValueMemo> template_memos;  // per leaf: the text of its last value
};

// What the last block measured per design (negative: nothing measured yet).
struct BlockCost {
  double seconds = -1.0;
  double bytes = -1.0;
};

// How many designs the next block takes (one before anything is measured).
std::uint64_t BlockDesigns(const BlockCost& cost);

// The shard's designs [first, first + count) into *out; what a design cost in *cost.
void EvaluateBlock(const RunPlan& plan, std::uint64_t first, std::uint64_t count,
                   core::Progress* progress, Worker* worker, BlockResult* out, BlockCost* cost);

}  // namespace sweetspot::api::explore_run
