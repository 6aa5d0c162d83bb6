// The non-template half of the typed-endpoint driver (api/handlers/endpoint.hpp).
#include "api/handlers/endpoint.hpp"

#include "api/scene_json.hpp"

namespace sweetspot::api {

ProvenanceInputs BodyOptions(const nlohmann::json& body, std::optional<unsigned long long> seed) {
  ProvenanceInputs inputs;
  if (body.contains("options")) inputs.options = body["options"];
  inputs.seed = seed;
  return inputs;
}

namespace endpoint_detail {

Response Answer(nlohmann::json out, const core::Summary* summary,
                const std::optional<ProvenanceInputs>& provenance, const nlohmann::json& body,
                std::chrono::steady_clock::time_point start, const std::optional<Unmet>& unmet) {
  if (summary != nullptr) out["summary"] = SummaryToJson(*summary);
  if (provenance) out["provenance"] = Provenance(body, provenance->options, provenance->seed);
  out["timing_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!unmet) return {200, std::move(out)};
  return {422,
          {{"code", ErrorCodeName(unmet->code)},
           {"message", unmet->message},
           {"field", unmet->field},
           {"closest", std::move(out)}}};
}

void AnswerTail(const core::Summary* summary, const std::optional<ProvenanceInputs>& provenance,
                const nlohmann::json& body, std::chrono::steady_clock::time_point start,
                TextObject& out) {
  if (summary != nullptr) {
    out.Object("summary", [&](TextObject& block) { WriteSummary(*summary, block); });
  }
  if (provenance) {
    out.Object("provenance", [&](TextObject& block) {
      WriteProvenance(body, provenance->options, provenance->seed, block);
    });
  }
  out.Set("timing_s",
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace endpoint_detail
}  // namespace sweetspot::api
