// The table of settable fields (api/fields.hpp) and how a written name finds its row.
#include "api/fields.hpp"

#include <algorithm>

#include "api/json_path.hpp"
#include "api/json_reader.hpp"
#include "api/trade_units.hpp"
#include "core/bat/material.hpp"

namespace sweetspot::api {
namespace {

using G = FieldGroup;
using H = FieldHost;

core::Bat& BatOf(const H& h) { return *h.bat; }
core::Material& MaterialOf(const H& h) { return *h.material; }
core::Fill& FillOf(const H& h) { return *h.fill; }

// The scene's rows (SI): the ball, the swing, the contact and the COR, appended to *f.
void AddSceneFields(std::vector<Field>* f) {
  // The ball, the swing, the COR: explore parameters only. Each object's rows in the order
  // the parser reads them (ReadFieldGroup): the same error for the same request.
  f->push_back({"ball.mass_kg", "kg", G::kBall, core::kMinBallMassKg, core::kMaxBallMassKg, true,
                false, "", [](const H& h) { return h.ball->mass_kg; },
                [](const H& h, double v) { h.ball->mass_kg = v; }});
  f->push_back({"ball.radius_m", "m", G::kBall, core::kMinBallRadiusM, core::kMaxBallRadiusM, true,
                false, "", [](const H& h) { return h.ball->radius_m; },
                [](const H& h, double v) { h.ball->radius_m = v; }});
  f->push_back({"ball.speed_mps", "m/s", G::kBall, 0.0, core::kMaxBallSpeedMps, true, false, "",
                [](const H& h) { return h.ball->speed_mps; },
                [](const H& h, double v) { h.ball->speed_mps = v; }});
  f->push_back({"ball.stiffness_n_m_p", "N/m^p", G::kBall, 0.0, core::kMaxBallStiffness, true,
                false, "", [](const H& h) { return h.ball->stiffness; },
                [](const H& h, double v) { h.ball->stiffness = v; }});
  f->push_back({"ball.stiffness_exponent", "1", G::kBall, 1.0, 3.0, true, false, "",
                [](const H& h) { return h.ball->stiffness_exponent; },
                [](const H& h, double v) { h.ball->stiffness_exponent = v; }});
  // The oblique impact's (batted_ball): the pitch's path and spin at the plate.
  f->push_back({"ball.descent_angle_deg", "deg", G::kBall, -core::kMaxPathAngleDeg,
                core::kMaxPathAngleDeg, true, false, "",
                [](const H& h) { return h.ball->descent_angle_deg; },
                [](const H& h, double v) { h.ball->descent_angle_deg = v; }});
  f->push_back({"ball.spin_rpm", "rpm", G::kBall, -core::kMaxPitchSpinRpm, core::kMaxPitchSpinRpm,
                true, false, "", [](const H& h) { return h.ball->spin_rpm; },
                [](const H& h, double v) { h.ball->spin_rpm = v; }});
  f->push_back({"swing.angular_speed_rad_s", "rad/s", G::kSwing, 0.0,
                core::kMaxSwingAngularSpeedRadS, true, false, "",
                [](const H& h) { return h.swing->angular_speed_rad_s; },
                [](const H& h, double v) { h.swing->angular_speed_rad_s = v; }});
  // The bat's speed: it sets the angular speed once the bat's length is known
  // (core::ResolveSwing); the parser takes one of it and the angular speed (ReadSwing).
  // A sweep of it on a template with the angular speed is refused before its first design
  // (explore's probe of the template), so the binder sets it only where the parser would.
  f->push_back({"swing.bat_speed_mps", "m/s", G::kSwing, 0.0, core::kMaxBatSpeedMps, true, false,
                "", [](const H& h) { return h.swing->bat_speed_mps.value_or(0.0); },
                [](const H& h, double v) { h.swing->bat_speed_mps = v; }});
  f->push_back({"swing.bat_speed_from_tip_m", "m", G::kSwing, 0.0, core::kMaxSwingOffsetM, true,
                false, "", [](const H& h) { return h.swing->bat_speed_from_tip_m; },
                [](const H& h, double v) { h.swing->bat_speed_from_tip_m = v; }});
  // swing.speed_model "swing_weight"'s settings (core/scene/swing_speed.hpp); the parser reads
  // the model's name and bat_speed_from_tip_m's "sweet_spot" itself (ReadSwing).
  f->push_back({"swing.reference_moi_kg_m2", "kg·m²", G::kSwing, 0.0, core::kMaxSwingMoiKgM2, true,
                false, "",
                [](const H& h) {
                  return h.swing->reference_moi_kg_m2.value_or(core::kSwingWeightReferenceMoiKgM2);
                },
                [](const H& h, double v) { h.swing->reference_moi_kg_m2 = v; }});
  f->push_back({"swing.swing_weight_exponent", "1", G::kSwing, 0.0, core::kMaxSwingWeightExponent,
                true, false, "", [](const H& h) { return h.swing->swing_weight_exponent; },
                [](const H& h, double v) { h.swing->swing_weight_exponent = v; }});
  f->push_back({"swing.pivot_from_knob_m", "m", G::kSwing, -core::kMaxSwingOffsetM,
                core::kMaxSwingOffsetM, true, false, "",
                [](const H& h) { return h.swing->pivot_from_knob_m; },
                [](const H& h, double v) { h.swing->pivot_from_knob_m = v; }});
  f->push_back({"swing.hands_from_knob_m", "m", G::kSwing, -core::kMaxSwingOffsetM,
                core::kMaxSwingOffsetM, true, false, "",
                [](const H& h) { return h.swing->hands_from_knob_m; },
                [](const H& h, double v) { h.swing->hands_from_knob_m = v; }});
  f->push_back({"swing.attack_angle_deg", "deg", G::kSwing, -core::kMaxPathAngleDeg,
                core::kMaxPathAngleDeg, true, false, "",
                [](const H& h) { return h.swing->attack_angle_deg; },
                [](const H& h, double v) { h.swing->attack_angle_deg = v; }});
  // Where across the bat the ball meets it (batted_ball).
  f->push_back({"contact.undercut_m", "m", G::kContact, -core::kMaxUndercutM, core::kMaxUndercutM,
                true, false, "", [](const H& h) { return h.contact->undercut_m; },
                [](const H& h, double v) { h.contact->undercut_m = v; }});
  f->push_back({"cor", "1", G::kCor, 0.0, 1.0, true, false, "",
                [](const H& h) { return h.cor->value_or(0.0); },
                [](const H& h, double v) { *h.cor = v; }});
}

// The bat's shape rows (m): the three-segment shape and a profile's knots, appended to *f.
void AddShapeFields(std::vector<Field>* f) {
  // The three-segment shape.
  f->push_back({"bat.three_segment.length_m", "m", G::kShape, 0.0, core::kMaxBatLengthM, true, true,
                "length_m", [](const H& h) { return h.shape->length_m; },
                [](const H& h, double v) { h.shape->length_m = v; }, true});
  f->push_back({"bat.three_segment.handle_radius_m", "m", G::kShape, 0.0, core::kMaxBatRadiusM,
                true, true, "handle_radius_m", [](const H& h) { return h.shape->handle_radius_m; },
                [](const H& h, double v) { h.shape->handle_radius_m = v; }, true});
  f->push_back({"bat.three_segment.barrel_radius_m", "m", G::kShape, 0.0, core::kMaxBatRadiusM,
                true, true, "barrel_radius_m", [](const H& h) { return h.shape->barrel_radius_m; },
                [](const H& h, double v) { h.shape->barrel_radius_m = v; }, true});
  f->push_back({"bat.three_segment.taper_start_m", "m", G::kShape, 0.0, core::kMaxBatLengthM, true,
                true, "taper_start_m", [](const H& h) { return h.shape->taper_start_m; },
                [](const H& h, double v) { h.shape->taper_start_m = v; }, true});
  f->push_back({"bat.three_segment.taper_end_m", "m", G::kShape, 0.0, core::kMaxBatLengthM, true,
                true, "taper_end_m", [](const H& h) { return h.shape->taper_end_m; },
                [](const H& h, double v) { h.shape->taper_end_m = v; }, true});
  // A profile's knots.
  f->push_back({"bat.profile.knots[].x_m", "m", G::kKnot, 0.0, core::kMaxBatLengthM, true, true, "",
                [](const H& h) { return BatOf(h).knots[h.knot].x_m; },
                [](const H& h, double v) { BatOf(h).knots[h.knot].x_m = v; }, true});
  f->push_back({"bat.profile.knots[].radius_m", "m", G::kKnot, 0.0, core::kMaxBatRadiusM, true,
                true, "", [](const H& h) { return BatOf(h).knots[h.knot].radius_m; },
                [](const H& h, double v) { BatOf(h).knots[h.knot].radius_m = v; }, true});
  f->push_back({"bat.profile.knots[].wall_thickness_m", "m", G::kKnot, 0.0, core::kMaxBatRadiusM,
                false, false, "",
                [](const H& h) { return BatOf(h).knots[h.knot].wall_thickness_m; },
                [](const H& h, double v) { BatOf(h).knots[h.knot].wall_thickness_m = v; }});
}

// The bat's material rows (SI: kg/m³, Pa, 1), appended to *f.
void AddMaterialFields(std::vector<Field>* f) {
  // The material, given as an object.
  f->push_back({"bat.material.density_kg_m3", "kg/m³", G::kMaterial, 0.0, core::kMaxDensityKgM3,
                true, true, "density_kg_m3",
                [](const H& h) { return MaterialOf(h).density_kg_m3; },
                [](const H& h, double v) { MaterialOf(h).density_kg_m3 = v; }, true});
  f->push_back({"bat.material.youngs_modulus_pa", "Pa", G::kMaterial, 0.0, core::kMaxModulusPa,
                true, false, "", [](const H& h) { return MaterialOf(h).youngs_modulus_pa; },
                [](const H& h, double v) { MaterialOf(h).youngs_modulus_pa = v; }, true});
  f->push_back({"bat.material.shear_modulus_pa", "Pa", G::kMaterial, 0.0, core::kMaxModulusPa,
                true, false, "", [](const H& h) { return MaterialOf(h).shear_modulus_pa; },
                [](const H& h, double v) {
                  MaterialOf(h).shear_modulus_pa = v;
                  MaterialOf(h).poissons_ratio_assumed = false;  // given: no "nu assumed"
                }});
  f->push_back({"bat.material.poissons_ratio", "1", G::kMaterial, -1.0, 0.5, true, false, "",
                [](const H& h) { return MaterialOf(h).poissons_ratio; },
                [](const H& h, double v) {
                  MaterialOf(h).poissons_ratio = v;
                  MaterialOf(h).poissons_ratio_assumed = false;
                }});
  f->push_back({"bat.material.cor", "1", G::kMaterial, 0.0, 1.0, true, false, "",
                [](const H& h) { return MaterialOf(h).cor.value_or(0.0); },
                [](const H& h, double v) { MaterialOf(h).cor = v; }});
}

// The bat's parts' rows (m, kg, kg/m³): the wall, the fill, the end cap, the knob, a
// two-piece bat's handle and the fill's material, appended to *f.
void AddPartFields(std::vector<Field>* f) {
  // The wall and the fill.
  f->push_back({"bat.wall_thickness_m", "m", G::kWall, 0.0, core::kMaxBatRadiusM, true, true,
                "wall_thickness_m", [](const H& h) { return BatOf(h).wall_thickness_m; },
                [](const H& h, double v) { BatOf(h).wall_thickness_m = v; }});
  f->push_back({"bat.fill.diameter_m", "m", G::kFill, 0.0, core::kMaxFillDiameterM, true, true,
                "fill.diameter_m", [](const H& h) { return FillOf(h).diameter_m; },
                [](const H& h, double v) { FillOf(h).diameter_m = v; }, true});
  f->push_back({"bat.fill.depth_m", "m", G::kFill, 0.0, core::kMaxBatLengthM, true, true,
                "fill.depth_m", [](const H& h) { return FillOf(h).depth_m; },
                [](const H& h, double v) { FillOf(h).depth_m = v; }, true});
  // The end cap and the knob (issue 35): each its mass and length, required in its object.
  f->push_back({"bat.end_cap.mass_kg", "kg", G::kEndCap, 0.0, core::kMaxBatPartMassKg, false,
                false, "", [](const H& h) { return BatOf(h).end_cap->mass_kg; },
                [](const H& h, double v) { BatOf(h).end_cap->mass_kg = v; }, true});
  f->push_back({"bat.end_cap.length_m", "m", G::kEndCap, 0.0, core::kMaxBatLengthM, false, false,
                "", [](const H& h) { return BatOf(h).end_cap->length_m; },
                [](const H& h, double v) { BatOf(h).end_cap->length_m = v; }, true});
  f->push_back({"bat.knob.mass_kg", "kg", G::kKnob, 0.0, core::kMaxBatPartMassKg, false, false,
                "", [](const H& h) { return BatOf(h).knob->mass_kg; },
                [](const H& h, double v) { BatOf(h).knob->mass_kg = v; }, true});
  f->push_back({"bat.knob.length_m", "m", G::kKnob, 0.0, core::kMaxBatLengthM, false, false, "",
                [](const H& h) { return BatOf(h).knob->length_m; },
                [](const H& h, double v) { BatOf(h).knob->length_m = v; }, true});
  // A two-piece bat's handle (issue 35): where it joins the barrel (required in its object) and
  // its own wall (optional: absent = the bat's walls, 0 = solid).
  f->push_back({"bat.handle.joint_from_knob_m", "m", G::kHandle, 0.0, core::kMaxBatLengthM, false,
                false, "", [](const H& h) { return BatOf(h).handle->joint_from_knob_m; },
                [](const H& h, double v) { BatOf(h).handle->joint_from_knob_m = v; }, true});
  f->push_back({"bat.handle.wall_thickness_m", "m", G::kHandle, 0.0, core::kMaxBatRadiusM, false,
                false, "",
                [](const H& h) { return BatOf(h).handle->wall_thickness_m.value_or(0.0); },
                [](const H& h, double v) { BatOf(h).handle->wall_thickness_m = v; }});
  f->push_back({"bat.fill.material.density_kg_m3", "kg/m³", G::kFillMaterial, 0.0,
                core::kMaxDensityKgM3, false, true, "fill.density_kg_m3",
                [](const H& h) { return FillOf(h).material.density_kg_m3; },
                [](const H& h, double v) { FillOf(h).material.density_kg_m3 = v; }});
}

// The rows. The ranges are those the request's reader and core's Validate(Size) hold.
std::vector<Field> MakeFields() {
  std::vector<Field> f;
  AddSceneFields(&f);
  AddShapeFields(&f);
  AddMaterialFields(&f);
  AddPartFields(&f);
  return f;
}

constexpr std::string_view kBatPrefix = "bat.";

// The field's name in `scope` (its pattern, with "[]" for a knot's index), or "" when the
// scope does not take it.
std::string_view NameIn(const Field& field, FieldScope scope) {
  switch (scope) {
    case FieldScope::kRequest:
      return field.swept ? field.path : std::string_view();
    case FieldScope::kVariable:
      return field.variable ? field.path.substr(kBatPrefix.size()) : std::string_view();
    case FieldScope::kFitName:
      return field.fit_name;
  }
  return {};
}

// The field named `pattern` in `scope`, or nullptr.
const Field* FindIn(std::string_view pattern, FieldScope scope) {
  for (const Field& field : Fields()) {
    const std::string_view name = NameIn(field, scope);
    if (!name.empty() && name == pattern) return &field;
  }
  return nullptr;
}

// `written` with its knot indices as "[]" (and the indices), or nullopt for no path.
std::optional<std::string> PatternOf(std::string_view written,
                                     std::vector<std::size_t>* indices) {
  std::string why;
  const auto steps = ParseJsonPath(std::string(written), &why);
  if (!steps || steps->empty()) return std::nullopt;
  std::string pattern;
  for (const PathStep& step : *steps) {
    if (const auto* key = std::get_if<std::string>(&step)) {
      if (!pattern.empty()) pattern += '.';
      pattern += *key;
    } else {
      pattern += "[]";
      indices->push_back(std::get<std::size_t>(step));
    }
  }
  return pattern;
}

// `pattern` with its "[]" replaced by `indices` in order.
std::string WithIndices(std::string_view pattern, const std::vector<std::size_t>& indices) {
  std::string out;
  std::size_t next = 0;
  for (std::size_t k = 0; k < pattern.size(); ++k) {
    if (pattern.compare(k, 2, "[]") == 0 && next < indices.size()) {
      out += '[';  // piece by piece: GCC 12 warns (falsely) on "[" + to_string(i)
      out += std::to_string(indices[next++]);
      out += ']';
      ++k;
    } else {
      out += pattern[k];
    }
  }
  return out;
}

}  // namespace

FieldHost FieldHost::Of(core::Scene* scene, core::ThreeSegmentShape* shape) {
  FieldHost host;
  host.ball = &scene->ball;
  host.swing = &scene->swing;
  host.cor = &scene->cor;
  host.contact = &scene->contact;
  if (scene->bat.has_value()) {
    host.bat = &*scene->bat;
    host.material = &host.bat->material;
    if (host.bat->fill.has_value()) host.fill = &*host.bat->fill;
  }
  host.shape = shape;
  return host;
}

std::string_view FieldKey(const Field& field) {
  return field.path.substr(field.path.rfind('.') + 1);
}

bool ReadFieldGroup(ObjectReader& reader, FieldGroup group, const FieldHost& host,
                    FieldPresence presence, std::vector<const Field*>* given) {
  for (const Field& field : Fields()) {
    if (field.group != group) continue;
    const std::string_view key = FieldKey(field);
    std::optional<double> value;
    if (field.required && presence == FieldPresence::kAsDeclared) {
      double number = 0.0;
      if (reader.Number(key, AnyNumber(), &number)) value = number;
    } else {
      value = reader.MaybeNumber(key, AnyNumber());
    }
    if (!reader.ok()) return false;
    if (!value) continue;
    field.set(host, *value);
    if (given != nullptr) given->push_back(&field);
  }
  return reader.ok();
}

const std::vector<Field>& Fields() {
  static const std::vector<Field> fields = MakeFields();
  return fields;
}

const Field* FindField(std::string_view pattern) {
  for (const Field& field : Fields()) {
    if (field.path == pattern) return &field;
  }
  return nullptr;
}

std::optional<FieldUse> ResolveField(std::string_view written, FieldScope scope) {
  std::vector<std::size_t> indices;
  const auto pattern = PatternOf(written, &indices);
  if (!pattern) return std::nullopt;
  const std::size_t dot = pattern->rfind('.');
  const std::string parent = dot == std::string::npos ? "" : pattern->substr(0, dot + 1);
  const std::string leaf = dot == std::string::npos ? *pattern : pattern->substr(dot + 1);
  // The SI name itself, then the SI fields the leaf is a trade spelling of, a radius from a
  // diameter first ("fill.diameter_in" is the fill's diameter_m: a fill has no radius).
  std::vector<TradeForm> candidates = {{leaf, 1.0}};
  for (TradeForm& form : SiFormsOf(leaf)) candidates.push_back(std::move(form));
  for (const TradeForm& candidate : candidates) {
    const std::string si_pattern = parent + candidate.key;
    if (const Field* field = FindIn(si_pattern, scope)) {
      FieldUse use;
      use.field = field;
      use.written = std::string(written);
      use.si = WithIndices(si_pattern, indices);
      use.to_si = candidate.to_si;
      use.indices = std::move(indices);
      return use;
    }
  }
  return std::nullopt;
}

namespace {

// Every name of `scope`, SI and trade forms, a knot's index written "[]".
std::vector<std::string> Patterns(FieldScope scope) {
  std::vector<std::string> names;
  for (const Field& field : Fields()) {
    const std::string name(NameIn(field, scope));
    if (name.empty()) continue;
    names.push_back(name);
    const std::size_t dot = name.rfind('.');
    const std::string parent = dot == std::string::npos ? "" : name.substr(0, dot + 1);
    for (const TradeForm& form : TradeForms(name.substr(parent.size()))) {
      // A fill's diameter is its own field: a radius's forms are no name of it.
      const auto use = ResolveField(WithIndices(parent + form.key, {0}), scope);
      if (use && use->field == &field) names.push_back(parent + form.key);
    }
  }
  return names;
}

}  // namespace

std::vector<std::string> FieldNames(FieldScope scope) {
  std::vector<std::string> names = Patterns(scope);
  for (std::string& name : names) {
    if (const std::size_t at = name.find("[]"); at != std::string::npos) name.replace(at, 2, "[i]");
  }
  return names;
}

std::string DidYouMeanField(std::string_view written, FieldScope scope) {
  // Compared with a knot's index left out: "profile.knots[3].radus_m".
  std::vector<std::size_t> indices;
  std::string typed(written);
  if (const auto pattern = PatternOf(written, &indices)) typed = *pattern;
  const std::string nearest = NearestName(typed, Patterns(scope));
  if (nearest.empty()) return "";
  return " (did you mean \"" + WithIndices(nearest, indices) + "\"?)";
}

}  // namespace sweetspot::api
