// POST /v1/sweet-spot, POST /v1/collision and POST /v1/compare: a scene (bat,
// ball, swing, COR) and what is wanted; only the models those outputs need run.
#include <chrono>

#include "api/handlers.hpp"
#include "api/scene_json.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Reads the required bat at `key` into `scene` (and returns its spec). Its mass properties
// are left to core, which computes them once per scene (SceneFailure checks them).
std::optional<BatSpec> ReadBat(ObjectReader& reader, const char* key, const ApiLimits& limits,
                               core::Scene* scene) {
  const Json* value = reader.Get(key);
  if (!reader.ok()) return std::nullopt;
  if (value == nullptr) {
    reader.Missing(key);
    return std::nullopt;
  }
  auto spec = ParseBatGeometry(*value, reader.PathOf(key), limits, reader.error());
  if (spec && scene != nullptr) scene->bat = spec->bat;
  return spec;
}

// Validates the assembled scene with core's rules (e.g. the hands within the bat).
bool CheckScene(const core::Scene& scene, ApiError* error) {
  core::Refusal refusal;
  if (scene.Validate(&refusal)) return true;
  return CoreRefusal(refusal, "", error);
}

}  // namespace

Response HandleSweetSpot(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response failure;
  const auto body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  ApiError error;
  ObjectReader reader(*body, "", &error);
  core::Scene scene;
  core::SceneOptions options;
  const auto spec = ReadBat(reader, "bat", context.limits, &scene);
  if (!spec || !ReadSceneCommon(reader, &scene) || !ReadOutputs(reader, &scene) ||
      !ReadSceneOptions(reader, context.limits, &options) || !reader.Finish() ||
      !CheckScene(scene, &error)) {
    return ToResponse(error);
  }
  options.flexible.modes_cache = context.modes_cache;
  const core::SceneResult result = core::EvaluateScene(scene, options);
  if (!result.summary.IsSolutionUsable()) {
    return SceneFailure(result.summary, result.missing_model, result.mass_properties, "bat",
                        result.refused_field.empty() ? "outputs" : result.refused_field,
                        /*options_object=*/true);
  }
  Json out = SceneResultToJson(result);
  out["properties"] = PropertiesToJson(result.mass_properties, result.length_m);
  out["summary"] = SummaryToJson(result.summary);
  Json provenance_options = body->contains("options") ? (*body)["options"] : Json::object();
  out["provenance"] = Provenance(*body, provenance_options,
                                 options.method == core::SweetSpotMethod::kNlopt
                                     ? std::optional<unsigned long long>(options.nlopt.seed)
                                     : std::nullopt);
  out["timing_s"] = SecondsSince(start);
  return {200, std::move(out)};
}

Response HandleCollision(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response failure;
  const auto body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  ApiError error;
  ObjectReader reader(*body, "", &error);
  core::Scene scene;
  const auto spec = ReadBat(reader, "bat", context.limits, &scene);
  if (!spec || !ReadSceneCommon(reader, &scene)) return ToResponse(error);
  double impact = 0.0;
  reader.Number("impact_from_knob_m", Between(0.0, spec->bat.LengthM()), &impact);
  std::string model_name = "auto";
  reader.OptionalString("model", &model_name,
                        {"auto", "rigid_pivot", "free_bat", "hertz", "flexible"});
  core::CollisionOptions options;
  ClampToLimits(context.limits, &options.hertz);
  ClampToLimits(context.limits, &options.flexible);
  reader.OptionalBool("contact_details", &options.want_contact_details);
  if (const Json* hertz = reader.Get("hertz")) {
    ReadHertzOptions(*hertz, reader.PathOf("hertz"), context.limits, &options.hertz, &error);
  }
  if (const Json* flexible = reader.Get("flexible")) {
    ReadFlexibleOptions(*flexible, reader.PathOf("flexible"), context.limits, &options.flexible,
                        &error);
  }
  options.flexible.modes_cache = context.modes_cache;
  if (!reader.Finish() || !CheckScene(scene, &error)) return ToResponse(error);
  const core::CollisionResult result =
      core::Collide(scene, impact, *core::ParseCollisionModel(model_name), options);
  if (!result.summary.IsSolutionUsable()) {
    return SceneFailure(result.summary, result.missing_model, result.mass_properties, "bat",
                        "model");
  }
  Json out = CollisionResultToJson(result);
  out["summary"] = SummaryToJson(result.summary);
  out["provenance"] = Provenance(*body, Json::object());
  out["timing_s"] = SecondsSince(start);
  return {200, std::move(out)};
}

namespace {

// A /v1/compare row's deltas, variant minus baseline, from the core results
// (both evaluated with the same outputs): the mass properties, and the
// positions and speeds of the sweet spots both have.
Json CompareDeltas(const core::SceneResult& variant, const core::SceneResult& base) {
  const core::MassProperties& v = variant.mass_properties;
  const core::MassProperties& b = base.mass_properties;
  Json deltas{{"mass_kg", v.mass_kg - b.mass_kg},
              {"balance_point_m", v.balance_point_m - b.balance_point_m},
              {"moi_knob_kg_m2", v.moi_knob_kg_m2 - b.moi_knob_kg_m2},
              {"moi_six_inch_kg_m2", v.MoiSixInchKgM2() - b.MoiSixInchKgM2()},
              {"moi_centroid_kg_m2", v.moi_centroid_kg_m2 - b.moi_centroid_kg_m2}};
  if (variant.max_exit_speed && base.max_exit_speed) {
    deltas["max_exit_speed_position_m"] =
        variant.max_exit_speed->position_from_knob_m - base.max_exit_speed->position_from_knob_m;
    deltas["max_exit_speed_mps"] =
        variant.max_exit_speed->exit_speed_mps - base.max_exit_speed->exit_speed_mps;
  }
  if (variant.center_of_percussion && base.center_of_percussion) {
    deltas["center_of_percussion_m"] = variant.center_of_percussion->position_from_knob_m -
                                       base.center_of_percussion->position_from_knob_m;
  }
  return deltas;
}

}  // namespace

Response HandleCompare(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response failure;
  const auto body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  ApiError error;
  ObjectReader reader(*body, "", &error);
  core::Scene scene;
  core::SceneOptions options;
  const auto baseline = ReadBat(reader, "baseline", context.limits, nullptr);
  if (!baseline || !ReadSceneCommon(reader, &scene) || !ReadOutputs(reader, &scene) ||
      !ReadSceneOptions(reader, context.limits, &options)) {
    return ToResponse(error);
  }
  const Json* variants = reader.Get("variants");
  if (reader.ok() && variants == nullptr) reader.Missing("variants");
  if (!reader.ok()) return ToResponse(error);
  if (!variants->is_array()) {
    reader.Fail("variants", "must be an array of {\"name\", \"bat\"}");
    return ToResponse(error);
  }
  if (variants->size() > context.limits.max_variants) {
    reader.Fail("variants",
                "has " + std::to_string(variants->size()) +
                    " variants, over the limit max_variants = " +
                    std::to_string(context.limits.max_variants),
                ErrorCode::kTooBig);
    return ToResponse(error);
  }
  std::vector<std::pair<std::string, BatSpec>> bats = {{"baseline", *baseline}};
  for (std::size_t i = 0; i < variants->size(); ++i) {
    const std::string path = "variants[" + std::to_string(i) + "]";
    ObjectReader variant((*variants)[i], path, &error);
    std::string name;
    variant.String("name", &name);
    auto spec = ReadBat(variant, "bat", context.limits, nullptr);
    if (!spec || !variant.Finish()) return ToResponse(error);
    bats.emplace_back(name, std::move(*spec));
  }
  if (!reader.Finish()) return ToResponse(error);
  options.flexible.modes_cache = context.modes_cache;

  Json rows = Json::array();
  core::SceneResult base;
  for (std::size_t i = 0; i < bats.size(); ++i) {
    if (core::IsCancelled(context.progress)) {
      return ErrorResponse(409, ErrorCode::kCancelled, "the comparison was cancelled");
    }
    core::Scene bat_scene = scene;
    bat_scene.bat = bats[i].second.bat;
    const std::string field = i == 0 ? "baseline" : "variants[" + std::to_string(i - 1) + "]";
    if (core::Refusal refusal; !bat_scene.Validate(&refusal)) {
      CoreRefusal(refusal, "", &error);
      return ToResponse(error);
    }
    core::SceneResult result = core::EvaluateScene(bat_scene, options);
    if (!result.summary.IsSolutionUsable()) {
      return SceneFailure(result.summary, result.missing_model, result.mass_properties,
                          i == 0 ? field : field + ".bat",
                          result.refused_field.empty() ? field : result.refused_field,
                          /*options_object=*/true);
    }
    Json row = SceneResultToJson(result);
    row["name"] = bats[i].first;
    row["bat"] = bats[i].second.request_form;
    row["properties"] = PropertiesToJson(result.mass_properties, result.length_m);
    if (i == 0) {
      base = std::move(result);
    } else {
      row["deltas"] = CompareDeltas(result, base);
    }
    rows.push_back(std::move(row));
    if (context.progress != nullptr) {
      context.progress->Report(static_cast<double>(i + 1) / static_cast<double>(bats.size()));
    }
  }
  Json out{{"rows", std::move(rows)},
           {"deltas_are", "variant minus baseline"},
           {"timing_s", SecondsSince(start)}};
  out["provenance"] = Provenance(*body, body->contains("options") ? (*body)["options"] : Json::object());
  return {200, std::move(out)};
}

}  // namespace sweetspot::api
