// The outputs distance_sweet_spot and carry_map: where along the bat, and how far under the
// ball's centre, the ball carries farthest, and the carry over a grid of positions x undercuts
// (core/scene/batted_ball.hpp: DistanceSweetSpot, CarryMap; options.distance).
#include <string>

#include "core/scene/batted_ball.hpp"
#include "core/scene/output_registry.hpp"
#include "core/scene/scene_models.hpp"

namespace sweetspot::core {
namespace outputs_distance {
namespace {

// The batted-ball model of the context (the exit-speed model's collision model and modes).
BattedBallModel ModelOf(OutputContext& c) {
  const BatModes* modes = c.exit_model != nullptr ? c.exit_model->modes() : nullptr;
  return BattedBallModel(c.scene, c.resolved, c.model, c.options.hertz, c.options.flexible, modes,
                         &c.book);
}

// A search's summary into the context: a refusal, a failure, or a termination short of
// convergence.
bool Report(OutputContext& c, const char* name, const Summary& s) {
  if (s.refusal.has_value()) {
    c.Refuse(*s.refusal);
    return false;
  }
  if (!s.IsSolutionUsable()) {
    c.Note(Termination::kFailure, std::string(name) + ": " + s.message);
    return false;
  }
  if (s.termination != Termination::kConverged) {
    c.Note(s.termination, std::string(name) + ": " + s.message);
  }
  return true;
}

void ComputeDistanceSweetSpot(OutputContext& c) {
  if (!c.scene.bat.has_value()) {
    c.Warn(SceneOutput::kDistanceSweetSpot,
           "no bat geometry (mass_properties only): the bat's radius and roll inertia are "
           "the oblique impact's defaults");
  }
  BattedBallModel model = ModelOf(c);
  DistanceSweetSpotResult r =
      DistanceSweetSpot(model, c.resolved.length_m, c.options.distance, c.options.progress);
  if (!Report(c, "distance_sweet_spot", r.summary)) return;
  if (r.at_position_bound || r.at_undercut_bound) {
    c.Warn(SceneOutput::kDistanceSweetSpot,
           std::string("the farthest carry is at the edge of the region searched (") +
               (r.at_position_bound ? "position" : "undercut") +
               "): widen options.distance's ranges to see whether it carries farther beyond");
  }
  c.out.distance_sweet_spot = std::move(r);
}

void ComputeCarryMap(OutputContext& c) {
  BattedBallModel model = ModelOf(c);
  CarryMapResult r = CarryMap(model, c.resolved.length_m, c.options.distance, c.options.progress);
  if (!Report(c, "carry_map", r.summary)) return;
  c.out.carry_map = std::move(r);
}

}  // namespace
}  // namespace outputs_distance

extern const SceneOutputDecl kDistanceSweetSpotOutput{
    SceneOutput::kDistanceSweetSpot,
    "distance_sweet_spot",
    /*uses_exit_model=*/true,
    /*models=*/{"oblique_impact", "flight"},
    /*needs_geometry=*/false,
    /*needs_cor=*/true,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kDistanceSweetSpot,
    OutputWorkload::kCompute,  // hundreds of flights (and, hertz/flexible, a table of impacts)
    outputs_distance::ComputeDistanceSweetSpot,
    SlotPresent<&SceneOutputResults::distance_sweet_spot>,
    ResetSlot<&SceneOutputResults::distance_sweet_spot>,
    nullptr,
};

extern const SceneOutputDecl kCarryMapOutput{
    SceneOutput::kCarryMap,
    "carry_map",
    /*uses_exit_model=*/true,
    /*models=*/{"oblique_impact", "flight"},
    /*needs_geometry=*/false,
    /*needs_cor=*/true,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kCarryMap,
    OutputWorkload::kCompute,  // hundreds of flights (and, hertz/flexible, a table of impacts)
    outputs_distance::ComputeCarryMap,
    SlotPresent<&SceneOutputResults::carry_map>,
    ResetSlot<&SceneOutputResults::carry_map>,
    nullptr,
};

}  // namespace sweetspot::core
