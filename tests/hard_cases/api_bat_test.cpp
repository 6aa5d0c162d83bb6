// Endpoint hard cases of the bat endpoints: POST /v1/bat/properties, /v1/bat/fit and
// /v1/bat/modes. Each nasty request must answer 200 with finite numbers in a bounded range, or
// the named 4xx refusal; never a 500, never NaN or Infinity (checked on every row).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "tests/hard_cases/hard_case.hpp"

namespace sweetspot::hard_cases {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace api_bat_test {
namespace {

constexpr long double kPi = 3.141592653589793238462643383279502884L;
constexpr long double kRho = 649;  // paper-wood, kg/m^3 (the default material)

// The double nearest to a decimal (as the JSON parser reads it), widened exactly.
constexpr long double Wide(double v) { return v; }

// A number as JSON text, round-trip exact.
std::string N(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// A cylinder bat of paper-wood (`extra`: more fields of the bat, with a leading comma).
std::string Cylinder(double length_m, double radius_m, const std::string& extra = "") {
  return R"({"three_segment": {"length_m": )" + N(length_m) + R"(, "handle_radius_m": )" +
         N(radius_m) + R"(, "barrel_radius_m": )" + N(radius_m) +
         R"(, "taper_start_m": 0, "taper_end_m": 0})" + extra + "}";
}

std::string Bat(const std::string& bat, const std::string& rest = "") {
  return R"({"bat": )" + bat + rest + "}";
}

const char* const kPaper = R"({"preset": "paper-wood"})";

// paper-wood's properties (README, presets): M, C, I_cm, V.
constexpr long double kPaperMass = 1.0078187508438627L;
constexpr long double kPaperBalance = 0.6089948432432433L;
constexpr long double kPaperMoiCentroid = 0.03865419654549034L;
constexpr long double kPaperVolume = 0.0015528794311923924L;

// Relative tolerance of closed-form properties in the API (core's rows bound them to 8 eps;
// the JSON round trip is exact): 16 eps.
constexpr long double kRel = 16 * kEps;

JsonCheck Rel(std::string pointer, long double expected, long double rel = kRel) {
  return Near(std::move(pointer), expected, rel * (expected < 0 ? -expected : expected));
}

// POST /v1/bat/properties: scales, degenerate geometry, cancellation, underflow.
std::vector<ApiCase> PropertiesCases() {
  const std::string p = "/v1/bat/properties";
  const long double cyl_mass = kRho * kPi * 0.03L * 0.03L * 0.86L;
  return {
      Ok("MicrometreBat", p, Bat(Cylinder(1e-6, 1e-6)),
         {Rel("/mass_kg", kRho * kPi * 1e-18L),
          Rel("/moi_centroid_kg_m2", kRho * kPi * 1e-18L * (1e-12L / 12 + 1e-12L / 4))}),
      // The largest bat the API takes: 100 m long, radius 10 m.
      Ok("HundredMetreBat", p, Bat(Cylinder(100, 10)),
         {Rel("/mass_kg", kRho * kPi * 1e4L), Rel("/balance_point_m", 50),
          Rel("/moi_centroid_kg_m2", kRho * kPi * 1e4L * (1e4L / 12 + 25))}),
      Refusal("LongerThanAHundredMetres", p, Bat(Cylinder(101, 0.03)), 400, "InvalidValue",
              "bat.three_segment.length_m"),
      Refusal("ZeroLengthBat", p, Bat(Cylinder(0, 0.03)), 400, "InvalidValue",
              "bat.three_segment.length_m"),
      Refusal(
          "ZeroLengthProfile", p,
          Bat(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 0.01}, {"x_m": 0, "radius_m": 0.01}]}})"),
          400, "InvalidValue", "bat.profile.knots[1].x_m"),
      Refusal("SingleKnot", p, Bat(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 0.01}]}})"),
              400, "InvalidValue", "bat.profile.knots"),
      // A single segment is a cylinder: closed forms.
      Ok("SingleSegmentProfile", p,
         Bat(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 0.03}, {"x_m": 0.86, "radius_m": 0.03}]}})"),
         {Rel("/mass_kg", cyl_mass), Rel("/balance_point_m", 0.43L),
          Rel("/moi_centroid_kg_m2", cyl_mass * (0.86L * 0.86L / 12 + 0.03L * 0.03L / 4))}),
      // A step 1e-12 m wide: the short taper's mass is ~1e-12 of the total, so the two
      // cylinders' mass holds to 1e-11 relative.
      Ok("StepKnotsPicometreApart", p,
         Bat(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 0.0125}, {"x_m": 0.4, "radius_m": 0.0125},
             {"x_m": 0.400000000001, "radius_m": 0.035}, {"x_m": 0.86, "radius_m": 0.035}]}})"),
         {Rel("/mass_kg", kRho * kPi * (0.0125L * 0.0125L * 0.4L + 0.035L * 0.035L * 0.46L),
              1e-11)}),
      // Radii of 1e-300 m: r^2 underflows, the mass is 0: refused, not NaN.
      Refusal(
          "RadiusWhoseSquareUnderflows", p,
          Bat(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 1e-300}, {"x_m": 0.8, "radius_m": 1e-300}]}})"),
          400, "InvalidValue", "bat"),
      Refusal(
          "SubnormalDensity", p,
          Bat(R"({"preset": "paper-wood", "material": {"density_kg_m3": 4e-320, "youngs_modulus_pa": 1e10}})"),
          400, "InvalidValue", "bat"),
      // Density 1e-300: mass 1.55e-303 kg, still a normal double: answered.
      Ok("DensityOf1e-300", p,
         Bat(R"({"preset": "paper-wood", "material": {"density_kg_m3": 1e-300, "youngs_modulus_pa": 1e10}})"),
         {Rel("/mass_kg", 1e-300L * kPaperVolume, 1e-15), Rel("/balance_point_m", kPaperBalance)}),
      Ok("DensityAndStiffnessAtTheirMaxima", p,
         Bat(R"({"preset": "paper-wood", "material": {"density_kg_m3": 1e5, "youngs_modulus_pa": 1e13}})"),
         {Rel("/mass_kg", 1e5L * kPaperVolume, 1e-15)}),
      // Catastrophic cancellation: a wall 1e-9 of the radius, rho pi t (2r - t) L.
      Ok("ShellWallBillionthOfRadius", p,
         Bat(Cylinder(0.86, 0.03, R"(, "wall_thickness_m": 3e-11)")),
         {Rel("/mass_kg", kRho * kPi * Wide(3e-11) * (2 * Wide(0.03) - Wide(3e-11)) * Wide(0.86))}),
      Ok("WallAlmostTheRadius", p,
         Bat(R"({"preset": "paper-wood", "wall_thickness_m": 0.0124999999})"),
         {Between("/mass_kg", 0.5, kPaperMass),
          Between("/moi_centroid_kg_m2", 0, kPaperMoiCentroid)}),
      Refusal("WallEqualToTheRadius", p,
              Bat(R"({"preset": "paper-wood", "wall_thickness_m": 0.0125})"), 400, "InvalidValue",
              "bat.wall_thickness_m"),
      // A bore leaving 1e-9 of the radius: rho pi (r - r_f)(r + r_f) L, to the 8 eps x 5e8
      // the superposed bore allows (core table).
      Ok("BoreLeavesABillionthOfTheRadius", p,
         Bat(Cylinder(
             0.86, 0.03,
             R"(, "fill": {"material": "empty", "diameter_m": 0.05999999994, "depth_m": 0.86})")),
         {Rel("/mass_kg",
              kRho * kPi * (Wide(0.03) - Wide(0.05999999994 / 2)) *
                  (Wide(0.03) + Wide(0.05999999994 / 2)) * Wide(0.86),
              1e-6)}),
      Refusal(
          "BoreAsWideAsTheBat", p,
          Bat(Cylinder(0.86, 0.03,
                       R"(, "fill": {"material": "empty", "diameter_m": 0.06, "depth_m": 0.86})")),
          400, "InvalidValue", "bat.fill.diameter_m"),
      // A pivot 100 m away (the limit): I_cm + M (p - C)^2.
      Ok("PivotAHundredMetresAway", p, Bat(Cylinder(0.86, 0.03), R"(, "pivot_from_knob_m": 100)"),
         {Rel("/moi_pivot_kg_m2",
              cyl_mass * (0.86L * 0.86L / 12 + 0.03L * 0.03L / 4) +
                  cyl_mass * (100 - 0.43L) * (100 - 0.43L),
              64 * kEps)}),
      Refusal("PivotAMillionMetresAway", p, Bat(kPaper, R"(, "pivot_from_knob_m": 1e6)"), 400,
              "InvalidValue", "pivot_from_knob_m"),
      // 1e400 overflows a double: refused while parsing (a body-level error: field null).
      Refusal("NumberBeyondTheDoubleRange", p, Bat(kPaper, R"(, "pivot_from_knob_m": 1e400)"), 400,
              "InvalidValue", ""),
      Ok("SlenderRodMicrometreBat", p,
         Bat(Cylinder(1e-6, 1e-6), R"(, "inertia_model": "slender_rod")"),
         {Rel("/moi_centroid_kg_m2", kRho * kPi * 1e-18L * 1e-12L / 12)}),
  };
}

class HardCaseBatPropertiesEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseBatPropertiesEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseBatPropertiesEndpoint, testing::ValuesIn(PropertiesCases()),
                         RowName<ApiCase>);

// POST /v1/bat/fit: targets at and beyond their ranges, unattainable targets, budgets.
std::vector<ApiCase> FitCases() {
  const std::string p = "/v1/bat/fit";
  return {
      Refusal("TargetMassOfANanogram", p, Bat(kPaper, R"(, "targets": {"mass_kg": 1e-9})"), 400,
              "InvalidValue", "targets.mass_kg"),
      Refusal("TargetMassOfAThousandTonnes", p, Bat(kPaper, R"(, "targets": {"mass_kg": 1e6})"),
              400, "InvalidValue", "targets.mass_kg"),
      Refusal("TargetBalancePointAtTheKnob", p,
              Bat(kPaper, R"(, "targets": {"balance_point_m": 0})"), 400, "InvalidValue",
              "targets.balance_point_m"),
      Refusal("ToleranceOf1e-300", p,
              Bat(kPaper, R"(, "targets": {"mass_kg": 0.95}, "options": {"tolerance": 1e-300})"),
              400, "InvalidValue", "options.tolerance"),
      Refusal(
          "ScaleOf1e-300", p,
          Bat(kPaper, R"(, "targets": {"mass_kg": 0.95}, "options": {"mass_scale_kg": 1e-300})"),
          400, "InvalidValue", "options.mass_scale_kg"),
      Refusal(
          "EqualUnknownBounds", p,
          Bat(kPaper,
              R"(, "targets": {"mass_kg": 0.95}, "unknowns": [{"name": "density_kg_m3", "min": 600, "max": 600}])"),
          400, "InvalidValue", "unknowns[0].max"),
      // Tolerance 1e-12: met; the residuals are below 1e-12 of the targets.
      Ok("Tolerance1e-12", p,
         Bat(kPaper,
             R"(, "targets": {"mass_kg": 0.95, "balance_point_m": 0.60}, "options": {"tolerance": 1e-12})"),
         {Near("/residuals/mass_kg", 0, 0.95e-12), Near("/residuals/balance_point_m", 0, 0.6e-12)}),
      // The balance point at the middle: only a cylinder of the barrel radius (x2 -> 0) gets
      // there; the fitted taper is a degenerate 2e-20 m.
      Ok("BalancePointAtTheMiddle", p, Bat(kPaper, R"(, "targets": {"balance_point_m": 0.4275})"),
         {Near("/properties/balance_point_m", 0.4275, 0.4275e-9),
          Between("/bat/three_segment/taper_end_m", 0, 1e-6)}),
      Ok("WallFromAPicometreToTheRadius", p,
         Bat(R"({"preset": "paper-wood", "wall_thickness_m": 0.002})",
             R"(, "targets": {"mass_kg": 0.3}, "unknowns": [{"name": "wall_thickness_m", "min": 1e-12, "max": 0.0125}])"),
         {Near("/properties/mass_kg", 0.3, 0.3e-9),
          Between("/bat/wall_thickness_m", 1e-12, 0.0125)}),
      AsJob(Refusal("PaperTable2TargetsAreInfeasible", p,
                    Bat(kPaper, R"(, "targets": {"mass_kg": 0.885, "balance_point_m": 0.564})"),
                    422, "Infeasible", "targets")),
      // The unknowns (where a taper between equal radii starts and ends) change nothing: the
      // metric is flat, every bat is the closest one, and it is certified so.
      Refusal(
          "CylinderCannotMoveItsBalancePoint", p,
          Bat(Cylinder(0.86, 0.03), R"(, "targets": {"mass_kg": 0.95, "balance_point_m": 0.60})"),
          422, "Infeasible", "targets"),
      // One evaluation: the budget ends the fit before the targets are met.
      Refusal(
          "OneEvaluation", p,
          Bat(kPaper,
              R"(, "targets": {"mass_kg": 0.95, "balance_point_m": 0.60}, "options": {"max_evaluations": 1})"),
          422, "Timeout", "targets"),
  };
}

class HardCaseBatFitEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseBatFitEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseBatFitEndpoint, testing::ValuesIn(FitCases()),
                         RowName<ApiCase>);

// POST /v1/bat/modes: materials from nearly rigid to very soft, shear extremes, mode counts,
// tolerances and mesh bounds at and beyond their limits.
std::vector<ApiCase> ModesCases() {
  const std::string p = "/v1/bat/modes";
  // paper-wood, Timoshenko: 176.90 Hz (docs/models.md), to the default tolerance 1e-4.
  const long double f1 = 176.89856757848946L;
  return {
      Ok("TwentyModes", p, Bat(kPaper, R"(, "modes": 20)"),
         {Near("/frequencies_hz/0", f1, f1 * 1e-4), Between("/frequencies_hz/19", 1e4, 1e6)}),
      Refusal("TwentyOneModes", p, Bat(kPaper, R"(, "modes": 21)"), 400, "InvalidValue", "modes"),
      Refusal("ToleranceOf1e-12", p, Bat(kPaper, R"(, "tolerance": 1e-12)"), 400, "InvalidValue",
              "tolerance"),
      Ok("ToleranceOf1e-9", p, Bat(kPaper, R"(, "tolerance": 1e-9)"),
         {Near("/frequencies_hz/0", f1, f1 * 1e-8)}),
      Refusal("TwoElements", p, Bat(kPaper, R"(, "max_elements": 2)"), 400, "InvalidValue",
              "max_elements"),
      // The mesh bound below what the tolerance needs: 200 no_convergence with the error said.
      Ok("MeshBoundReached", p, Bat(kPaper, R"(, "modes": 1, "max_elements": 12)"),
         {Is("/summary/termination", "no_convergence"), Near("/frequencies_hz/0", f1, f1 * 1e-2)}),
      // E = 1e13 Pa (the API's largest): f ~ sqrt(E): 176.9 x sqrt(1e13 / 1.814e10) = 4153.4 Hz,
      // to the tolerance and the shear term's Poisson ratio (0.3 here, 0.25 in the catalogue).
      Ok("NearlyRigidMaterial", p,
         Bat(R"({"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1e13}})"),
         {Near("/frequencies_hz/0", 4153.4183, 0.5)}),
      Ok("VerySoftMaterial", p,
         Bat(R"({"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1e-3}})"),
         {Near("/frequencies_hz/0", 4.1534183e-5, 0.5e-8)}),
      // G = 1e13 Pa: Timoshenko tends to Euler-Bernoulli with rotary inertia (178.0 Hz).
      Ok("VeryStiffShear", p,
         Bat(R"({"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1.814e10, "shear_modulus_pa": 1e13}})"),
         {Between("/frequencies_hz/0", 176.0, 178.1)}),
      // G = 1e-3 Pa: the shear modes sink below the rigid modes' round-off: a named failure.
      Refusal(
          "ShearOf1e-3Pascal", p,
          Bat(R"({"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1.814e10, "shear_modulus_pa": 1e-3}})"),
          422, "ModelFailed", "bat"),
      Ok("ShellWallBillionthOfRadius", p,
         Bat(R"({"preset": "paper-wood", "wall_thickness_m": 1.25e-11})"),
         {Between("/frequencies_hz/0", 176.9, 400.0)}),
      Ok("StepKnotsPicometreApart", p,
         Bat(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 0.0125}, {"x_m": 0.4, "radius_m": 0.0125},
             {"x_m": 0.400000000001, "radius_m": 0.035}, {"x_m": 0.86, "radius_m": 0.035}]}})"),
         {Between("/frequencies_hz/0", 100.0, 300.0)}),
      // A 1 um bat of radius 1e-8 m: f1 = (4.73^2 / (2 pi L^2)) sqrt(E r^2 / (4 rho)) ~ 9.4e7 Hz
      // (Timoshenko slightly lower).
      Ok("MicrometreBat", p, Bat(Cylinder(1e-6, 1e-8)),
         {Between("/frequencies_hz/0", 9.0e7, 9.45e7)}),
      Refusal("StubbyBatIsNotABeam", p, Bat(Cylinder(0.1, 0.035)), 400, "InvalidValue",
              "bat.length_m"),
  };
}

class HardCaseBatModesEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseBatModesEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseBatModesEndpoint, testing::ValuesIn(ModesCases()),
                         RowName<ApiCase>);

}  // namespace
}  // namespace api_bat_test
}  // namespace sweetspot::hard_cases
