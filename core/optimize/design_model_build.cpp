// DesignModel::Build, by concern: the scene and objective checks, the base design, the
// parameters and variables, the rule sets, and the objective with the scales; the constraints
// are in design_model_constraints.cpp. See design_model.hpp.
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/optimize/design_integrals.hpp"
#include "core/optimize/design_model_builder.hpp"

namespace sweetspot::core {
namespace design_detail {

// Scene and objective.
bool ModelBuilder::CheckScene() {
  if (problem.objective != DesignObjective::kLeastSquares &&
      ParseDesignObjective(DesignObjectiveName(problem.objective)) != problem.objective) {
    return Refuse(why, TextRefusal("objective", "not a known objective"));
  }
  if (!LeastSquaresObjective()) return false;
  if (!problem.ball.Validate(why) || !problem.swing.Validate(why)) return false;
  // The scenes' swing settings the optimiser does not take (its swing weight is the objective
  // max_exit_speed_swing_weight's): refused, not ignored.
  if (problem.swing.bat_speed_point != BatSpeedPoint::kFromTip) {
    return Refuse(why, QuotedRefusal("swing.bat_speed_from_tip_m", "sweet_spot",
                                     "is not taken by the optimiser: give a distance"));
  }
  if (problem.swing.speed_model != SwingSpeedModel::kFixed) {
    return Refuse(why, QuotedRefusal("swing.speed_model", "swing_weight",
                                     "is not taken by the optimiser: use objective "
                                     "max_exit_speed_swing_weight"));
  }
  if (!(std::isfinite(problem.swing_weight_exponent) && problem.swing_weight_exponent >= 0.0 &&
        problem.swing_weight_exponent <= kMaxSwingWeightExponent)) {
    return Refuse(why, "swing_weight_exponent", problem.swing_weight_exponent,
                  "must be in [0, " + FormatNumber(kMaxSwingWeightExponent) + "]");
  }
  if (problem.swing_weight_reference_kg_m2.has_value()) {
    if (problem.objective != DesignObjective::kMaxExitSpeedSwingWeight) {
      return Refuse(why, "swing_weight_reference_kg_m2", *problem.swing_weight_reference_kg_m2,
                    "applies only to objective max_exit_speed_swing_weight (objective is " +
                        std::string(DesignObjectiveName(problem.objective)) + ")");
    }
    if (!CheckInRange(why, "swing_weight_reference_kg_m2", *problem.swing_weight_reference_kg_m2,
                      0.0, kMaxDesignMoiKgM2, /*lo_open=*/true)) {
      return false;
    }
  }
  if (!CheckInRange(why, "sweet_zone_tolerance_mps", problem.sweet_zone_tolerance_mps, 0.0,
                    kMaxDesignZoneToleranceMps, /*lo_open=*/true)) {
    return false;
  }
  exit_speed_objective = problem.objective != DesignObjective::kMinMoi &&
                         problem.objective != DesignObjective::kLeastSquares;
  const bool by_bat_speed = problem.swing.bat_speed_mps.has_value();
  if (exit_speed_objective && problem.ball.speed_mps == 0.0 &&
      (by_bat_speed ? *problem.swing.bat_speed_mps : problem.swing.angular_speed_rad_s) == 0.0) {
    return Refuse(why,
                  QuotedRefusal("ball.speed_mps",
                                by_bat_speed ? "0 and swing.bat_speed_mps = 0"
                                             : "0 and swing.angular_speed_rad_s = 0",
                                "nothing moves, the exit speed is 0 everywhere (objective " +
                                    std::string(DesignObjectiveName(problem.objective)) + ")"));
  }
  if (problem.inertia_model != InertiaModel::kRigidBody &&
      problem.inertia_model != InertiaModel::kSlenderRod) {
    return Refuse(why, TextRefusal("inertia_model", "not a known inertia model"));
  }
  if ((problem.objective == DesignObjective::kMinSting ||
       problem.constraints.min_frequency_hz.has_value()) &&
      !problem.flexible.Validate(why)) {
    return false;
  }

  return true;
}

// The base design and the COR.
bool ModelBuilder::BaseDesign() {
  base = problem.bat;
  if (problem.three_segment.has_value()) {
    if (!problem.three_segment->Validate(inner_ptr)) {
      return Refuse(why, Prefixed("three_segment.", inner));
    }
    base.knots = problem.three_segment->Knots();
  }
  if (!base.Validate(inner_ptr)) return Refuse(why, Prefixed("bat.", inner));
  if (problem.cor.has_value()) {
    if (!(std::isfinite(*problem.cor) && *problem.cor >= 0.0 && *problem.cor <= 1.0)) {
      return Refuse(why, "cor", *problem.cor, "must be in [0, 1]");
    }
    model.cor_ = *problem.cor;
  } else if (problem.cor_from_barrel) {
    model.cor_ = kNaN;  // the start's barrel COR, set by BarrelCor() (which checks the request)
  } else if (base.material.cor.has_value()) {
    model.cor_ = *base.material.cor;
  } else if (exit_speed_objective) {
    return Refuse(why, TextRefusal("cor", "not given, and material '" + base.material.name +
                                              "' has no default COR"));
  } else {
    model.cor_ = 0.5;  // unused by min_moi; the rules' BBCOR check uses it only if given
  }

  return true;
}

// The design parameters of the base design.
void ModelBuilder::Parameters() {
  model.base_bat_ = base;
  model.base_shape_ = problem.three_segment;
  model.hollow_ = base.IsHollow();
  model.has_fill_ = base.fill.has_value();
  model.rigid_ = problem.inertia_model == InertiaModel::kRigidBody;
  if (problem.three_segment.has_value()) {
    model.base_parameters_ = ThreeSegmentParameters(base, *problem.three_segment);
    model.num_knots_ = 4;
  } else {
    const Eigen::VectorXd p = DesignParameters(base);
    model.base_parameters_.assign(p.data(), p.data() + p.size());
    model.num_knots_ = static_cast<int>(base.knots.size());
  }
  lay = DesignParameterLayout{model.num_knots_};
  model.parameter_variable_.assign(static_cast<std::size_t>(lay.Size()), -1);
  model.parameter_scale_.assign(static_cast<std::size_t>(lay.Size()), 1.0);
}

// The parameters a variable moves, with the flags the rules need.
std::vector<int> ModelBuilder::ParametersOf(const DesignVariableRef& ref) {
  density_variable = density_variable || ref.kind == DesignVariableKind::kDensity;
  wall_variable = wall_variable || ref.kind == DesignVariableKind::kWallThickness;
  fill_density_variable = fill_density_variable || ref.kind == DesignVariableKind::kFillDensity;
  return DesignParametersOf(ref, lay);
}

// The field `path` (named `field` in a refusal) checked against the design: a variable path
// that applies to it, not named before.
bool ModelBuilder::CheckVariablePath(const std::string& field, const std::string& path,
                                     const std::optional<DesignVariableRef>& ref,
                                     std::set<std::string>* seen) {
  // "<field> = <path>: rule".
  auto refuse_path = [&](const std::string& rule) {
    return Refuse(why, QuotedRefusal(field, path, rule));
  };
  if (!ref.has_value()) {
    return refuse_path(
        "not a design variable (known: profile.knots[i].radius_m, "
        "profile.knots[i].x_m, three_segment.length_m, "
        "three_segment.handle_radius_m, three_segment.barrel_radius_m, "
        "three_segment.taper_start_m, three_segment.taper_end_m, "
        "material.density_kg_m3, wall_thickness_m, fill.diameter_m, "
        "fill.depth_m, fill.material.density_kg_m3)");
  }
  if (!seen->insert(path).second) return refuse_path("appears more than once");
  if (IsProfileKind(ref->kind) && problem.three_segment.has_value()) {
    return refuse_path("the design is a three_segment shape (use three_segment.*)");
  }
  if (IsThreeSegmentKind(ref->kind) && !problem.three_segment.has_value()) {
    return refuse_path("the design is a profile, not a three_segment shape");
  }
  if (IsProfileKind(ref->kind) && ref->knot >= model.num_knots_) {
    return refuse_path("the profile has " + std::to_string(model.num_knots_) + " knots");
  }
  if (ref->kind == DesignVariableKind::kKnotPosition && ref->knot == 0) {
    return refuse_path("must stay 0 (positions are measured from the knob)");
  }
  if (IsFillKind(ref->kind) && !base.fill.has_value()) {
    return refuse_path("the bat has no fill");
  }
  return true;
}

// Variable i's bounds: finite, ordered, within kMaxDesignBound.
bool ModelBuilder::CheckBounds(std::size_t i, const DesignVariable& v) {
  const std::string field = IndexedField("variables", i, "");
  if (!std::isfinite(v.min)) {
    return Refuse(why, field + "min", v.min,
                  "must be finite (an optimisation needs bounded variables)");
  }
  if (!std::isfinite(v.max)) {
    return Refuse(why, field + "max", v.max,
                  "must be finite (an optimisation needs bounded variables)");
  }
  if (!CheckInRange(why, field + "min", v.min, -kMaxDesignBound, kMaxDesignBound) ||
      !CheckInRange(why, field + "max", v.max, -kMaxDesignBound, kMaxDesignBound)) {
    return false;
  }
  if (!(v.max > v.min)) {
    return Refuse(why, field + "max", v.max,
                  "must be greater than " + field + "min = " + Num(v.min));
  }
  return true;
}

// Variable i checked against the design (refused with the reason in *why).
bool ModelBuilder::CheckVariable(std::size_t i, const DesignVariable& v,
                                 const std::optional<DesignVariableRef>& ref,
                                 std::set<std::string>* seen) {
  const std::string field = IndexedField("variables", i, "");
  if (!CheckVariablePath(field + "path", v.path, ref, seen) || !CheckBounds(i, v)) return false;
  if (NeedsPositive(ref->kind) && !(v.min > 0.0)) {
    return Refuse(why, field + "min", v.min,
                  "must be positive for " + v.path +
                      (ref->kind == DesignVariableKind::kWallThickness
                           ? " (the bat stays hollow: wall = 0 is a solid bat, a jump)"
                           : ""));
  }
  if (!NeedsPositive(ref->kind) && v.min < 0.0) {
    return Refuse(why, field + "min", v.min, "must be non-negative for " + v.path);
  }
  return true;
}

// Scale variable i: its name, bounds and fields checked, then added with its parameters, each
// parameter's coefficient the field's base value.
bool ModelBuilder::AddScaleVariable(std::size_t i, std::set<std::string>* seen) {
  const DesignVariable& v = problem.variables[i];
  const std::string field = IndexedField("variables", i, "");
  if (!v.linked_paths.empty()) {
    return Refuse(why, TextRefusal(field + "linked_paths",
                                   "a scale variable (scale_paths) has no linked paths: give "
                                   "paths or scale_paths, not both"));
  }
  if (v.path.empty() || ParseDesignVariablePath(v.path).has_value()) {
    return Refuse(why, QuotedRefusal(field + "path", v.path,
                                     "a scale variable's name must be given and must not be a "
                                     "variable path (its fields are in scale_paths)"));
  }
  if (!seen->insert(v.path).second) {
    return Refuse(why, QuotedRefusal(field + "path", v.path, "appears more than once"));
  }
  if (!CheckBounds(i, v)) return false;
  DesignVariableSpec spec;
  spec.path = v.path;
  spec.scale = true;
  spec.lower = v.min;
  spec.upper = v.max;
  spec.base = 1.0;  // the base design
  const auto j = static_cast<int>(model.variables_.size());
  for (std::size_t k = 0; k < v.scale_paths.size(); ++k) {
    const std::string& path = v.scale_paths[k];
    const std::string path_field = field + "scale_paths[" + std::to_string(k) + "]";
    const std::optional<DesignVariableRef> ref = ParseDesignVariablePath(path);
    if (!CheckVariablePath(path_field, path, ref, seen)) return false;
    const std::vector<int> parameters = ParametersOf(*ref);
    const double base_value = Param(parameters.front());
    if (base_value == 0.0) {
      return Refuse(why, QuotedRefusal(path_field, path,
                                       "is 0 in the base design, so scaling it keeps it 0 "
                                       "(give it as a path of its own)"));
    }
    // The field's own rules over the range the scale gives it.
    const double lo = std::min(v.min * base_value, v.max * base_value);
    const double hi = std::max(v.min * base_value, v.max * base_value);
    const bool positive = NeedsPositive(ref->kind);
    if (positive ? !(lo > 0.0) : lo < 0.0) {
      const bool by_min = lo == v.min * base_value;
      return Refuse(why, field + (by_min ? "min" : "max"), by_min ? v.min : v.max,
                    "gives " + path + " = " + Num(lo) + " (" + Num(base_value) +
                        " in the base design), which must be " +
                        (positive ? "positive" : "non-negative"));
    }
    if (!(hi <= kMaxDesignBound)) {
      return Refuse(why, field + "max", v.max,
                    "gives " + path + " = " + Num(hi) + ", over " + Num(kMaxDesignBound));
    }
    for (int idx : parameters) {
      spec.parameters.push_back(idx);
      model.parameter_variable_[static_cast<std::size_t>(idx)] = j;
      model.parameter_scale_[static_cast<std::size_t>(idx)] = Param(idx);
    }
    spec.scale_paths.push_back(path);
    spec.scale_bases.push_back(base_value);
  }
  if (spec.scale_paths.empty()) {
    return Refuse(why, TextRefusal(field + "scale_paths", "must name at least one field"));
  }
  model.variables_.push_back(spec);
  return true;
}

// Variable i: checked, then added with its parameters.
bool ModelBuilder::AddVariable(std::size_t i, std::set<std::string>* seen) {
  const DesignVariable& v = problem.variables[i];
  if (!v.scale_paths.empty()) return AddScaleVariable(i, seen);
  const std::optional<DesignVariableRef> ref = ParseDesignVariablePath(v.path);
  if (!CheckVariable(i, v, ref, seen)) return false;
  DesignVariableSpec spec;
  spec.path = v.path;
  spec.ref = *ref;
  spec.lower = v.min;
  spec.upper = v.max;
  spec.parameters = ParametersOf(*ref);
  spec.base = Param(spec.parameters.front());
  for (const std::string& path : v.linked_paths) {
    // Each linked field is checked as a variable of its own would be; it takes the value.
    DesignVariable linked = v;
    linked.path = path;
    linked.linked_paths.clear();
    const std::optional<DesignVariableRef> linked_ref = ParseDesignVariablePath(path);
    if (!CheckVariable(i, linked, linked_ref, seen)) return false;
    for (int idx : ParametersOf(*linked_ref)) {
      if (std::find(spec.parameters.begin(), spec.parameters.end(), idx) == spec.parameters.end()) {
        spec.parameters.push_back(idx);
      }
    }
    spec.linked_paths.push_back(path);
  }
  for (int idx : spec.parameters) {
    model.parameter_variable_[static_cast<std::size_t>(idx)] =
        static_cast<int>(model.variables_.size());
  }
  model.variables_.push_back(spec);
  return true;
}

// Every variable.
bool ModelBuilder::Variables() {
  if (problem.variables.empty() ||
      problem.variables.size() > static_cast<std::size_t>(options.max_variables)) {
    return Refuse(why, "variables.size()", static_cast<double>(problem.variables.size()),
                  "must be between 1 and " + std::to_string(options.max_variables));
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < problem.variables.size(); ++i) {
    if (!AddVariable(i, &seen)) return false;
  }
  if (wall_variable) model.hollow_ = true;
  if (fill_density_variable) {
    Material f = base.fill->material;
    f.density_kg_m3 = 1.0;  // check the other fields: the fill may become non-empty
    if (!f.Validate(inner_ptr)) {
      return Refuse(why, Noted(Prefixed("fill.material.", inner),
                               " (fill.material.density_kg_m3 is a variable, so the fill "
                               "material must be complete)"));
    }
  }

  return true;
}

// Rules: the discrete limits.
bool ModelBuilder::Rules() {
  {
    std::set<RuleSet> rules_seen;
    for (std::size_t i = 0; i < problem.constraints.rules.size(); ++i) {
      const RuleSet rule = problem.constraints.rules[i];
      if (!ParseRuleSet(RuleSetName(rule)).has_value()) {
        return Refuse(
            why, TextRefusal(IndexedField("constraints.rules", i, ""), "not a known rule set"));
      }
      if (!rules_seen.insert(rule).second) {
        return Refuse(why, TextRefusal("constraints.rules",
                                       std::string(RuleSetName(rule)) + " appears more than once"));
      }
      RuleFacts facts;
      facts.material = base.material;
      facts.density_variable = density_variable;
      facts.wall_thickness_m = base.wall_thickness_m;
      facts.wall_variable = wall_variable;
      facts.has_fill = base.fill.has_value();
      facts.fill_density_kg_m3 = base.fill.has_value() ? base.fill->material.density_kg_m3 : 0.0;
      facts.fill_density_variable = fill_density_variable;
      facts.cor = model.cor_;
      if (!RuleAllowsDesign(rule, facts, why)) return false;
    }
  }

  return true;
}

// Scene numbers and references.
bool ModelBuilder::SceneNumbers() {
  model.ball_mass_kg_ = problem.ball.mass_kg;
  model.ball_speed_mps_ = problem.ball.speed_mps;
  model.omega0_rad_s_ = problem.swing.angular_speed_rad_s;
  model.pivot_from_knob_m_ = problem.swing.pivot_from_knob_m;
  if (!SwingByBatSpeed()) return false;
  if (problem.model != CollisionModel::kRigidPivot && problem.model != CollisionModel::kFreeBat) {
    return Refuse(why, Refusal{"model", std::numeric_limits<double>::quiet_NaN(),
                               CollisionModelName(problem.model),
                               problem.objective == DesignObjective::kMaxDistance
                                   ? "must be rigid_pivot or free_bat (max_distance searches the "
                                     "distance sweet spot of every design with the closed-form "
                                     "normal law; hertz and flexible need a table of ODE impacts "
                                     "per design)"
                                   : "must be rigid_pivot or free_bat (the design's derivatives "
                                     "need a closed form)"});
  }
  model.free_bat_ = problem.model == CollisionModel::kFreeBat;
  model.swing_weight_exponent_ = problem.swing_weight_exponent;
  model.zone_tolerance_mps_ = problem.sweet_zone_tolerance_mps;
  model.objective_kind_ = problem.objective;
  if (problem.objective == DesignObjective::kMinSting) {
    model.sting_scene_.ball = problem.ball;
    model.sting_scene_.swing = problem.swing;
    model.sting_scene_.cor = model.cor_;
    model.sting_scene_.model = problem.model;
    model.sting_scene_.inertia_model = problem.inertia_model;
    model.sting_scene_.flexible = problem.flexible;
    model.sting_scene_.flexible.modes_cache = nullptr;  // the model's own cache instead
    model.sting_modes_ = std::make_shared<ModesCache>(kStingModesCacheEntries);
  }
  if (problem.objective == DesignObjective::kMaxDistance) {
    if (!problem.distance.Validate(why)) return false;  // names "distance.<field>"
    auto scene = std::make_shared<DistanceScene>();
    scene->ball = problem.ball;
    scene->swing = problem.swing;
    scene->cor = model.cor_;
    scene->inertia_model = problem.inertia_model;
    scene->model = problem.model;
    scene->environment = problem.environment;
    scene->aero = problem.aero;
    scene->distance = problem.distance;
    model.distance_scene_ = std::move(scene);
  }
  const MassProperties base_properties = problem.base_mass_properties.has_value()
                                             ? *problem.base_mass_properties
                                             : ComputeMassProperties(base, problem.inertia_model);
  model.c0_ = base_properties.balance_point_m;
  if (!(std::isfinite(model.c0_) && base_properties.MoiSixInchKgM2() > 0.0)) {
    return Refuse(why, TextRefusal("bat", "its mass properties are not finite"));
  }
  model.i6_ref_ = problem.swing_weight_reference_kg_m2.value_or(base_properties.MoiSixInchKgM2());

  return true;
}

// A swing given by its bat speed (swing.bat_speed_mps at bat_speed_from_tip_m): omega0 =
// v / (L - from_tip - pivot), resolved once when no variable moves the length L, else a
// function of the design's L (the objective's derivatives include d omega0 / dL).
bool ModelBuilder::SwingByBatSpeed() {
  const Swing& swing = problem.swing;
  if (!swing.bat_speed_mps.has_value()) return true;
  const int length_idx = lay.KnotPosition(model.num_knots_ - 1);
  const bool varies = model.parameter_variable_[static_cast<std::size_t>(length_idx)] >= 0;
  // The shortest bat the variables allow has the shortest arm and the fastest omega0: if the
  // bat-speed point lies beyond the pivot there, with omega0 in range, it does on every design.
  const double shortest_m = ParamLower(length_idx);
  Swing resolved;
  Refusal refusal;
  if (!ResolveSwing(swing, shortest_m, &resolved, why != nullptr ? &refusal : nullptr)) {
    if (!varies) return Refuse(why, std::move(refusal));
    return Refuse(why, Noted(std::move(refusal),
                             " (for the shortest bat the variables allow, L = " + Num(shortest_m) +
                                 " m: the bat length is a design variable)"));
  }
  if (!varies) {
    model.omega0_rad_s_ = resolved.angular_speed_rad_s;  // the base design's length
    return true;
  }
  model.omega_from_length_ = true;
  model.bat_speed_mps_ = *swing.bat_speed_mps;
  model.bat_speed_from_tip_m_ = swing.bat_speed_from_tip_m;
  return true;
}

// Objective and the scales.
bool ModelBuilder::Objective() {
  model.objective_.function = DesignFunction::kObjective;
  model.maximize_ = problem.objective != DesignObjective::kMinMoi &&
                    problem.objective != DesignObjective::kMinSting &&
                    problem.objective != DesignObjective::kLeastSquares;
  model.objective_unit_ = problem.objective == DesignObjective::kMinMoi            ? "kg_m2"
                          : problem.objective == DesignObjective::kWidestSweetZone ? "m"
                          : problem.objective == DesignObjective::kMaxDistance     ? "m"
                          : problem.objective == DesignObjective::kMinSting        ? "j"
                          : problem.objective == DesignObjective::kLeastSquares    ? ""
                                                                                   : "mps";
  const std::vector<double> x0 = model.BaseX();
  double f0 = kNaN;
  if (problem.objective == DesignObjective::kMinSting) {
    // The flexible model refuses some bats (too stubby for a beam, ...): say so by name.
    const StingEvaluation sting = model.StingOf(model.BatAt(x0.data()), false);
    if (!sting.ok) {
      return Refuse(why, QuotedRefusal("objective", "min_sting",
                                       "the sting of the start (the base design clamped into "
                                       "the variables' bounds) cannot be computed: " +
                                           sting.message));
    }
    f0 = sting.sting_j;
  } else if (problem.objective == DesignObjective::kMaxDistance) {
    const DistanceEvaluation d = model.DistanceOf(model.BatAt(x0.data()));
    if (!d.ok) {
      return Refuse(why, QuotedRefusal("objective", "max_distance",
                                       "the distance sweet spot of the start (the base design "
                                       "clamped into the variables' bounds) cannot be computed: " +
                                           d.message));
    }
    f0 = d.distance_m;
  } else {
    f0 = model.Value(model.objective_, x0.data());
  }
  if (!std::isfinite(f0)) {
    return Refuse(why, TextRefusal("variables",
                                   "the objective is not finite at the start (the base design "
                                   "clamped into the variables' bounds)"));
  }
  model.objective_scale_ = std::abs(f0) > 0.0 ? std::abs(f0) : 1.0;
  // The least-squares metric is already scaled (0 at a root, which the start may be).
  if (problem.objective == DesignObjective::kLeastSquares) model.objective_scale_ = 1.0;
  // The parameters once: a linear constraint's value from them (Value's bits) in O(its terms),
  // not O(n) per constraint.
  const std::vector<double> t0 = model.Parameters(x0.data());
  for (DesignConstraintSpec& c : model.constraints_) {
    double s = std::abs(c.f.function == DesignFunction::kLinear
                            ? DesignModel::LinearValueAt(c.f, t0)
                            : model.Value(c.f, x0.data()));
    if (!std::isfinite(s)) s = 0.0;
    if (std::isfinite(c.lower)) s = std::max(s, std::abs(c.lower));
    if (std::isfinite(c.upper)) s = std::max(s, std::abs(c.upper));
    c.scale = std::max(s, ScaleFloor(c.unit));
  }
  return true;
}

// Every step in order.
bool ModelBuilder::Run() {
  if (!CheckScene() || !BaseDesign()) return false;
  Parameters();
  if (!Variables() || !Rules() || !SceneNumbers() || !BarrelCor()) return false;
  if (!LengthConstraint() || !PropertyConstraints()) return false;
  RadiusKnots();
  if (!DiameterConstraints() || !TaperConstraints()) return false;
  CupConstraints();
  ValidityConstraints();
  if (!FrequencyConstraint() || !BbcorConstraint()) return false;
  return Objective();
}

}  // namespace design_detail

DesignModel DesignModel::WithConstraintLimits(int index, double lower, double upper) const {
  DesignModel copy = *this;
  DesignConstraintSpec& c = copy.constraints_[static_cast<std::size_t>(index)];
  c.lower = lower;
  c.upper = upper;
  // The scale as Objective() sets it (design_detail::ModelBuilder::Objective): the value at
  // the start and the limits.
  const std::vector<double> x0 = BaseX();
  double s = std::abs(Value(c.f, x0.data()));
  if (!std::isfinite(s)) s = 0.0;
  if (std::isfinite(c.lower)) s = std::max(s, std::abs(c.lower));
  if (std::isfinite(c.upper)) s = std::max(s, std::abs(c.upper));
  c.scale = std::max(s, design_detail::ScaleFloor(c.unit));
  return copy;
}

bool DesignModel::Build(const DesignProblem& problem, const DesignOptions& options,
                        DesignModel* out, Refusal* why) {
  design_detail::ModelBuilder builder(problem, options, why);
  if (!builder.Run()) return false;
  *out = std::move(builder.model);
  return true;
}

}  // namespace sweetspot::core
