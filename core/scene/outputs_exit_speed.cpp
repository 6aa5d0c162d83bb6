// The outputs of the exit-speed model along the bat: max_exit_speed, sweet_zone and
// exit_speed_curve (their models are the scene's exit-speed model; core/sweet_spot/ computes).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/scene/output_registry.hpp"
#include "core/sweet_spot/numeric.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
namespace outputs_exit_speed {
namespace {

void ComputeMaxExitSpeed(OutputContext& c) {
  ExitSpeedModel& model = *c.exit_model;
  const double length_m = c.resolved.length_m;
  MaxExitSpeedResult& mx = c.out.max_exit_speed.emplace();
  if (c.closed_form) {
    const auto tm = c.book.Now();
    mx = ClosedFormMaxExitSpeed(*model.profile(), length_m);
    mx.model = model.name();
    mx.summary.solve_time_s = c.book.Since(tm);
    mx.summary.models_used = {model.name()};
    c.book.Add(model.name(), mx.summary.solve_time_s, 1);
  } else if (c.model == CollisionModel::kFlexible &&
             c.options.method == SweetSpotMethod::kClosedForm) {
    mx = BracketMaxExitSpeed(&model, length_m, c.options.flexible.search);
    mx.summary.models_used = {model.name()};
  } else {
    mx = SearchMaxExitSpeed(&model, length_m, c.options.nlopt);
    mx.summary.models_used = {model.name()};
  }
  for (const auto& w : mx.summary.warnings) c.Warn(SceneOutput::kMaxExitSpeed, w);
  c.Note(mx.summary.termination,
         mx.summary.IsSolutionUsable() ? std::string() : "max_exit_speed: " + mx.summary.message);
}

// Reads max_exit_speed's result (its declaration's needs_output).
void ComputeSweetZone(OutputContext& c) {
  const MaxExitSpeedResult& mx = *c.out.max_exit_speed;
  if (!mx.summary.IsSolutionUsable()) {
    c.Note(Termination::kFailure, "sweet_zone: needs max_exit_speed, which failed");
    return;
  }
  const SceneOptions& options = c.options;
  const double tol = options.sweet_zone_unit == ToleranceUnit::kPercent
                         ? options.sweet_zone_tolerance / 100.0 * std::abs(mx.exit_speed_mps)
                         : options.sweet_zone_tolerance;
  ExitSpeedModel& model = *c.exit_model;
  if (c.closed_form) {
    const auto tz = c.book.Now();
    c.out.sweet_zone = ClosedFormSweetZone(*model.profile(), c.resolved.length_m, mx, tol);
    c.book.Add(model.name(), c.book.Since(tz), 1);
    return;
  }
  std::string error;
  c.out.sweet_zone = RootFindSweetZone(&model, c.resolved.length_m, mx, tol, &error);
  c.out.sweet_zone->error_estimate_m += mx.error_estimate_m;
  if (!error.empty()) {
    c.Note(Termination::kFailure, "sweet_zone: " + error);
    c.out.sweet_zone.reset();
  }
}

void ComputeExitSpeedCurve(OutputContext& c) {
  ExitSpeedCurveResult curve;
  curve.model = c.exit_model->name();
  std::vector<double> xs = c.options.curve_positions_from_knob_m;
  const double length_m = c.resolved.length_m;
  if (xs.empty()) {
    const int n = c.options.curve_samples;
    for (int i = 0; i < n; ++i) xs.push_back(i + 1 == n ? length_m : length_m * i / (n - 1));
  }
  bool ok = true;
  std::string error;
  for (double x : xs) {
    double v = 0.0, e = 0.0;
    if (IsCancelled(c.options.progress)) {
      ok = false;
      error = "cancelled after " + std::to_string(curve.points.size()) + " of " +
              std::to_string(xs.size()) + " points";
      break;
    }
    if (!c.exit_model->Eval(x, &v, nullptr, &e, &error)) {
      ok = false;
      break;
    }
    curve.points.push_back({x, v});
    curve.error_estimate_mps = std::max(curve.error_estimate_mps, e);
  }
  if (ok) {
    c.out.exit_speed_curve = std::move(curve);
  } else {
    c.Note(Termination::kFailure, "exit_speed_curve: " + error);
  }
}

double MaxExitSpeedError(const SceneOutputResults& r) { return r.max_exit_speed->error_estimate_m; }

}  // namespace
}  // namespace outputs_exit_speed

extern const SceneOutputDecl kMaxExitSpeedOutput{
    SceneOutput::kMaxExitSpeed,
    "max_exit_speed",
    /*uses_exit_model=*/true,
    /*models=*/{},
    /*needs_geometry=*/false,
    /*needs_cor=*/true,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kMaxExitSpeed,
    OutputWorkload::kAsExitModel,
    outputs_exit_speed::ComputeMaxExitSpeed,
    SlotPresent<&SceneOutputResults::max_exit_speed>,
    ResetSlot<&SceneOutputResults::max_exit_speed>,
    outputs_exit_speed::MaxExitSpeedError,
};

extern const SceneOutputDecl kSweetZoneOutput{
    SceneOutput::kSweetZone,
    "sweet_zone",
    /*uses_exit_model=*/true,
    /*models=*/{},
    /*needs_geometry=*/false,
    /*needs_cor=*/true,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kMaxExitSpeed,
    OutputWorkload::kAsExitModel,
    outputs_exit_speed::ComputeSweetZone,
    SlotPresent<&SceneOutputResults::sweet_zone>,
    ResetSlot<&SceneOutputResults::sweet_zone>,
    nullptr,
};

extern const SceneOutputDecl kExitSpeedCurveOutput{
    SceneOutput::kExitSpeedCurve,
    "exit_speed_curve",
    /*uses_exit_model=*/true,
    /*models=*/{},
    /*needs_geometry=*/false,
    /*needs_cor=*/true,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kExitSpeedCurve,
    OutputWorkload::kAsExitModel,
    outputs_exit_speed::ComputeExitSpeedCurve,
    SlotPresent<&SceneOutputResults::exit_speed_curve>,
    ResetSlot<&SceneOutputResults::exit_speed_curve>,
    nullptr,
};

}  // namespace sweetspot::core
