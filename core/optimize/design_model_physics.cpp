// DesignModel::Build's constraints of the design's physics beyond its mass properties: the first
// bending frequency, the barrel's own COR and the bbcor rule. Split from
// design_model_constraints.cpp (issue 33, item 6).
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/ball/ball_catalogue.hpp"
#include "core/collision/barrel.hpp"
#include "core/flexible/beam_frequency.hpp"
#include "core/flexible/modes.hpp"
#include "core/optimize/design_bbcor.hpp"
#include "core/optimize/design_model_builder.hpp"
#include "core/units.hpp"

namespace sweetspot::core::design_detail {

// The first bending frequency (min_frequency_hz) on its fixed mesh.
bool ModelBuilder::FrequencyConstraint() {
  if (!cons.min_frequency_hz.has_value()) return true;
  const double bound = *cons.min_frequency_hz;
  if (!CheckInRange(why, "constraints.min_frequency_hz", bound, 0.0, kMaxDesignFrequencyHz,
                    /*lo_open=*/true)) {
    return false;
  }
  if (options.hessian == HessianMode::kExact) {
    return Refuse(why, TextRefusal("options.hessian",
                                   "exact is not available with constraints.min_frequency_hz "
                                   "(the frequency has an exact gradient but no second "
                                   "derivatives): use limited_memory"));
  }
  // The mesh: the modes code's final mesh for the start design at vibration_node's settings,
  // its nodes kept as fractions of the length for the whole optimisation.
  const std::vector<double> x0 = model.BaseX();
  const Bat start = model.BatAt(x0.data());
  const BeamModesOptions mo = problem.flexible.VibrationModes();
  const BatModes modes = ComputeBatModes(start, mo);
  if (!modes.summary.IsSolutionUsable() || modes.modes.size() < 2) {
    return Refuse(why, "constraints.min_frequency_hz", bound,
                  "the bending modes of the start (the base design clamped into the "
                  "variables' bounds) cannot be computed: " +
                      modes.summary.message);
  }
  FixedMeshBeam beam = MakeFixedMeshBeam(start, modes.nodes_m, model.num_knots_, model.hollow_,
                                         model.has_fill_, mo.theory, mo.rotary_inertia);
  const Eigen::Index ndof = modes.modes.front().vector.size();
  beam.start_basis.resize(ndof, 4);
  beam.start_basis.col(0) = modes.TranslationMode();
  beam.start_basis.col(1) = modes.RotationMode();
  beam.start_basis.col(2) = modes.modes[0].vector;
  beam.start_basis.col(3) = modes.modes[1].vector;
  const double omega = 2.0 * kPi * modes.modes[0].frequency_hz;
  beam.shift = omega * omega;
  const std::vector<double> t0 = model.ParametersAt(x0.data());
  const FirstBendingMode check = ComputeFirstBendingMode(beam, t0, false);
  if (!check.ok) {
    return Refuse(
        why, "constraints.min_frequency_hz", bound,
        "the first bending mode of the start cannot be computed on its mesh: " + check.message);
  }
  model.frequency_beam_ = std::make_shared<const FixedMeshBeam>(std::move(beam));
  DesignConstraintSpec c;
  c.name = c.min_name = c.max_name = "min_frequency_hz";
  c.unit = "hz";
  c.f.function = DesignFunction::kFirstFrequency;
  c.lower = bound;
  c.upper = kInf;
  c.property = true;  // analysed for conflicts (its reach within the bounds)
  model.constraints_.push_back(std::move(c));
  return true;
}

// cor_from_barrel: the exit-speed objectives' COR is the design's own barrel's, EffectiveCorAt's
// quasi-static trampoline for the scene's ball at kCorReferenceFromTipM from the tip (the point
// ResolveScene evaluates a scene's COR at, so the answer's COR is the one /v1/sweet-spot gives
// its bat), recomputed per design with exact derivatives (design_bbcor.hpp, DesignModel::WallJet).
bool ModelBuilder::BarrelCor() {
  if (!problem.cor_from_barrel) return true;
  const std::string field = "cor_from_barrel";
  if (problem.cor.has_value()) {
    return Refuse(why, TextRefusal(field, "needs cor unset (a given cor is held fixed)"));
  }
  if (!problem.ball.cor_law.has_value()) {
    return Refuse(why, TextRefusal(field, "needs a ball with a COR law (ball.preset)"));
  }
  if (!model.hollow_) {
    return Refuse(why,
                  TextRefusal(field,
                              "needs a hollow design (bat.wall_thickness_m > 0 or "
                              "wall_thickness_m a variable): a solid bat's COR is the ball's"));
  }
  if (problem.objective != DesignObjective::kMaxExitSpeed &&
      problem.objective != DesignObjective::kMaxExitSpeedSwingWeight &&
      problem.objective != DesignObjective::kWidestSweetZone) {
    return Refuse(why, TextRefusal(field,
                                   "applies to the exit-speed objectives (max_exit_speed, "
                                   "max_exit_speed_swing_weight, widest_sweet_zone) only"));
  }
  const double shortest_m = ParamLower(lay.KnotPosition(model.num_knots_ - 1));
  if (!(shortest_m > kCorReferenceFromTipM)) {
    return Refuse(
        why, TextRefusal(field, "the shortest bat the variables allow, L = " + Num(shortest_m) +
                                    " m, is not longer than " + Num(kCorReferenceFromTipM) +
                                    " m, the COR's impact point from the tip"));
  }
  BarrelCorConstants k;
  k.trampoline = TrampolineConstantsOf(problem.ball, base.material, BarrelOptions{});
  k.cor_law = *problem.ball.cor_law;
  k.impact_from_tip_m = kCorReferenceFromTipM;
  model.barrel_cor_ = std::make_shared<const BarrelCorConstants>(k);
  const std::vector<double> x0 = model.BaseX();
  model.cor_ = model.CorAt(x0.data());
  if (!std::isfinite(model.cor_)) {
    return Refuse(why, TextRefusal(field,
                                   "the barrel COR of the start (the base design clamped into "
                                   "the variables' bounds) cannot be computed (the ball must "
                                   "approach the point 0.1524 m from the tip)"));
  }
  return true;
}

// The `bbcor` rule on a hollow design: BBCOR <= 0.50 by ComputeBbcor's model (the NCAA protocol,
// the default barrel options) as a nonlinear constraint with exact derivatives (design_bbcor.hpp).
// A solid design keeps the check of the scene's COR before solving (Rules()).
bool ModelBuilder::BbcorConstraint() {
  const auto& rules = cons.rules;
  const bool rule = std::find(rules.begin(), rules.end(), RuleSet::kBbcor) != rules.end();
  if (cons.bbcor_max.has_value()) {
    if (!CheckInRange(why, "constraints.bbcor_max", *cons.bbcor_max, 0.0, 1.0,
                      /*lo_open=*/true)) {
      return false;
    }
    if (!model.hollow_) {
      return Refuse(why, TextRefusal("constraints.bbcor_max",
                                     "applies to a hollow design (a wall_thickness_m on the "
                                     "bat or as a variable); a solid bat's BBCOR is the "
                                     "ball's COR less its bending loss, which no variable "
                                     "here sets"));
    }
  }
  if (!model.hollow_ || (!rule && !cons.bbcor_max.has_value())) return true;
  // THE BBCOR's bound (bbcor_constraint.hpp): the estimate held below it less the offset the
  // certification rounds set (0 on the first round without a hollow base).
  const double rule_limit = *LimitsOf(RuleSet::kBbcor).max_bbcor;
  const bool margin = cons.bbcor_max.has_value() && (!rule || *cons.bbcor_max < rule_limit);
  const double bound = margin ? *cons.bbcor_max : rule_limit;
  const BbcorProtocol protocol;
  const BarrelOptions barrel;
  const std::optional<BallPreset> ball = FindBallPreset(protocol.ball);
  if (!ball.has_value()) {
    return Refuse(why, TextRefusal("rules.bbcor", "the protocol's ball '" + protocol.ball +
                                                      "' is not in the catalogue"));
  }
  BbcorConstants k;
  k.trampoline = TrampolineConstantsOf(*ball, base.material, barrel);
  k.ball_cor = ball->cor_law.CorAt(protocol.ball_speed_mps);
  k.speed_mps = protocol.ball_speed_mps;
  k.pivot_from_knob_m = protocol.pivot_from_knob_m;
  k.impact_from_tip_m = protocol.impact_from_tip_m;
  // The impact point must lie beyond the pivot on every design: on the shortest one.
  const double shortest_m = ParamLower(lay.KnotPosition(model.num_knots_ - 1));
  if (!(shortest_m - k.impact_from_tip_m > k.pivot_from_knob_m)) {
    return Refuse(why,
                  TextRefusal("rules.bbcor",
                              "the shortest bat the variables allow, L = " + Num(shortest_m) +
                                  " m, does not put the BBCOR protocol's impact point (" +
                                  Num(k.impact_from_tip_m) + " m from the tip) beyond its pivot (" +
                                  Num(k.pivot_from_knob_m) + " m from the knob)"));
  }
  model.bbcor_ = std::make_shared<const BbcorConstants>(k);
  const std::vector<double> x0 = model.BaseX();
  const double start = model.BbcorAt(x0.data());
  if (!std::isfinite(start)) {
    return Refuse(why, TextRefusal("rules.bbcor",
                                   "the BBCOR of the start (the base design clamped into the "
                                   "variables' bounds) cannot be computed"));
  }
  DesignConstraintSpec c;
  c.name = c.min_name = c.max_name = margin ? "bbcor_max" : "rules.bbcor.bbcor";
  c.unit = "";
  c.f.function = DesignFunction::kBbcor;
  c.upper = bound - cons.bbcor_estimate_offset;
  c.property = true;  // analysed for conflicts (its reach within the bounds)
  model.constraints_.push_back(std::move(c));
  return true;
}

}  // namespace sweetspot::core::design_detail
