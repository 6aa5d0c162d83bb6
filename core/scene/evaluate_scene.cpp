#include "core/scene/evaluate_scene.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "core/geometry_format.hpp"
#include "core/scene/output_registry.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene_models.hpp"
#include "core/scene/sweet_spot_swing.hpp"

namespace sweetspot::core {
namespace evaluate_scene {
namespace {

// The outputs a scene runs: those it asks for and those they read (needs_output).
std::array<bool, kSceneOutputCount> OutputsToRun(const std::array<bool, kSceneOutputCount>& wanted) {
  std::array<bool, kSceneOutputCount> run = wanted;
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    if (wanted[static_cast<std::size_t>(d->id)]) run[static_cast<std::size_t>(d->needs_output)] = true;
  }
  return run;
}

// The refusal of an output (or of model = flexible) that needs the bat's geometry when the
// scene has only mass properties; false when there is none.
bool RefuseMissingGeometry(const std::array<bool, kSceneOutputCount>& run, bool flexible_exit,
                           SceneResult* out) {
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    if (!d->needs_geometry || !run[static_cast<std::size_t>(d->id)]) continue;
    out->summary.SetRefusal(TextRefusal(
        "bat", std::string(d->name) + " needs the bat's geometry (a bat, not only mass_properties)"));
    out->refused_field = "bat";
    return true;
  }
  if (!flexible_exit) return false;
  out->summary.SetRefusal(TextRefusal(
      "bat", "model = flexible needs the bat's geometry (a bat, not only mass_properties)"));
  out->refused_field = "bat";
  return true;
}

// The curve positions the options give, each on the bat; otherwise the refusal in *s.
bool CurvePositionsOnBat(const SceneOptions& options, double length_m, Summary* s) {
  for (size_t i = 0; i < options.curve_positions_from_knob_m.size(); ++i) {
    const double x = options.curve_positions_from_knob_m[i];
    if (!(x >= 0.0 && x <= length_m)) {
      s->SetRefusal(Number17Refusal("curve_positions_from_knob_m[" + std::to_string(i) + "]", x,
                                    "must be within the bat [0, " + FormatNumber17(length_m) + "]"));
      return false;
    }
  }
  return true;
}

// The shared handling of an output's modes that are not usable (the same for every output that
// needs them): an invalid input is a refusal on the bat, keeping the modes' message first (it
// names the field); anything else a failure "<name>: <modes_failure><message>".
void NoteUnusableModes(const BatModes& modes, const SceneOutputDecl& d, OutputContext* c) {
  const bool invalid = modes.summary.termination == Termination::kInvalidInput;
  const std::string note = std::string(" (") + d.name + ")";
  if (invalid && modes.summary.refusal.has_value()) {
    c->Refuse(Noted(*modes.summary.refusal, note));
  } else {
    c->Note(invalid ? Termination::kInvalidInput : Termination::kFailure,
            invalid ? modes.summary.message + note
                    : std::string(d.name) + ": " + d.modes_failure + modes.summary.message);
  }
  if (invalid) c->out.refused_field = "bat";
}

// The summary's message, iterations and error estimate once every output has run.
void Conclude(const std::vector<SceneOutput>& wanted, const std::vector<std::string>& messages,
              SceneResult* out) {
  Summary& s = out->summary;
  if (messages.empty()) {
    s.message = "computed";
    for (SceneOutput o : wanted) s.message.append(" ").append(SceneOutputName(o));
  } else {
    for (size_t i = 0; i < messages.size(); ++i) s.message += (i ? "; " : "") + messages[i];
  }
  s.iterations = -1;
  double worst_err = 0.0;
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    if (d->error_estimate_m != nullptr && d->present(*out)) {
      worst_err = std::max(worst_err, d->error_estimate_m(*out));
    }
  }
  s.error_estimate = worst_err;
}

}  // namespace
}  // namespace evaluate_scene

void SceneResult::Reset() {
  // A field added to SceneResult must be reset here too: on x86-64 (the size this list was
  // written for) the size check says so. The outputs' slots are reset by their declarations.
  // A new slot can move this difference too (the base's tail padding: 600 -> 608 with
  // batted_ball's slot, SceneResult's own fields unchanged). 608 -> 752: Swing gained the
  // speed model's settings and its resolution (reset with `swing` below).
#if defined(__x86_64__)
  static_assert(sizeof(SceneResult) - sizeof(SceneOutputResults) == 752,
                "SceneResult gained a field: reset it in Reset");
#endif
  summary.Reset();
  missing_model.clear();
  refused_field.clear();
  cor.reset();
  cor_source.clear();
  cor_impact_speed_mps.reset();
  mass_properties = MassProperties{};
  length_m = 0.0;
  swing = Swing{};
  exit_speed_model.clear();
  model_reason.clear();
  for (const SceneOutputDecl* d : SceneOutputTable()) d->reset(this);
  timings.clear();
}

SceneEvaluator::SceneEvaluator(SceneOptions options) : options_(std::move(options)) {
  if (Refusal refusal; !options_.Validate(&refusal)) options_refusal_ = std::move(refusal);
  wanted_.reserve(kSceneOutputCount);
  messages_.reserve(4);
}

SceneResult EvaluateScene(const Scene& scene, const SceneOptions& options) {
  SceneResult out;
  SceneEvaluator(options).Evaluate(scene, &out);
  return out;
}

void SceneEvaluator::Evaluate(const Scene& scene, SceneResult* out_ptr) {
  // TimedRequest's frame ("scene"), over the previous result's buffers.
  const bool timed = options_.time_models;
  const auto t0 =
      timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
  SceneResult& out = *out_ptr;
  out.Reset();
  book_.Reset(timed);
  Summary& s = out.summary;
  s.backend = "scene";
  CatchInternalError(&s, [&] {
    if (options_refusal_.has_value()) {
      s.SetRefusal(*options_refusal_);
      return;
    }
    EvaluateOutputs(scene, &out);
  });
  if (timed) s.solve_time_s = SecondsSince(t0);
  book_.ModelsInto(&s.models_used);
  out.timings.assign(book_.timings().begin(), book_.timings().end());
}

void SceneEvaluator::EvaluateOutputs(const Scene& scene, SceneResult* out_ptr) {
  using namespace evaluate_scene;
  const SceneOptions& options = options_;
  SceneResult& out = *out_ptr;
  Summary& s = out.summary;
  std::array<bool, kSceneOutputCount> wanted{};
  wanted_.clear();
  for (SceneOutput o : scene.outputs) {
    if (!wanted[static_cast<std::size_t>(o)]) wanted_.push_back(o);
    wanted[static_cast<std::size_t>(o)] = true;
  }
  const std::array<bool, kSceneOutputCount> run = OutputsToRun(wanted);
  bool needs_exit = false, needs_cor = false;
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    if (!run[static_cast<std::size_t>(d->id)]) continue;
    needs_exit = needs_exit || d->uses_exit_model;
    needs_cor = needs_cor || d->needs_cor;
  }
  // The flexible beam needs the bat's geometry, not only its mass properties.
  const bool flexible_exit = needs_exit && options.model == CollisionModel::kFlexible;
  if (!scene.bat.has_value() && RefuseMissingGeometry(run, flexible_exit, &out)) return;
  ResolvedScene r;
  const bool resolved = ResolveScene(scene, needs_cor, &book_, &r, &s, std::nullopt, options.model);
  // Also when refused: the caller can then tell properties that are not usable (the bat's).
  out.mass_properties = r.mass_properties;
  if (!resolved) return;
  out.cor = r.cor;
  out.cor_source = r.cor_source;
  out.cor_impact_speed_mps = r.cor_impact_speed_mps;
  out.length_m = r.length_m;
  out.swing = r.swing;
  if (!CurvePositionsOnBat(options, r.length_m, &s)) return;
  const CollisionModel model = ResolveExitModel(options.model, scene, &out.model_reason);
  if (!needs_exit) out.model_reason.clear();
  s.termination = Termination::kConverged;
  messages_.clear();
  OutputContext context(scene, options, r, &book_, &out, &messages_);
  context.wanted_ = wanted;
  context.model = model;

  FlexibleModes flexible_modes(scene, options.flexible, &book_);
  std::optional<ExitSpeedModel> exit_model;
  std::shared_ptr<const BatModes> impact_modes;  // flexible: the exit model's modes
  if (needs_exit) {
    if (model == CollisionModel::kFlexible) {
      const auto& modes = flexible_modes.Impact();
      impact_modes = modes;
      if (FlexibleModesRefused(*modes, &s)) {
        if (s.termination == Termination::kInvalidInput) out.refused_field = "bat";
        return;
      }
      for (const auto& w : modes->summary.warnings) s.warnings.push_back("flexible_beam: " + w);
      exit_model.emplace(model, scene, r, options.hertz, &book_, &options.flexible, modes);
    } else {
      exit_model.emplace(model, scene, r, options.hertz, &book_);
    }
    out.exit_speed_model = exit_model->name();
    context.exit_model = &*exit_model;
    context.closed_form =
        exit_model->profile().has_value() && options.method == SweetSpotMethod::kClosedForm;
    // A swing at its sweet spot with hertz or flexible: the point moved to the model's own
    // maximum (the swing and a ball-law COR re-resolved).
    if (!SolveSweetSpotSwing(scene, options, model, needs_cor, &book_, impact_modes, &r,
                             &exit_model, &s)) {
      return;
    }
    out.cor = r.cor;
    out.cor_source = r.cor_source;
    out.cor_impact_speed_mps = r.cor_impact_speed_mps;
    out.swing = r.swing;
  }
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    if (!run[static_cast<std::size_t>(d->id)]) continue;
    context.modes = nullptr;
    if (d->modes != OutputModes::kNone) {
      const bool vibration = d->modes == OutputModes::kVibration;
      const auto& modes = vibration ? flexible_modes.Vibration() : flexible_modes.Impact();
      if (!modes->summary.IsSolutionUsable()) {
        NoteUnusableModes(*modes, *d, &context);
        continue;
      }
      context.modes = modes.get();
      context.modes_cache_hit =
          vibration ? flexible_modes.vibration_hit() : flexible_modes.impact_hit();
    }
    d->compute(context);
  }
  // An output run only because another reads it is not part of the answer.
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    if (run[static_cast<std::size_t>(d->id)] && !wanted[static_cast<std::size_t>(d->id)]) {
      d->reset(&out);
    }
  }
  if (exit_model.has_value()) {
    for (const auto& w : exit_model->warnings()) s.warnings.push_back(w);
  }
  Conclude(wanted_, messages_, &out);
}

}  // namespace sweetspot::core
