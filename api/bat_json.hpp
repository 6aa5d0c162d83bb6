// The bat as JSON: parsing the contract's three forms (preset, three_segment,
// profile; with material, wall and fill beside the shape) into core::Bat, and
// rendering materials, presets and mass properties.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "api/json_reader.hpp"
#include "api/json_writer.hpp"
#include "api/limits.hpp"
#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"

namespace sweetspot::api {

/// A parsed bat: the core bat, plus the request's own form so that results
/// can hand a bat back "in the request's form".
struct BatSpec {
  core::Bat bat;                ///< The bat (valid).
  nlohmann::json request_form;  ///< The bat object as the request wrote it.
  std::string shape_form;  ///< "preset", "three_segment" or "profile": where the shape came from.
  std::optional<core::ThreeSegmentShape> three_segment;  ///< Set for the three_segment form.
  /// From one of the paper's presets ("paper-wood", "paper-wood-m885"): a scene's model auto
  /// is then the paper's rigid_pivot (core::Scene::paper_bat).
  bool paper = false;
  /// The bat's mass properties under both inertia models, computed once by ParseBat (its
  /// check that the bat is computable) for the request to use; ParseBatGeometry leaves them
  /// unset (a scene's are computed by core).
  std::optional<core::MassPropertiesOfBothModels> properties;
};

/// Parses the bat object at `path` (e.g. "bat"). On error returns nullopt with
/// *error naming the field (e.g. "bat.profile.knots[2].x_m = 0.1: must be
/// greater than knots[1].x_m = 0.2"); a bat too small or light to compute with
/// (CheckComputable under either inertia model) is refused on `path`. The spec carries the
/// mass properties it computed (`properties`), so the request computes them once.
std::optional<BatSpec> ParseBat(const nlohmann::json& value, const std::string& path,
                                const ApiLimits& limits, ApiError* error);

/// ParseBat without computing the mass properties: for requests whose core call
/// computes them itself, once (the scene endpoints); they check that result with
/// CheckComputable (SceneFailure does).
std::optional<BatSpec> ParseBatGeometry(const nlohmann::json& value, const std::string& path,
                                        const ApiLimits& limits, ApiError* error);

/// False, with *error on `path` ("is too small or too light to compute with: ..."),
/// when `properties` are not positive and finite (a bat whose integrals underflow).
bool CheckComputable(const core::MassProperties& properties, const std::string& path,
                     ApiError* error);

/// Parses a material: a catalogue name or an object with at least
/// density_kg_m3 and youngs_modulus_pa. `allow_empty` accepts "empty" (a fill).
std::optional<core::Material> ParseMaterial(const nlohmann::json& value, const std::string& path,
                                            bool allow_empty, ApiError* error);

/// A material with its properties and source (and `base` when it has one other than itself).
nlohmann::json MaterialToJson(const core::Material& material);

/// The bat's shape and build as JSON (profile knots, material name, wall, fill).
nlohmann::json BatToJson(const core::Bat& bat);

/// The contract's property block: mass_kg, balance_point_m, moi_knob_kg_m2,
/// moi_six_inch_kg_m2, moi_centroid_kg_m2, volume_m3, length_m (+ moi_pivot_kg_m2
/// when `pivot_from_knob_m` is set), the inertia model and an "imperial" block.
nlohmann::json PropertiesToJson(const core::MassProperties& properties, double length_m,
                                std::optional<double> pivot_from_knob_m = std::nullopt);
/// The same members written to `out` (api/json_writer.hpp's Out: TreeObject or TextObject).
template <class Out>
void WriteProperties(const core::MassProperties& properties, double length_m,
                     std::optional<double> pivot_from_knob_m, Out& out);

/// "rigid_body" or "slender_rod".
const char* InertiaModelName(core::InertiaModel model);

}  // namespace sweetspot::api
