#include "core/ball/ball_catalogue.hpp"

#include <algorithm>
#include <cmath>

#include "core/geometry_format.hpp"

namespace sweetspot::core {
namespace {

// Unit conversions of the rule books (exact by definition).
constexpr double kBallOunceKg = 0.028349523125;  // avoirdupois ounce
constexpr double kBallInchM = 0.0254;
constexpr double kBallMphMps = 0.44704;
constexpr double kBallFootPerSecondMps = 0.3048;
constexpr double kBallPoundForceN = 4.4482216152605;
constexpr double kBallPi = 3.14159265358979323846;

// The ASTM F1887 test speed of baseballs and softballs: 60 mph (88 ft/s).
constexpr double kF1887SpeedMps = 60.0 * kBallMphMps;
// The speed range over which the linear COR laws are used: 30 to 160 mph (13.4 to 71.5 m/s),
// from below the lowest test speed to above the fastest game collisions (a 100 mph pitch on a
// 80 mph bat); the COR is held constant outside it.
constexpr double kCorLawMinSpeedMps = 30.0 * kBallMphMps;
constexpr double kCorLawMaxSpeedMps = 160.0 * kBallMphMps;
// The MLB ball's COR falls by 0.0005 per mph of relative speed: FITTED, not sourced, to issue
// 18's two points (about 0.55 at 58 mph on ash, about 0.50 at game speeds, i.e. a 160 mph
// relative speed: (0.546 - 0.50) / (160 - 58) = 0.00045, rounded to 0.0005); no primary source
// giving a number was found (docs/validation.md says where we looked).
constexpr double kMlbCorSlopePerMps = 0.0005 / kBallMphMps;
// The NCAA/NFHS ball keeps 0.001 per mph (not sourced either): with the MLB fit its rule maximum
// 0.555 at 60 mph would give 0.517 at the BBCOR test's 136 mph, above the 0.500 limit the NCAA
// set from wood bats, so a solid wood bat would fail BBCOR and no barrel shell factor could put
// the BBCOR preset at the limit. Its slope must be at least (0.555 - 0.500) / 76 = 0.00072 per
// mph for a (near-rigid) wood bat to pass; 0.001 gives 0.479 at 136 mph.
constexpr double kNcaaCorSlopePerMps = 0.001 / kBallMphMps;
// The project's calibrated baseball contact law (core/scene/scene.hpp, docs/models.md).
constexpr double kBaseballStiffness = 4.0e7;
constexpr double kBallExponent = 1.5;
// ASTM F1888's compression displacement: 0.25 in.
constexpr double kF1888DisplacementM = 0.25 * kBallInchM;

// A ball with nominal mass and radius at the midpoints of the rule's ranges.
BallPreset RuleBall(std::string name, double mass_min_oz, double mass_max_oz,
                    double circumference_min_in, double circumference_max_in) {
  BallPreset b;
  b.name = std::move(name);
  b.mass_min_kg = mass_min_oz * kBallOunceKg;
  b.mass_max_kg = mass_max_oz * kBallOunceKg;
  b.mass_kg = 0.5 * (b.mass_min_kg + b.mass_max_kg);
  b.circumference_min_m = circumference_min_in * kBallInchM;
  b.circumference_max_m = circumference_max_in * kBallInchM;
  b.radius_m = 0.5 * (b.circumference_min_m + b.circumference_max_m) / (2.0 * kBallPi);
  b.stiffness_exponent = kBallExponent;
  return b;
}

BallCorLaw Law(double cor, double reference_speed_mps, double slope_per_mps) {
  BallCorLaw law;
  law.cor_at_reference = cor;
  law.reference_speed_mps = reference_speed_mps;
  law.slope_per_mps = slope_per_mps;
  law.min_speed_mps = kCorLawMinSpeedMps;
  law.max_speed_mps = kCorLawMaxSpeedMps;
  return law;
}

const char kMlbSlopeSource[] =
    " Speed dependence: 0.0005 per mph of relative speed, FITTED (not from a primary source) to "
    "issue 18's two points, about 0.55 at 58 mph on ash and about 0.50 at game speeds (a 160 "
    "mph relative speed): 0.495 at 160 mph. That the baseball's COR falls with speed is "
    "documented (M. M. Shenoy, L. V. Smith, J. T. Axtell, 'Performance assessment of wood, metal "
    "and composite baseball bats', Composite Structures 52, 397 (2001): 'the baseball's speed "
    "dependent coefficient of restitution'); no published slope was found (docs/validation.md). "
    "At the NCAA BBCOR test speed (136 mph) the law gives 0.507, 0.007 above the 0.500 limit "
    "the NCAA set from wood bats. Used from 30 to 160 mph, held constant outside.";

const char kNcaaSlopeSource[] =
    " Speed dependence: 0.001 per mph of relative speed, NOT sourced: kept so that a solid wood "
    "bat passes BBCOR (0.479 at the test's 136 mph; the 0.500 limit was set from wood bats, which "
    "needs at least 0.00072 per mph from the 0.555 maximum); the MLB entry's 0.0005 per mph "
    "(fitted to issue 18's points) would give 0.517. Used from 30 to 160 mph, held constant "
    "outside.";

const char kBaseballStiffnessBasis[] =
    "not a measured value: the project's calibrated baseball law (docs/models.md, 'hertz'): "
    "k = 4.0e7 N/m^1.5, p = 1.5, chosen for a 0.6-1 ms contact and a peak force of a few 10^4 N "
    "at game speeds; ASTM F2845 dynamic stiffness equivalent at 60 mph about 4.0e6 N/m.";

// A 12 in softball of USA Softball (formerly ASA) with the given COR and compression limits.
BallPreset Softball12(std::string name, std::string play, double cor, double compression_lbf) {
  BallPreset b = RuleBall(std::move(name), 6.25, 7.00, 11.875, 12.125);
  b.description = "12 in softball, " + play + ": COR " + FormatNumber(cor) + ", compression " +
                  FormatNumber(compression_lbf) + " lbf (USA Softball limits)";
  b.cor_law = Law(cor, kF1887SpeedMps, 0.0);
  b.cor_test =
      "ASTM F1887: fired at 60 mph (88 ft/s, 26.82 m/s) at a rigid flat wall; rebound / inbound "
      "speed";
  b.stiffness = StiffnessFromStaticCompression(compression_lbf * kBallPoundForceN,
                                               kF1888DisplacementM, kBallExponent);
  b.stiffness_basis =
      "from the rule's compression limit, ASTM F1888 (static): " + FormatNumber(compression_lbf) +
      " lbf shortens the diameter by 0.25 in between two plates, i.e. F = k (0.125 in)^1.5 at "
      "each plate. Quasi-static: a ball is stiffer at impact rates (ASTM F2845's motivation), so "
      "contact times come out long.";
  b.source =
      "USA Softball (ASA) official rules, 12 in ball: circumference 11 7/8 to 12 1/8 in, weight "
      "6 1/4 to 7 oz; the COR and compression limits of its approved balls (fast pitch and "
      "modified .47/375, slow pitch .44/375 and .52/300; e.g. verydays.net/articles_eg5bha.html); "
      "COR by ASTM F1887 at 60 mph, compression by ASTM F1888 at 0.25 in (Loughborough ISEA "
      "2024, 'Coefficient of restitution for normal and oblique impacts': 'projected normally "
      "onto a flat rigid wall at 60 mph'). Speed dependence: none found in the sources; the COR "
      "is held at the rule's value (slope 0).";
  return b;
}

std::vector<BallPreset> BuildBallCatalogue() {
  std::vector<BallPreset> out;

  BallPreset mlb = RuleBall("mlb", 5.0, 5.25, 9.0, 9.25);
  mlb.description =
      "Major League Baseball ball (Official Baseball Rules 3.01), COR 0.546 +/- 0.032 at 85 ft/s "
      "on ash";
  mlb.cor_law = Law(0.546, 85.0 * kBallFootPerSecondMps, kMlbCorSlopePerMps);
  mlb.cor_test =
      "MLB specification: fired at 85 ft/s (58 mph, 25.91 m/s) at a slab of northern white ash "
      "mounted on a wall; rebound / inbound speed; 0.546 +/- 0.032 (0.514 to 0.578)";
  mlb.stiffness = kBaseballStiffness;
  mlb.stiffness_basis = kBaseballStiffnessBasis;
  mlb.source =
      std::string(
          "Official Baseball Rules 3.01: weight 5 to 5 1/4 oz, circumference 9 to 9 1/4 in. "
          "COR: the MLB specification 0.514 to 0.578 (0.546 +/- 0.032) at 85 ft/s against "
          "northern white ash, as tested at UMass Lowell (D. Ropeik, 'Squeezing the juice out of "
          "baseballs', msnbc.com 2003; the upper limit 0.578 also in the Courier-Journal, 15 "
          "June 2013).") +
      kMlbSlopeSource;
  out.push_back(mlb);

  BallPreset ncaa = RuleBall("ncaa-nfhs", 5.0, 5.25, 9.0, 9.25);
  ncaa.description =
      "NCAA / NFHS baseball (NOCSAE standard), COR at most 0.555 at 60 mph (ASTM F1887)";
  ncaa.cor_law = Law(0.555, kF1887SpeedMps, kNcaaCorSlopePerMps);
  ncaa.cor_test =
      "ASTM F1887: fired at 60 mph (88 ft/s, 26.82 m/s) at a solid northern white ash wall; the "
      "rule's maximum 0.555 is used";
  ncaa.stiffness = kBaseballStiffness;
  ncaa.stiffness_basis = kBaseballStiffnessBasis;
  ncaa.source =
      std::string(
          "NCAA and NFHS baseball rules (NFHS rule 1-3-1: balls meeting the NOCSAE standard "
          "since 2019): weight 5 to 5 1/4 oz, circumference 9 to 9 1/4 in, as MLB. COR: at most "
          "0.555 for the college ball against 0.578 for the pro ball (D. Keilitz, ABCA, in the "
          "Courier-Journal, 15 June 2013), by ASTM F1887 at 60 mph.") +
      kNcaaSlopeSource;
  out.push_back(ncaa);

  out.push_back(Softball12("softball-12-fastpitch", "fast pitch", 0.47, 375.0));
  out.push_back(Softball12("softball-12-slowpitch-44", "slow pitch", 0.44, 375.0));
  out.push_back(Softball12("softball-12-slowpitch-52", "slow pitch", 0.52, 300.0));
  return out;
}

}  // namespace

double BallCorLaw::CorAt(double speed_mps) const {
  const double v = std::clamp(speed_mps, min_speed_mps, max_speed_mps);
  return std::clamp(cor_at_reference - slope_per_mps * (v - reference_speed_mps), 0.0, 1.0);
}

bool BallCorLaw::Validate(Refusal* why) const {
  if (!(std::isfinite(cor_at_reference) && cor_at_reference >= 0.0 && cor_at_reference <= 1.0))
    return Refuse(why, "ball.cor_law.cor_at_reference", cor_at_reference, "must be in [0, 1]");
  if (!(std::isfinite(reference_speed_mps) && reference_speed_mps > 0.0))
    return Refuse(why, "ball.cor_law.reference_speed_mps", reference_speed_mps,
                  "must be finite and > 0");
  if (!(std::isfinite(slope_per_mps) && slope_per_mps >= 0.0))
    return Refuse(why, "ball.cor_law.slope_per_mps", slope_per_mps, "must be finite and >= 0");
  if (!(std::isfinite(min_speed_mps) && min_speed_mps >= 0.0 &&
        min_speed_mps <= reference_speed_mps))
    return Refuse(why, "ball.cor_law.min_speed_mps", min_speed_mps,
                  "must be in [0, reference_speed_mps]");
  if (!(std::isfinite(max_speed_mps) && max_speed_mps >= reference_speed_mps))
    return Refuse(why, "ball.cor_law.max_speed_mps", max_speed_mps,
                  "must be finite and >= reference_speed_mps");
  return true;
}

const std::vector<BallPreset>& BallCatalogue() {
  static const std::vector<BallPreset> catalogue = BuildBallCatalogue();
  return catalogue;
}

std::optional<BallPreset> FindBallPreset(std::string_view name) {
  for (const BallPreset& b : BallCatalogue()) {
    if (b.name == name) return b;
  }
  return std::nullopt;
}

std::string BallPresetNames() {
  std::string names;
  for (const BallPreset& b : BallCatalogue()) names += (names.empty() ? "" : ", ") + b.name;
  return names;
}

double StiffnessFromStaticCompression(double force_n, double displacement_m, double exponent) {
  return force_n / std::pow(0.5 * displacement_m, exponent);
}

double StiffnessFromDynamicStiffness(double dynamic_stiffness_n_m, double mass_kg, double speed_mps,
                                     double exponent) {
  // Rigid wall: (k/(p+1)) d^(p+1) = m v^2 / 2 at the peak compression d, F = k d^p; hence
  // F = k^(1/(p+1)) (E (p+1))^(p/(p+1)) with E = m v^2 / 2, solved for k.
  const double energy_j = 0.5 * mass_kg * speed_mps * speed_mps;
  const double force_n = speed_mps * std::sqrt(dynamic_stiffness_n_m * mass_kg);
  return std::pow(force_n, exponent + 1.0) / std::pow((exponent + 1.0) * energy_j, exponent);
}

double DynamicStiffnessOf(double stiffness, double exponent, double mass_kg, double speed_mps) {
  const double energy_j = 0.5 * mass_kg * speed_mps * speed_mps;
  const double d = std::pow((exponent + 1.0) * energy_j / stiffness, 1.0 / (exponent + 1.0));
  const double force_n = stiffness * std::pow(d, exponent);
  return force_n * force_n / (mass_kg * speed_mps * speed_mps);
}

}  // namespace sweetspot::core
