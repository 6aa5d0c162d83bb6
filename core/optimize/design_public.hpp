// Internal to core: the public re-evaluation of a design the optimiser returns (the public mass
// properties, the closed-form sweet spot, min_sting's flexible impact, the barrel COR), and the
// answer filled from it. Split from design.cpp (issue 33, item 6). Included only by core's .cpp
// files.
#pragma once

#include <optional>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core::design_detail {

/// `p` when its moments are the rigid body's (what the barrel models use), else null.
const MassProperties* RigidBodyPropertiesOrNull(const MassProperties& p);

/// The public re-evaluation of a design (ComputeMassProperties + the closed-form sweet spot;
/// min_sting: + Collide(kFlexible) there, with the error checks).
struct PublicEvaluation {
  MassProperties properties;
  double objective = kNaN;
  double sweet_spot_m = kNaN;
  double max_exit_speed_mps = kNaN;
  double omega_rad_s = kNaN;
  Placement placement = Placement::kOnBat;     ///< Of the sweet spot.
  std::optional<StingEvaluation> sting;        ///< min_sting.
  std::optional<DistanceEvaluation> distance;  ///< max_distance: the distance sweet spot.
  /// The COR used: the model's fixed one, or (cor_from_barrel) the design's barrel's through
  /// EffectiveCorAt at the point and speed below.
  double cor = kNaN;
  double cor_impact_m = kNaN;   ///< cor_from_barrel: m from the knob.
  double cor_speed_mps = kNaN;  ///< cor_from_barrel: the normal impact speed there.
  double cor_ball = kNaN;       ///< cor_from_barrel: the ball's law at that speed.
};

/// The public re-evaluation of `bat`.
PublicEvaluation EvaluatePublic(const DesignProblem& problem, const DesignModel& model,
                                const Bat& bat, bool cor_known);
/// Value of constraint c for a design, through the public path for the properties.
double PublicConstraintValue(const DesignModel& model, const DesignConstraintSpec& c,
                             const PublicEvaluation& e, const Bat& bat, const double* x);
/// The answer's first bending mode: the modes code on its own adaptive mesh, and the fixed
/// mesh's value that the constraint holds.
DesignFrequency FirstBendingModeOf(const DesignProblem& problem, const DesignModel& model,
                                   const Bat& bat, const std::vector<double>& x);
/// The answer at the solver's point x: the bat, its variables, the public evaluation's numbers
/// and their warnings (a sweet spot off the bat, a fixed mesh that no longer resolves the
/// design); returns the public evaluation.
PublicEvaluation AnswerAt(const DesignProblem& problem, const DesignModel& model,
                          const std::vector<double>& x, bool cor_known, DesignResult* result);
/// The worst violation of the model's constraints re-checked through the public path, absolute
/// and relative to each constraint's scale.
void RecheckConstraints(const DesignModel& model, const PublicEvaluation& pub, const Bat& bat,
                        const std::vector<double>& x, double* worst, double* worst_relative);

}  // namespace sweetspot::core::design_detail
