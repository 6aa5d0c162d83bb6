#include "api/bat_json.hpp"

#include <cmath>
#include <utility>

#include "api/fields.hpp"
#include "core/bat/presets.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

std::optional<core::ThreeSegmentShape> ParseThreeSegment(const Json& value, const std::string& path,
                                                         ApiError* error) {
  ObjectReader reader(value, path, error);
  core::ThreeSegmentShape shape;
  // Presence and types here; the ranges are core's (ThreeSegmentShape::ValidateSize).
  // The shape's fields, from the table of fields (api/fields.hpp).
  FieldHost host;
  host.shape = &shape;
  ReadFieldGroup(reader, FieldGroup::kShape, host);
  if (!reader.Finish()) return std::nullopt;
  if (core::Refusal refusal; !shape.ValidateSize(&refusal)) {
    CoreRefusal(refusal, path, error);
    return std::nullopt;
  }
  return shape;
}

std::optional<std::vector<core::ProfileKnot>> ParseProfile(const Json& value,
                                                           const std::string& path,
                                                           const ApiLimits& limits,
                                                           ApiError* error) {
  ObjectReader reader(value, path, error);
  const Json* knots = reader.Get("knots");
  if (!reader.ok()) return std::nullopt;
  if (knots == nullptr) {
    reader.Missing("knots");
    return std::nullopt;
  }
  const std::string knots_path = JoinPath(path, "knots");
  if (!knots->is_array()) {
    SetError(error, ErrorCode::kInvalidValue, knots_path, knots,
             "must be an array of {x_m, radius_m}");
    return std::nullopt;
  }
  if (knots->size() < 2) {
    SetError(error, ErrorCode::kInvalidValue, knots_path, knots, "must have at least 2 knots");
    return std::nullopt;
  }
  if (knots->size() > limits.max_knots) {
    SetError(error, ErrorCode::kTooBig, knots_path, nullptr,
             "has " + std::to_string(knots->size()) + " knots, over the limit max_knots = " +
                 std::to_string(limits.max_knots) + " (--max-knots)");
    return std::nullopt;
  }
  // Each knot's x_m and radius_m, from the table of fields (api/fields.hpp); the ranges: core's
  // Bat::ValidateSize.
  core::Bat knotted;
  knotted.knots.resize(knots->size());
  FieldHost host;
  host.bat = &knotted;
  for (std::size_t i = 0; i < knots->size(); ++i) {
    ObjectReader knot((*knots)[i], knots_path + "[" + std::to_string(i) + "]", error);
    host.knot = i;
    ReadFieldGroup(knot, FieldGroup::kKnot, host);
    if (!knot.Finish()) return std::nullopt;
  }
  if (!reader.Finish()) return std::nullopt;
  return std::move(knotted.knots);
}

std::optional<core::Fill> ParseFill(const Json& value, const std::string& path, ApiError* error) {
  ObjectReader reader(value, path, error);
  core::Fill fill;
  const Json* material = reader.Get("material");
  if (material == nullptr) {
    reader.Missing("material");
    return std::nullopt;
  }
  auto parsed = ParseMaterial(*material, JoinPath(path, "material"), /*allow_empty=*/true, error);
  if (!parsed) return std::nullopt;
  fill.material = *parsed;
  // diameter_m, depth_m, from the table of fields; the ranges: Bat::ValidateSize.
  FieldHost host;
  host.fill = &fill;
  ReadFieldGroup(reader, FieldGroup::kFill, host);
  if (!reader.Finish()) return std::nullopt;
  return fill;
}

// An end cap or knob object at `path` into *part: mass_kg and length_m (the table of fields;
// their ranges: Bat::ValidateSize) and an optional catalogue "material" name.
bool ParsePart(const Json& value, const std::string& path, FieldGroup group, core::Bat* bat,
               ApiError* error) {
  ObjectReader reader(value, path, error);
  std::optional<core::BatPart>& part = group == FieldGroup::kEndCap ? bat->end_cap : bat->knob;
  part = core::BatPart{};
  FieldHost host;
  host.bat = bat;
  ReadFieldGroup(reader, group, host);
  reader.OptionalString("material", &part->material);
  if (!reader.ok()) return false;
  if (reader.Has("material") && !core::FindMaterial(part->material)) {
    reader.Fail("material", "is not a catalogue material (GET /v1/materials lists: " +
                                core::MaterialNamesList() + ")");
    return false;
  }
  if (const auto found = core::FindMaterial(part->material)) part->material = found->name;
  return reader.Finish();
}

// A two-piece bat's handle object at `path` into bat->handle: its "material" (a catalogue name
// or a material object, as the bat's), joint_from_knob_m (required) and wall_thickness_m
// (optional: absent = the bat's walls) through the table of fields; ranges: Bat::ValidateSize.
bool ParseHandle(const Json& value, const std::string& path, core::Bat* bat, ApiError* error) {
  ObjectReader reader(value, path, error);
  bat->handle = core::Handle{};
  const Json* material = reader.Get("material");
  if (material == nullptr) {
    reader.Fail("material", "is required (a catalogue name or a material object)");
    return false;
  }
  auto parsed = ParseMaterial(*material, JoinPath(path, "material"), /*allow_empty=*/false, error);
  if (!parsed) return false;
  bat->handle->material = *parsed;
  FieldHost host;
  host.bat = bat;
  ReadFieldGroup(reader, FieldGroup::kHandle, host);
  return reader.Finish();
}

}  // namespace

std::optional<core::Material> ParseMaterial(const Json& value, const std::string& path,
                                            bool allow_empty, ApiError* error) {
  const auto names = [allow_empty] {
    return core::MaterialNamesList() + (allow_empty ? ", empty" : "");
  };
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    if (allow_empty && name == "empty") return core::EmptyFillMaterial();
    if (auto material = core::FindMaterial(name)) return material;
    SetError(error, ErrorCode::kInvalidValue, path, &value,
             "is not a catalogue material (GET /v1/materials lists: " + names() + ")");
    return std::nullopt;
  }
  ObjectReader reader(value, path, error);
  core::Material material;
  material.name = "custom";
  material.source = "given in the request";
  // {"base": NAME, ...overrides}: the catalogue entry's numbers, kind and COR, each field
  // given overriding its own; without a base, density and E are required.
  std::string base;
  reader.OptionalString("base", &base);
  const bool has_base = reader.ok() && reader.Has("base");
  if (has_base) {
    const auto found = core::FindMaterial(base);
    if (!found) {
      reader.Fail("base", "is not a catalogue material (GET /v1/materials lists: " +
                              core::MaterialNamesList() + ")");
      return std::nullopt;
    }
    material = *found;
    material.name = "custom";
    material.source =
        "base " + found->name + " with the request's overrides; base source: " + found->source;
    // A density range is the base's; given another density, it is not this material's.
    material.density_min_kg_m3 = material.density_max_kg_m3 = 0.0;
  }
  reader.OptionalString("name", &material.name);
  // Without a base and without G or nu, nu = 0.3 (as before) but not silently: scenes warn.
  // (The table's setters of G and nu clear it.)
  material.poissons_ratio_assumed = !has_base;
  // density_kg_m3, youngs_modulus_pa (required without a base), shear_modulus_pa,
  // poissons_ratio, cor: the table of fields (api/fields.hpp). Presence and types here; the
  // ranges are core's (Material::ValidateSize, below).
  FieldHost host;
  host.material = &material;
  ReadFieldGroup(reader, FieldGroup::kMaterial, host,
                 has_base ? FieldPresence::kAllOptional : FieldPresence::kAsDeclared);
  if (!reader.Finish()) return std::nullopt;
  if (core::Refusal refusal; !material.ValidateSize(&refusal)) {
    CoreRefusal(refusal, path, error);
    return std::nullopt;
  }
  return material;
}

std::optional<BatSpec> ParseBatGeometry(const Json& value, const std::string& path,
                                        const ApiLimits& limits, ApiError* error) {
  ObjectReader reader(value, path, error);
  if (!reader.ok()) return std::nullopt;
  BatSpec spec;
  spec.request_form = value;
  const core::BatPreset* preset = nullptr;  // BatPresets()'s own: no copy
  if (const Json* name = reader.Get("preset")) {
    if (!name->is_string()) {
      reader.Fail("preset", "must be a string");
      return std::nullopt;
    }
    preset = core::PresetNamed(name->get_ref<const std::string&>());
    if (!preset) {
      std::string names;
      for (const auto& p : core::BatPresets()) names += (names.empty() ? "" : ", ") + p.name;
      reader.Fail("preset", "is not a preset (GET /v1/presets lists: " + names + ")");
      return std::nullopt;
    }
    spec.bat = preset->bat;
    spec.shape_form = "preset";
    spec.paper = preset->name.rfind("paper-", 0) == 0;
  }
  const bool has_three = reader.Has("three_segment");
  const bool has_profile = reader.Has("profile");
  if (has_three && has_profile) {
    reader.Fail("profile", "cannot be given together with three_segment (choose one shape)");
    return std::nullopt;
  }
  if (!preset && !has_three && !has_profile) {
    SetError(error, ErrorCode::kMissingField, path, nullptr,
             "needs a shape: one of preset, three_segment or profile");
    return std::nullopt;
  }
  if (has_three) {
    auto shape =
        ParseThreeSegment(*reader.Get("three_segment"), JoinPath(path, "three_segment"), error);
    if (!shape) return std::nullopt;
    spec.bat.knots = shape->Knots();
    spec.three_segment = shape;
    spec.shape_form = "three_segment";
  } else if (has_profile) {
    auto knots = ParseProfile(*reader.Get("profile"), JoinPath(path, "profile"), limits, error);
    if (!knots) return std::nullopt;
    spec.bat.knots = std::move(*knots);
    spec.shape_form = "profile";
  }
  if (const Json* material = reader.Get("material")) {
    auto parsed = ParseMaterial(*material, JoinPath(path, "material"), false, error);
    if (!parsed) return std::nullopt;
    spec.bat.material = *parsed;
  } else if (!preset) {
    spec.bat.material = *core::FindMaterial("paper-wood");
  }
  FieldHost host;  // wall_thickness_m: the table of fields
  host.bat = &spec.bat;
  ReadFieldGroup(reader, FieldGroup::kWall, host);
  if (const Json* fill = reader.Get("fill")) {
    if (fill->is_null()) {
      spec.bat.fill.reset();
    } else {
      auto parsed = ParseFill(*fill, JoinPath(path, "fill"), error);
      if (!parsed) return std::nullopt;
      spec.bat.fill = *parsed;
    }
  }
  // The end cap and the knob (a preset's own are replaced; null removes one).
  for (const auto& [key, group] :
       {std::pair{"end_cap", FieldGroup::kEndCap}, std::pair{"knob", FieldGroup::kKnob}}) {
    if (const Json* part = reader.Get(key)) {
      if (part->is_null()) {
        (group == FieldGroup::kEndCap ? spec.bat.end_cap : spec.bat.knob).reset();
      } else if (!ParsePart(*part, JoinPath(path, key), group, &spec.bat, error)) {
        return std::nullopt;
      }
    }
  }
  // A two-piece bat's handle (a preset's own is replaced; null removes it).
  if (const Json* handle = reader.Get("handle")) {
    if (handle->is_null()) {
      spec.bat.handle.reset();
    } else if (!ParseHandle(*handle, JoinPath(path, "handle"), &spec.bat, error)) {
      return std::nullopt;
    }
  }
  if (!reader.Finish()) return std::nullopt;
  if (core::Refusal refusal; !spec.bat.ValidateSize(&refusal)) {
    // Knot refusals belong under the profile (or the preset's/three-segment's knots).
    const std::string prefix = refusal.field.rfind("knots[", 0) == 0 && spec.shape_form == "profile"
                                   ? JoinPath(path, "profile")
                                   : path;
    CoreRefusal(refusal, prefix, error);
    return std::nullopt;
  }
  return spec;
}

bool CheckComputable(const core::MassProperties& p, const std::string& path, ApiError* error) {
  // A valid but absurdly small or light bat (e.g. radii of 1e-300 m) has a mass
  // or moment of inertia that underflows to 0, and a balance point of 0/0:
  // refuse it rather than answer NaN or fail in core (found by fuzzing:
  // fuzz/regressions/parse_bat/).
  if (std::isfinite(p.mass_kg) && p.mass_kg > 0 && std::isfinite(p.balance_point_m) &&
      std::isfinite(p.moi_knob_kg_m2) && std::isfinite(p.moi_centroid_kg_m2) &&
      p.moi_centroid_kg_m2 > 0) {
    return true;
  }
  return SetError(error, ErrorCode::kInvalidValue, path, nullptr,
                  "is too small or too light to compute with: its mass or moment of inertia is "
                  "not a positive finite number (use SI units: metres, kg/m3)");
}

std::optional<BatSpec> ParseBat(const Json& value, const std::string& path, const ApiLimits& limits,
                                ApiError* error) {
  auto spec = ParseBatGeometry(value, path, limits, error);
  if (!spec) return std::nullopt;
  // Both inertia models from one computation; kept for the request (BatSpec::properties).
  core::MassPropertiesOfBothModels properties = core::ComputeMassPropertiesOfBothModels(spec->bat);
  for (const core::InertiaModel model :
       {core::InertiaModel::kRigidBody, core::InertiaModel::kSlenderRod}) {
    if (!CheckComputable(properties.Of(model), path, error)) return std::nullopt;
  }
  spec->properties = properties;
  return spec;
}

Json MaterialToJson(const core::Material& material) {
  Json out{{"name", material.name},
           {"density_kg_m3", material.density_kg_m3},
           {"youngs_modulus_pa", material.youngs_modulus_pa},
           {"shear_modulus_pa", material.EffectiveShearModulusPa()},
           {"poissons_ratio", material.poissons_ratio},
           {"source", material.source}};
  out["cor"] = material.cor ? Json(*material.cor) : Json(nullptr);
  if (!material.base.empty() && material.base != material.name) out["base"] = material.base;
  if (material.density_min_kg_m3 > 0 || material.density_max_kg_m3 > 0) {
    out["density_range_kg_m3"] = {{"min", material.density_min_kg_m3},
                                  {"max", material.density_max_kg_m3}};
  }
  return out;
}

Json BatToJson(const core::Bat& bat) {
  Json knots = Json::array();
  for (const auto& k : bat.knots) {
    Json knot{{"x_m", k.x_m}, {"radius_m", k.radius_m}};
    if (k.wall_thickness_m > 0.0) knot["wall_thickness_m"] = k.wall_thickness_m;
    knots.push_back(std::move(knot));
  }
  Json out{{"profile", {{"knots", std::move(knots)}}}, {"material", bat.material.name}};
  if (bat.material.name == "custom" || !core::FindMaterial(bat.material.name)) {
    out["material"] = MaterialToJson(bat.material);
    out["material"].erase("source");
    out["material"].erase("density_range_kg_m3");
    if (out["material"]["cor"].is_null()) out["material"].erase("cor");
  }
  if (bat.wall_thickness_m > 0) out["wall_thickness_m"] = bat.wall_thickness_m;
  if (bat.fill) {
    out["fill"] = {
        {"material", bat.fill->IsEmpty() ? Json("empty") : Json(bat.fill->material.name)},
        {"diameter_m", bat.fill->diameter_m},
        {"depth_m", bat.fill->depth_m}};
  }
  for (const auto& [key, part] :
       {std::pair{"end_cap", &bat.end_cap}, std::pair{"knob", &bat.knob}}) {
    if (!part->has_value()) continue;
    Json p{{"mass_kg", (*part)->mass_kg}, {"length_m", (*part)->length_m}};
    if (!(*part)->material.empty()) p["material"] = (*part)->material;
    out[key] = std::move(p);
  }
  if (bat.handle.has_value()) {
    const core::Handle& h = *bat.handle;
    Json j{{"material", h.material.name}, {"joint_from_knob_m", h.joint_from_knob_m}};
    if (h.material.name == "custom" || !core::FindMaterial(h.material.name)) {
      j["material"] = MaterialToJson(h.material);
    }
    if (h.wall_thickness_m.has_value()) j["wall_thickness_m"] = *h.wall_thickness_m;
    out["handle"] = std::move(j);
  }
  return out;
}

const char* InertiaModelName(core::InertiaModel model) {
  return model == core::InertiaModel::kSlenderRod ? "slender_rod" : "rigid_body";
}

template <class Out>
void WriteProperties(const core::MassProperties& p, double length_m,
                     std::optional<double> pivot_from_knob_m, Out& out) {
  // In key order (the text writer then only checks it).
  out.Set("balance_point_m", p.balance_point_m);
  out.Object("imperial", [&](Out& in_imperial) {
    const core::ImperialProperties imperial = core::ToImperial(p, length_m);
    in_imperial.Set("balance_point_in", imperial.balance_point_in);
    in_imperial.Set("drop", imperial.drop);
    in_imperial.Set("length_in", imperial.length_in);
    in_imperial.Set("moi_centroid_oz_in2", imperial.moi_centroid_oz_in2);
    in_imperial.Set("moi_knob_oz_in2", imperial.moi_knob_oz_in2);
    in_imperial.Set("moi_six_inch_oz_in2", imperial.moi_six_inch_oz_in2);
    in_imperial.Set("weight_oz", imperial.weight_oz);
  });
  out.Set("inertia_model", InertiaModelName(p.inertia_model));
  out.Set("length_m", length_m);
  out.Set("mass_kg", p.mass_kg);
  out.Set("moi_centroid_kg_m2", p.moi_centroid_kg_m2);
  out.Set("moi_knob_kg_m2", p.moi_knob_kg_m2);
  if (pivot_from_knob_m) out.Set("moi_pivot_kg_m2", p.MoiAboutKgM2(*pivot_from_knob_m));
  out.Set("moi_six_inch_kg_m2", p.MoiSixInchKgM2());
  if (pivot_from_knob_m) out.Set("pivot_from_knob_m", *pivot_from_knob_m);
  out.Set("volume_m3", p.volume_m3);
}
template void WriteProperties(const core::MassProperties&, double, std::optional<double>,
                              TreeObject&);
template void WriteProperties(const core::MassProperties&, double, std::optional<double>,
                              TextObject&);

Json PropertiesToJson(const core::MassProperties& p, double length_m,
                      std::optional<double> pivot_from_knob_m) {
  return TreeOf([&](TreeObject& out) { WriteProperties(p, length_m, pivot_from_knob_m, out); });
}

}  // namespace sweetspot::api
