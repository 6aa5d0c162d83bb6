#include "core/scene/sweet_spot_swing.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/sweet_spot/numeric.hpp"

namespace sweetspot::core {

bool SolveSweetSpotSwing(const Scene& scene, const SceneOptions& options, CollisionModel model,
                         bool needs_cor, TimingBook* book,
                         const std::shared_ptr<const BatModes>& modes, ResolvedScene* r,
                         std::optional<ExitSpeedModel>* exit_model, Summary* s) {
  if (model != CollisionModel::kHertz && model != CollisionModel::kFlexible) return true;
  if (!r->swing.resolution.has_value() ||
      scene.swing.bat_speed_point != BatSpeedPoint::kSweetSpot || !exit_model->has_value()) {
    return true;
  }
  const double v = r->swing.resolution->bat_speed_mps;
  const double pivot = r->swing.pivot_from_knob_m;
  // The scene re-resolved at a distance from the tip, with its mass properties (not computed
  // again): ResolveScene's swing (the same speed model) and COR at the new angular speed.
  Scene at = scene;
  at.mass_properties = r->mass_properties;
  at.swing.bat_speed_point = BatSpeedPoint::kFromTip;
  int iterations = 0;
  bool met = false;
  double speed_error = 0.0;
  std::string stopped;
  for (iterations = 1; iterations <= kMaxSweetSpotIterations; ++iterations) {
    ExitSpeedModel& m = **exit_model;
    const MaxExitSpeedResult mx =
        model == CollisionModel::kFlexible && options.method == SweetSpotMethod::kClosedForm
            ? BracketMaxExitSpeed(&m, r->length_m, options.flexible.search)
            : SearchMaxExitSpeed(&m, r->length_m, options.nlopt);
    if (!mx.summary.IsSolutionUsable()) {
      stopped = "the maximum's search failed (" + mx.summary.message + ")";
      break;
    }
    const double omega = r->swing.angular_speed_rad_s;
    const double x = mx.position_from_knob_m;
    speed_error = omega * (x - pivot) - v;
    const double tolerance =
        std::max(kSweetSpotSpeedRelTolerance * v, omega * std::abs(mx.error_estimate_m));
    if (std::abs(speed_error) <= tolerance) {
      met = true;
      break;
    }
    if (iterations == kMaxSweetSpotIterations) {
      stopped = std::to_string(kMaxSweetSpotIterations) + " iterations";
      break;
    }
    at.swing.bat_speed_from_tip_m = std::max(0.0, r->length_m - x);
    ResolvedScene next;
    Summary quiet;  // the warnings of the first resolution are already in *s
    if (!ResolveScene(at, needs_cor, book, &next, &quiet, std::nullopt, model)) {
      if (quiet.refusal.has_value()) {
        s->SetRefusal(*quiet.refusal);
      } else {
        s->termination = quiet.termination;
        s->message = quiet.message;
      }
      return false;
    }
    next.swing.bat_speed_point = BatSpeedPoint::kSweetSpot;
    *r = std::move(next);
    if (model == CollisionModel::kFlexible) {
      exit_model->emplace(model, scene, *r, options.hertz, book, &options.flexible, modes);
    } else {
      exit_model->emplace(model, scene, *r, options.hertz, book);
    }
  }
  SwingResolution& how = *r->swing.resolution;
  how.point_model = CollisionModelName(model);
  how.iterations = std::min(iterations, kMaxSweetSpotIterations);
  how.speed_error_mps = speed_error;
  if (!met) {
    s->warnings.push_back(std::string("swing.bat_speed_from_tip_m = sweet_spot: ") + stopped +
                          "; the speed at " + CollisionModelName(model) +
                          "'s maximum differs from the given one by " +
                          FormatNumber17(speed_error) + " m/s");
  }
  return true;
}

}  // namespace sweetspot::core
