// GET /v1/materials, GET /v1/presets and GET /v1/balls: the catalogues with their sources.
#include "api/bat_json.hpp"
#include "api/handlers/handlers.hpp"
#include "core/ball/ball_catalogue.hpp"
#include "core/bat/presets.hpp"

namespace sweetspot::api {

Response HandleMaterials(const Request&, const Context&) {
  nlohmann::json materials = nlohmann::json::array();
  for (const auto& material : core::MaterialCatalogue()) {
    nlohmann::json entry = MaterialToJson(material);
    // Catalogue-only fields (a request's material object takes neither: its base has a kind).
    entry["kind"] = material.kind ? nlohmann::json(core::MaterialKindName(*material.kind))
                                  : nlohmann::json(nullptr);
    entry["aliases"] = core::MaterialAliases(material.name);
    materials.push_back(std::move(entry));
  }
  return {200, {{"materials", std::move(materials)}}};
}

Response HandlePresets(const Request&, const Context&) {
  nlohmann::json presets = nlohmann::json::array();
  for (const auto& preset : core::BatPresets()) {
    const core::MassProperties properties = core::ComputeMassProperties(preset.bat);
    presets.push_back({{"name", preset.name},
                       {"description", preset.description},
                       {"source", preset.source},
                       {"bat", BatToJson(preset.bat)},
                       {"properties", PropertiesToJson(properties, preset.bat.LengthM())}});
  }
  return {200, {{"presets", std::move(presets)}}};
}

Response HandleBalls(const Request&, const Context&) {
  nlohmann::json balls = nlohmann::json::array();
  for (const auto& b : core::BallCatalogue()) {
    const core::BallCorLaw& law = b.cor_law;
    balls.push_back(
        {{"name", b.name},
         {"description", b.description},
         {"mass_kg", b.mass_kg},
         {"mass_range_kg", {b.mass_min_kg, b.mass_max_kg}},
         {"radius_m", b.radius_m},
         {"circumference_range_m", {b.circumference_min_m, b.circumference_max_m}},
         {"cor", law.cor_at_reference},
         {"cor_test_speed_mps", law.reference_speed_mps},
         {"cor_test", b.cor_test},
         {"cor_law",
          {{"form",
            "e(v) = cor - slope_per_mps (clamp(v, min_speed_mps, max_speed_mps) - "
            "cor_test_speed_mps)"},
           {"slope_per_mps", law.slope_per_mps},
           {"min_speed_mps", law.min_speed_mps},
           {"max_speed_mps", law.max_speed_mps},
           {"cor_at_min_speed", law.CorAt(law.min_speed_mps)},
           {"cor_at_max_speed", law.CorAt(law.max_speed_mps)}}},
         {"stiffness_n_m_p", b.stiffness},
         {"stiffness_exponent", b.stiffness_exponent},
         {"dynamic_stiffness_n_m", core::DynamicStiffnessOf(b.stiffness, b.stiffness_exponent,
                                                            b.mass_kg, law.reference_speed_mps)},
         {"stiffness_basis", b.stiffness_basis},
         {"source", b.source}});
  }
  return {200, {{"balls", std::move(balls)}}};
}

}  // namespace sweetspot::api
