// The contract's optimisation example (../shared/docs/api-contract.md, docs/api.md): an ash
// 34 in three-segment bat, the taper start and barrel radius free, an 0.88 kg MLB-legal bat of
// the most exit speed. Shared by the api and server tests that post it.
#pragma once

#include <nlohmann/json.hpp>

namespace sweetspot::testing {

/// The example's body without "options" (each test sets its own).
inline nlohmann::json ContractOptimisation() {
  return nlohmann::json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5},
                  {"path": "three_segment.barrel_radius_m", "min": 0.028, "max": 0.0331}],
    "constraints": {"mass_kg": 0.88, "balance_point_m": {"min": 0.56, "max": 0.60},
                    "moi_six_inch_kg_m2": {"max": 0.20}, "rules": "mlb-wood"},
    "objective": "max_exit_speed", "cor": 0.5})");
}

}  // namespace sweetspot::testing
