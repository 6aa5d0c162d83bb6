#include "api/flight_json.hpp"

#include <cmath>
#include <initializer_list>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/units.hpp"

namespace sweetspot::api {
namespace flight_json {
namespace {

using Json = nlohmann::json;
namespace flight = core::flight;

// One spelling of a quantity: SI = written * scale + offset.
struct Spelling {
  const char* key;
  double scale = 1.0;
  double offset = 0.0;
};

constexpr double kPaPerInHg = 3386.389;  // at 0 °C, NIST SP 811
constexpr double kPaPerHpa = 100.0;

// Reads the quantity `core_field` from the first spelling of `spellings` the object gives (at
// most one may be given), into *out in SI; records where it was given. The range is core's.
bool ReadQuantity(ObjectReader& reader, const std::string& core_field,
                  std::initializer_list<Spelling> spellings, double* out,
                  std::vector<GivenField>* given) {
  if (!reader.ok()) return false;
  const Spelling* found = nullptr;
  for (const Spelling& s : spellings) {
    if (!reader.Has(s.key)) continue;
    if (found != nullptr) {
      return reader.Fail(s.key, "cannot be given together with " + reader.PathOf(found->key) +
                                    " (one quantity, give it in one form)");
    }
    found = &s;
  }
  if (found == nullptr) return true;
  const Json* value = reader.Get(found->key);
  if (!value->is_number()) return reader.Fail(found->key, "must be a number");
  const double written = value->get<double>();
  *out = written * found->scale + found->offset;
  given->push_back({core_field, reader.PathOf(found->key), written});
  return true;
}

// Maps core's refusal of a struct read at `prefix` onto the request: under the name and the
// value the request wrote when it wrote another unit.
bool Refused(const core::Refusal& refusal, const std::string& prefix,
             const std::vector<GivenField>& given, ApiError* error) {
  for (const GivenField& g : given) {
    if (g.core_field != refusal.field) continue;
    const std::string written_key = g.path.substr(g.path.rfind('.') + 1);
    const std::string core_key = g.core_field.substr(g.core_field.rfind('.') + 1);
    if (written_key == core_key) break;
    // "path = written: rule as core_key (SI value)", the number as the request wrote it.
    return SetError(error, ErrorCode::kInvalidValue, g.path, nullptr,
                    "= " + core::FormatNumber(g.written) + ": " + refusal.rule + " as " + core_key +
                        " (" + refusal.shown + ")");
  }
  return CoreRefusal(refusal, prefix, error);
}

bool ReadWind(ObjectReader& parent, flight::Wind* wind, std::vector<GivenField>* given) {
  const Json* value = parent.Get("wind");
  if (value == nullptr || !parent.ok()) return parent.ok();
  ObjectReader reader(*value, parent.PathOf("wind"), parent.error());
  ReadQuantity(reader, "wind.speed_mps", {{"speed_mps"}, {"speed_mph", core::flight::kMpsPerMph}},
               &wind->speed_mps, given);
  ReadQuantity(reader, "wind.direction_deg", {{"direction_deg"}}, &wind->direction_deg, given);
  return reader.Finish();
}

}  // namespace
}  // namespace flight_json

using flight_json::ReadQuantity;
using flight_json::Refused;
using flight_json::Spelling;

bool ReadLaunch(const nlohmann::json& value, const std::string& path, core::flight::Launch* launch,
                ApiError* error) {
  ObjectReader reader(value, path, error);
  std::vector<GivenField> given;
  constexpr double kFt = core::flight::kMetresPerFoot, kIn = 0.0254;
  if (reader.ok() && !reader.Has("exit_speed_mps") && !reader.Has("exit_speed_mph")) {
    return reader.Missing("exit_speed_mps");
  }
  ReadQuantity(reader, "exit_speed_mps",
               {{"exit_speed_mps"}, {"exit_speed_mph", core::flight::kMpsPerMph}},
               &launch->exit_speed_mps, &given);
  if (reader.ok() && !reader.Has("launch_angle_deg")) return reader.Missing("launch_angle_deg");
  ReadQuantity(reader, "launch_angle_deg", {{"launch_angle_deg"}}, &launch->launch_angle_deg,
               &given);
  ReadQuantity(reader, "spray_angle_deg", {{"spray_angle_deg"}}, &launch->spray_angle_deg, &given);
  double spin = 0.0;
  if (reader.ok() && reader.Has("backspin_rpm")) {
    ReadQuantity(reader, "backspin_rpm", {{"backspin_rpm"}}, &spin, &given);
    launch->backspin_rpm = spin;
  }
  if (reader.ok() && reader.Has("sidespin_rpm")) {
    ReadQuantity(reader, "sidespin_rpm", {{"sidespin_rpm"}}, &spin, &given);
    launch->sidespin_rpm = spin;
  }
  ReadQuantity(reader, "height_m", {{"height_m"}, {"height_ft", kFt}, {"height_in", kIn}},
               &launch->height_m, &given);
  ReadQuantity(reader, "start_x_m", {{"start_x_m"}, {"start_x_ft", kFt}, {"start_x_in", kIn}},
               &launch->start_x_m, &given);
  ReadQuantity(reader, "start_y_m", {{"start_y_m"}, {"start_y_ft", kFt}, {"start_y_in", kIn}},
               &launch->start_y_m, &given);
  std::string hand = "right";
  reader.OptionalString("batter_hand", &hand, {"right", "left"});
  launch->batter_hand =
      hand == "left" ? core::flight::BatterHand::kLeft : core::flight::BatterHand::kRight;
  if (!reader.Finish()) return false;
  if (core::Refusal refusal; !launch->Validate(&refusal)) {
    return Refused(refusal, path, given, error);
  }
  return true;
}

bool ReadEnvironment(ObjectReader& parent, core::flight::Environment* environment) {
  const nlohmann::json* value = parent.Get("environment");
  if (value == nullptr || !parent.ok()) return parent.ok();
  const std::string path = parent.PathOf("environment");
  ObjectReader reader(*value, path, parent.error());
  std::vector<GivenField> given;
  ReadQuantity(reader, "temperature_c",
               {{"temperature_c"}, {"temperature_f", 5.0 / 9.0, -32.0 * 5.0 / 9.0}},
               &environment->temperature_c, &given);
  ReadQuantity(reader, "elevation_m",
               {{"elevation_m"}, {"elevation_ft", core::flight::kMetresPerFoot}},
               &environment->elevation_m, &given);
  ReadQuantity(reader, "relative_humidity_pct", {{"relative_humidity_pct"}},
               &environment->relative_humidity_pct, &given);
  ReadQuantity(
      reader, "sea_level_pressure_pa",
      {{"pressure_hpa", flight_json::kPaPerHpa}, {"pressure_inhg", flight_json::kPaPerInHg}},
      &environment->sea_level_pressure_pa, &given);
  flight_json::ReadWind(reader, &environment->wind, &given);
  if (!reader.Finish()) return false;
  if (core::Refusal refusal; !environment->Validate(&refusal)) {
    return Refused(refusal, path, given, parent.error());
  }
  return true;
}

bool ReadAero(ObjectReader& parent, core::flight::AeroOptions* aero) {
  const nlohmann::json* value = parent.Get("aero");
  if (value == nullptr || !parent.ok()) return parent.ok();
  const std::string path = parent.PathOf("aero");
  ObjectReader reader(*value, path, parent.error());
  std::string model = "nathan-2016";
  reader.OptionalString("model", &model, {"nathan-2016", "sawicki-2003", "vacuum", "custom"});
  if (model == "sawicki-2003") aero->model = core::flight::AeroModel::kSawicki2003;
  if (model == "vacuum") aero->model = core::flight::AeroModel::kVacuum;
  if (model == "custom") aero->model = core::flight::AeroModel::kCustom;
  const bool custom = aero->model == core::flight::AeroModel::kCustom;
  std::vector<GivenField> given;
  // The custom coefficients only with "custom": a coefficient that would be ignored is refused.
  struct Coefficient {
    const char* key;
    double* out;
  };
  const Coefficient coefficients[] = {
      {"cd0", &aero->cd0}, {"cd_spin_per_krpm", &aero->cd_spin_per_krpm},
      {"cl0", &aero->cl0}, {"cl1", &aero->cl1},
      {"cl2", &aero->cl2}, {"cl_per_spin_factor", &aero->cl_per_spin_factor}};
  for (const Coefficient& c : coefficients) {
    if (!reader.ok()) break;
    if (reader.Has(c.key) && !custom) {
      reader.Fail(c.key, "is a coefficient of \"model\": \"custom\" (model is \"" + model + "\")");
      break;
    }
    ReadQuantity(reader, c.key, {{c.key}}, c.out, &given);
  }
  if (reader.ok() && reader.Has("lift_law")) {
    if (!custom) {
      reader.Fail("lift_law", "is a setting of \"model\": \"custom\" (model is \"" + model + "\")");
    }
    std::string law = "saturating";
    reader.OptionalString("lift_law", &law, {"saturating", "linear"});
    aero->lift_law =
        law == "linear" ? core::flight::LiftLaw::kLinear : core::flight::LiftLaw::kSaturating;
  }
  if (reader.ok() && reader.Has("spin_decay_s") &&
      aero->model != core::flight::AeroModel::kNathan2016 && !custom) {
    reader.Fail("spin_decay_s", "applies to nathan-2016 and custom only (model is \"" + model +
                                    "\", which keeps its spin)");
  }
  ReadQuantity(reader, "spin_decay_s", {{"spin_decay_s"}}, &aero->spin_decay_s, &given);
  ReadQuantity(reader, "ball_mass_kg",
               {{"ball_mass_kg"}, {"ball_mass_oz", core::kKilogramsPerOunce}}, &aero->ball_mass_kg,
               &given);
  ReadQuantity(reader, "ball_circumference_m",
               {{"ball_circumference_m"}, {"ball_circumference_in", 0.0254}},
               &aero->ball_circumference_m, &given);
  if (!reader.Finish()) return false;
  if (core::Refusal refusal; !aero->Validate(&refusal)) {
    return Refused(refusal, path, given, parent.error());
  }
  return true;
}

std::optional<FlightRequest> ParseFlight(const nlohmann::json& body, const ApiLimits& limits,
                                         ApiError* error) {
  ObjectReader reader(body, "", error);
  FlightRequest request;
  const nlohmann::json* one = reader.Get("launch");
  const nlohmann::json* many = reader.Get("launches");
  if (!reader.ok()) return std::nullopt;
  if (one != nullptr && many != nullptr) {
    reader.Fail("launches", "cannot be given together with launch (one launch, or an array)");
    return std::nullopt;
  }
  if (one == nullptr && many == nullptr) {
    reader.Missing("launch");
    return std::nullopt;
  }
  if (one != nullptr) {
    request.launches.emplace_back();
    if (!ReadLaunch(*one, "launch", &request.launches.back(), error)) return std::nullopt;
  } else {
    request.many = true;
    if (!many->is_array() || many->empty()) {
      reader.Fail("launches", "must be a non-empty array of launch objects");
      return std::nullopt;
    }
    if (many->size() > limits.max_launches) {
      reader.Fail("launches",
                  "has " + std::to_string(many->size()) +
                      " launches, over the limit max_launches = " +
                      std::to_string(limits.max_launches) + " (--max-launches)",
                  ErrorCode::kTooBig);
      return std::nullopt;
    }
    request.launches.resize(many->size());
    for (std::size_t i = 0; i < many->size(); ++i) {
      if (!ReadLaunch((*many)[i], "launches[" + std::to_string(i) + "]", &request.launches[i],
                      error)) {
        return std::nullopt;
      }
    }
  }
  if (!ReadEnvironment(reader, &request.environment) || !ReadAero(reader, &request.aero)) {
    return std::nullopt;
  }
  if (const nlohmann::json* outputs = reader.Get("outputs"); outputs != nullptr && reader.ok()) {
    if (!outputs->is_array()) {
      reader.Fail("outputs", "must be an array of output names (\"trajectory\")");
      return std::nullopt;
    }
    for (std::size_t i = 0; i < outputs->size(); ++i) {
      const nlohmann::json& item = (*outputs)[i];
      if (!item.is_string() || item.get<std::string>() != "trajectory") {
        reader.Fail("outputs", "outputs[" + std::to_string(i) + "] = " + Show(item) +
                                   " is not one of trajectory");
        return std::nullopt;
      }
      request.trajectory = true;
    }
  }
  if (const nlohmann::json* options = reader.Get("options"); options != nullptr && reader.ok()) {
    ObjectReader o(*options, "options", error);
    std::vector<GivenField> given;
    ReadQuantity(o, "relative_tolerance", {{"relative_tolerance"}},
                 &request.options.relative_tolerance, &given);
    ReadQuantity(o, "absolute_tolerance_m", {{"absolute_tolerance_m"}},
                 &request.options.absolute_tolerance_m, &given);
    ReadQuantity(o, "max_flight_time_s", {{"max_flight_time_s"}},
                 &request.options.max_flight_time_s, &given);
    ReadQuantity(o, "trajectory_interval_s", {{"trajectory_interval_s"}},
                 &request.options.trajectory_interval_s, &given);
    if (!o.Finish()) return std::nullopt;
    if (core::Refusal refusal; !request.options.Validate(&refusal)) {
      Refused(refusal, "options", given, error);
      return std::nullopt;
    }
  }
  // A trajectory is bounded by the answer's size: at most kMaxTrajectorySamples samples over
  // all launches (about 8 MB of JSON), counted at the time limit (a flight's most).
  if (request.trajectory) {
    const double per_flight =
        std::floor(request.options.max_flight_time_s / request.options.trajectory_interval_s) + 2;
    const double total = per_flight * static_cast<double>(request.launches.size());
    if (total > kMaxTrajectorySamples) {
      SetError(error, ErrorCode::kTooBig, "outputs", nullptr,
               "asks for up to " + core::FormatNumber(total) +
                   " trajectory samples (launches x (max_flight_time_s / trajectory_interval_s "
                   "+ 2)), over the limit of " +
                   core::FormatNumber(kMaxTrajectorySamples) +
                   ": fewer launches, a longer options.trajectory_interval_s or a shorter "
                   "options.max_flight_time_s");
      return std::nullopt;
    }
  }
  if (!reader.Finish()) return std::nullopt;
  return request;
}

std::string NotLandedMessage(const core::flight::FlightResult& result,
                             const core::flight::FlightOptions& options) {
  using core::flight::FlightTermination;
  switch (result.termination) {
    case FlightTermination::kTimeLimit:
      return "the ball was still in the air at max_flight_time_s = " +
             core::FormatNumber(options.max_flight_time_s) + " s (no landing)";
    case FlightTermination::kStepLimit:
      return "the integrator took max_steps = " + std::to_string(options.max_steps) +
             " steps before the ball landed";
    case FlightTermination::kNonFinite:
      return "the equations of motion gave a non-finite value";
    default:
      return result.refusal ? result.refusal->Message() : "refused";
  }
}

nlohmann::json FlightToJson(const core::flight::FlightResult& r,
                            const core::flight::AeroOptions& aero,
                            const std::vector<core::flight::TrajectoryPoint>* trajectory) {
  using core::flight::FlightTerminationName;
  nlohmann::json numerics = {{"method", "dormand_prince_5_4"},
                             {"termination", FlightTerminationName(r.termination)},
                             {"error_estimate_m", r.error_estimate_m},
                             {"steps", r.steps},
                             {"rejected_steps", r.rejected_steps},
                             {"evaluations", r.evaluations}};
  nlohmann::json out = {{"aero_model", core::flight::AeroModelName(aero.model)},
                        {"spin_source", core::flight::SpinSourceName(r.spin_source)},
                        {"backspin_rpm", r.spin.backspin_rpm},
                        {"sidespin_rpm", r.spin.sidespin_rpm},
                        {"air_density_kg_m3", r.air_density_kg_m3},
                        {"classification",
                         {{"barrel", r.classification.barrel},
                          {"hard_hit", r.classification.hard_hit},
                          {"sweet_spot_launch", r.classification.sweet_spot_launch}}},
                        {"numerics", std::move(numerics)}};
  if (r.Landed()) {
    out["distance_m"] = r.distance_m;
    out["hang_time_s"] = r.hang_time_s;
    out["apex_m"] = r.apex_m;
    out["apex_time_s"] = r.apex_time_s;
    out["landing"] = {{"x_m", r.landing_x_m}, {"y_m", r.landing_y_m}};
    out["bearing_deg"] = r.bearing_deg;
    out["landing_speed_mps"] = r.landing_speed_mps;
    out["landing_angle_deg"] = r.landing_angle_deg;
  }
  if (aero.model == core::flight::AeroModel::kSawicki2003) {
    // Its drag curve is this service's reading of the paper's description, not the paper's
    // numbers (core/flight/flight.cpp, SawickiDrag): the answer says so.
    out["warnings"] = nlohmann::json::array(
        {"aero.model sawicki-2003: the lift law is the paper's fit; the drag curve is an "
         "approximation of the paper's description of the drag crisis (0.5 to 0.2 around "
         "30 m/s), not values read from its figure, and is not validated (docs/flight.md)"});
  }
  if (trajectory != nullptr) {
    nlohmann::json points = nlohmann::json::array();
    for (const auto& p : *trajectory) {
      points.push_back({{"t_s", p.t_s},
                        {"x_m", p.x_m},
                        {"y_m", p.y_m},
                        {"z_m", p.z_m},
                        {"speed_mps", p.speed_mps}});
    }
    out["trajectory"] = std::move(points);
  }
  return out;
}

}  // namespace sweetspot::api
