// GET /v1/materials and GET /v1/presets: the catalogues with their sources.
#include "api/bat_json.hpp"
#include "api/handlers.hpp"
#include "core/presets.hpp"

namespace sweetspot::api {

Response HandleMaterials(const Request&, const Context&) {
  nlohmann::json materials = nlohmann::json::array();
  for (const auto& material : core::MaterialCatalogue()) {
    materials.push_back(MaterialToJson(material));
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

}  // namespace sweetspot::api
