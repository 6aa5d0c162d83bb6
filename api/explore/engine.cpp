#include "api/explore/engine.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <new>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>

#include "api/bat_json.hpp"
#include "api/explore/direct_columns.hpp"
#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/numerics/timing_book.hpp"

namespace sweetspot::api {

using Json = nlohmann::json;

namespace {

using explore_direct::AppendJsonValue;
using explore_direct::CompileAccessor;
using explore_direct::DirectAccessor;
using explore_direct::DirectValue;
using explore_direct::DirectView;
using explore_direct::DumpRow;
using explore_direct::JsonValueMemo;
using explore_direct::NeedsImperial;
using explore_direct::Number;
using explore_direct::ReadDirect;
using explore_direct::Source;
using explore_direct::ToJson;
using explore_direct::ToObjective;
using explore_direct::ViewOf;
using explore_direct::WriteCsv;

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

// The text DumpRow gives `node` (part of a row template: objects and leaves), cut at each
// leaf: the text before the leaf and its index in `leaves` into *pieces; what follows the last
// leaf so far in *pending. False when a leaf is not one of `leaves`.
bool CompileTemplateText(const Json& node,
                         const std::vector<std::pair<Json*, DirectAccessor>>& leaves,
                         std::vector<std::pair<std::string, std::size_t>>* pieces,
                         std::string* pending) {
  if (node.is_object()) {
    pending->push_back('{');
    bool first = true;
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (!first) pending->push_back(',');
      first = false;
      pending->append(DumpRow(Json(it.key())));
      pending->push_back(':');
      if (!CompileTemplateText(it.value(), leaves, pieces, pending)) return false;
    }
    pending->push_back('}');
    return true;
  }
  for (std::size_t k = 0; k < leaves.size(); ++k) {
    if (leaves[k].first == &node) {
      pieces->emplace_back(std::move(*pending), k);
      pending->clear();
      return true;
    }
  }
  return false;
}

// The leaves of `node` (at `tokens`) with their accessors into *leaves; false when one is not
// read directly (or is an array).
bool CollectLeaves(Json* node, std::vector<std::string>* tokens, const Sweep& sweep,
                   std::vector<std::pair<Json*, DirectAccessor>>* leaves) {
  if (node->is_array()) return false;
  if (node->is_object()) {
    for (auto it = node->begin(); it != node->end(); ++it) {
      tokens->push_back(it.key());
      const bool ok = CollectLeaves(&it.value(), tokens, sweep, leaves);
      tokens->pop_back();
      if (!ok) return false;
    }
    return true;
  }
  const auto accessor = CompileAccessor(*tokens, sweep.parameters, sweep.outputs);
  if (!accessor || accessor->source == Source::kMissing) return false;
  leaves->emplace_back(node, *accessor);
  return true;
}

// True when `value` is of the kind of the template's leaf `node` (so the leaf set to it dumps
// as a freshly rendered row would).
bool LeafTakes(const DirectValue& value, const Json& node) {
  switch (value.kind) {
    case DirectValue::kNumber:
      return node.is_number_float();
    case DirectValue::kUnsigned:
      return node.is_number_unsigned();
    case DirectValue::kBool:
      return node.is_boolean();
    case DirectValue::kString:
      return node.is_string();
    case DirectValue::kMissing:
      return false;
  }
  return false;
}

// Sets `value` on the template's leaf `node` when it is of the leaf's own kind (so the dump is
// the one of a freshly rendered row); false otherwise.
bool SetLeaf(const DirectValue& value, Json* node) {
  if (!LeafTakes(value, *node)) return false;
  switch (value.kind) {
    case DirectValue::kNumber:
      *node->get_ptr<double*>() = value.number;
      return true;
    case DirectValue::kUnsigned:
      *node->get_ptr<std::uint64_t*>() = value.count;
      return true;
    case DirectValue::kBool:
      *node->get_ptr<bool*>() = value.flag;
      return true;
    case DirectValue::kString:
      node->get_ptr<std::string*>()->assign(value.text);
      return true;
    case DirectValue::kMissing:
      return false;
  }
  return false;
}

// The row of design `i` from its JSON row (the JSON path, or a bound design whose columns are
// not all direct): the trade-unit fields added when the plan wants them (for a feasible row,
// `length_m` its bat's length; nullopt when they are there already), index and parameters
// added, objectives read, then written in the format.
void AddJsonRow(const RunPlan& plan, std::uint64_t i, const std::vector<double>& point, Json row,
                std::optional<double> length_m, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  if (plan.json_twins && length_m) AddImperialToRow(&row, *length_m);
  Json values = Json::object();
  for (std::size_t k = 0; k < sweep.parameters.size(); ++k)
    values[sweep.parameters[k].path] = point[k];
  row["index"] = i;
  row["parameters"] = std::move(values);
  if (!row["feasible"].get<bool>()) ++out->failed;
  if (!sweep.objectives.empty()) {
    std::vector<double> v;
    for (const auto& objective : sweep.objectives) {
      const Json* value = FindAt(row, objective.tokens);
      v.push_back(value != nullptr && value->is_number() ? value->get<double>() : std::nan(""));
    }
    out->objective_values.push_back(std::move(v));
    out->indices.push_back(i);
  }
  const std::vector<ExploreColumn>& columns = *plan.columns;
  switch (plan.format) {
    case RowFormat::kCsv:
      AppendCsvRow(row, columns, &out->rows.text);
      break;
    case RowFormat::kNdjson:
      out->rows.text += DumpRow(columns.empty() ? row : ProjectRow(row, columns));
      out->rows.text += '\n';
      break;
    case RowFormat::kJson:
      out->rows.rows.push_back(columns.empty() ? std::move(row) : ProjectRow(row, columns));
      break;
  }
}

// The full row of feasible bound design `i` from the worker's template, its leaves set from
// `outcome`: the bytes of RenderDesignRow's row (explore_engine_test checks it). False, with
// nothing written, when a leaf's value is not of the template's kind (render it instead).
bool FillTemplate(const RunPlan& plan, std::uint64_t i, const std::vector<double>& point,
                  const DirectView& view, Worker* worker, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  const core::ImperialProperties imperial = core::ToImperial(*view.properties, view.length_m);
  if (plan.format == RowFormat::kNdjson && sweep.objectives.empty() &&
      !worker->template_pieces.empty()) {
    // DumpRow's text of the template with its leaves set, written leaf by leaf.
    std::string& text = out->rows.text;
    const std::size_t start = text.size();
    worker->template_memos.resize(worker->leaves.size());
    for (const auto& [before, k] : worker->template_pieces) {
      text.append(before);
      const DirectValue value = ReadDirect(worker->leaves[k].second, i, point, view, imperial);
      if (!LeafTakes(value, *worker->leaves[k].first)) {
        text.resize(start);
        return false;
      }
      AppendJsonValue(value, &worker->template_memos[k], &text);
    }
    text.append(worker->template_tail);
    text.push_back('\n');
    return true;
  }
  for (auto& [node, accessor] : worker->leaves) {
    if (!SetLeaf(ReadDirect(accessor, i, point, view, imperial), node)) {
      // The template is left part-filled: the next design overwrites every leaf again.
      return false;
    }
  }
  const Json& row = *worker->row_template;
  if (!sweep.objectives.empty()) {
    std::vector<double> v;
    for (const auto& objective : sweep.objectives) {
      const Json* value = FindAt(row, objective.tokens);
      v.push_back(value != nullptr && value->is_number() ? value->get<double>() : std::nan(""));
    }
    out->objective_values.push_back(std::move(v));
    out->indices.push_back(i);
  }
  if (plan.format == RowFormat::kNdjson) {
    out->rows.text += DumpRow(row);
    out->rows.text += '\n';
  } else {
    out->rows.rows.push_back(row);
  }
  return true;
}

// The most characters of a direct CSV row written in a local buffer (WriteDirectRow), where a
// field has room for 32 characters and its separator.
constexpr std::size_t kCsvRowBytes = 512;
static_assert(sizeof(CsvNumberMemo::text) <= 32, "a number's text copied whole into its room");

// The CSV row of WriteDirectRow. Flattened: ReadDirect's switch and the value it returns,
// inlined, cost a row's two columns about as much as the calls did.
[[gnu::flatten]] void WriteDirectCsvRow(const RunPlan& plan, std::uint64_t i,
                                        const std::vector<double>& point, const DirectView& view,
                                        const core::ImperialProperties& imperial, Worker* worker,
                                        BlockResult* out) {
  const std::size_t n = plan.column_accessors.size();
  worker->csv_memos.resize(n);
  // The row in a local buffer, appended at once, when it fits: a field takes at most 32
  // characters and a separator unless it is a string (CsvRowWriter then writes the row).
  char row[kCsvRowBytes];
  std::size_t size = 0;
  bool local = n * 33 <= sizeof(row);
  for (std::size_t c = 0; local && c < n; ++c) {
    const DirectValue value = ReadDirect(plan.column_accessors[c], i, point, view, imperial);
    if (c > 0) row[size++] = ',';
    switch (value.kind) {
      case DirectValue::kMissing:
        break;
      case DirectValue::kNumber: {
        // The memo's whole buffer (a fixed-size copy; the field's room is 32 characters),
        // of which its text's characters count.
        CsvNumberMemo& memo = worker->csv_memos[c];
        const std::size_t length = CsvNumberText(value.number, &memo).size();
        std::memcpy(row + size, memo.text, sizeof(memo.text));
        size += length;
        break;
      }
      case DirectValue::kUnsigned:
        size = static_cast<std::size_t>(
            std::to_chars(row + size, row + size + 32, value.count).ptr - row);
        break;
      case DirectValue::kBool:
        std::memcpy(row + size, value.flag ? "true" : "false", value.flag ? 4 : 5);
        size += value.flag ? 4 : 5;
        break;
      case DirectValue::kString:
        local = false;
        break;
    }
  }
  if (local) {
    row[size++] = '\n';
    out->rows.text.append(row, size);
    return;
  }
  CsvRowWriter writer(&out->rows.text);
  for (std::size_t c = 0; c < n; ++c) {
    const DirectValue value = ReadDirect(plan.column_accessors[c], i, point, view, imperial);
    if (value.kind == DirectValue::kNumber) {
      writer.Number(value.number, &worker->csv_memos[c]);
    } else {
      WriteCsv(value, &writer);
    }
  }
  writer.EndRow();
}

// The row of feasible bound design `i` from its direct columns (plan.direct).
void WriteDirectRow(const RunPlan& plan, std::uint64_t i, const std::vector<double>& point,
                    const DirectView& view, Worker* worker, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  const core::ImperialProperties imperial = plan.imperial
                                                ? core::ToImperial(*view.properties, view.length_m)
                                                : core::ImperialProperties{};
  if (!sweep.objectives.empty()) {
    std::vector<double> v;
    for (const DirectAccessor& a : plan.objective_accessors) {
      v.push_back(ToObjective(ReadDirect(a, i, point, view, imperial)));
    }
    out->objective_values.push_back(std::move(v));
    out->indices.push_back(i);
  }
  const std::vector<ExploreColumn>& columns = *plan.columns;
  if (plan.format == RowFormat::kCsv) {
    WriteDirectCsvRow(plan, i, point, view, imperial, worker, out);
    return;
  }
  if (plan.format == RowFormat::kNdjson) {
    // The text DumpRow gives the flat object below, written value by value.
    std::string& text = out->rows.text;
    worker->json_memos.resize(columns.size());
    text.push_back('{');
    bool first = true;
    for (const auto& [c, key] : plan.ndjson_keys) {
      if (!first) text.push_back(',');
      first = false;
      text.append(key);
      AppendJsonValue(ReadDirect(plan.column_accessors[c], i, point, view, imperial),
                      &worker->json_memos[c], &text);
    }
    text.append("}\n");
    return;
  }
  Json flat = Json::object();
  for (std::size_t c = 0; c < columns.size(); ++c) {
    flat[columns[c].path] = ToJson(ReadDirect(plan.column_accessors[c], i, point, view, imperial));
  }
  out->rows.rows.push_back(std::move(flat));
}

// Design `i` (the JSON path, or bound) into *out.
void EvaluateOne(const RunPlan& plan, std::uint64_t i, Worker* worker, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  if (!worker->designs) worker->designs.emplace(*sweep.designs);
  const std::vector<double>& point = worker->designs->Design(i);
  if (sweep.binder) {
    if (!worker->scene) worker->scene = sweep.binder->base_scene();
    if (sweep.binder->Bind(point, &*worker->scene)) {
      // Full rows go the lean path once a full evaluation has made the worker's template.
      if (plan.lean && (plan.direct || worker->row_template)) {
        if (!worker->lean) {
          worker->lean.emplace(sweep.options, *worker->scene, sweep.binder->changes());
          worker->lean_model_name = core::CollisionModelName(worker->lean->model());
        }
        core::ClosedFormDesign& design = worker->lean_design;
        if (worker->lean->Evaluate(*worker->scene, &design)) {
          const DirectView view = ViewOf(design, worker->lean_model_name);
          bool written = true;
          if (plan.direct) {
            WriteDirectRow(plan, i, point, view, worker, out);
          } else {
            written = FillTemplate(plan, i, point, view, worker, out);
          }
          if (written) {
            const core::Placement at = design.max_exit_speed.placement;
            out->beyond_tip += at == core::Placement::kBeyondTip;
            out->before_knob += at == core::Placement::kBeforeKnob;
            return;
          }
        }
        // Not vouched for by the lean path (or not a row of the template): evaluated in full.
      }
      DesignOutcome& outcome = worker->outcome;
      if (!worker->evaluator) worker->evaluator.emplace(sweep.options);
      ComputeDesign(*worker->scene, sweep.outputs, &*worker->evaluator, &outcome);
      if (outcome.feasible && outcome.result.max_exit_speed) {
        const core::Placement at = outcome.result.max_exit_speed->placement;
        out->beyond_tip += at == core::Placement::kBeyondTip;
        out->before_knob += at == core::Placement::kBeforeKnob;
      }
      if (outcome.feasible && !plan.direct && plan.columns->empty() &&
          plan.format != RowFormat::kCsv) {
        if (worker->row_template && FillTemplate(plan, i, point, ViewOf(outcome), worker, out)) {
          return;
        }
        if (!worker->template_tried) {
          // The first feasible row: rendered, and kept as the template when it can be.
          worker->template_tried = true;
          Json row = RenderDesignRow(outcome, sweep.outputs);
          if (plan.json_twins) AddImperialToRow(&row, outcome.result.length_m);
          Json values = Json::object();
          for (std::size_t k = 0; k < sweep.parameters.size(); ++k) {
            values[sweep.parameters[k].path] = point[k];
          }
          row["index"] = i;
          row["parameters"] = std::move(values);
          std::vector<std::string> tokens;
          worker->row_template = row;
          if (!CollectLeaves(&*worker->row_template, &tokens, sweep, &worker->leaves)) {
            worker->row_template.reset();
            worker->leaves.clear();
          } else if (std::string tail; CompileTemplateText(*worker->row_template, worker->leaves,
                                                           &worker->template_pieces, &tail)) {
            worker->template_tail = std::move(tail);
          } else {
            worker->template_pieces.clear();
          }
          AddJsonRow(plan, i, point, std::move(row), std::nullopt, out);
          return;
        }
      }
      if (outcome.feasible && !plan.direct) {
        AddJsonRow(plan, i, point, RenderDesignRow(outcome, sweep.outputs), outcome.result.length_m,
                   out);
        return;
      }
      if (outcome.feasible) {
        WriteDirectRow(plan, i, point, ViewOf(outcome), worker, out);
        return;
      }
    }
    // A bound design that fails a check or a model: the JSON path says why, as a single
    // request would.
  }
  Json design = sweep.base;
  for (std::size_t k = 0; k < sweep.parameters.size(); ++k) {
    const SweepParameter& parameter = sweep.parameters[k];
    for (std::size_t t = 0; t < parameter.targets.size(); ++t) {
      SetNumberAtPath(&design, parameter.targets[t], parameter.TargetValue(t, point[k]), nullptr);
    }
  }
  DesignRow evaluated = EvaluateDesign(design, sweep.outputs, sweep.options, sweep.limits);
  const Json& row = evaluated.row;
  if (const Json* at = FindAt(row, {"max_exit_speed", "placement"}); at != nullptr) {
    out->beyond_tip += *at == core::PlacementName(core::Placement::kBeyondTip);
    out->before_knob += *at == core::PlacementName(core::Placement::kBeforeKnob);
  }
  AddJsonRow(plan, i, point, std::move(evaluated.row), evaluated.length_m, out);
}

// The most designs in a block, and the time a block aims at: blocks of fast designs are
// large (few hand-overs), those of slow ones short, so a streamed answer gets its first rows
// within about kBlockTargetS whatever a design costs.
constexpr std::uint64_t kMaxBlockDesigns = 256;
constexpr double kBlockTargetS = 0.01;
// A block's text stays under malloc's mmap threshold (128 KiB), so that its buffer is reused
// from the heap rather than mapped and faulted in anew each time.
constexpr double kBlockTargetBytes = 64 * 1024;

// What the last block measured per design (negative: nothing measured yet).
struct BlockCost {
  double seconds = -1.0;
  double bytes = -1.0;
};

// How many designs the next block takes (one before anything is measured).
std::uint64_t BlockDesigns(const BlockCost& cost) {
  if (!(cost.seconds >= 0.0)) return 1;
  double n = static_cast<double>(kMaxBlockDesigns);
  if (cost.seconds > 0.0) n = std::min(n, kBlockTargetS / cost.seconds);
  if (cost.bytes > 0.0) n = std::min(n, kBlockTargetBytes / cost.bytes);
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(n));
}

// The shard's designs [first, first + count) into *out; what a design cost in *cost.
void EvaluateBlock(const RunPlan& plan, std::uint64_t first, std::uint64_t count,
                   core::Progress* progress, Worker* worker, BlockResult* out, BlockCost* cost) {
  const auto start = std::chrono::steady_clock::now();
  if (plan.format != RowFormat::kJson && cost->bytes > 0.0) {
    out->rows.text.reserve(
        static_cast<std::size_t>(cost->bytes * static_cast<double>(count) * 1.25));
  }
  for (std::uint64_t k = first; k < first + count; ++k) {
    if (core::IsCancelled(progress)) {
      out->cancelled = true;
      return;
    }
    // An allocation failed since the run started and the memory reserve was spent on it
    // (api/memory_reserve.hpp): stop here, where unwinding has the reserve's memory, rather
    // than at an allocation inside the json code.
    if (MemoryFailures() != plan.memory_failures) throw std::bad_alloc();
    EvaluateOne(plan, plan.DesignIndex(k), worker, out);
    ++out->rows.count;
  }
  cost->seconds = core::SecondsSince(start) / static_cast<double>(count);
  cost->bytes = static_cast<double>(out->rows.text.size()) / static_cast<double>(count);
}

}  // namespace

// ---- RunSweep --------------------------------------------------------------------------------

SweepOutcome RunSweep(const Sweep& sweep, RowFormat format,
                      const std::vector<ExploreColumn>& columns, core::Progress* progress,
                      const std::function<bool(BlockRows&)>& emit) {
  SweepOutcome outcome;
  if (!RestoreMemoryReserve()) {
    // An earlier allocation failed and its reserve cannot be taken back yet: a sweep now could
    // fail where nothing is left to unwind with (api/memory_reserve.hpp).
    outcome.failed = true;
    outcome.message =
        "the server is low on memory (an allocation failed earlier and the memory "
        "it kept back cannot be taken again yet)";
    return outcome;
  }
  RunPlan plan;
  plan.memory_failures = MemoryFailures();
  plan.sweep = &sweep;
  plan.format = format;
  plan.columns = &columns;
  const core::Shard& shard = sweep.shard;
  const std::uint64_t total = sweep.total;
  plan.in_shard = total / shard.count + (shard.index < total % shard.count ? 1 : 0);
  // The trade-unit fields: in full rows with report_units imperial; in the JSON rows that
  // columns and objectives read when one of them names such a field (not in the SI row).
  plan.row_twins = sweep.imperial && columns.empty();
  plan.json_twins = plan.row_twins;
  if (!columns.empty()) {
    std::vector<std::string> parameter_paths;
    for (const SweepParameter& parameter : sweep.parameters)
      parameter_paths.push_back(parameter.path);
    const Json si_shape = RowShape(parameter_paths, sweep.outputs);
    for (const ExploreColumn& column : columns) {
      plan.json_twins = plan.json_twins || FindAt(si_shape, column.tokens) == nullptr;
    }
    for (const ParetoObjective& objective : sweep.objectives) {
      plan.json_twins = plan.json_twins || FindAt(si_shape, objective.tokens) == nullptr;
    }
  }
  // Direct rows: every column and objective is read from the outcome (a full row is JSON).
  if (sweep.binder && !columns.empty()) {
    plan.direct = true;
    for (const ExploreColumn& column : columns) {
      const auto a = CompileAccessor(column.tokens, sweep.parameters, sweep.outputs);
      if (!a) plan.direct = false;
      if (a) plan.column_accessors.push_back(*a);
    }
    for (const ParetoObjective& objective : sweep.objectives) {
      const auto a = CompileAccessor(objective.tokens, sweep.parameters, sweep.outputs);
      if (!a) plan.direct = false;
      if (a) plan.objective_accessors.push_back(*a);
    }
    plan.imperial = NeedsImperial(plan.column_accessors) || NeedsImperial(plan.objective_accessors);
  }
  if (plan.direct && format == RowFormat::kNdjson) {
    // A JSON object's keys are in std::map order, each once (the last value set wins; a path's
    // values are the same).
    std::vector<std::size_t> order(columns.size());
    for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
    std::stable_sort(order.begin(), order.end(), [&columns](std::size_t a, std::size_t b) {
      return columns[a].path < columns[b].path;
    });
    for (const std::size_t c : order) {
      if (!plan.ndjson_keys.empty() &&
          columns[plan.ndjson_keys.back().first].path == columns[c].path) {
        continue;
      }
      plan.ndjson_keys.emplace_back(c, DumpRow(Json(columns[c].path)) + ":");
    }
  }
  // The lean path reads no collision efficiency (the outputs do not ask for it) and no centre
  // of percussion (an output it does not take).
  plan.lean = (plan.direct || (sweep.binder && columns.empty() && format != RowFormat::kCsv)) &&
              !sweep.outputs.collision_efficiency &&
              core::ClosedFormDesigns::Applies(sweep.options, sweep.binder->base_scene());

  std::vector<std::vector<double>> objective_values;
  std::vector<std::uint64_t> indices;
  std::vector<core::Sense> senses;
  for (const auto& o : sweep.objectives) senses.push_back(o.sense);
  // The Pareto front kept as it grows: a design dominated by the designs so far is dominated
  // in the whole sweep, and a design on the whole front is on the front of any set holding it,
  // so the values are cut to their front whenever they have grown 8-fold since the last cut
  // (memory of the order of the front, not of the sweep; the same front, in design order). A
  // cut costs O(values x front), so cutting more often would cost more time than one cut at
  // the end.
  std::size_t cut_at = std::max<std::size_t>(1, sweep.pareto_cut_min);
  const auto cut_to_front = [&] {
    std::vector<std::vector<double>> kept_values;
    std::vector<std::uint64_t> kept_indices;
    for (const std::size_t k : core::ParetoFront(objective_values, senses)) {
      kept_values.push_back(std::move(objective_values[k]));
      kept_indices.push_back(indices[k]);
    }
    objective_values = std::move(kept_values);
    indices = std::move(kept_indices);
  };
  std::uint64_t evaluated = 0, failed = 0, beyond_tip = 0, before_knob = 0;
  // Takes a finished block: false when the sweep ends here (cancelled or stopped).
  const auto take = [&](BlockResult& block) {
    if (block.cancelled || core::IsCancelled(progress)) {
      outcome.cancelled = true;
      outcome.message = "the sweep was cancelled after " + std::to_string(evaluated) + " designs";
      return false;
    }
    failed += block.failed;
    beyond_tip += block.beyond_tip;
    before_knob += block.before_knob;
    for (auto& v : block.objective_values) objective_values.push_back(std::move(v));
    indices.insert(indices.end(), block.indices.begin(), block.indices.end());
    if (!senses.empty() && objective_values.size() >= cut_at) {
      cut_to_front();
      cut_at = std::max(sweep.pareto_cut_min, 8 * objective_values.size());
    }
    if (!emit(block.rows)) {
      outcome.stopped = true;
      return false;
    }
    evaluated += block.rows.count;
    if (progress != nullptr && plan.in_shard > 0) {
      progress->Report(static_cast<double>(evaluated) / static_cast<double>(plan.in_shard));
    }
    return true;
  };

  // Threads beyond this one come from the budget, without waiting for it.
  const std::uint64_t n = plan.in_shard;
  int helpers = static_cast<int>(std::min<std::uint64_t>(
      static_cast<std::uint64_t>(std::max(1, sweep.threads) - 1), n > 0 ? n - 1 : 0));
  if (helpers > 0 && sweep.budget != nullptr) helpers = sweep.budget->TryTake(helpers);
  // An exception (std::bad_alloc) in any thread of the sweep ends it as a failure: in a
  // helper std::thread it would otherwise reach std::terminate and end the process.
  const auto fail = [&](const std::exception_ptr& caught) {
    outcome = SweepOutcome{};
    outcome.failed = true;
    std::string what = "an unknown exception";
    try {
      std::rethrow_exception(caught);
    } catch (const std::bad_alloc&) {
      what = "out of memory (std::bad_alloc)";
    } catch (const std::system_error& e) {
      what = std::string("a system error (") + e.code().message() + ")";
    } catch (...) {
    }
    outcome.message = "the sweep failed after " + std::to_string(evaluated) + " designs: " + what;
    return outcome;
  };
  if (helpers <= 0) {
    try {
      Worker worker;
      BlockCost cost;
      for (std::uint64_t k = 0; k < n;) {
        BlockResult block;
        const std::uint64_t count = std::min(n - k, BlockDesigns(cost));
        EvaluateBlock(plan, k, count, progress, &worker, &block, &cost);
        k += count;
        if (!take(block)) return outcome;
      }
    } catch (...) {
      return fail(std::current_exception());
    }
  } else {
    // Workers (this thread among them) take the next designs as a block; this thread hands
    // the blocks on in design order. At most `window` blocks are finished or being evaluated
    // beyond the one handed on next.
    std::mutex mutex;
    std::condition_variable ready, room;
    std::map<std::uint64_t, BlockResult> done;  // by first design
    std::uint64_t next = 0;                     // the first design not taken yet
    std::uint64_t in_flight = 0;                // blocks being evaluated
    BlockCost cost;                             // what a design of the last block cost
    bool stop = false;
    std::exception_ptr failure;  // the first exception of any thread (then stop)
    const std::uint64_t window = 4 * static_cast<std::uint64_t>(helpers + 1);
    const auto has_room = [&] { return next < n && done.size() + in_flight < window; };
    // Takes the next block under the lock: [*first, *first + *count).
    const auto claim = [&](std::uint64_t* first, std::uint64_t* count) {
      *first = next;
      *count = std::min(n - next, BlockDesigns(cost));
      next += *count;
      ++in_flight;
    };
    // Evaluates a claimed block outside the lock, then files it under the lock.
    const auto evaluate = [&](std::unique_lock<std::mutex>& lock, std::uint64_t first,
                              std::uint64_t count, Worker* worker) {
      BlockResult block;
      BlockCost measured = cost;
      lock.unlock();
      EvaluateBlock(plan, first, count, progress, worker, &block, &measured);
      lock.lock();
      cost = measured;
      done.emplace(first, std::move(block));
      --in_flight;
    };
    // Records the first exception of any thread and stops every thread (`lock` may or may not
    // hold the mutex: an exception inside `evaluate` leaves it released).
    const auto record_failure = [&](std::unique_lock<std::mutex>& lock) {
      if (!lock.owns_lock()) lock.lock();
      if (!failure) failure = std::current_exception();
      stop = true;
      lock.unlock();
      ready.notify_all();
      room.notify_all();
    };
    const auto work = [&]() {
      std::unique_lock<std::mutex> lock(mutex, std::defer_lock);
      try {
        Worker worker;
        lock.lock();
        for (;;) {
          room.wait(lock, [&] { return stop || next >= n || has_room(); });
          if (stop || next >= n) return;
          std::uint64_t first = 0, count = 0;
          claim(&first, &count);
          evaluate(lock, first, count, &worker);
          ready.notify_all();
        }
      } catch (...) {
        record_failure(lock);
      }
    };
    std::vector<std::thread> threads;
    bool ok = true;
    try {
      threads.reserve(static_cast<std::size_t>(helpers));
      for (int t = 0; t < helpers; ++t) threads.emplace_back(work);
    } catch (...) {
      // A thread that could not start (std::system_error: no memory for its stack): the
      // threads that did start, and this one, do the work; the rest go back to the budget.
    }
    if (sweep.budget != nullptr) sweep.budget->Give(helpers - static_cast<int>(threads.size()));
    std::uint64_t handed = 0;  // the first design not handed on yet
    {
      std::unique_lock<std::mutex> lock(mutex, std::defer_lock);
      try {
        Worker own_worker;
        while (ok && handed < n) {
          BlockResult block;
          lock.lock();
          ready.wait(lock, [&] { return failure || done.count(handed) > 0 || has_room(); });
          if (failure) {
            lock.unlock();
            break;
          }
          if (done.count(handed) == 0) {
            // The next block is not finished and there is room: this thread evaluates one too.
            std::uint64_t first = 0, count = 0;
            claim(&first, &count);
            evaluate(lock, first, count, &own_worker);
            lock.unlock();
            continue;
          }
          block = std::move(done[handed]);
          done.erase(handed);
          // A cancelled block is short: what follows it is never handed on.
          handed += block.cancelled ? n : block.rows.count;
          lock.unlock();
          room.notify_all();
          ok = take(block);
        }
      } catch (...) {
        record_failure(lock);
      }
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      stop = true;
    }
    room.notify_all();
    for (std::thread& t : threads) t.join();
    if (sweep.budget != nullptr) sweep.budget->Give(static_cast<int>(threads.size()));
    if (failure) return fail(failure);
    if (!ok) return outcome;
  }

  Json summary{{"designs_total", total},
               {"designs_in_shard", evaluated},
               {"failed", failed},
               {"sampling", core::SamplingMethodName(sweep.plan.method)},
               {"seed", sweep.plan.seed},
               {"shard", {{"index", shard.index}, {"count", shard.count}}},
               {"timing_s", core::SecondsSince(sweep.start)}};
  if (!sweep.objectives.empty()) {
    cut_to_front();
    Json front = indices;
    summary["pareto_front"] = std::move(front);
    summary["pareto_objectives"] = ObjectivesToJson(sweep.objectives);  // for explore-merge
    summary["pareto_scope"] = "the rows of this response (this shard)";
  }
  if (std::any_of(sweep.outputs.scene.begin(), sweep.outputs.scene.end(), [](auto o) {
        return o == core::SceneOutput::kMaxExitSpeed || o == core::SceneOutput::kSweetZone ||
               o == core::SceneOutput::kExitSpeedCurve;
      })) {
    summary["exit_speed_model"] = sweep.exit_speed_model;
    summary["model_reason"] = sweep.model_reason;
  }
  AddEndPlacements(beyond_tip, before_knob, &summary);
  if (sweep.imperial) summary["report_units"] = "imperial";  // explore-merge keeps it
  summary["provenance"] = sweep.provenance;
  outcome.summary = std::move(summary);
  return outcome;
}

}  // namespace sweetspot::api
