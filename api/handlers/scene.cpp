// POST /v1/sweet-spot, POST /v1/collision and POST /v1/compare: a scene (bat,
// ball, swing, COR) and what is wanted; only the models those outputs need run.
// Each is a typed endpoint (api/handlers/endpoint.hpp): parse -> core call -> render.
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/outputs/scene_outputs.hpp"
#include "api/scene_json.hpp"
#include "core/scene/sanity.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

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
  if (spec && scene != nullptr) {
    scene->bat = spec->bat;
    scene->paper_bat = spec->paper;
  }
  return spec;
}

// Validates the assembled scene with core's rules (e.g. the hands within the bat).
bool CheckScene(const core::Scene& scene, ApiError* error) {
  core::Refusal refusal;
  if (scene.Validate(&refusal)) return true;
  return CoreRefusal(refusal, "", error);
}

// ---- POST /v1/sweet-spot ----

// A parsed /v1/sweet-spot request: the scene (outputs included) and the options.
struct SweetSpotRequest {
  core::Scene scene;
  core::SceneOptions options;
};

std::optional<SweetSpotRequest> ParseSweetSpot(const Json& body, const Context& context,
                                               ApiError* error) {
  ObjectReader reader(body, "", error);
  SweetSpotRequest request;
  const auto spec = ReadBat(reader, "bat", context.limits, &request.scene);
  if (!spec || !ReadSceneCommon(reader, &request.scene) || !ReadOutputs(reader, &request.scene) ||
      !ReadSceneOptions(reader, context.limits, &request.options) || !reader.Finish() ||
      !CheckScene(request.scene, error)) {
    return std::nullopt;
  }
  request.options.flexible.modes_cache = context.modes_cache;
  request.options.progress = context.progress;  // the server's cancel flag (or null)
  return request;
}

// The answer's members: the outputs (WriteSceneResult, with `warnings`), the bat's properties
// and the resolved swing.
template <class Out>
void WriteSweetSpot(const core::SceneResult& result, const std::vector<std::string>& warnings,
                    Out& out) {
  WriteSceneResult(result, warnings, out);
  out.Object("properties", [&](Out& properties) {
    WriteProperties(result.mass_properties, result.length_m, std::nullopt, properties);
  });
  out.Object("swing", [&](Out& swing) { WriteSwing(result.swing, swing); });
}

const Endpoint<SweetSpotRequest, core::SceneResult>& SweetSpotEndpoint() {
  static const auto endpoint = [] {
    Endpoint<SweetSpotRequest, core::SceneResult> e;
    e.parse = ParseSweetSpot;
    e.run = [](const SweetSpotRequest& request, const Context&) {
      return core::EvaluateScene(request.scene, request.options);
    };
    e.failure = [](const SweetSpotRequest&,
                   const core::SceneResult& result) -> std::optional<Response> {
      if (result.summary.IsSolutionUsable()) return std::nullopt;
      return SceneFailure(result.summary, result.missing_model, result.mass_properties, "bat",
                          result.refused_field.empty() ? "outputs" : result.refused_field,
                          /*options_object=*/true);
    };
    e.render = [](const SweetSpotRequest&, const core::SceneResult& result) {
      return TreeOf([&](TreeObject& out) { WriteSweetSpot(result, {}, out); });
    };
    e.write = [](const SweetSpotRequest&, const core::SceneResult& result,
                 const std::vector<std::string>& warnings,
                 TextObject& out) { WriteSweetSpot(result, warnings, out); };
    e.summary = [](const core::SceneResult& result) -> const core::Summary& {
      return result.summary;
    };
    e.warnings = [](const SweetSpotRequest& request, const core::SceneResult& result) {
      return core::SceneSanityWarnings(request.scene, result.mass_properties);
    };
    e.provenance = [](const SweetSpotRequest& request, const Json& body) {
      return BodyOptions(body, request.options.method == core::SweetSpotMethod::kNlopt
                                   ? std::optional<unsigned long long>(request.options.nlopt.seed)
                                   : std::nullopt);
    };
    return e;
  }();
  return endpoint;
}

// ---- POST /v1/collision ----

// A parsed /v1/collision request: the scene, the impact point, the model and its options.
struct CollisionRequest {
  core::Scene scene;
  double impact_from_knob_m = 0.0;
  core::CollisionModel model = core::CollisionModel::kAuto;
  core::CollisionOptions options;
};

std::optional<CollisionRequest> ParseCollision(const Json& body, const Context& context,
                                               ApiError* error) {
  ObjectReader reader(body, "", error);
  CollisionRequest request;
  const auto spec = ReadBat(reader, "bat", context.limits, &request.scene);
  if (!spec || !ReadSceneCommon(reader, &request.scene)) return std::nullopt;
  // Its range, within the bat, is core's: Collide refuses a point off the bat by name.
  reader.Number("impact_from_knob_m", AnyNumber(), &request.impact_from_knob_m);
  std::string model_name = "auto";
  reader.OptionalString("model", &model_name,
                        {"auto", "rigid_pivot", "free_bat", "hertz", "flexible"});
  core::CollisionOptions& options = request.options;
  ClampToLimits(context.limits, &options.hertz);
  ClampToLimits(context.limits, &options.flexible);
  reader.OptionalBool("contact_details", &options.want_contact_details);
  // "outputs": ["batted_ball"], the one scene output an impact point answers (its block beside
  // the impact's).
  if (const Json* outputs = reader.Get("outputs"); outputs != nullptr && reader.ok()) {
    if (!outputs->is_array()) {
      reader.Fail("outputs", "must be an array of output names (\"batted_ball\")");
    } else {
      for (std::size_t i = 0; i < outputs->size() && reader.ok(); ++i) {
        const Json& item = (*outputs)[i];
        if (!item.is_string() || item.get<std::string>() != "batted_ball") {
          reader.Fail("outputs", "outputs[" + std::to_string(i) + "] = " + Show(item) +
                                     " is not one of batted_ball (the scene outputs /v1/collision "
                                     "answers at impact_from_knob_m)");
        }
      }
      options.want_batted_ball = reader.ok();
    }
  }
  if (const Json* hertz = reader.Get("hertz")) {
    ReadHertzOptions(*hertz, reader.PathOf("hertz"), context.limits, &options.hertz, error);
  }
  if (const Json* flexible = reader.Get("flexible")) {
    ReadFlexibleOptions(*flexible, reader.PathOf("flexible"), context.limits, &options.flexible,
                        error);
  }
  options.flexible.modes_cache = context.modes_cache;
  if (!reader.Finish() || !CheckScene(request.scene, error)) return std::nullopt;
  request.model = *core::ParseCollisionModel(model_name);
  return request;
}

const Endpoint<CollisionRequest, core::CollisionResult>& CollisionEndpoint() {
  static const auto endpoint = [] {
    Endpoint<CollisionRequest, core::CollisionResult> e;
    e.parse = ParseCollision;
    e.run = [](const CollisionRequest& request, const Context&) {
      return core::Collide(request.scene, request.impact_from_knob_m, request.model,
                           request.options);
    };
    e.failure = [](const CollisionRequest&,
                   const core::CollisionResult& result) -> std::optional<Response> {
      if (result.summary.IsSolutionUsable()) return std::nullopt;
      return SceneFailure(result.summary, result.missing_model, result.mass_properties, "bat",
                          "model");
    };
    e.render = [](const CollisionRequest&, const core::CollisionResult& result) {
      Json out = CollisionResultToJson(result);
      if (result.batted_ball.has_value()) {
        // The block as /v1/sweet-spot writes it (its api declaration), its error beside the
        // impact's.
        core::SceneResult ball;
        ball.batted_ball = result.batted_ball;
        Json errors = Json::object();
        ApiOutputDeclaration(core::SceneOutput::kBattedBall).render(ball, &out, &errors);
        out["error_estimate"]["batted_ball"] = errors["batted_ball"];
      }
      return out;
    };
    e.summary = [](const core::CollisionResult& result) -> const core::Summary& {
      return result.summary;
    };
    e.warnings = [](const CollisionRequest& request, const core::CollisionResult& result) {
      return core::SceneSanityWarnings(request.scene, result.mass_properties);
    };
    e.provenance = [](const CollisionRequest&, const Json&) { return ProvenanceInputs{}; };
    // The answer states no length: the impact's and the swing's distances from the tip need it.
    e.length_m = [](const CollisionRequest& request,
                    const core::CollisionResult&) -> std::optional<double> {
      const core::Scene& scene = request.scene;
      return scene.bat ? scene.bat->LengthM() : scene.length_m;
    };
    return e;
  }();
  return endpoint;
}

// ---- POST /v1/compare ----

// A parsed /v1/compare request: the scene shared by every bat, the options, and the bats
// by name, the baseline first.
struct CompareRequest {
  core::Scene scene;
  core::SceneOptions options;
  std::vector<std::pair<std::string, BatSpec>> bats;
};

// The core results of a comparison, one per bat in order, up to the first that stops it.
struct CompareResult {
  std::vector<core::SceneResult> results;  // the last one may be unusable (it stopped the run)
  bool cancelled = false;                  // Progress::Cancel() before the next bat
  std::optional<core::Refusal> refusal;    // core refused the next bat's scene
};

// The request field of bat `i` (0 = the baseline).
std::string CompareField(std::size_t i) {
  return i == 0 ? "baseline" : "variants[" + std::to_string(i - 1) + "]";
}

std::optional<CompareRequest> ParseCompare(const Json& body, const Context& context,
                                           ApiError* error) {
  ObjectReader reader(body, "", error);
  CompareRequest request;
  const auto baseline = ReadBat(reader, "baseline", context.limits, nullptr);
  if (!baseline || !ReadSceneCommon(reader, &request.scene) ||
      !ReadOutputs(reader, &request.scene) ||
      !ReadSceneOptions(reader, context.limits, &request.options)) {
    return std::nullopt;
  }
  const Json* variants = reader.Get("variants");
  if (reader.ok() && variants == nullptr) reader.Missing("variants");
  if (!reader.ok()) return std::nullopt;
  if (!variants->is_array()) {
    reader.Fail("variants", "must be an array of {\"name\", \"bat\"}");
    return std::nullopt;
  }
  if (variants->size() > context.limits.max_variants) {
    reader.Fail("variants",
                "has " + std::to_string(variants->size()) +
                    " variants, over the limit max_variants = " +
                    std::to_string(context.limits.max_variants) + " (--max-variants)",
                ErrorCode::kTooBig);
    return std::nullopt;
  }
  request.bats = {{"baseline", *baseline}};
  for (std::size_t i = 0; i < variants->size(); ++i) {
    ObjectReader variant((*variants)[i], CompareField(i + 1), error);
    std::string name;
    variant.String("name", &name);
    auto spec = ReadBat(variant, "bat", context.limits, nullptr);
    if (!spec || !variant.Finish()) return std::nullopt;
    request.bats.emplace_back(name, std::move(*spec));
  }
  if (!reader.Finish()) return std::nullopt;
  request.options.flexible.modes_cache = context.modes_cache;
  request.options.progress = context.progress;  // the server's cancel flag (or null)
  return request;
}

// Evaluates the scene with each bat in turn, reporting progress; stops at a cancel, a scene
// core refuses, or a result that is not usable.
CompareResult RunCompare(const CompareRequest& request, const Context& context) {
  CompareResult out;
  for (std::size_t i = 0; i < request.bats.size(); ++i) {
    if (core::IsCancelled(context.progress)) {
      out.cancelled = true;
      return out;
    }
    core::Scene bat_scene = request.scene;
    bat_scene.bat = request.bats[i].second.bat;
    bat_scene.paper_bat = request.bats[i].second.paper;
    if (core::Refusal refusal; !bat_scene.Validate(&refusal)) {
      out.refusal = std::move(refusal);
      return out;
    }
    out.results.push_back(core::EvaluateScene(bat_scene, request.options));
    if (!out.results.back().summary.IsSolutionUsable()) return out;
    if (context.progress != nullptr) {
      context.progress->Report(static_cast<double>(i + 1) /
                               static_cast<double>(request.bats.size()));
    }
  }
  return out;
}

// The answer for a comparison that stopped early.
std::optional<Response> CompareFailure(const CompareRequest&, const CompareResult& compare) {
  if (compare.cancelled) {
    return ErrorResponse(409, ErrorCode::kCancelled, "the comparison was cancelled");
  }
  if (compare.refusal) {
    ApiError error;
    CoreRefusal(*compare.refusal, "", &error);
    return ToResponse(error);
  }
  const core::SceneResult& last = compare.results.back();
  if (last.summary.IsSolutionUsable()) return std::nullopt;
  const std::string field = CompareField(compare.results.size() - 1);
  return SceneFailure(last.summary, last.missing_model, last.mass_properties,
                      compare.results.size() == 1 ? field : field + ".bat",
                      last.refused_field.empty() ? field : last.refused_field,
                      /*options_object=*/true);
}

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
  // A swing whose speed depends on the bat (swing.speed_model swing_weight, or the bat-speed
  // point at each bat's sweet spot): how much faster the variant is swung.
  const core::Swing& vs = variant.swing;
  if (vs.resolution.has_value() && base.swing.resolution.has_value() &&
      (vs.speed_model == core::SwingSpeedModel::kSwingWeight ||
       vs.bat_speed_point == core::BatSpeedPoint::kSweetSpot)) {
    deltas["bat_speed_mps"] = vs.resolution->bat_speed_mps - base.swing.resolution->bat_speed_mps;
    deltas["angular_speed_rad_s"] = vs.angular_speed_rad_s - base.swing.angular_speed_rad_s;
  }
  if (variant.center_of_percussion && base.center_of_percussion) {
    deltas["center_of_percussion_m"] = variant.center_of_percussion->position_from_knob_m -
                                       base.center_of_percussion->position_from_knob_m;
  }
  return deltas;
}

// One row per bat: its outputs, name, bat as written, properties and (variants) deltas.
Json RenderCompare(const CompareRequest& request, const CompareResult& compare) {
  Json rows = Json::array();
  for (std::size_t i = 0; i < compare.results.size(); ++i) {
    const core::SceneResult& result = compare.results[i];
    Json row = SceneResultToJson(result);
    row["name"] = request.bats[i].first;
    row["bat"] = request.bats[i].second.request_form;
    row["properties"] = PropertiesToJson(result.mass_properties, result.length_m);
    row["swing"] = SwingToJson(result.swing);  // per bat: a bat speed gives each its own omega
    if (i > 0) row["deltas"] = CompareDeltas(result, compare.results.front());
    rows.push_back(std::move(row));
  }
  return {{"rows", std::move(rows)}, {"deltas_are", "variant minus baseline"}};
}

const Endpoint<CompareRequest, CompareResult>& CompareEndpoint() {
  static const auto endpoint = [] {
    Endpoint<CompareRequest, CompareResult> e;
    e.parse = ParseCompare;
    e.run = RunCompare;
    e.failure = CompareFailure;
    e.render = RenderCompare;
    e.warnings = [](const CompareRequest& request, const CompareResult& compare) {
      // The shared ball and swing once; each bat under its name, with the mass properties its
      // scene computed (a rendered comparison has a result for every bat).
      std::vector<std::string> out =
          core::SanityWarnings(nullptr, nullptr, &request.scene.ball, nullptr);
      for (std::size_t i = 0; i < request.bats.size() && i < compare.results.size(); ++i) {
        const auto& [name, spec] = request.bats[i];
        for (const std::string& w : core::SanityWarnings(
                 &spec.bat, &compare.results[i].mass_properties, nullptr, &request.scene.swing)) {
          out.push_back(name + ": " + w);
        }
      }
      return out;
    };
    e.provenance = [](const CompareRequest&, const Json& body) { return BodyOptions(body); };
    return e;
  }();
  return endpoint;
}

}  // namespace

Response HandleSweetSpot(const Request& request, const Context& context) {
  return ServeEndpoint(SweetSpotEndpoint(), request, context);
}

Response HandleCollision(const Request& request, const Context& context) {
  return ServeEndpoint(CollisionEndpoint(), request, context);
}

Response HandleCompare(const Request& request, const Context& context) {
  return ServeEndpoint(CompareEndpoint(), request, context);
}

}  // namespace sweetspot::api
