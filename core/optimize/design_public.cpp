// The public re-evaluation of an optimised design and the answer filled from it
// (design_public.hpp).
#include "core/optimize/design_public.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/collision/rigid_pivot.hpp"
#include "core/flexible/modes.hpp"
#include "core/geometry_format.hpp"
#include "core/optimize/design_runs.hpp"
#include "core/scene/resolved_scene.hpp"

namespace sweetspot::core::design_detail {
namespace {

// The barrel COR of `bat` (mass properties p, swing omega) as ResolveScene gives it: the ball's
// law at the normal impact speed kCorReferenceFromTipM from the tip, through EffectiveCorAt.
void PublicBarrelCor(const DesignProblem& problem, const DesignModel& model, const Bat& bat,
                     const MassProperties& p, double omega_rad_s, PublicEvaluation* out) {
  const double length = bat.LengthM();
  const double x = std::max(0.0, length - model.cor_impact_from_tip_m());
  const double v = problem.ball.speed_mps + omega_rad_s * (x - problem.swing.pivot_from_knob_m);
  out->cor_impact_m = x;
  out->cor_speed_mps = v;
  if (!(v > 0.0) || !problem.ball.cor_law.has_value()) return;
  const Ball& b = problem.ball;
  out->cor_ball = b.cor_law->CorAt(v);
  const TrampolineResult t = EffectiveCorAt(bat, p, x, b.mass_kg, b.radius_m, b.stiffness,
                                            b.stiffness_exponent, out->cor_ball, v);
  if (t.ok) out->cor = t.effective_cor;
}

}  // namespace

// `p` when its moments are the rigid body's (what the barrel models use), else null.
const MassProperties* RigidBodyPropertiesOrNull(const MassProperties& p) {
  return p.inertia_model == InertiaModel::kRigidBody ? &p : nullptr;
}


PublicEvaluation EvaluatePublic(const DesignProblem& problem, const DesignModel& model,
                                const Bat& bat, bool cor_known) {
  PublicEvaluation out;
  out.properties = ComputeMassProperties(bat, problem.inertia_model);
  const MassProperties& p = out.properties;
  const double length = bat.LengthM();
  out.omega_rad_s = model.AngularSpeedFor(p.MoiSixInchKgM2(), length);
  double zone_width = kNaN;
  out.cor = model.cor();
  if (model.cor_from_barrel()) PublicBarrelCor(problem, model, bat, p, out.omega_rad_s, &out);
  if (cor_known && std::isfinite(out.cor)) {
    Swing swing = problem.swing;
    // The design's own (from its swing weight, and from its length for a bat speed).
    swing.angular_speed_rad_s = out.omega_rad_s;
    swing.bat_speed_mps.reset();  // resolved: omega is the design's
    const ExitSpeedProfile profile =
        ClosedFormProfileFor(problem.model, p, problem.ball, swing, out.cor);
    const MaxExitSpeedResult max = ClosedFormMaxExitSpeed(profile, length);
    out.sweet_spot_m = max.position_from_knob_m;
    out.placement = max.placement;
    out.max_exit_speed_mps = max.exit_speed_mps;
    const SweetZoneResult zone =
        ClosedFormSweetZone(profile, length, max, problem.sweet_zone_tolerance_mps);
    zone_width = zone.to_knob_m - zone.from_knob_m;
  }
  switch (problem.objective) {
    case DesignObjective::kMaxExitSpeed:
    case DesignObjective::kMaxExitSpeedSwingWeight:
      out.objective = out.max_exit_speed_mps;
      break;
    case DesignObjective::kWidestSweetZone:
      out.objective = zone_width;
      break;
    case DesignObjective::kMinMoi:
      out.objective = p.MoiSixInchKgM2();
      break;
    case DesignObjective::kLeastSquares:
      out.objective = problem.least_squares->Value(p.mass_kg, p.balance_point_m);
      break;
    case DesignObjective::kMinSting:
      out.sting = model.StingOf(bat, true);
      out.objective = out.sting->sting_j;
      break;
    case DesignObjective::kMaxDistance: {
      out.distance = model.DistanceOf(bat);
      out.objective = out.distance->distance_m;  // NaN when it cannot be computed
      break;
    }
  }
  return out;
}

// Value of constraint c for a design, through the public path for the properties.
double PublicConstraintValue(const DesignModel& model, const DesignConstraintSpec& c,
                             const PublicEvaluation& e, const Bat& bat, const double* x) {
  switch (c.f.function) {
    case DesignFunction::kMass:
      return e.properties.mass_kg;
    case DesignFunction::kBalancePoint:
      return e.properties.balance_point_m;
    case DesignFunction::kMoiSixInch:
      return e.properties.MoiSixInchKgM2();
    case DesignFunction::kDrop:
      return ToImperial(e.properties, bat.LengthM()).drop;
    case DesignFunction::kBbcor: {
      // Recomputed through the public model (ComputeBbcor on the answer's bat, with the answer's
      // mass properties when they are the rigid body's).
      const BbcorResult b = ComputeBbcor(bat, BbcorProtocol{}, BarrelOptions{},
                                         RigidBodyPropertiesOrNull(e.properties));
      return b.ok ? b.value : kNaN;
    }
    case DesignFunction::kLinear:
    case DesignFunction::kObjective:
    case DesignFunction::kFirstFrequency:  // the fixed mesh the constraint is defined on
    case DesignFunction::kBoreBottom:      // a closed form of the shape's own numbers
      break;
  }
  return model.Value(c.f, x);
}

// The answer's first bending mode: the modes code on its own adaptive mesh, and the fixed mesh's
// value that the constraint holds.
DesignFrequency FirstBendingModeOf(const DesignProblem& problem, const DesignModel& model,
                                   const Bat& bat, const std::vector<double>& x) {
  DesignFrequency out;
  const BatModes modes = ComputeBatModes(bat, problem.flexible.VibrationModes());
  out.frequency_hz = kNaN;
  out.error_estimate_hz = kNaN;
  if (modes.summary.IsSolutionUsable() && !modes.modes.empty()) {
    out.frequency_hz = modes.modes.front().frequency_hz;
    out.error_estimate_hz = modes.modes.front().error_estimate_hz;
    out.elements = modes.Elements();
  }
  out.model_frequency_hz = model.FirstFrequencyAt(x.data());
  out.model_elements = model.frequency_elements();
  return out;
}

PublicEvaluation AnswerAt(const DesignProblem& problem, const DesignModel& model,
                          const std::vector<double>& x, bool cor_known, DesignResult* result) {
  result->bat = model.BatAt(x.data());
  result->three_segment = model.ShapeAt(x.data());
  for (std::size_t j = 0; j < x.size(); ++j) {
    const DesignVariableSpec& v = model.variables()[j];
    result->variables.push_back({v.path, x[j], v.scale});
    for (const std::string& linked : v.linked_paths) {
      result->variables.push_back({linked, x[j]});  // set to the same value
    }
    for (std::size_t k = 0; k < v.scale_paths.size(); ++k) {
      // The product the model's parameters hold (DesignModel::ParametersAt), so the bat's field.
      result->variables.push_back({v.scale_paths[k], v.scale_bases[k] * x[j]});
    }
  }
  const PublicEvaluation pub = EvaluatePublic(problem, model, result->bat, cor_known);
  result->properties = pub.properties;
  result->objective_value = pub.objective;
  result->sweet_spot_from_knob_m = pub.sweet_spot_m;
  result->max_exit_speed_mps = pub.max_exit_speed_mps;
  result->angular_speed_rad_s = pub.omega_rad_s;
  if (model.cor_from_barrel()) {
    result->cor = pub.cor;
    result->cor_impact_from_knob_m = pub.cor_impact_m;
    result->cor_impact_speed_mps = pub.cor_speed_mps;
    result->cor_ball = pub.cor_ball;
  }
  result->sweet_spot_placement = pub.placement;
  if (pub.placement != Placement::kOnBat && std::isfinite(pub.sweet_spot_m)) {
    result->summary.warnings.push_back(
        std::string("sweet_spot: the exit speed's maximum lies ") +
        (pub.placement == Placement::kBeyondTip ? "beyond the tip" : "before the knob") +
        "; the sweet spot reported is the bat's end (" + PlacementName(pub.placement) + ")");
  }
  result->summary.objective = pub.objective;
  if (problem.constraints.min_frequency_hz.has_value()) {
    result->first_bending_mode = FirstBendingModeOf(problem, model, result->bat, x);
    const DesignFrequency& f = *result->first_bending_mode;
    const double gap = std::abs(f.frequency_hz - f.model_frequency_hz);
    if (!(gap <= problem.flexible.frequency_tolerance * f.frequency_hz)) {
      result->summary.warnings.push_back(
          "min_frequency_hz: the fixed mesh's first frequency " +
          FormatNumber(f.model_frequency_hz) + " Hz differs from the modes code's " +
          FormatNumber(f.frequency_hz) + " Hz by more than frequency_tolerance = " +
          FormatNumber(problem.flexible.frequency_tolerance) +
          " (the start's mesh no longer resolves this design: start from it again)");
    }
  }

  return pub;
}

void RecheckConstraints(const DesignModel& model, const PublicEvaluation& pub, const Bat& bat,
                        const std::vector<double>& x, double* worst, double* worst_relative) {
  // The parameters once (a linear constraint's value from them: Value's bits), not once per
  // constraint (O(m n) at 256 knots).
  const std::vector<double> t = model.Parameters(x.data());
  for (const DesignConstraintSpec& c : model.constraints()) {
    const double v = c.f.function == DesignFunction::kLinear
                         ? DesignModel::LinearValueAt(c.f, t)
                         : PublicConstraintValue(model, c, pub, bat, x.data());
    const double viol = Violation(c, v);
    *worst = std::max(*worst, viol);
    *worst_relative = std::max(*worst_relative, viol / c.scale);
  }
}

}  // namespace sweetspot::core::design_detail
