// The max_distance objective (issue 34, part 3): the carry of a design's distance sweet spot
// (DistanceSweetSpot, core/scene/batted_ball.hpp: the impact position and undercut that carry
// the ball farthest) in the problem's scene, evaluated through the same public path
// /v1/sweet-spot takes (ResolveScene of the design's bat, then the search), so the optimiser's
// value of a design is the distance_sweet_spot.distance_m that endpoint reports for it.
// Values only: the carry comes from an adaptive flight integration and an iterative 2-D search,
// so max_distance is solved derivative-free (NLopt COBYLA, as min_sting); the reason and its
// measurement are in docs/optimization.md ("max_distance").
#pragma once

#include <string>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/numerics/limits.hpp"
#include "core/scene/batted_ball.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::core {

/// The scene of a max_distance evaluation, taken from the DesignProblem.
struct DistanceScene {
  Ball ball;                                              ///< The pitched ball (descent, spin).
  Swing swing;                                            ///< The swing (attack angle).
  double cor = 0.5;                                       ///< The COR used (dimensionless).
  InertiaModel inertia_model = InertiaModel::kRigidBody;  ///< For the mass properties.
  CollisionModel model = CollisionModel::kFreeBat;        ///< rigid_pivot or free_bat.
  flight::Environment environment;                        ///< The air of the flight.
  flight::AeroOptions aero;                               ///< The flight's aero model.
  DistanceOptions distance;                               ///< The search's region and tolerances.
};

/// The distance sweet spot of one design.
struct DistanceEvaluation {
  bool ok = false;                 ///< True when the search returned a usable optimum.
  double distance_m = kNaN;        ///< Its carry, m (NaN when !ok).
  std::string message;             ///< Why not ok.
  DistanceSweetSpotResult result;  ///< The search's answer (when ok).
};

/// The distance sweet spot of `bat` in `scene`: a Scene of the bat with the problem's ball,
/// swing, COR, environment and aero, resolved (mass properties, the swing's omega from a bat
/// speed), then DistanceSweetSpot. Never throws.
DistanceEvaluation EvaluateDistance(const Bat& bat, const DistanceScene& scene);

}  // namespace sweetspot::core
