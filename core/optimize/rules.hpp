// League rule sets a bat design may be held to: the continuous limits (diameter, length,
// length-minus-weight) become constraints of the design problem; the discrete ones (solid
// wood only, no fill, the ball-bat COR) are checked before solving and refused by name.
// Sources: see RuleSetLimits::source and docs/optimization.md.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/bat/material.hpp"
#include "core/collision/barrel.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {

/// A named league rule set.
enum class RuleSet {
  kMlbWood,  ///< "mlb-wood": MLB Official Baseball Rules 3.02(a).
  kBbcor,    ///< "bbcor": NCAA / NFHS BBCOR standard.
  kUsssa,    ///< "usssa": USSSA baseball bat standard (diameter only).
};

/// Stable name: "mlb-wood", "bbcor", "usssa".
const char* RuleSetName(RuleSet rule);
/// The rule set called `name`, or nullopt.
std::optional<RuleSet> ParseRuleSet(std::string_view name);
/// Every rule set, in enum order.
const std::vector<RuleSet>& AllRuleSets();

/// The limits of a rule set (SI; unset = no such limit).
struct RuleSetLimits {
  double max_diameter_m = 0.0;            ///< Largest diameter anywhere on the bat, m.
  std::optional<double> max_length_m;     ///< Longest bat, m.
  std::optional<double> max_drop;         ///< Largest length_in - weight_oz (dimensionless).
  std::optional<double> max_bbcor;        ///< Largest ball-bat COR (dimensionless).
  bool solid_wood_only = false;           ///< One piece of solid wood: no shell, no fill.
  std::optional<double> max_cup_depth_m;  ///< Solid wood: an empty cup at the end, m deep at most.
  std::optional<double> min_cup_diameter_m;  ///< ... at least this wide, m.
  std::optional<double> max_cup_diameter_m;  ///< ... at most this wide, m.
  std::string source;                        ///< Where the limits come from.
};

/// The limits of `rule` (constant data).
RuleSetLimits LimitsOf(RuleSet rule);

/// True for a material of kind wood whose base is an allowed species ("ash", "hard-maple",
/// "yellow-birch", "paper-wood"): a catalogue wood, or a request's {"base": wood, ...overrides},
/// whatever its name; a custom material without a base is not known to be wood.
bool IsWoodMaterial(const Material& material);

/// The discrete facts of a design that a rule set checks before solving.
struct RuleFacts {
  Material material;                   ///< The bat's material.
  bool density_variable = false;       ///< The material's density is a design variable.
  double wall_thickness_m = 0.0;       ///< The base design's wall, m (0 = solid).
  bool wall_variable = false;          ///< The wall thickness is a design variable.
  bool has_fill = false;               ///< The design has a fill.
  double fill_density_kg_m3 = 0.0;     ///< The fill's density, kg/m³ (0 = an empty bore).
  bool fill_density_variable = false;  ///< The fill's density is a design variable.
  double cor = 0.5;                    ///< The ball-bat COR the scene uses (dimensionless).
};

/// True when nothing discrete in `facts` breaks `rule`; otherwise the refusal in *why (if
/// non-null): field "rules.<name>", the rule the broken part (Message(): "rules.mlb-wood:
/// ..."). The continuous limits are not checked here (they are constraints of the design
/// problem).
bool RuleAllowsDesign(RuleSet rule, const RuleFacts& facts, Refusal* why);

/// The `bbcor` rule's check of a finished hollow design, by recomputing THE BBCOR (issue 35):
/// *bbcor = ComputeCertifiedBbcor(bat) (scene_barrel.hpp: the flexible scan's maximum by the NCAA
/// protocol, default flexible and barrel options, the fixed-point estimate beside it). The design
/// model holds the BBCOR as a constraint (bbcor_constraint.hpp); this is the independent check of
/// its answer. False, with "rules.bbcor: ..." (or "constraints.bbcor_max: ..." when `bound` is
/// below the rule's 0.50) in *why, when the value exceeds `bound` (default: the rule's limit)
/// by more than tolerance (>= 0; the optimiser passes its feasibility tolerance) or the model
/// fails. `rigid_body_properties`: the bat's mass properties under InertiaModel::kRigidBody when
/// the caller has them (null: computed).
bool BbcorRuleHolds(const Bat& bat, BbcorResult* bbcor, std::string* why, double tolerance = 0.0,
                    const MassProperties* rigid_body_properties = nullptr,
                    std::optional<double> bound = std::nullopt);

}  // namespace sweetspot::core
