// The batted_ball output: at max_exit_speed's point, the oblique bat-ball impact
// (core/collision/oblique_impact.hpp: the normal part from the scene's collision model, the
// tangential part by the law's defaults), then the ball's flight (core/flight/flight.hpp) with
// the scene's environment and aero: BattedBallModel (core/scene/batted_ball.hpp). rigid_pivot
// and free_bat give the normal part in closed form (M_n(x), e); hertz and flexible by their own
// impact at the normal approach speed (NormalImpactLaw::ball_normal_impulse_n_s), so that a
// head-on impact is exactly the model's own.
#include <string>

#include "core/scene/batted_ball.hpp"
#include "core/scene/output_registry.hpp"
#include "core/scene/scene_models.hpp"

namespace sweetspot::core {
namespace outputs_batted_ball {
namespace {

// Reads max_exit_speed's result (its declaration's needs_output).
void ComputeBattedBall(OutputContext& c) {
  const MaxExitSpeedResult& mx = *c.out.max_exit_speed;
  if (!mx.summary.IsSolutionUsable()) {
    c.Note(Termination::kFailure, "batted_ball: needs max_exit_speed, which failed");
    return;
  }
  if (!c.scene.bat.has_value()) {
    c.Warn(SceneOutput::kBattedBall,
           "no bat geometry (mass_properties only): the bat's radius and roll inertia are "
           "the oblique impact's defaults");
  }
  const BatModes* modes = c.exit_model != nullptr ? c.exit_model->modes() : nullptr;
  BattedBallModel model(c.scene, c.resolved, c.model, c.options.hertz, c.options.flexible, modes,
                        &c.book);
  BattedBallResult out;
  Refusal refusal;
  std::string failure;
  if (!model.Evaluate(mx.position_from_knob_m, c.scene.contact.undercut_m, &out, &refusal,
                      &failure)) {
    if (!refusal.field.empty() || !refusal.rule.empty()) {
      c.Refuse(std::move(refusal));
    } else {
      c.Note(Termination::kFailure, "batted_ball: " + failure);
    }
    return;
  }
  c.out.batted_ball = std::move(out);
}

}  // namespace
}  // namespace outputs_batted_ball

extern const SceneOutputDecl kBattedBallOutput{
    SceneOutput::kBattedBall,
    "batted_ball",
    /*uses_exit_model=*/true,
    /*models=*/{"oblique_impact", "flight"},
    /*needs_geometry=*/false,
    /*needs_cor=*/true,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kMaxExitSpeed,
    OutputWorkload::kAsExitModel,
    outputs_batted_ball::ComputeBattedBall,
    SlotPresent<&SceneOutputResults::batted_ball>,
    ResetSlot<&SceneOutputResults::batted_ball>,
    nullptr,
};

}  // namespace sweetspot::core
