// A structure-aware mutation for the libFuzzer targets: the input's JSON part
// (from its first '{' or '[') is parsed, one value in it is changed the way
// hostile clients change requests (extreme or special numbers, other field
// names and enum values, dropped, duplicated or swapped members), and the
// input is written back. Byte-level mutations alone rarely keep a request
// valid JSON, so they seldom reach the handlers' numerical code.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace sweetspot::fuzz {

namespace internal {

// Numbers that break numerical code: zeros, extremes, subnormals, integers
// just past common limits.
inline const std::vector<double>& SpecialNumbers() {
  // clang-format off
  static const std::vector<double> numbers = {
      0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 3.0, 10.0, 64.0, 65.0, 100.0, 1e4, 10001.0, 1e5,
      1e-300, -1e-300, 5e-324, 1e-15, 1e-9, 1e-6, 1e-3, 1e3, 1e9, 1e12, 1e15, 1e300, -1e300,
      4294967296.0, 9007199254740993.0, 1.7976931348623157e308, 2.2250738585072014e-308};
  // clang-format on
  return numbers;
}

// Strings the handlers compare against: field names and enumerated values.
inline const std::vector<std::string>& SpecialStrings() {
  // clang-format off
  static const std::vector<std::string> strings = {
      "", "bat", "baseline", "variants", "name", "preset", "three_segment", "profile", "knots",
      "x_m", "radius_m", "material", "fill", "wall_thickness_m", "diameter_m", "depth_m",
      "length_m", "handle_radius_m", "barrel_radius_m", "taper_start_m", "taper_end_m",
      "density_kg_m3", "youngs_modulus_pa", "shear_modulus_pa", "poissons_ratio", "cor", "ball",
      "mass_kg", "speed_mps", "stiffness_n_m_p", "stiffness_exponent", "swing",
      "angular_speed_rad_s", "pivot_from_knob_m", "hands_from_knob_m", "inertia_model",
      "rigid_body", "slender_rod", "outputs", "max_exit_speed", "center_of_percussion",
      "vibration_node", "sweet_zone", "exit_speed_curve", "collision_efficiency", "properties",
      "options", "model", "auto", "rigid_pivot", "free_bat", "hertz", "flexible", "method",
      "closed_form", "nlopt", "algorithm", "LN_BOBYQA", "LN_COBYLA", "LD_SLSQP", "GN_DIRECT_L",
      "GN_AGS", "x_tolerance_m", "max_evaluations", "max_time_s", "seed", "curve_samples",
      "curve_positions_from_knob_m", "sweet_zone_tolerance_mps", "sweet_zone_tolerance_percent",
      "law", "paper_constants", "ball_power_law", "k1", "k2", "k3", "hands_stiffness_n_m",
      "hands_damping_n_s_m", "bat_surface_compliance", "relative_tolerance", "max_steps",
      "refine_check", "contact_details", "impact_from_knob_m", "targets", "unknowns",
      "fill.depth_m", "fill.diameter_m", "fill.density_kg_m3", "tolerance", "mass_scale_kg",
      "balance_point_m", "balance_point_scale_m", "parameters", "path", "min", "max", "count",
      "sampling", "grid", "lhs", "sobol", "samples", "pareto", "objectives", "output", "sense",
      "shard", "index", "format", "json", "ndjson", "paper-wood", "paper-wood-m885", "wood-34-ash",
      "bbcor-33-aluminium", "ash", "hard-maple", "yellow-birch", "aluminium-7046", "aluminium-7050",
      "cork", "rubber", "empty", "/v1/sweet-spot", "/v1/compare", "bat.profile.knots[1].radius_m",
      "max_exit_speed.exit_speed_mps", "parameters.cor"};
  // clang-format on
  return strings;
}

// Every value in `root` (pre-order), for picking one at random.
inline void CollectValues(nlohmann::json* root, std::vector<nlohmann::json*>* out) {
  out->push_back(root);
  if (root->is_structured()) {
    for (auto& item : *root) CollectValues(&item, out);
  }
}

// Changes `value` once; `all` is every value of the document (for copies).
inline void MutateValue(nlohmann::json* value, const std::vector<nlohmann::json*>& all,
                        std::minstd_rand* rng) {
  auto pick = [rng](std::size_t n) { return static_cast<std::size_t>((*rng)() % n); };
  const auto& numbers = SpecialNumbers();
  const auto& strings = SpecialStrings();
  switch (pick(value->is_number() ? 10 : value->is_structured() ? 8 : 6)) {
    case 0:  // a copy of another value (crossover within the document)
      *value = nlohmann::json(*all[pick(all.size())]);
      return;
    case 1:
      *value = strings[pick(strings.size())];
      return;
    case 2:
      *value = numbers[pick(numbers.size())];
      return;
    case 3: {
      const nlohmann::json kinds[] = {nullptr, true, false, nlohmann::json::object(),
                                      nlohmann::json::array()};
      *value = kinds[pick(5)];
      return;
    }
    case 4:
    case 5:
      if (value->is_object()) {
        (*value)[strings[pick(strings.size())]] = nlohmann::json(*all[pick(all.size())]);
        return;
      }
      if (value->is_array()) {
        value->push_back(value->empty() ? nlohmann::json(numbers[pick(numbers.size())])
                                        : nlohmann::json((*value)[pick(value->size())]));
        return;
      }
      if (value->is_string()) {
        *value = strings[pick(strings.size())];
        return;
      }
      *value = numbers[pick(numbers.size())];
      return;
    case 6:  // drop a member or an element
    case 7:
      if (value->is_object() && !value->empty()) {
        auto it = value->begin();
        std::advance(it, static_cast<std::ptrdiff_t>(pick(value->size())));
        value->erase(it);
      } else if (value->is_array() && !value->empty()) {
        value->erase(pick(value->size()));
      } else {
        *value = nlohmann::json(*all[pick(all.size())]);
      }
      return;
    default: {  // numbers only: scale, negate, nudge
      const double x = value->get<double>();
      const double factors[] = {10.0, 0.1, -1.0, 1.0 + 1e-12, 1.0 - 1e-12, 1e100, 1e-100, 2.0};
      const double y = x * factors[pick(8)];
      *value = std::isfinite(y) ? y : numbers[pick(numbers.size())];
      return;
    }
  }
}

}  // namespace internal

/// Mutates the JSON part of `data` (size bytes, capacity max_size) in place
/// and returns the new size, or 0 when the input holds no parsable JSON (the
/// caller then mutates the bytes instead).
inline std::size_t MutateJson(std::uint8_t* data, std::size_t size, std::size_t max_size,
                              unsigned seed) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t start = input.find_first_of("{[");
  if (start == std::string_view::npos) return 0;
  nlohmann::json root = nlohmann::json::parse(input.substr(start), nullptr,
                                              /*allow_exceptions=*/false);
  if (root.is_discarded() || !root.is_structured()) return 0;
  std::minstd_rand rng(seed == 0 ? 1u : seed);
  const int rounds = 1 + static_cast<int>(rng() % 3);
  for (int i = 0; i < rounds; ++i) {
    std::vector<nlohmann::json*> all;
    internal::CollectValues(&root, &all);
    if (all.size() > 4096) return 0;  // keep a mutation cheap
    internal::MutateValue(all[rng() % all.size()], all, &rng);
  }
  const std::string json = root.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (start + json.size() > max_size) return 0;
  std::memcpy(data + start, json.data(), json.size());
  return start + json.size();
}

}  // namespace sweetspot::fuzz
