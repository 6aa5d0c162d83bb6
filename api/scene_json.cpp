#include "api/scene_json.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "api/bat_json.hpp"
#include "api/fields.hpp"
#include "api/flight_json.hpp"
#include "api/router.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// The ball's and the swing's numbers: their ranges are core's (core::Ball::Validate,
// core::Swing::Validate), checked with the assembled scene.
// "preset" first (a catalogue ball), then the explicit fields, which override the preset's.
bool ReadBall(const Json& value, const std::string& path, core::Ball* ball, ApiError* error) {
  ObjectReader reader(value, path, error);
  std::string preset;
  reader.OptionalString("preset", &preset);
  if (reader.ok() && reader.Has("preset")) {
    const auto found = core::FindBallPreset(preset);
    if (!found) {
      reader.Fail("preset", "is not a ball (GET /v1/balls lists: " + core::BallPresetNames() + ")");
      return false;
    }
    core::ApplyBallPreset(*found, ball);
  }
  // mass_kg, radius_m, speed_mps, stiffness_n_m_p, stiffness_exponent: the table of fields.
  FieldHost host;
  host.ball = ball;
  ReadFieldGroup(reader, FieldGroup::kBall, host);
  return reader.Finish();
}

// angular_speed_rad_s, bat_speed_mps, bat_speed_from_tip_m, pivot_from_knob_m,
// hands_from_knob_m: the table of fields (api/fields.hpp). Exactly one of angular_speed_rad_s
// and bat_speed_mps (which core turns into the angular speed once the bat's length is known:
// core::ResolveSwing), read into a copy so that the swing changes only when they are one.
// swing.speed_model ("fixed" or "swing_weight") and bat_speed_from_tip_m (or _in) given as
// "sweet_spot" are read here; the numbers by the table.
bool ReadSwing(const Json& value, const std::string& path, core::Swing* swing, ApiError* error) {
  core::Swing read = *swing;
  // "sweet_spot" in place of the bat-speed point's distance: taken out of a copy of the object
  // before the table reads its numbers.
  std::optional<Json> without_point;
  if (value.is_object()) {
    for (const char* key : {"bat_speed_from_tip_m", "bat_speed_from_tip_in"}) {
      const auto it = value.find(key);
      if (it == value.end() || !it->is_string()) continue;
      if (it->get<std::string>() != "sweet_spot") {
        ObjectReader point_reader(value, path, error);
        return point_reader.Fail(key, "must be a number or \"sweet_spot\" (the bat's own "
                                      "max-exit-speed point)");
      }
      if (!without_point.has_value()) without_point = value;
      without_point->erase(key);
      read.bat_speed_point = core::BatSpeedPoint::kSweetSpot;
    }
  }
  ObjectReader reader(without_point.has_value() ? *without_point : value, path, error);
  if (std::string model; reader.OptionalString("speed_model", &model, {"fixed", "swing_weight"}) &&
                         reader.Has("speed_model")) {
    read.speed_model = *core::ParseSwingSpeedModel(model);
  }
  if (!reader.ok()) return false;
  FieldHost host;
  host.swing = &read;
  std::vector<const Field*> given;
  if (!ReadFieldGroup(reader, FieldGroup::kSwing, host, FieldPresence::kAsDeclared, &given)) {
    return false;
  }
  const auto has = [&given](std::string_view pattern) {
    return std::any_of(given.begin(), given.end(),
                       [pattern](const Field* field) { return IsField(field, pattern); });
  };
  const bool angular = has("swing.angular_speed_rad_s");
  if (angular && has("swing.bat_speed_mps")) {
    return reader.Fail("bat_speed_mps",
                       "give exactly one of swing.bat_speed_mps and swing.angular_speed_rad_s "
                       "(both are given; the bat speed sets the angular speed)");
  }
  if (angular) read.bat_speed_mps.reset();
  if (read.bat_speed_point == core::BatSpeedPoint::kSweetSpot &&
      has("swing.bat_speed_from_tip_m")) {
    return reader.Fail("bat_speed_from_tip_m",
                       "give either a distance or \"sweet_spot\" (both are given)");
  }
  *swing = read;
  return reader.Finish();
}

}  // namespace

bool ReadSceneCommon(ObjectReader& reader, core::Scene* scene) {
  if (const Json* ball = reader.Get("ball")) {
    if (!ReadBall(*ball, reader.PathOf("ball"), &scene->ball, reader.error())) return false;
  }
  if (const Json* swing = reader.Get("swing")) {
    if (!ReadSwing(*swing, reader.PathOf("swing"), &scene->swing, reader.error())) return false;
  }
  FieldHost host;  // "cor": the table of fields
  host.cor = &scene->cor;
  ReadFieldGroup(reader, FieldGroup::kCor, host);
  if (const Json* contact = reader.Get("contact")) {  // "contact": its object's rows
    ObjectReader contact_reader(*contact, reader.PathOf("contact"), reader.error());
    FieldHost contact_host;
    contact_host.contact = &scene->contact;
    if (!ReadFieldGroup(contact_reader, FieldGroup::kContact, contact_host) ||
        !contact_reader.Finish()) {
      return false;
    }
  }
  // "environment" and "aero": the batted ball's flight, read as /v1/flight reads them.
  if (!ReadEnvironment(reader, &scene->environment) || !ReadAero(reader, &scene->aero)) {
    return false;
  }
  std::string inertia = "rigid_body";
  reader.OptionalString("inertia_model", &inertia, {"rigid_body", "slender_rod"});
  scene->inertia_model =
      inertia == "slender_rod" ? core::InertiaModel::kSlenderRod : core::InertiaModel::kRigidBody;
  return reader.ok();
}

bool ReadOutputs(ObjectReader& reader, core::Scene* scene) {
  const Json* outputs = reader.Get("outputs");
  if (outputs == nullptr || !reader.ok()) return reader.ok();
  if (!outputs->is_array() || outputs->empty()) {
    return reader.Fail("outputs", "must be a non-empty array of output names");
  }
  scene->outputs.clear();
  for (std::size_t i = 0; i < outputs->size(); ++i) {
    const Json& item = (*outputs)[i];
    const auto parsed =
        item.is_string() ? core::ParseSceneOutput(item.get<std::string>()) : std::nullopt;
    if (!parsed) {
      return reader.Fail("outputs", "outputs[" + std::to_string(i) + "] = " + Show(item) +
                                        " is not one of " + core::SceneOutputNameList());
    }
    if (std::find(scene->outputs.begin(), scene->outputs.end(), *parsed) == scene->outputs.end()) {
      scene->outputs.push_back(*parsed);
    }
  }
  return true;
}

void ClampToLimits(const ApiLimits& limits, core::HertzOptions* options) {
  options->solver.max_steps = static_cast<int>(
      std::min<long long>(options->solver.max_steps, limits.max_integration_steps));
}

void ClampToLimits(const ApiLimits& limits, core::FlexibleOptions* options) {
  options->impact.max_steps = static_cast<int>(
      std::min<long long>(options->impact.max_steps, limits.max_integration_steps));
}

void ClampToLimits(const ApiLimits& limits, core::SceneOptions* options) {
  options->nlopt.max_time_s = std::min(options->nlopt.max_time_s, limits.max_time_s);
  options->nlopt.max_evaluations = std::min(options->nlopt.max_evaluations, limits.max_iterations);
  // The configured limit is the only cap on curve points (core checks against it).
  options->max_curve_points = static_cast<int>(std::min<std::size_t>(
      limits.max_curve_samples, static_cast<std::size_t>(std::numeric_limits<int>::max())));
  ClampToLimits(limits, &options->hertz);
  ClampToLimits(limits, &options->flexible);
}

bool ReadFlexibleOptions(const Json& value, const std::string& path, const ApiLimits& limits,
                         core::FlexibleOptions* options, ApiError* error) {
  // Types only: the ranges are core's (core::FlexibleOptions::Validate, run by
  // ReadSceneOptions), except max_steps, whose bound is configuration.
  ObjectReader reader(value, path, error);
  std::string theory = core::BeamTheoryName(options->theory);
  reader.OptionalString("theory", &theory, {"timoshenko", "euler_bernoulli"});
  options->theory = core::ParseBeamTheory(theory).value_or(core::BeamTheory::kTimoshenko);
  reader.OptionalNumber("frequency_tolerance", AnyNumber(), &options->frequency_tolerance);
  reader.OptionalInt("max_elements", &options->max_elements);
  core::FlexibleImpactOptions& impact = options->impact;
  reader.OptionalInt("max_modes", &impact.max_modes);
  reader.OptionalNumber("mode_frequency_tolerance", AnyNumber(), &impact.frequency_tolerance);
  reader.OptionalNumber("cutoff_factor", AnyNumber(), &impact.cutoff_factor);
  reader.OptionalBool("static_correction", &impact.static_correction);
  reader.OptionalNumber("relative_tolerance", AnyNumber(), &impact.relative_tolerance);
  ClampToLimits(limits, options);
  long long max_steps = impact.max_steps;
  reader.OptionalInteger("max_steps", 10, limits.max_integration_steps, &max_steps);
  impact.max_steps = static_cast<int>(max_steps);
  reader.OptionalInt("max_contacts", &impact.max_contacts);
  reader.OptionalBool("refine_check", &impact.refine_check);
  reader.OptionalNumber("hands_grip_length_m", AnyNumber(), &impact.hands_grip_length_m);
  reader.OptionalNumber("sting_window_s", AnyNumber(), &impact.sting_window_s);
  reader.OptionalInt("sting_samples", &options->sting_samples);
  reader.OptionalNumber("sting_zone_fraction", AnyNumber(), &options->sting_zone_fraction);
  if (!reader.Finish()) return false;
  // Core names the fields from "flexible." on: the refusal goes under this object's parent
  // ("options" of "options.flexible"; "" of a top-level "flexible").
  core::Refusal refusal;
  if (options->Validate(&refusal)) return true;
  const std::size_t dot = path.rfind('.');
  return CoreRefusal(refusal, dot == std::string::npos ? "" : path.substr(0, dot), error);
}

bool ReadHertzOptions(const Json& value, const std::string& path, const ApiLimits& limits,
                      core::HertzOptions* options, ApiError* error) {
  ClampToLimits(limits, options);
  ObjectReader reader(value, path, error);
  std::string law = core::ContactLawName(options->law);
  reader.OptionalString("law", &law, {"ball_power_law", "paper_constants"});
  options->law = law == "paper_constants" ? core::ContactLaw::kPaperConstants
                                          : core::ContactLaw::kBallPowerLaw;
  if (const Json* paper = reader.Get("paper_constants")) {
    ObjectReader k(*paper, reader.PathOf("paper_constants"), error);
    // Numbers only: their ranges are core's (core::HertzOptions::Validate).
    k.OptionalNumber("k1", AnyNumber(), &options->paper.k1);
    k.OptionalNumber("k2", AnyNumber(), &options->paper.k2);
    k.OptionalNumber("k3", AnyNumber(), &options->paper.k3);
    if (!k.Finish()) return false;
  }
  reader.OptionalNumber("hands_stiffness_n_m", AnyNumber(), &options->hands_stiffness_n_m);
  reader.OptionalNumber("hands_damping_n_s_m", AnyNumber(), &options->hands_damping_n_s_m);
  reader.OptionalBool("bat_surface_compliance", &options->bat_surface_compliance);
  // Its range is core's (ContactIntegrationValidate: [1e-13, 1e-2]).
  reader.OptionalNumber("relative_tolerance", AnyNumber(), &options->solver.relative_tolerance);
  long long max_steps = options->solver.max_steps;
  reader.OptionalInteger("max_steps", 10, limits.max_integration_steps, &max_steps);
  options->solver.max_steps = static_cast<int>(max_steps);
  reader.OptionalBool("refine_check", &options->solver.refine_check);
  return reader.Finish();
}

bool ReadDistanceOptions(const Json& value, const std::string& path, core::DistanceOptions* options,
                         ApiError* error) {
  // Ranges are core's (DistanceOptions::Validate, named "distance.<field>"), checked with the
  // options.
  ObjectReader reader(value, path, error);
  const auto optional_position = [&reader](const char* key, std::optional<double>* out) {
    if (!reader.ok() || !reader.Has(key)) return;
    double v = 0.0;
    reader.OptionalNumber(key, AnyNumber(), &v);
    *out = v;
  };
  optional_position("position_min_from_knob_m", &options->position_min_from_knob_m);
  optional_position("position_max_from_knob_m", &options->position_max_from_knob_m);
  reader.OptionalNumber("undercut_min_m", AnyNumber(), &options->undercut_min_m);
  reader.OptionalNumber("undercut_max_m", AnyNumber(), &options->undercut_max_m);
  reader.OptionalNumber("position_tolerance_m", AnyNumber(), &options->position_tolerance_m);
  reader.OptionalNumber("undercut_tolerance_m", AnyNumber(), &options->undercut_tolerance_m);
  const struct {
    const char* key;
    int* out;
    long long lo, hi;
  } counts[] = {{"coarse_positions", &options->coarse_positions, 2, 201},
                {"coarse_undercuts", &options->coarse_undercuts, 2, 201},
                {"max_evaluations", &options->max_evaluations, 10, 100000},
                {"map_positions", &options->map_positions, 2, 401},
                {"map_undercuts", &options->map_undercuts, 2, 401},
                {"normal_table_speeds", &options->normal_table_speeds, 2, 16},
                {"normal_table_positions", &options->normal_table_positions, 3, 401}};
  for (const auto& c : counts) {
    long long v = *c.out;
    reader.OptionalInteger(c.key, c.lo, c.hi, &v);
    *c.out = static_cast<int>(v);
  }
  return reader.Finish();
}

bool ReadSceneOptions(ObjectReader& top, const ApiLimits& limits, core::SceneOptions* options) {
  ClampToLimits(limits, options);
  const Json* value = top.Get("options");
  if (value == nullptr || !top.ok()) return top.ok();
  ObjectReader reader(*value, top.PathOf("options"), top.error());
  std::string model = "auto";
  reader.OptionalString("model", &model, {"auto", "rigid_pivot", "free_bat", "hertz", "flexible"});
  options->model = *core::ParseCollisionModel(model);
  std::string method = "closed_form";
  reader.OptionalString("method", &method, {"closed_form", "nlopt"});
  options->method =
      method == "nlopt" ? core::SweetSpotMethod::kNlopt : core::SweetSpotMethod::kClosedForm;
  if (const Json* nlopt = reader.Get("nlopt")) {
    ObjectReader n(*nlopt, reader.PathOf("nlopt"), top.error());
    std::string algorithm;
    n.OptionalString("algorithm", &algorithm);
    if (n.ok() && !algorithm.empty()) {
      std::string why;
      const auto parsed = core::ParseNloptAlgorithm(algorithm, &why);
      if (!parsed) {
        std::string names;
        for (const auto a : core::OfferedNloptAlgorithms()) {
          names += (names.empty() ? "" : ", ") + std::string(core::NloptAlgorithmName(a));
        }
        n.Fail("algorithm", "must be one of " + names);
        return false;
      }
      options->nlopt.algorithm = parsed;
    }
    n.OptionalNumber("x_tolerance_m", NumberRule{0.0, 1.0, true, false, false},
                     &options->nlopt.x_tolerance_m);
    long long evaluations = options->nlopt.max_evaluations;
    n.OptionalInteger("max_evaluations", 10, limits.max_iterations, &evaluations);
    options->nlopt.max_evaluations = static_cast<int>(evaluations);
    n.OptionalNumber("max_time_s", Positive(limits.max_time_s), &options->nlopt.max_time_s);
    long long seed = options->nlopt.seed;
    n.OptionalInteger("seed", 0, 4294967295LL, &seed);
    options->nlopt.seed = static_cast<unsigned>(seed);
    if (!n.Finish()) return false;
  }
  const bool has_mps = reader.Has("sweet_zone_tolerance_mps");
  const bool has_percent = reader.Has("sweet_zone_tolerance_percent");
  if (has_mps && has_percent) {
    return reader.Fail("sweet_zone_tolerance_percent",
                       "cannot be given with sweet_zone_tolerance_mps (choose one unit)");
  }
  // Its range is core's (SceneOptions::Validate), which names it by its unit too.
  if (has_percent) {
    reader.OptionalNumber("sweet_zone_tolerance_percent", AnyNumber(),
                          &options->sweet_zone_tolerance);
    options->sweet_zone_unit = core::ToleranceUnit::kPercent;
  } else {
    reader.OptionalNumber("sweet_zone_tolerance_mps", AnyNumber(), &options->sweet_zone_tolerance);
  }
  const double max_samples = static_cast<double>(options->max_curve_points);
  long long samples = options->curve_samples;
  reader.OptionalInteger("curve_samples", 2, static_cast<long long>(max_samples), &samples);
  options->curve_samples = static_cast<int>(samples);
  if (const Json* positions = reader.Get("curve_positions_from_knob_m")) {
    if (!positions->is_array() || positions->empty()) {
      return reader.Fail("curve_positions_from_knob_m", "must be a non-empty array of numbers");
    }
    if (static_cast<double>(positions->size()) > max_samples) {
      return reader.Fail("curve_positions_from_knob_m",
                         "has " + std::to_string(positions->size()) +
                             " positions, over the limit max_curve_samples = " +
                             std::to_string(static_cast<long long>(max_samples)) +
                             " (--max-curve-samples)",
                         ErrorCode::kTooBig);
    }
    for (std::size_t i = 0; i < positions->size(); ++i) {
      const Json& p = (*positions)[i];
      if (!p.is_number()) {
        return reader.Fail("curve_positions_from_knob_m", "curve_positions_from_knob_m[" +
                                                              std::to_string(i) + "] = " + Show(p) +
                                                              " must be a number");
      }
      options->curve_positions_from_knob_m.push_back(p.get<double>());
    }
  }
  if (const Json* hertz = reader.Get("hertz")) {
    if (!ReadHertzOptions(*hertz, reader.PathOf("hertz"), limits, &options->hertz, top.error())) {
      return false;
    }
  }
  if (const Json* distance = reader.Get("distance")) {
    if (!ReadDistanceOptions(*distance, reader.PathOf("distance"), &options->distance,
                             top.error())) {
      return false;
    }
  }
  if (const Json* flexible = reader.Get("flexible")) {
    if (!ReadFlexibleOptions(*flexible, reader.PathOf("flexible"), limits, &options->flexible,
                             top.error())) {
      return false;
    }
  }
  if (!reader.Finish()) return false;
  core::Refusal refusal;
  if (!options->Validate(&refusal)) return CoreRefusal(refusal, top.PathOf("options"), top.error());
  return true;
}

Response CoreFailure(const core::Summary& summary, const std::string& missing_model,
                     const std::string& field, bool options_object) {
  if (!missing_model.empty()) {
    return ErrorResponse(501, ErrorCode::kNotImplemented, summary.message, field);
  }
  if (summary.termination == core::Termination::kInvalidInput) {
    // The summary's refusal names the field in core's names; without one, `field` is reported.
    if (!summary.refusal.has_value() || summary.refusal->field.empty()) {
      return ErrorResponse(400, ErrorCode::kInvalidValue, summary.message, field);
    }
    const core::Refusal& refusal = *summary.refusal;
    const std::string prefix = options_object && !IsSceneField(refusal.field) ? "options" : "";
    // The message in the request's names where core's differ (RequestName); the rest as is.
    std::string message = summary.message;
    const std::string core_text = refusal.Message();
    if (message.compare(0, core_text.size(), core_text) == 0) {
      message.replace(0, core_text.size(), RequestMessage(refusal));
    }
    return ErrorResponse(400, ErrorCode::kInvalidValue, message, RequestField(refusal, prefix));
  }
  // The model ran and could not finish with these inputs and settings (e.g. a
  // step or evaluation budget): the client's to change, so 422, not a 500.
  return ErrorResponse(422, ErrorCode::kModelFailed, "the model failed: " + summary.message, field);
}

Response SceneFailure(const core::Summary& summary, const std::string& missing_model,
                      const core::MassProperties& properties, const std::string& bat_path,
                      const std::string& field, bool options_object) {
  if (summary.termination == core::Termination::kFailure) {
    if (ApiError error; !CheckComputable(properties, bat_path, &error)) return ToResponse(error);
  }
  return CoreFailure(summary, missing_model, field, options_object);
}

}  // namespace sweetspot::api
