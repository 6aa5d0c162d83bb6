#include "api/explore/merge_stream.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>

#include "api/explore/merge_reader.hpp"
#include "api/explore/shards.hpp"
#include "core/explore/sampling.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;
using merge_detail::OutputBuffer;
using merge_detail::RecordReader;
using merge_detail::Stop;

std::string Dump(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// What an NDJSON line is, read without building it (the rows are most of the bytes): a
// top-level object, its unsigned "index", whether it has "error" or "summary" keys.
class LineShape : public nlohmann::json_sax<Json> {
 public:
  bool object = false;
  bool has_index = false;
  std::uint64_t index = 0;
  bool has_error = false;
  bool has_summary = false;

  bool null() override { return Value(); }
  bool boolean(bool) override { return Value(); }
  bool number_integer(number_integer_t) override { return Value(); }
  bool number_unsigned(number_unsigned_t value) override {
    if (depth_ == 1 && index_key_) {
      has_index = true;
      index = value;
    }
    return Value();
  }
  bool number_float(number_float_t, const string_t&) override { return Value(); }
  bool string(string_t&) override { return Value(); }
  bool binary(binary_t&) override { return Value(); }
  bool start_object(std::size_t) override {
    if (depth_ == 0) object = true;
    ++depth_;
    return Value();
  }
  bool end_object() override {
    --depth_;
    return true;
  }
  bool start_array(std::size_t) override {
    ++depth_;
    return Value();
  }
  bool end_array() override {
    --depth_;
    return true;
  }
  bool key(string_t& key) override {
    if (depth_ == 1) {
      index_key_ = key == "index";
      has_error = has_error || key == "error";
      has_summary = has_summary || key == "summary";
    }
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  bool Value() {
    index_key_ = false;
    return true;
  }
  int depth_ = 0;
  bool index_key_ = false;
};

// One NDJSON shard as its first reading found it.
struct NdjsonScan {
  std::string name;
  merge_detail::IndexRun run;  // the rows' indices
  Json first_row;              // where the objectives' paths are checked
  Json summary;
};

// The first reading of an NDJSON shard: every line checked, the summary kept. "" when it
// reads as a finished shard.
std::string ScanNdjson(RecordReader* reader, NdjsonScan* scan) {
  const std::string who = scan->name + ": ";
  std::string line;
  bool cut = false, have_summary = false;
  while (reader->Line(&line, &cut)) {
    const std::string at = who + "line " + std::to_string(reader->line_number());
    if (line.empty()) continue;
    if (have_summary) return at + " follows the summary line";
    LineShape shape;
    if (!Json::sax_parse(line, &shape) || !shape.object) return at + " is not a JSON object";
    if (shape.has_index) {  // a row (a failed design's row has an "error" too)
      if (scan->run.rows == 0) scan->first_row = Json::parse(line, nullptr, false);
      const std::string why = scan->run.Take(shape.index);
      if (!why.empty()) return at + ": " + why;
    } else if (shape.has_error) {
      const Json value = Json::parse(line, nullptr, false);
      return at + " is an error: the shard did not finish (" + Dump(value["error"]) + ")";
    } else if (shape.has_summary) {
      scan->summary = Json::parse(line, nullptr, false)["summary"];
      have_summary = true;
    } else {
      return at + " is neither a row (with an index) nor the summary";
    }
  }
  if (!have_summary || !scan->summary.is_object()) {
    return who +
           "has no summary line: the shard did not finish, or this is not "
           "the NDJSON output of /v1/explore";
  }
  return "";
}

// The summary fields every shard of one sweep shares.
struct SweepIdentity {
  Json provenance;
  std::uint64_t total = 0;
  std::uint64_t count = 0;
  Json sampling, seed, objectives;
  Json exit_speed_model, model_reason;  // null when the sweep needs no exit-speed model
  Json report_units;                    // "imperial", or null (SI rows)
};

// What the second reading needs, and the summary's sums.
struct NdjsonPlan {
  SweepIdentity sweep;
  std::vector<std::size_t> shard_file;             // shard s is names[shard_file[s]]
  std::vector<std::vector<std::uint64_t>> fronts;  // each shard's Pareto front (indices)
  std::vector<ParetoObjective> objectives;
  std::uint64_t failed = 0, beyond_tip = 0, before_knob = 0;
  double timing_s = 0.0;
};

// Reads a shard's identity from its summary (throws on a field of the wrong type).
std::string ReadIdentity(const NdjsonScan& scan, SweepIdentity* id, std::uint64_t* index) {
  const Json& s = scan.summary;
  if (!s.contains("shard") || !s["shard"].contains("index") || !s["shard"].contains("count") ||
      !s.contains("designs_total") || !s.contains("provenance")) {
    return scan.name + ": its summary lacks shard, designs_total or provenance";
  }
  id->provenance = s["provenance"];
  id->total = s["designs_total"].get<std::uint64_t>();
  id->count = s["shard"]["count"].get<std::uint64_t>();
  id->sampling = s.value("sampling", Json());
  id->seed = s.value("seed", Json());
  id->objectives = s.value("pareto_objectives", Json());
  id->exit_speed_model = s.value("exit_speed_model", Json());
  id->model_reason = s.value("model_reason", Json());
  id->report_units = s.value("report_units", Json());
  *index = s["shard"]["index"].get<std::uint64_t>();
  if (id->count == 0 || *index >= id->count) {
    return scan.name + ": its summary's shard " + std::to_string(*index) + " of " +
           std::to_string(id->count) + " is not a shard (0 <= index < count)";
  }
  return "";
}

// "" when `id` is the first shard's sweep, else why not.
std::string SameSweep(const std::string& who, const SweepIdentity& id, const std::string& first_name,
                      const SweepIdentity& first) {
  if (id.provenance != first.provenance) {
    return who + "belongs to another sweep: its provenance (input hash " +
           Dump(id.provenance.value("input_hash", Json())) + ") differs from " + first_name +
           "'s (" + Dump(first.provenance.value("input_hash", Json())) + ")";
  }
  if (id.count != first.count || id.total != first.total || id.sampling != first.sampling ||
      id.seed != first.seed || id.objectives != first.objectives) {
    return who + "has shard count " + std::to_string(id.count) + " and " +
           std::to_string(id.total) + " designs, " + first_name + " has " +
           std::to_string(first.count) + " and " + std::to_string(first.total);
  }
  if (id.report_units != first.report_units) {
    // One sweep's rows in one set of units: a merge of SI and imperial rows would have
    // fields in some rows only.
    const auto units = [](const Json& u) { return u.is_null() ? std::string("\"si\"") : Dump(u); };
    return who + "has report_units " + units(id.report_units) + ", " + first_name + " has " +
           units(first.report_units) + ": run every shard with the same";
  }
  return "";
}

// "" when the shard's rows are exactly its designs (i mod count = index, each once).
std::string CheckRows(const std::string& who, const NdjsonScan& scan, std::uint64_t index,
                      const SweepIdentity& id) {
  const std::uint64_t expected = id.total / id.count + (index < id.total % id.count ? 1 : 0);
  const merge_detail::IndexRun& run = scan.run;
  if (run.rows != expected) {
    return who + "has " + std::to_string(run.rows) + " rows; shard " + std::to_string(index) +
           " of " + std::to_string(id.count) + " has " + std::to_string(expected);
  }
  const auto stray = [&](std::uint64_t i) {
    return who + "row index " + std::to_string(i) + " does not belong to shard " +
           std::to_string(index) + " of " + std::to_string(id.count);
  };
  if (run.rows >= 1 && run.first != index) return stray(run.first);
  if (run.rows >= 2 && run.step != id.count) return stray(run.first + run.step);
  return "";
}

// The shard's Pareto front from its summary, checked against the shard and the rows.
std::string ReadFront(const std::string& who, const NdjsonScan& scan, std::uint64_t index,
                      const NdjsonPlan& plan, std::vector<std::uint64_t>* front) {
  const Json& listed = scan.summary.value("pareto_front", Json::array());
  for (const Json& i : listed) {
    const bool number = i.is_number_unsigned();
    const std::uint64_t v = number ? i.get<std::uint64_t>() : 0;
    if (!number || v >= plan.sweep.total || v % plan.sweep.count != index ||
        (!front->empty() && v <= front->back())) {
      return who + "its summary's pareto_front holds " + Dump(i) +
             ", not an increasing index of the shard's rows";
    }
    front->push_back(v);
  }
  if (front->empty() || scan.first_row.value("feasible", true) == false) return "";
  for (const ParetoObjective& o : plan.objectives) {
    if (!scan.first_row.contains(o.output) && FindAt(scan.first_row, o.tokens) == nullptr) {
      return who + "its rows have no " + o.output +
             " (a Pareto objective), so the sweep's front cannot be found: run the shards with "
             "it among the columns";
    }
  }
  return "";
}

std::vector<ParetoObjective> ObjectivesFrom(const Json& listed) {
  std::vector<ParetoObjective> objectives;
  if (!listed.is_array()) return objectives;
  for (const Json& o : listed) {
    ParetoObjective objective;
    objective.output = o.at("output").get<std::string>();
    objective.tokens = ObjectiveTokens(objective.output);
    objective.sense =
        o.at("sense").get<std::string>() == "max" ? core::Sense::kMaximize : core::Sense::kMinimize;
    objectives.push_back(std::move(objective));
  }
  return objectives;
}

// Checks the scanned shards make one complete sweep and plans the second reading.
std::string PlanNdjson(const std::vector<NdjsonScan>& scans, NdjsonPlan* plan) {
  const std::uint64_t unset = UINT64_MAX;
  for (std::size_t f = 0; f < scans.size(); ++f) {
    const NdjsonScan& scan = scans[f];
    const std::string who = scan.name + ": ";
    SweepIdentity id;
    std::uint64_t index = 0;
    if (std::string why = ReadIdentity(scan, &id, &index); !why.empty()) return why;
    if (f == 0) {
      plan->sweep = id;
      plan->shard_file.assign(id.count <= (1u << 24) ? id.count : 0, unset);
      if (plan->shard_file.empty()) return who + "has " + std::to_string(id.count) +
                                           " shards: more than 2^24 cannot be merged";
      plan->fronts.resize(id.count);
      plan->objectives = ObjectivesFrom(id.objectives);
    } else if (std::string why = SameSweep(who, id, scans[0].name, plan->sweep); !why.empty()) {
      return why;
    }
    if (plan->shard_file[index] != unset) {
      return who + "repeats shard " + std::to_string(index) + " of " + std::to_string(id.count);
    }
    plan->shard_file[index] = f;
    if (std::string why = CheckRows(who, scan, index, id); !why.empty()) return why;
    if (std::string why = ReadFront(who, scan, index, *plan, &plan->fronts[index]); !why.empty()) {
      return why;
    }
    const Json& s = scan.summary;
    plan->failed += s.value("failed", std::uint64_t{0});
    if (const auto at_end = s.find("max_exit_speed_at_bat_end"); at_end != s.end()) {
      plan->beyond_tip += at_end->value("beyond_tip", std::uint64_t{0});
      plan->before_knob += at_end->value("before_knob", std::uint64_t{0});
    }
    plan->timing_s += s.value("timing_s", 0.0);
  }
  std::vector<std::uint64_t> missing;
  for (std::uint64_t s = 0; s < plan->shard_file.size(); ++s) {
    if (plan->shard_file[s] == unset) missing.push_back(s);
  }
  if (!missing.empty()) {
    return "the shards are incomplete: " + MissingShardsMessage(missing, plan->sweep.count) +
           " (" + std::to_string(scans.size()) + " of " + std::to_string(plan->sweep.count) +
           " given)";
  }
  return "";
}

// The whole sweep's summary, as the unsharded sweep writes it (api/explore_engine.cpp).
Json MergedSummary(const NdjsonPlan& plan, std::vector<std::uint64_t> front) {
  const SweepIdentity& first = plan.sweep;
  Json summary{{"designs_total", first.total},
               {"designs_in_shard", first.total},
               {"failed", plan.failed},
               {"sampling", first.sampling},
               {"seed", first.seed},
               {"shard", {{"index", 0}, {"count", 1}}},
               {"timing_s", plan.timing_s}};
  if (!plan.objectives.empty()) {
    summary["pareto_front"] = std::move(front);
    summary["pareto_objectives"] = first.objectives;
    summary["pareto_scope"] = "the rows of this response (this shard)";
  }
  if (!first.exit_speed_model.is_null()) {
    summary["exit_speed_model"] = first.exit_speed_model;
    summary["model_reason"] = first.model_reason;
  }
  AddEndPlacements(plan.beyond_tip, plan.before_knob, &summary);
  if (!first.report_units.is_null()) summary["report_units"] = first.report_units;
  summary["provenance"] = first.provenance;
  return summary;
}

// A front row's objective values (a flat row's keys are the objectives' paths).
bool ObjectiveValues(const std::string& line, const std::vector<ParetoObjective>& objectives,
                     std::vector<double>* values) {
  const Json row = Json::parse(line, nullptr, false);
  for (const ParetoObjective& o : objectives) {
    const auto flat = row.find(o.output);
    const Json* value = flat != row.end() ? &*flat : FindAt(row, o.tokens);
    if (value == nullptr || !value->is_number()) return false;
    values->push_back(value->get<double>());
  }
  return true;
}

// The second reading: the rows of the shards in index order, then the summary.
StreamedMerge WriteNdjson(const std::vector<std::string>& names, const ShardOpener& open,
                          const NdjsonPlan& plan, RecordReader::Context context,
                          const MergeSink& sink, const MergeStreamOptions& options,
                          StreamedMerge* out) {
  const std::uint64_t count = plan.sweep.count;
  std::vector<std::unique_ptr<std::istream>> streams(count);
  std::vector<RecordReader> readers;
  readers.reserve(count);
  for (std::uint64_t s = 0; s < count; ++s) {
    streams[s] = open(plan.shard_file[s]);
    if (!streams[s]) return Stop(out, MergeStatus::kUnreadable, "cannot read " + names[plan.shard_file[s]]);
    readers.emplace_back(streams[s].get(), context);
  }
  OutputBuffer output(&sink, options.sink_chunk_bytes);
  std::vector<std::size_t> next_front(count, 0);
  std::vector<std::vector<double>> values;
  std::vector<std::uint64_t> indices;
  std::string line;
  bool cut = false;
  for (std::uint64_t i = 0; i < plan.sweep.total; ++i) {
    const std::uint64_t s = i % count;
    const std::string& name = names[plan.shard_file[s]];
    do {
      if (!readers[s].Line(&line, &cut)) {
        return Stop(out, MergeStatus::kRefused, name + ": changed while it was merged (it ends early)");
      }
    } while (line.empty());
    const std::vector<std::uint64_t>& front = plan.fronts[s];
    if (next_front[s] < front.size() && front[next_front[s]] == i) {
      ++next_front[s];
      values.emplace_back();
      if (!ObjectiveValues(line, plan.objectives, &values.back())) {
        return Stop(out, MergeStatus::kRefused,
                    name + ": row " + std::to_string(i) +
                        " is on the shard's Pareto front but has no number at an objective's "
                        "path: run the shards with the objectives among the columns");
      }
      indices.push_back(i);
    }
    if (!output.Line(line)) return Stop(out, MergeStatus::kOutputFailed, "the output failed");
    ++out->rows;
  }
  std::vector<core::Sense> senses;
  for (const ParetoObjective& o : plan.objectives) senses.push_back(o.sense);
  std::vector<std::uint64_t> front;
  if (!senses.empty()) {
    for (const std::size_t k : core::ParetoFront(values, senses)) front.push_back(indices[k]);
  }
  if (!output.Line(Dump(Json{{"summary", MergedSummary(plan, std::move(front))}})) ||
      !output.Flush()) {
    return Stop(out, MergeStatus::kOutputFailed, "the output failed");
  }
  out->status = MergeStatus::kMerged;
  return *out;
}

StreamedMerge MergeNdjsonShards(const std::vector<std::string>& names, const ShardOpener& open,
                                const MergeSink& sink, RecordReader::Context context,
                                const MergeStreamOptions& options) {
  StreamedMerge out;
  out.format = "ndjson";
  std::vector<NdjsonScan> scans(names.size());
  for (std::size_t f = 0; f < names.size(); ++f) {
    scans[f].name = names[f];
    const std::unique_ptr<std::istream> in = open(f);
    if (!in) return Stop(&out, MergeStatus::kUnreadable, "cannot read " + names[f]);
    RecordReader reader(in.get(), context);
    std::string why = ScanNdjson(&reader, &scans[f]);
    if (reader.failed()) return Stop(&out, MergeStatus::kUnreadable, "cannot read " + names[f]);
    if (!why.empty()) return Stop(&out, MergeStatus::kRefused, std::move(why));
    if (!scans[f].first_row.is_object()) scans[f].first_row = Json::object();  // no rows
  }
  NdjsonPlan plan;
  if (std::string why = PlanNdjson(scans, &plan); !why.empty()) {
    return Stop(&out, MergeStatus::kRefused, std::move(why));
  }
  out.shards = plan.sweep.count;
  scans.clear();
  return WriteNdjson(names, open, plan, context, sink, options, &out);
}

}  // namespace

namespace merge_detail {
StreamedMerge Stop(StreamedMerge* out, MergeStatus status, std::string why) {
  out->status = status;
  out->error = std::move(why);
  return *out;
}
}  // namespace merge_detail

std::string MissingShardsMessage(const std::vector<std::uint64_t>& missing, std::uint64_t count) {
  const std::size_t shown = std::min<std::size_t>(missing.size(), 20);
  std::string list;
  for (std::size_t k = 0; k < shown; ++k) {
    const bool last = k + 1 == shown && shown == missing.size();
    list += (k == 0 ? "" : last ? " and " : ", ") + std::to_string(missing[k]);
  }
  if (shown < missing.size()) list += " and " + std::to_string(missing.size() - shown) + " more";
  return (missing.size() == 1 ? "shard " : "shards ") + list + " of " + std::to_string(count) +
         " missing";
}

StreamedMerge MergeShardStreams(const std::vector<std::string>& names, const ShardOpener& open,
                                const MergeSink& sink, const MergeProgress& progress,
                                const MergeStreamOptions& options) {
  StreamedMerge out;
  try {
    if (names.empty()) return Stop(&out, MergeStatus::kRefused, "no shards given");
    MergeStreamOptions checked = options;
    checked.sink_chunk_bytes = std::max<std::size_t>(1, options.sink_chunk_bytes);
    checked.progress_every_bytes = std::max<std::uint64_t>(1, options.progress_every_bytes);
    std::uint64_t read = 0;
    const RecordReader::Context context{&read, &progress, checked.progress_every_bytes};
    // The first file's first byte tells the format: an NDJSON line is an object.
    const std::unique_ptr<std::istream> first = open(0);
    if (!first) return Stop(&out, MergeStatus::kUnreadable, "cannot read " + names[0]);
    const int c = first->peek();
    if (c != std::char_traits<char>::eof() && c != '{') {
      return merge_detail::MergeCsvShards(names, open, sink, context, checked);
    }
    return MergeNdjsonShards(names, open, sink, context, checked);
  } catch (const nlohmann::json::exception&) {
    // A summary field of the wrong type (a hand-edited file): say so.
    return Stop(&out, MergeStatus::kRefused,
                "a summary field has the wrong type (not an output of /v1/explore?)");
  } catch (const std::exception& e) {
    return Stop(&out, MergeStatus::kUnreadable, std::string("the merge failed: ") + e.what());
  }
}

}  // namespace sweetspot::api
