// The max_distance objective's evaluation of one design (design_distance.hpp).
#include "core/optimize/design_distance.hpp"

#include <string>

#include "core/numerics/timing_book.hpp"
#include "core/scene/resolved_scene.hpp"

namespace sweetspot::core {

DistanceEvaluation EvaluateDistance(const Bat& bat, const DistanceScene& scene) {
  DistanceEvaluation out;
  try {
    Scene s;
    s.bat = bat;
    s.inertia_model = scene.inertia_model;
    s.ball = scene.ball;
    s.swing = scene.swing;
    s.environment = scene.environment;
    s.aero = scene.aero;
    s.cor = scene.cor;
    s.outputs = {SceneOutput::kDistanceSweetSpot};
    ResolvedScene resolved;
    Summary summary;
    TimingBook book(/*timed=*/false);  // ResolveScene books the mass properties: not reported
    if (!ResolveScene(s, /*needs_cor=*/true, &book, &resolved, &summary, std::nullopt,
                      scene.model)) {
      out.message = summary.refusal.has_value() ? summary.refusal->Message() : summary.message;
      return out;
    }
    const HertzOptions hertz;        // unused by the closed forms
    const FlexibleOptions flexible;  // unused by the closed forms
    BattedBallModel model(s, resolved, scene.model, hertz, flexible, nullptr, nullptr);
    DistanceSweetSpotResult r = DistanceSweetSpot(model, resolved.length_m, scene.distance);
    if (r.summary.refusal.has_value()) {
      out.message = r.summary.refusal->Message();
      return out;
    }
    if (!r.summary.IsSolutionUsable()) {
      out.message = "distance_sweet_spot: " + r.summary.message;
      return out;
    }
    out.ok = true;
    out.distance_m = r.distance_m;
    out.result = std::move(r);
  } catch (const std::exception& e) {
    out.ok = false;
    out.distance_m = kNaN;
    out.message = std::string("failure: ") + e.what();
  }
  return out;
}

}  // namespace sweetspot::core
