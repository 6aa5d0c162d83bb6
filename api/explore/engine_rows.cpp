// A sweep design's row: evaluated by the lean path or in full, written as JSON, into the
// worker's row template, or directly from the outcome (engine_internal.hpp; the blocks of them
// that RunSweep runs on threads, engine.cpp).
#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>
#include <string_view>
#include <utility>

#include "api/bat_json.hpp"
#include "api/explore/engine_internal.hpp"
#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/numerics/timing_book.hpp"

namespace sweetspot::api::explore_run {
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

}  // namespace

std::uint64_t BlockDesigns(const BlockCost& cost) {
  if (!(cost.seconds >= 0.0)) return 1;
  double n = static_cast<double>(kMaxBlockDesigns);
  if (cost.seconds > 0.0) n = std::min(n, kBlockTargetS / cost.seconds);
  if (cost.bytes > 0.0) n = std::min(n, kBlockTargetBytes / cost.bytes);
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(n));
}

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

}  // namespace sweetspot::api::explore_run
