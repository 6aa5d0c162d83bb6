#include "core/bat/presets.hpp"

#include <initializer_list>
#include <utility>

#include "core/units.hpp"

namespace sweetspot::core {
namespace {

// Knots from (position from the knob in inches, DIAMETER in inches) pairs.
std::vector<ProfileKnot> FromInches(std::initializer_list<std::pair<double, double>> points) {
  std::vector<ProfileKnot> out;
  out.reserve(points.size());
  for (const auto& [x_in, diameter_in] : points) {
    out.push_back({InchesToMetres(x_in), 0.5 * InchesToMetres(diameter_in)});
  }
  return out;
}

// Wall thickness of "bbcor-33-aluminium", m: the root of mass(wall) = 30 oz
// (0.850485694 kg) for its profile and 7050 aluminium, solved by bisection
// to 1e-12 m (presets_test re-solves it and checks the weight).
constexpr double kBbcorWallM = 0.0027614431802374;

// The handle-and-taper wall of "bbcor-33-alloy-capped", m: the root of mass(wall) = 30 oz with
// its barrel wall kBbcorWallM, end cap and knob (presets_test re-solves it).
constexpr double kCappedHandleWallM = 0.0022337768345169033;
// The wall of "composite-33-bbcor", m: the root of mass(wall) = 30 oz with its end cap and
// knob (presets_test re-solves it).
constexpr double kCompositeWallM = 0.00479454539185681;

// The seed paper's bats (SI, the paper's shape): "paper-wood" and its 0.885-kg variant
// "paper-wood-m885", appended to *out.
void AddPaperPresets(std::vector<BatPreset>* out) {
  const Material paper_wood = *FindMaterial("paper-wood");

  BatPreset paper;
  paper.name = "paper-wood";
  paper.bat = MakeThreeSegmentBat(PaperThreeSegmentShape(), paper_wood);
  paper.description =
      "The seed paper's bat: 0.855 m, handle radius 0.0125 m to x1 = 0.3459 m, taper to barrel "
      "radius 0.035 m at x2 = 0.6423 m, wood of 649 kg/m3; 1.0078 kg, balance point 0.6090 m.";
  paper.source =
      "Seed paper Table 2 and its x1, x2 (0.3459, 0.6423); its '7 cm' and '2.5 cm' radii are "
      "read as diameters, the only reading that gives a bat of realistic mass "
      "(shared/docs/paper-notes.md, shared/docs/api-contract.md). The paper's own targets "
      "M = 0.885 kg, C = 0.564 m cannot both be met by this family (see shape_fit).";
  out->push_back(paper);

  BatPreset m885 = paper;
  m885.name = "paper-wood-m885";
  m885.bat.material.name = "custom";
  m885.bat.material.density_kg_m3 = 569.9;
  m885.bat.material.source =
      "paper-wood with density 569.9 kg/m3, the density at which the paper's shape weighs the "
      "paper's 0.885 kg (shared/docs/paper-notes.md).";
  m885.description =
      "The paper's bat shape at 569.9 kg/m3 so that it weighs the paper's 0.885 kg; balance "
      "point 0.6090 m (independent of density).";
  m885.source = "As paper-wood, density scaled so that M = 0.885 kg (paper Table 2's mass).";
  out->push_back(m885);
}

// The solid wood bats turned to pro profiles (knots in inches, converted to m): "wood-34-ash"
// and "wood-34-maple-turned", appended to *out.
void AddWoodPresets(std::vector<BatPreset>* out) {
  BatPreset ash;
  ash.name = "wood-34-ash";
  ash.bat.knots = FromInches({{0.0, 1.60},
                              {0.25, 1.75},
                              {0.55, 1.75},
                              {0.95, 1.05},
                              {1.6, 0.93},
                              {12.0, 0.95},
                              {15.0, 1.05},
                              {18.0, 1.28},
                              {21.0, 1.70},
                              {23.0, 2.08},
                              {25.0, 2.42},
                              {27.0, 2.61},
                              {33.25, 2.61},
                              {34.0, 2.35}});
  ash.bat.material = *FindMaterial("ash");
  ash.description =
      "A 34-in solid white-ash bat: 1.75-in knob, 0.93-0.95-in handle, taper from 12 in to "
      "27 in, 2.61-in barrel, rounded (uncupped) end; 31.5 oz (drop 2.5), balance point 24.0 in.";
  ash.source =
      "Profile drawn for this service to the limits of the MLB Official Baseball Rules 3.02 "
      "(solid wood, at most 2.61 in diameter and 42 in long) with knob, handle and taper "
      "dimensions typical of turned pro models (not a specific manufacturer's model); "
      "white ash from the Wood Handbook FPL-GTR-190 (material 'ash').";
  out->push_back(ash);

  // A turned pro maple bat (issue 35, "wood bats that ring like wood bats"): the knots below,
  // in inches, are this service's reading of the published descriptions of a medium-handle
  // pro turning model (C271 class), not a manufacturer's drawing; see `source`.
  BatPreset maple;
  maple.name = "wood-34-maple-turned";
  maple.bat.knots = FromInches({{0.0, 1.70},
                                {0.25, 1.85},
                                {0.55, 1.85},
                                {1.0, 1.20},
                                {2.5, 0.96},
                                {3.5, 0.95},
                                {11.0, 0.95},
                                {14.0, 1.10},
                                {17.5, 1.50},
                                {21.0, 2.08},
                                {23.0, 2.38},
                                {24.5, 2.50},
                                {33.6, 2.50},
                                {34.0, 2.30}});
  maple.bat.material = *FindMaterial("maple-bat-billet");
  maple.description =
      "A 34-in solid maple bat turned to a medium-handle pro model: flared 1.85-in knob, "
      "0.95-in handle to 11 in, S-shaped taper to a 2.50-in barrel at 24.5 in, rounded end; "
      "bat-grade maple billet (637 kg/m3, E = 15.16 GPa); 32.0 oz (drop 2), balance point "
      "23.2 in; first free-free bending mode 143 Hz.";
  maple.source =
      "Profile: MLB Official Baseball Rules 3.02 (solid wood, at most 2.61 in); handle 0.95 in, "
      "'medium handles are the most common and are typically around .95\"', flared knob, "
      "models 271 and others (Outlaw Bats, 'Anatomy of a wood bat'); handle length 10.5-11.5 in "
      "for a 34-in professional bat (dimensions.com, 'Baseball bat - professional'), so the taper "
      "starts at 11 in; a 2.5-in barrel (below the 2.61-in maximum, as most turning models); "
      "volume 87.0 in3, within the 79.7-90.4 in3 of the four popular pro profiles of Appl. Sci. "
      "12(7), 3494 (2022). No published table of a turning model's diameters was found, so the "
      "knots between those anchors are this service's. Material 'maple-bat-billet' (that "
      "study's bat-grade billet values).";
  out->push_back(maple);
}

// The hollow BBCOR bats (knots in inches, walls in m): "bbcor-33-aluminium", its capped build
// "bbcor-33-alloy-capped" and the composite "composite-33-bbcor", appended to *out.
void AddHollowPresets(std::vector<BatPreset>* out) {
  BatPreset bbcor;
  bbcor.name = "bbcor-33-aluminium";
  bbcor.bat.knots = FromInches({{0.0, 1.50},
                                {0.30, 1.55},
                                {0.60, 1.55},
                                {1.0, 0.95},
                                {1.5, 0.875},
                                {11.0, 0.875},
                                {13.0, 0.95},
                                {15.0, 1.20},
                                {17.0, 1.65},
                                {19.0, 2.20},
                                {20.5, 2.625},
                                {32.75, 2.625},
                                {33.0, 2.50}});
  bbcor.bat.material = *FindMaterial("aluminium-7050");
  bbcor.bat.wall_thickness_m = kBbcorWallM;
  bbcor.description =
      "A 33-in hollow 7050-aluminium BBCOR bat: 1.55-in knob, 7/8-in handle, taper from 11 in "
      "to 20.5 in, 2 5/8-in barrel; open-tube shell of 2.761 mm wall; 30.0 oz (drop 3).";
  bbcor.source =
      "NCAA / NFHS BBCOR bat standard: barrel diameter at most 2 5/8 in, length minus weight at "
      "most 3 (33 in -> 30 oz), ball-bat COR at most 0.50. Profile drawn for this service, "
      "typical of one-piece alloy BBCOR bats (not a specific model). The uniform wall thickness "
      "is solved so that the open-tube shell (no end cap, no knob plug; see bat.hpp) weighs "
      "exactly 30 oz; real bats vary the wall along the barrel.";
  out->push_back(bbcor);

  // Issue 35, "bats as they are built": the same alloy bat closed by an end cap and a knob,
  // its barrel wall kept (the barrel model's calibration, validation.md) and its handle and
  // taper wall solved for the weight.
  BatPreset capped = bbcor;
  capped.name = "bbcor-33-alloy-capped";
  for (ProfileKnot& k : capped.bat.knots) {
    if (k.x_m < InchesToMetres(20.5)) k.wall_thickness_m = kCappedHandleWallM;
  }
  capped.bat.end_cap = BatPart{OuncesToKilograms(1.0), InchesToMetres(0.5), "rubber"};
  capped.bat.knob = BatPart{OuncesToKilograms(1.0), InchesToMetres(0.75), "aluminium-7050"};
  capped.description =
      "bbcor-33-aluminium closed as built: a 1-oz end cap over the last 0.5 in and a 1-oz knob "
      "over the first 0.75 in; barrel wall 2.761 mm (from 20.5 in), handle and taper wall "
      "solved for 30.0 oz (drop 3).";
  capped.source =
      "bbcor-33-aluminium's profile and alloy (its source). The end cap and knob masses (1 oz "
      "each) and lengths are this service's round figures for a polymer end cap and an alloy "
      "knob, not a manufacturer's: no published part masses were found. The barrel keeps the "
      "BBCOR-calibrated 2.761 mm wall; the wall from the knob to the taper's end (20.5 in) is "
      "solved so that the bat weighs 30 oz (kCappedHandleWallM, presets_test re-solves it).";
  out->push_back(capped);

  BatPreset composite = bbcor;
  composite.name = "composite-33-bbcor";
  composite.bat.material = *FindMaterial("carbon-epoxy-fabric");
  composite.bat.wall_thickness_m = kCompositeWallM;
  composite.bat.end_cap = capped.bat.end_cap;
  composite.bat.knob = BatPart{OuncesToKilograms(1.0), InchesToMetres(0.75), ""};
  composite.description =
      "A 33-in one-piece composite BBCOR bat: bbcor-33-aluminium's profile in carbon/epoxy "
      "fabric, a 1-oz end cap and a 1-oz knob, uniform wall solved for 30.0 oz (drop 3).";
  composite.source =
      "The BBCOR limits and bbcor-33-aluminium's profile (its source); material "
      "'carbon-epoxy-fabric' (its source); end cap and knob as bbcor-33-alloy-capped's (this "
      "service's figures); the uniform wall solved for 30 oz (kCompositeWallM, presets_test "
      "re-solves it). A real composite bat's lay-up and wall vary; not a specific model.";
  out->push_back(composite);
}

// Every preset, in the catalogue's order: the paper's, the wood, the hollow ones.
std::vector<BatPreset> BuildPresets() {
  std::vector<BatPreset> out;
  AddPaperPresets(&out);
  AddWoodPresets(&out);
  AddHollowPresets(&out);
  return out;
}

}  // namespace

ThreeSegmentShape PaperThreeSegmentShape() {
  ThreeSegmentShape shape;
  shape.length_m = 0.855;
  shape.handle_radius_m = 0.0125;
  shape.barrel_radius_m = 0.035;
  shape.taper_start_m = 0.3459;
  shape.taper_end_m = 0.6423;
  return shape;
}

const std::vector<BatPreset>& BatPresets() {
  static const std::vector<BatPreset> presets = BuildPresets();
  return presets;
}

const BatPreset* PresetNamed(std::string_view name) {
  for (const BatPreset& p : BatPresets()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

std::optional<BatPreset> FindPreset(std::string_view name) {
  const BatPreset* found = PresetNamed(name);
  return found != nullptr ? std::optional<BatPreset>(*found) : std::nullopt;
}

}  // namespace sweetspot::core
