#include "core/scene/collide.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene_models.hpp"

namespace sweetspot::core {

bool CollisionOptions::Validate(Refusal* why) const {
  return hertz.Validate(why) && flexible.Validate(why);
}

CollisionResult Collide(const Scene& scene, double impact_from_knob_m, CollisionModel model,
                        const CollisionOptions& options) {
  return TimedRequest<CollisionResult>("closed_form", [&](CollisionResult& out, TimingBook& book) {
    Summary& s = out.summary;
    out.impact_from_knob_m = impact_from_knob_m;
    if (Refusal refusal; !options.Validate(&refusal)) {
      s.SetRefusal(std::move(refusal));
      return;
    }
    if (model == CollisionModel::kFlexible && !scene.bat.has_value()) {
      out.model = model;
      s.SetRefusal(TextRefusal(
          "bat", "model = flexible needs the bat's geometry (a bat, not only mass_properties)"));
      return;
    }
    ResolvedScene r;
    // A ball's COR law is evaluated at this impact's own normal speed.
    const bool resolved =
        ResolveScene(scene, /*needs_cor=*/true, &book, &r, &s, impact_from_knob_m, model);
    // Also when refused: the caller can then tell properties that are not usable (the bat's).
    out.mass_properties = r.mass_properties;
    if (!resolved) return;
    out.swing = r.swing;
    out.cor = *r.cor;
    out.cor_source = r.cor_source;
    out.cor_impact_speed_mps = r.cor_impact_speed_mps;
    if (!(std::isfinite(impact_from_knob_m) && impact_from_knob_m >= 0.0 &&
          impact_from_knob_m <= r.length_m)) {
      s.SetRefusal(
          Number17Refusal("impact_from_knob_m", impact_from_knob_m,
                          "must be within the bat [0, " + FormatNumber17(r.length_m) + "]"));
      return;
    }
    if (model == CollisionModel::kAuto) {
      if (options.want_contact_details) {
        model = CollisionModel::kHertz;
        out.model_reason =
            "auto: hertz, the only model that knows contact time, peak force and compression";
      } else {
        model = ResolveExitModel(model, scene, &out.model_reason);
      }
    } else {
      out.model_reason = "requested";
    }
    out.model = model;
    // A closed-form impact: exact up to rounding.
    const auto closed_form = [&](double exit_speed_mps, double approach_speed_mps) {
      out.exit_speed_mps = exit_speed_mps;
      out.approach_speed_mps = approach_speed_mps;
      out.error_estimate_mps = 8.0 * kEps * (scene.ball.speed_mps + std::abs(exit_speed_mps));
      s.termination = Termination::kConverged;
      s.message = "closed form";
    };
    // An integrated impact (hertz, flexible): its report becomes the collision's (termination,
    // message, backend, counts; its warnings after those already noted).
    const auto integrated = [&](const auto& impact) {
      const Summary& is = impact.summary;
      s.termination = is.termination;
      s.message = is.message;
      s.backend = is.backend;
      s.iterations = is.iterations;
      s.evaluations = is.evaluations;
      for (const auto& w : is.warnings) s.warnings.push_back(w);
      out.exit_speed_mps = impact.exit_speed_mps;
      out.error_estimate_mps = impact.error_estimate_exit_speed_mps;
    };
    auto tm = std::chrono::steady_clock::now();
    std::shared_ptr<const BatModes> impact_modes;  // model = flexible: for the batted ball too
    switch (model) {
      case CollisionModel::kRigidPivot:
        out.rigid_pivot = RigidPivotImpactAt(RigidPivotInputsFor(scene, r), impact_from_knob_m);
        closed_form(out.rigid_pivot->exit_speed_mps, out.rigid_pivot->approach_speed_mps);
        break;
      case CollisionModel::kFreeBat:
        out.free_bat = FreeBatImpactAt(FreeBatInputsFor(scene, r), impact_from_knob_m);
        closed_form(out.free_bat->exit_speed_mps, out.free_bat->approach_speed_mps);
        break;
      case CollisionModel::kHertz: {
        std::vector<std::string> warnings;
        const HertzProblem p =
            HertzProblemFor(scene, r, impact_from_knob_m, options.hertz, &warnings);
        out.approach_speed_mps = p.approach_speed_mps;
        out.hertz = SolveHertzImpact(p, options.hertz.solver);
        s.warnings = warnings;
        integrated(*out.hertz);
        break;
      }
      case CollisionModel::kFlexible: {
        FlexibleModes flexible_modes(scene, options.flexible, &book);
        const auto& modes = flexible_modes.Impact();
        impact_modes = modes;
        out.modes_cache_hit = flexible_modes.impact_hit();
        if (FlexibleModesRefused(*modes, &s)) return;
        tm = std::chrono::steady_clock::now();  // the modes have their own timing
        const FlexibleImpactInputs in =
            FlexibleImpactInputsFor(scene, r, impact_from_knob_m, options.hertz);
        out.approach_speed_mps = in.approach_speed_mps;
        out.flexible = SolveFlexibleImpact(*scene.bat, *modes, in, options.flexible.impact);
        for (const auto& w : modes->summary.warnings) s.warnings.push_back("flexible_beam: " + w);
        integrated(*out.flexible);
        if (out.flexible->summary.IsSolutionUsable() &&
            modes->summary.termination == Termination::kNoConvergence) {
          s.termination = Termination::kNoConvergence;
        }
        break;
      }
      default:
        s.termination = Termination::kFailure;
        s.message = "internal error: unknown model";
        break;
    }
    book.Add(CollisionModelName(model), SecondsSince(tm), 1);
    s.objective = out.exit_speed_mps;
    s.error_estimate = out.error_estimate_mps;
    if (options.want_batted_ball && s.IsSolutionUsable()) {
      BattedBallModel batted(scene, r, model, options.hertz, options.flexible, impact_modes.get(),
                             &book);
      BattedBallResult ball;
      Refusal refusal;
      std::string failure;
      if (batted.Evaluate(impact_from_knob_m, scene.contact.undercut_m, &ball, &refusal,
                          &failure)) {
        out.batted_ball = std::move(ball);
      } else if (!refusal.field.empty() || !refusal.rule.empty()) {
        s.SetRefusal(std::move(refusal));
      } else {
        s.termination = Termination::kFailure;
        s.message = "batted_ball: " + failure;
      }
    }
  });
}

}  // namespace sweetspot::core
