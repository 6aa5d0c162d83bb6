#include "core/optimize/rules.hpp"

#include "core/geometry_format.hpp"
#include "core/refusal.hpp"
#include "core/scene/scene_barrel.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

struct RuleName {
  RuleSet rule;
  const char* name;
};

constexpr RuleName kRuleNames[] = {
    {RuleSet::kMlbWood, "mlb-wood"},
    {RuleSet::kBbcor, "bbcor"},
    {RuleSet::kUsssa, "usssa"},
};

constexpr const char* kWoods[] = {"ash", "hard-maple", "yellow-birch", "paper-wood"};

}  // namespace

const char* RuleSetName(RuleSet rule) {
  for (const auto& r : kRuleNames) {
    if (r.rule == rule) return r.name;
  }
  return "unknown";
}

std::optional<RuleSet> ParseRuleSet(std::string_view name) {
  for (const auto& r : kRuleNames) {
    if (name == r.name) return r.rule;
  }
  return std::nullopt;
}

const std::vector<RuleSet>& AllRuleSets() {
  static const std::vector<RuleSet> kAll = {RuleSet::kMlbWood, RuleSet::kBbcor, RuleSet::kUsssa};
  return kAll;
}

RuleSetLimits LimitsOf(RuleSet rule) {
  RuleSetLimits out;
  switch (rule) {
    case RuleSet::kMlbWood:
      out.max_diameter_m = InchesToMetres(2.61);
      out.max_length_m = InchesToMetres(42.0);
      out.solid_wood_only = true;
      out.max_cup_depth_m = InchesToMetres(1.25);
      out.min_cup_diameter_m = InchesToMetres(1.0);
      out.max_cup_diameter_m = InchesToMetres(2.0);
      out.source =
          "MLB Official Baseball Rules 3.02(a): a smooth, round stick not more than 2.61 in in "
          "diameter at the thickest part and not more than 42 in long, one piece of solid wood; "
          "3.02(b) cupped bats: an indentation in the end up to 1 1/4 in deep (1 in in editions "
          "before 2015, rule 1.10(b)), 1 in to 2 in in diameter, with no foreign substance.";
      break;
    case RuleSet::kBbcor:
      out.max_diameter_m = InchesToMetres(2.625);
      out.max_drop = 3.0;
      out.max_bbcor = 0.50;
      out.source =
          "NCAA Baseball Rules 1-12 and NFHS Baseball Rules 1-3-2 (non-wood bats): barrel "
          "diameter at most 2 5/8 in, length in inches minus weight in ounces at most 3, "
          "certified BBCOR (batted-ball coefficient of restitution) at most 0.50. NFHS also "
          "limits the length to 36 in (not applied here).";
      break;
    case RuleSet::kUsssa:
      out.max_diameter_m = InchesToMetres(2.75);
      out.source =
          "USSSA Baseball bat rules: barrel diameter at most 2 3/4 in; the USSSA BPF 1.15 "
          "performance mark is a lab certification, not modelled here.";
      break;
  }
  return out;
}

bool IsWoodMaterial(const Material& material) {
  if (material.kind != MaterialKind::kWood) return false;
  for (const char* w : kWoods) {
    if (material.base == w) return true;
  }
  return false;
}

bool RuleAllowsDesign(RuleSet rule, const RuleFacts& facts, Refusal* why) {
  const RuleSetLimits limits = LimitsOf(rule);
  // "rules.<name>: what is broken": the field is the rule set (the api maps it to the
  // request's constraints.rules).
  const std::string field = std::string("rules.") + RuleSetName(rule);
  if (limits.solid_wood_only) {
    if (!IsWoodMaterial(facts.material)) {
      // About the bat's material: the field is that, the rule set is named in the rule.
      const Material& m = facts.material;
      const std::string what =
          !m.kind.has_value()
              ? "a custom material without a base (its kind is not known; give \"base\")"
          : *m.kind != MaterialKind::kWood
              ? std::string("of kind ") + MaterialKindName(*m.kind) +
                    (m.base.empty() ? "" : " (base " + m.base + ")")
              : "wood of base '" + m.base + "', not an allowed species";
      return Refuse(why, TextRefusal("bat.material",
                                     field + ": one piece of solid wood of an allowed species "
                                             "(base ash, hard-maple, yellow-birch or paper-wood): "
                                             "material '" + m.name + "' is " + what));
    }
    if (facts.wall_thickness_m > 0.0 || facts.wall_variable) {
      return Refuse(why,
                    TextRefusal(field, "one piece of solid wood: wall_thickness_m = " +
                                           FormatNumber(facts.wall_thickness_m) +
                                           (facts.wall_variable ? " (a design variable)" : "") +
                                           " makes a hollow shell"));
    }
    if (facts.has_fill && (facts.fill_density_kg_m3 != 0.0 || facts.fill_density_variable)) {
      return Refuse(
          why, TextRefusal(field, "one piece of solid wood: fill.material.density_kg_m3 = " +
                                      FormatNumber(facts.fill_density_kg_m3) +
                                      (facts.fill_density_variable ? " (a design variable)" : "") +
                                      " puts a foreign substance in the bat (only an empty cup "
                                      "is allowed)"));
    }
  }
  // A solid bat's BBCOR is the COR its scene uses. A hollow one's is the barrel model's, a
  // constraint of the design (rules.bbcor.bbcor): its scene COR, the trampoline's at the scene's
  // own ball and speed, may be above 0.50 for a legal bat.
  const bool hollow = facts.wall_thickness_m > 0.0 || facts.wall_variable;
  if (limits.max_bbcor.has_value() && !hollow && facts.cor > *limits.max_bbcor) {
    return Refuse(
        why, TextRefusal(field, "cor = " + FormatNumber(facts.cor) + " exceeds the BBCOR limit " +
                                    FormatNumber(*limits.max_bbcor) +
                                    " (for a rigid bat the BBCOR-style value equals the "
                                    "COR)"));
  }
  return true;
}

bool BbcorRuleHolds(const Bat& bat, BbcorResult* bbcor, std::string* why, double tolerance,
                    const MassProperties* rigid_body_properties, std::optional<double> bound) {
  // THE BBCOR (issue 35): the flexible scan's maximum, the fixed-point estimate beside it.
  *bbcor = ComputeCertifiedBbcor(bat, FlexibleOptions{}, BarrelOptions{}, rigid_body_properties);
  const double rule_limit = *LimitsOf(RuleSet::kBbcor).max_bbcor;
  const double limit = bound.value_or(rule_limit);
  const std::string name = limit < rule_limit ? "constraints.bbcor_max" : "rules.bbcor";
  if (!bbcor->ok) {
    if (why != nullptr) *why = name + ": the BBCOR could not be computed: " + bbcor->message;
    return false;
  }
  if (!(bbcor->value <= limit + tolerance)) {
    if (why != nullptr) {
      *why = name + ": the design's BBCOR = " + FormatNumber(bbcor->value) + " exceeds the limit " +
             FormatNumber(limit) +
             " (NCAA protocol, the flexible scan's maximum, recomputed on the answer: the "
             "optimiser found no design within the variables' bounds and the other constraints "
             "that meets it; raise the wall's upper bound or free the variables that lower the "
             "BBCOR)";
    }
    return false;
  }
  return true;
}

}  // namespace sweetspot::core
