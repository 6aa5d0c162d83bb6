// SI convention and unit conversions. Everything inside core is SI (m, kg, s,
// N, Pa, J, rad/s); imperial units appear only at the API boundary, through
// the helpers below. Positions along the bat are measured from the knob.
#pragma once

namespace sweetspot::core {

/// Metres per inch (exact, by definition).
inline constexpr double kMetresPerInch = 0.0254;
/// Kilograms per avoirdupois ounce (exact, by definition).
inline constexpr double kKilogramsPerOunce = 0.028349523125;
/// The bat industry's standard pivot for MOI: 6 in from the knob, in metres.
inline constexpr double kSixInchPivotM = 6.0 * kMetresPerInch;
/// pi to double precision.
inline constexpr double kPi = 3.14159265358979323846;

/// Inches to metres.
constexpr double InchesToMetres(double in) { return in * kMetresPerInch; }
/// Metres to inches.
constexpr double MetresToInches(double m) { return m / kMetresPerInch; }
/// Ounces to kilograms.
constexpr double OuncesToKilograms(double oz) { return oz * kKilogramsPerOunce; }
/// Kilograms to ounces.
constexpr double KilogramsToOunces(double kg) { return kg / kKilogramsPerOunce; }
/// kg·m² to oz·in².
constexpr double KgM2ToOzIn2(double kg_m2) {
  return kg_m2 / (kKilogramsPerOunce * kMetresPerInch * kMetresPerInch);
}

/// oz·in² to kg·m².
constexpr double OzIn2ToKgM2(double oz_in2) {
  return oz_in2 * (kKilogramsPerOunce * kMetresPerInch * kMetresPerInch);
}
/// A bat's drop: length in inches minus weight in ounces (3 for a 33-in, 30-oz
/// bat, which the industry labels "-3").
constexpr double BatDrop(double length_in, double weight_oz) { return length_in - weight_oz; }

}  // namespace sweetspot::core
