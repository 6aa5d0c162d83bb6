#include "api/explore/shards.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

std::string Dump(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
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

}  // namespace

std::vector<std::string> ObjectiveTokens(const std::string& output) {
  if (output.rfind("parameters.", 0) == 0) return {"parameters", output.substr(11)};
  std::vector<std::string> tokens;
  std::string token;
  for (const char c : output) {
    if (c == '.') {
      tokens.push_back(token);
      token.clear();
    } else {
      token.push_back(c);
    }
  }
  tokens.push_back(token);
  return tokens;
}

const Json* FindAt(const Json& row, const std::vector<std::string>& tokens) {
  const Json* node = &row;
  for (const std::string& token : tokens) {
    if (node->is_object()) {
      const auto it = node->find(token);
      if (it == node->end()) return nullptr;
      node = &*it;
    } else if (node->is_array()) {
      if (token.empty() || token.size() > 9 ||
          !std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        return nullptr;
      }
      const std::size_t index = std::stoul(token);  // at most 9 digits: cannot overflow
      if (index >= node->size()) return nullptr;
      node = &(*node)[index];
    } else {
      return nullptr;
    }
  }
  return node;
}

Json ObjectivesToJson(const std::vector<ParetoObjective>& objectives) {
  Json list = Json::array();
  for (const ParetoObjective& o : objectives) {
    list.push_back(
        {{"output", o.output}, {"sense", o.sense == core::Sense::kMaximize ? "max" : "min"}});
  }
  return list;
}

void AddEndPlacements(std::uint64_t beyond_tip, std::uint64_t before_knob, Json* summary) {
  if (beyond_tip + before_knob == 0) return;
  (*summary)["max_exit_speed_at_bat_end"] = {{"beyond_tip", beyond_tip},
                                             {"before_knob", before_knob}};
  // As /v1/sweet-spot warns for one design: the sweet spot reported is the bat's end.
  (*summary)["warnings"] =
      Json::array({"max_exit_speed: the maximum of " + std::to_string(beyond_tip) +
                   " designs lies beyond the tip and of " + std::to_string(before_knob) +
                   " before the knob; their sweet spot is the bat's end (each row's "
                   "max_exit_speed.placement says which)"});
}

MergedSweep MergeExploreShards(const std::vector<ShardOutput>& shards) {
  MergedSweep out;
  const auto fail = [&out](const std::string& why) {
    out.ok = false;
    out.error = why;
    return out;
  };
  try {
    if (shards.empty()) return fail("no shards given");
    std::map<std::uint64_t, Json> rows;  // by design index
    std::set<std::uint64_t> shard_indices;
    SweepIdentity first;
    std::uint64_t failed = 0, beyond_tip = 0, before_knob = 0;
    double timing_s = 0.0;
    for (std::size_t f = 0; f < shards.size(); ++f) {
      const ShardOutput& shard = shards[f];
      const std::string who = shard.name + ": ";
      std::istringstream lines(shard.text);
      std::string line;
      std::vector<Json> shard_rows;
      Json summary;
      std::size_t number = 0;
      while (std::getline(lines, line)) {
        ++number;
        if (line.empty()) continue;
        if (!summary.is_null()) {
          return fail(who + "line " + std::to_string(number) + " follows the summary line");
        }
        Json value = Json::parse(line, nullptr, /*allow_exceptions=*/false);
        if (value.is_discarded() || !value.is_object()) {
          return fail(who + "line " + std::to_string(number) + " is not a JSON object");
        }
        if (value.contains("error")) {
          return fail(who + "line " + std::to_string(number) +
                      " is an error: the shard did not finish (" + Dump(value["error"]) + ")");
        }
        if (value.contains("summary")) {
          summary = std::move(value["summary"]);
        } else if (value.contains("index") && value["index"].is_number_unsigned()) {
          shard_rows.push_back(std::move(value));
        } else {
          return fail(who + "line " + std::to_string(number) +
                      " is neither a row (with an index) nor the summary");
        }
      }
      if (summary.is_null() || !summary.is_object()) {
        return fail(who +
                    "has no summary line: the shard did not finish, or this is not "
                    "the NDJSON output of /v1/explore");
      }
      const Json& s = summary;
      if (!s.contains("shard") || !s["shard"].contains("index") || !s["shard"].contains("count") ||
          !s.contains("designs_total") || !s.contains("provenance")) {
        return fail(who + "its summary lacks shard, designs_total or provenance");
      }
      SweepIdentity id;
      id.provenance = s["provenance"];
      id.total = s["designs_total"].get<std::uint64_t>();
      id.count = s["shard"]["count"].get<std::uint64_t>();
      id.sampling = s.value("sampling", Json());
      id.seed = s.value("seed", Json());
      id.objectives = s.value("pareto_objectives", Json());
      id.exit_speed_model = s.value("exit_speed_model", Json());
      id.model_reason = s.value("model_reason", Json());
      id.report_units = s.value("report_units", Json());
      const std::uint64_t index = s["shard"]["index"].get<std::uint64_t>();
      if (f == 0) {
        first = id;
      } else if (id.provenance != first.provenance) {
        return fail(who + "belongs to another sweep: its provenance (input hash " +
                    Dump(id.provenance.value("input_hash", Json())) + ") differs from " +
                    shards[0].name + "'s (" + Dump(first.provenance.value("input_hash", Json())) +
                    ")");
      } else if (id.count != first.count || id.total != first.total ||
                 id.sampling != first.sampling || id.seed != first.seed ||
                 id.objectives != first.objectives) {
        return fail(who + "has shard count " + std::to_string(id.count) + " and " +
                    std::to_string(id.total) + " designs, " + shards[0].name + " has " +
                    std::to_string(first.count) + " and " + std::to_string(first.total));
      } else if (id.report_units != first.report_units) {
        // One sweep's rows in one set of units: a merge of SI and imperial rows would have
        // fields in some rows only.
        const auto units = [](const Json& u) {
          return u.is_null() ? std::string("\"si\"") : Dump(u);
        };
        return fail(who + "has report_units " + units(id.report_units) + ", " + shards[0].name +
                    " has " + units(first.report_units) + ": run every shard with the same");
      }
      if (!shard_indices.insert(index).second) {
        return fail(who + "repeats shard " + std::to_string(index) + " of " +
                    std::to_string(id.count));
      }
      const std::uint64_t expected = id.total / id.count + (index < id.total % id.count ? 1 : 0);
      if (shard_rows.size() != expected) {
        return fail(who + "has " + std::to_string(shard_rows.size()) + " rows; shard " +
                    std::to_string(index) + " of " + std::to_string(id.count) + " has " +
                    std::to_string(expected));
      }
      for (Json& row : shard_rows) {
        const std::uint64_t i = row["index"].get<std::uint64_t>();
        if (i >= id.total || i % id.count != index) {
          return fail(who + "row index " + std::to_string(i) + " does not belong to shard " +
                      std::to_string(index) + " of " + std::to_string(id.count));
        }
        if (!rows.emplace(i, std::move(row)).second) {
          return fail(who + "repeats row index " + std::to_string(i));
        }
      }
      failed += s.value("failed", std::uint64_t{0});
      if (const auto at_end = s.find("max_exit_speed_at_bat_end"); at_end != s.end()) {
        beyond_tip += at_end->value("beyond_tip", std::uint64_t{0});
        before_knob += at_end->value("before_knob", std::uint64_t{0});
      }
      timing_s += s.value("timing_s", 0.0);
    }
    if (shard_indices.size() != first.count) {
      std::string missing;
      for (std::uint64_t i = 0; i < first.count && missing.size() < 200; ++i) {
        if (shard_indices.count(i) == 0)
          missing += (missing.empty() ? "" : ", ") + std::to_string(i);
      }
      return fail("the shards are incomplete: " + std::to_string(shard_indices.size()) + " of " +
                  std::to_string(first.count) + " given; missing shard(s) " + missing);
    }

    Json summary{{"designs_total", first.total},
                 {"designs_in_shard", rows.size()},
                 {"failed", failed},
                 {"sampling", first.sampling},
                 {"seed", first.seed},
                 {"shard", {{"index", 0}, {"count", 1}}},
                 {"timing_s", timing_s}};
    if (first.objectives.is_array() && !first.objectives.empty()) {
      std::vector<ParetoObjective> objectives;
      for (const Json& o : first.objectives) {
        ParetoObjective objective;
        objective.output = o.at("output").get<std::string>();
        objective.tokens = ObjectiveTokens(objective.output);
        objective.sense = o.at("sense").get<std::string>() == "max" ? core::Sense::kMaximize
                                                                    : core::Sense::kMinimize;
        objectives.push_back(std::move(objective));
      }
      std::vector<std::vector<double>> values;
      std::vector<std::uint64_t> indices;
      std::vector<core::Sense> senses;
      for (const ParetoObjective& o : objectives) senses.push_back(o.sense);
      for (const auto& [i, row] : rows) {
        std::vector<double> v;
        for (const ParetoObjective& o : objectives) {
          // A row with "columns" is flat: the objective's path is one key.
          const auto flat = row.find(o.output);
          const Json* value = flat != row.end() ? &*flat : FindAt(row, o.tokens);
          v.push_back(value != nullptr && value->is_number() ? value->get<double>() : std::nan(""));
        }
        values.push_back(std::move(v));
        indices.push_back(i);
      }
      Json front = Json::array();
      for (const std::size_t k : core::ParetoFront(values, senses)) front.push_back(indices[k]);
      summary["pareto_front"] = std::move(front);
      summary["pareto_objectives"] = first.objectives;
      summary["pareto_scope"] = "the rows of this response (this shard)";
    }
    if (!first.exit_speed_model.is_null()) {
      summary["exit_speed_model"] = first.exit_speed_model;
      summary["model_reason"] = first.model_reason;
    }
    AddEndPlacements(beyond_tip, before_knob, &summary);
    if (!first.report_units.is_null()) summary["report_units"] = first.report_units;
    summary["provenance"] = first.provenance;
    std::string text;
    for (const auto& [i, row] : rows) text += Dump(row) + "\n";
    text += Dump(Json{{"summary", std::move(summary)}}) + "\n";
    out.ok = true;
    out.ndjson = std::move(text);
    return out;
  } catch (const std::exception&) {
    // A summary field of the wrong type (a hand-edited file): say so.
    return fail("a summary field has the wrong type (not an output of /v1/explore?)");
  }
}

}  // namespace sweetspot::api
