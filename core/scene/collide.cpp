#include "core/scene/collide.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene_models.hpp"

namespace sweetspot::core {

bool CollisionOptions::Validate(Refusal* why) const {
  return hertz.Validate(why) && flexible.Validate(why);
}

namespace {

// Checks the options and the model's needs and resolves the scene into *r at this impact
// (impact_from_knob_m, m): false when refused (the refusal in out->summary). out takes the
// impact point, the mass properties (also when refused), the swing and the COR.
bool PrepareCollision(const Scene& scene, double impact_from_knob_m, CollisionModel model,
                      const CollisionOptions& options, TimingBook* book, ResolvedScene* r,
                      CollisionResult* out) {
  Summary& s = out->summary;
  out->impact_from_knob_m = impact_from_knob_m;
  if (Refusal refusal; !options.Validate(&refusal)) {
    s.SetRefusal(std::move(refusal));
    return false;
  }
  if (model == CollisionModel::kFlexible && !scene.bat.has_value()) {
    out->model = model;
    s.SetRefusal(TextRefusal(
        "bat", "model = flexible needs the bat's geometry (a bat, not only mass_properties)"));
    return false;
  }
  // A ball's COR law is evaluated at this impact's own normal speed.
  const bool resolved =
      ResolveScene(scene, /*needs_cor=*/true, book, r, &s, impact_from_knob_m, model);
  // Also when refused: the caller can then tell properties that are not usable (the bat's).
  out->mass_properties = r->mass_properties;
  if (!resolved) return false;
  out->swing = r->swing;
  out->cor = *r->cor;
  out->cor_source = r->cor_source;
  out->cor_impact_speed_mps = r->cor_impact_speed_mps;
  if (!(std::isfinite(impact_from_knob_m) && impact_from_knob_m >= 0.0 &&
        impact_from_knob_m <= r->length_m)) {
    s.SetRefusal(
        Number17Refusal("impact_from_knob_m", impact_from_knob_m,
                        "must be within the bat [0, " + FormatNumber17(r->length_m) + "]"));
    return false;
  }
  return true;
}

// The model the collision runs: `model` as requested, or auto's choice (hertz when the contact's
// details are wanted), with the reason in *reason.
CollisionModel CollisionModelFor(CollisionModel model, const Scene& scene,
                                 const CollisionOptions& options, std::string* reason) {
  if (model != CollisionModel::kAuto) {
    *reason = "requested";
    return model;
  }
  if (options.want_contact_details) {
    *reason = "auto: hertz, the only model that knows contact time, peak force and compression";
    return CollisionModel::kHertz;
  }
  return ResolveExitModel(model, scene, reason);
}

// A closed-form impact's exit and approach speeds (m/s) into *out: exact up to rounding.
void SetClosedFormExit(const Scene& scene, double exit_speed_mps, double approach_speed_mps,
                       CollisionResult* out) {
  Summary& s = out->summary;
  out->exit_speed_mps = exit_speed_mps;
  out->approach_speed_mps = approach_speed_mps;
  out->error_estimate_mps = 8.0 * kEps * (scene.ball.speed_mps + std::abs(exit_speed_mps));
  s.termination = Termination::kConverged;
  s.message = "closed form";
}

// An integrated impact (hertz, flexible): its report becomes the collision's (termination,
// message, backend, counts; its warnings after those already noted), its exit speed (m/s) and
// error estimate out's.
template <class Impact>
void TakeIntegratedExit(const Impact& impact, CollisionResult* out) {
  Summary& s = out->summary;
  const Summary& is = impact.summary;
  s.termination = is.termination;
  s.message = is.message;
  s.backend = is.backend;
  s.iterations = is.iterations;
  s.evaluations = is.evaluations;
  for (const auto& w : is.warnings) s.warnings.push_back(w);
  out->exit_speed_mps = impact.exit_speed_mps;
  out->error_estimate_mps = impact.error_estimate_exit_speed_mps;
}

// The flexible model's impact at impact_from_knob_m (m) into *out: the bat's modes (cached,
// kept in *impact_modes for the batted ball), then the impact; *tm restarts after the modes
// (they have their own timing). False when the modes are refused (out->summary says why).
bool RunFlexibleCollision(const Scene& scene, const ResolvedScene& r, double impact_from_knob_m,
                          const CollisionOptions& options, TimingBook* book,
                          std::chrono::steady_clock::time_point* tm,
                          std::shared_ptr<const BatModes>* impact_modes, CollisionResult* out) {
  Summary& s = out->summary;
  FlexibleModes flexible_modes(scene, options.flexible, book);
  const auto& modes = flexible_modes.Impact();
  *impact_modes = modes;
  out->modes_cache_hit = flexible_modes.impact_hit();
  if (FlexibleModesRefused(*modes, &s)) return false;
  *tm = std::chrono::steady_clock::now();  // the modes have their own timing
  const FlexibleImpactInputs in =
      FlexibleImpactInputsFor(scene, r, impact_from_knob_m, options.hertz);
  out->approach_speed_mps = in.approach_speed_mps;
  out->flexible = SolveFlexibleImpact(*scene.bat, *modes, in, options.flexible.impact);
  for (const auto& w : modes->summary.warnings) s.warnings.push_back("flexible_beam: " + w);
  TakeIntegratedExit(*out->flexible, out);
  if (out->flexible->summary.IsSolutionUsable() &&
      modes->summary.termination == Termination::kNoConvergence) {
    s.termination = Termination::kNoConvergence;
  }
  return true;
}

// The batted ball of the impact at impact_from_knob_m (m) with the scene's undercut, by the
// collision's `model`, into out->batted_ball; a refusal or failure goes to out->summary.
void AddCollisionBattedBall(const Scene& scene, const ResolvedScene& r, CollisionModel model,
                            const CollisionOptions& options, const BatModes* impact_modes,
                            double impact_from_knob_m, TimingBook* book, CollisionResult* out) {
  Summary& s = out->summary;
  BattedBallModel batted(scene, r, model, options.hertz, options.flexible, impact_modes, book);
  BattedBallResult ball;
  Refusal refusal;
  std::string failure;
  if (batted.Evaluate(impact_from_knob_m, scene.contact.undercut_m, &ball, &refusal, &failure)) {
    out->batted_ball = std::move(ball);
  } else if (!refusal.field.empty() || !refusal.rule.empty()) {
    s.SetRefusal(std::move(refusal));
  } else {
    s.termination = Termination::kFailure;
    s.message = "batted_ball: " + failure;
  }
}

}  // namespace

CollisionResult Collide(const Scene& scene, double impact_from_knob_m, CollisionModel model,
                        const CollisionOptions& options) {
  return TimedRequest<CollisionResult>("closed_form", [&](CollisionResult& out, TimingBook& book) {
    Summary& s = out.summary;
    ResolvedScene r;
    if (!PrepareCollision(scene, impact_from_knob_m, model, options, &book, &r, &out)) return;
    model = CollisionModelFor(model, scene, options, &out.model_reason);
    out.model = model;
    auto tm = std::chrono::steady_clock::now();
    std::shared_ptr<const BatModes> impact_modes;  // model = flexible: for the batted ball too
    switch (model) {
      case CollisionModel::kRigidPivot:
        out.rigid_pivot = RigidPivotImpactAt(RigidPivotInputsFor(scene, r), impact_from_knob_m);
        SetClosedFormExit(scene, out.rigid_pivot->exit_speed_mps,
                          out.rigid_pivot->approach_speed_mps, &out);
        break;
      case CollisionModel::kFreeBat:
        out.free_bat = FreeBatImpactAt(FreeBatInputsFor(scene, r), impact_from_knob_m);
        SetClosedFormExit(scene, out.free_bat->exit_speed_mps, out.free_bat->approach_speed_mps,
                          &out);
        break;
      case CollisionModel::kHertz: {
        std::vector<std::string> warnings;
        const HertzProblem p =
            HertzProblemFor(scene, r, impact_from_knob_m, options.hertz, &warnings);
        out.approach_speed_mps = p.approach_speed_mps;
        out.hertz = SolveHertzImpact(p, options.hertz.solver);
        s.warnings = warnings;
        TakeIntegratedExit(*out.hertz, &out);
        break;
      }
      case CollisionModel::kFlexible:
        if (!RunFlexibleCollision(scene, r, impact_from_knob_m, options, &book, &tm, &impact_modes,
                                  &out)) {
          return;
        }
        break;
      default:
        s.termination = Termination::kFailure;
        s.message = "internal error: unknown model";
        break;
    }
    book.Add(CollisionModelName(model), SecondsSince(tm), 1);
    s.objective = out.exit_speed_mps;
    s.error_estimate = out.error_estimate_mps;
    if (options.want_batted_ball && s.IsSolutionUsable()) {
      AddCollisionBattedBall(scene, r, model, options, impact_modes.get(), impact_from_knob_m,
                             &book, &out);
    }
  });
}

}  // namespace sweetspot::core
