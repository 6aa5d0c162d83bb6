#include "api/explore/shards.hpp"

#include <algorithm>
#include <memory>
#include <sstream>

#include "api/explore/merge_stream.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

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
  // The streamed merge over the texts (api/explore/merge_stream.hpp): one implementation of
  // the checks and the summary.
  std::vector<std::string> names;
  for (const ShardOutput& shard : shards) names.push_back(shard.name);
  MergedSweep out;
  const StreamedMerge merged = MergeShardStreams(
      names,
      [&shards](std::size_t k) -> std::unique_ptr<std::istream> {
        return std::make_unique<std::istringstream>(shards[k].text);
      },
      [&out](std::string_view bytes) {
        out.ndjson.append(bytes.data(), bytes.size());
        return true;
      });
  out.ok = merged.ok();
  out.error = merged.error;
  if (!out.ok) out.ndjson.clear();
  return out;
}

}  // namespace sweetspot::api
