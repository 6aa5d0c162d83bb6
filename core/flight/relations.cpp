// The published relations a flight uses besides its equations of motion (core/flight/flight.hpp):
// the air's density from the weather (Nathan's calculator, cell D2), the Statcast relation of
// spin to launch and spray angle, and Statcast's labels of a launch.
#include <cmath>

#include "core/flight/flight.hpp"

namespace sweetspot::core::flight {
namespace {

// Pa per mmHg (101325 / 760).
constexpr double kPaPerMmHg = 133.322368;
// The calculator's scale height of pressure with elevation, per metre.
constexpr double kPressureScalePerM = 1.217e-4;

}  // namespace

double SaturationVapourPressurePa(double temperature_c) {
  const double t = temperature_c;
  return 4.5841 * std::exp((18.687 - t / 234.5) * t / (257.14 + t)) * kPaPerMmHg;
}

double StationPressurePa(double sea_level_pressure_pa, double elevation_m) {
  return sea_level_pressure_pa * std::exp(-kPressureScalePerM * elevation_m);
}

double AirDensityKgM3(const Environment& e) {
  // The calculator's cell D2, with pressures in mmHg: 1.2929 kg/m³ is dry air at 0 °C and
  // 760 mmHg; 0.3783 = 1 − 0.622 (water vapour's molar mass over dry air's, the CRC form).
  const double t = e.temperature_c;
  const double p_mmhg = StationPressurePa(e.sea_level_pressure_pa, e.elevation_m) / kPaPerMmHg;
  const double svp_mmhg = SaturationVapourPressurePa(t) / kPaPerMmHg;
  return 1.2929 * (273.0 / (t + 273.0)) *
         (p_mmhg - 0.3783 * e.relative_humidity_pct * svp_mmhg / 100.0) / 760.0;
}

Spin EstimateSpin(double launch_angle_deg, double spray_angle_deg, BatterHand hand) {
  const double s = hand == BatterHand::kLeft ? -1.0 : 1.0;
  return {-763.0 + 120.0 * launch_angle_deg + 21.0 * spray_angle_deg * s,
          -849.0 * s - 94.0 * spray_angle_deg};
}

Classification Classify(double exit_speed_mps, double launch_angle_deg) {
  // Statcast's definitions are in mph; 1e-9 absorbs the round trip of an mph input.
  const double ev = exit_speed_mps / kMpsPerMph + 1e-9;
  const double la = launch_angle_deg;
  Classification c;
  c.hard_hit = ev >= 95.0;
  c.sweet_spot_launch = la >= 8.0 && la <= 32.0;
  c.barrel = ev >= 98.0 && la <= 50.0 && 1.5 * ev - la >= 117.0 && ev + la >= 124.0;
  return c;
}

}  // namespace sweetspot::core::flight
