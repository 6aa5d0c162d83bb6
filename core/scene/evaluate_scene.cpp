#include "core/scene/evaluate_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/geometry_format.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene_barrel.hpp"
#include "core/scene/scene_models.hpp"
#include "core/sweet_spot/least_sting.hpp"
#include "core/sweet_spot/numeric.hpp"
#include "core/sweet_spot/vibration_node.hpp"

namespace sweetspot::core {
namespace {

// The resolved mass properties when they are the rigid body's (what the barrel models use),
// else null (the models then compute the rigid body's themselves).
const MassProperties* SceneRigidBodyProperties(const ResolvedScene& r) {
  return r.mass_properties.inertia_model == InertiaModel::kRigidBody ? &r.mass_properties
                                                                     : nullptr;
}

Termination Worse(Termination a, Termination b) {
  auto rank = [](Termination t) {
    switch (t) {
      case Termination::kConverged:
        return 0;
      case Termination::kNoConvergence:
        return 1;
      case Termination::kInfeasible:
        return 2;
      case Termination::kFailure:
        return 3;
      case Termination::kInvalidInput:
        return 4;
    }
    return 3;
  };
  return rank(a) >= rank(b) ? a : b;
}

bool NeedsExitModel(SceneOutput o) {
  return o == SceneOutput::kMaxExitSpeed || o == SceneOutput::kSweetZone ||
         o == SceneOutput::kExitSpeedCurve;
}

// Outputs that run an impact (every impact model uses the COR): the exit-speed outputs and
// least_sting_zone's flexible impacts. center_of_percussion and vibration_node do not.
// barrel's effective COR starts from the ball's (the resolved COR when the ball has no law).
bool NeedsCor(SceneOutput o) {
  return NeedsExitModel(o) || o == SceneOutput::kLeastStingZone || o == SceneOutput::kBarrel;
}

bool Wants(const std::vector<SceneOutput>& wanted, SceneOutput o) {
  return std::find(wanted.begin(), wanted.end(), o) != wanted.end();
}

// least_sting_zone: the sweep from the hands to the tip with this scene's flexible impacts.
bool StingZone(const Scene& scene, const ResolvedScene& r, const SceneOptions& options,
               const BatModes& modes, TimingBook* book, std::vector<std::string>* warnings,
               LeastStingZoneResult* out, std::string* error) {
  const FlexibleOptions& fo = options.flexible;
  const double hands = scene.swing.hands_from_knob_m;
  if (!(r.length_m > hands)) {
    *error = "swing.hands_from_knob_m = " + FormatNumber17(hands) +
             ": the sweep runs from the hands to the tip, so the hands must be before the tip";
    return false;
  }
  FlexibleImpactOptions sample = fo.impact;
  sample.refine_check = false;  // the refinement check runs at the least-sting impact
  FlexibleImpactOptions search = sample;
  search.hands_loads = false;  // the searches read the hands' energy only
  const StingImpact impact = [&](double s, StingRun run) {
    const auto t0 = std::chrono::steady_clock::now();
    FlexibleImpactResult fr =
        SolveFlexibleImpact(*scene.bat, modes, FlexibleImpactInputsFor(scene, r, s, options.hertz),
                            run == StingRun::kChecked  ? fo.impact
                            : run == StingRun::kSample ? sample
                                                       : search);
    book->Add(CollisionModelName(CollisionModel::kFlexible), SecondsSince(t0), 1);
    return fr;
  };
  if (!LeastStingZone(impact, hands, r.length_m, fo.sting_samples, fo.sting_zone_fraction,
                      fo.search.x_tolerance_m, warnings, out, error)) {
    return false;
  }
  out->elements = modes.Elements();
  out->theory = BeamTheoryName(modes.theory);
  return true;
}

}  // namespace

std::vector<std::string> ModelsFor(SceneOutput output, CollisionModel exit_model) {
  if (exit_model == CollisionModel::kAuto) exit_model = CollisionModel::kFreeBat;
  switch (output) {
    case SceneOutput::kCenterOfPercussion:
      return {"mass_properties"};
    case SceneOutput::kVibrationNode:
      return {kFlexibleBeamModel};
    case SceneOutput::kLeastStingZone:
      return {"mass_properties", kFlexibleBeamModel, "flexible"};
    case SceneOutput::kBarrel:
    case SceneOutput::kBbcor:
      return {"mass_properties", kBarrelModel};
    case SceneOutput::kBbcorScan:
      return {"mass_properties", kFlexibleBeamModel, "flexible", kBarrelModel};
    case SceneOutput::kMaxExitSpeed:
    case SceneOutput::kSweetZone:
    case SceneOutput::kExitSpeedCurve:
      if (exit_model == CollisionModel::kFlexible) {
        return {"mass_properties", kFlexibleBeamModel, "flexible"};
      }
      return {"mass_properties", CollisionModelName(exit_model)};
  }
  return {};
}

void SceneResult::Reset() {
  // A field added to SceneResult must be reset here too: on x86-64 (the size this list was
  // written for) the size check says so.
#if defined(__x86_64__)
  static_assert(sizeof(SceneResult) == 1808 + kBarrelFieldsSize,
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
  max_exit_speed.reset();
  center_of_percussion.reset();
  sweet_zone.reset();
  exit_speed_curve.reset();
  vibration_node.reset();
  least_sting_zone.reset();
  barrel.reset();
  bbcor.reset();
  bbcor_scan.reset();
  timings.clear();
}

SceneEvaluator::SceneEvaluator(SceneOptions options) : options_(std::move(options)) {
  if (Refusal refusal; !options_.Validate(&refusal)) options_refusal_ = std::move(refusal);
  wanted_.reserve(8);
}

SceneResult EvaluateScene(const Scene& scene, const SceneOptions& options) {
  SceneResult out;
  SceneEvaluator(options).Evaluate(scene, &out);
  return out;
}

void SceneEvaluator::Evaluate(const Scene& scene, SceneResult* out_ptr) {
  // TimedRequest's frame ("scene"), over the previous result's buffers.
  const SceneOptions& options = options_;
  const bool timed = options.time_models;
  const auto t0 =
      timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
  SceneResult& out = *out_ptr;
  out.Reset();
  book_.Reset(timed);
  TimingBook& book = book_;
  Summary& s = out.summary;
  s.backend = "scene";
  CatchInternalError(&s, [&] {
    if (options_refusal_.has_value()) {
      s.SetRefusal(*options_refusal_);
      return;
    }
    std::vector<SceneOutput>& wanted = wanted_;
    wanted.clear();
    for (SceneOutput o : scene.outputs) {
      if (std::find(wanted.begin(), wanted.end(), o) == wanted.end()) wanted.push_back(o);
    }
    const bool needs_exit = std::any_of(wanted.begin(), wanted.end(), NeedsExitModel);
    // The flexible beam needs the bat's geometry, not only its mass properties.
    const bool flexible_exit = needs_exit && options.model == CollisionModel::kFlexible;
    if (!scene.bat.has_value()) {
      for (SceneOutput o : {SceneOutput::kVibrationNode, SceneOutput::kLeastStingZone,
                            SceneOutput::kBarrel, SceneOutput::kBbcor, SceneOutput::kBbcorScan}) {
        if (Wants(wanted, o)) {
          s.SetRefusal(TextRefusal("bat", std::string(SceneOutputName(o)) +
                                              " needs the bat's geometry (a bat, not only "
                                              "mass_properties)"));
          out.refused_field = "bat";
          return;
        }
      }
      if (flexible_exit) {
        s.SetRefusal(TextRefusal(
            "bat", "model = flexible needs the bat's geometry (a bat, not only mass_properties)"));
        out.refused_field = "bat";
        return;
      }
    }
    ResolvedScene r;
    const bool needs_cor = std::any_of(wanted.begin(), wanted.end(), NeedsCor);
    const bool resolved = ResolveScene(scene, needs_cor, &book, &r, &s);
    // Also when refused: the caller can then tell properties that are not usable (the bat's).
    out.mass_properties = r.mass_properties;
    if (!resolved) return;
    out.cor = r.cor;
    out.cor_source = r.cor_source;
    out.cor_impact_speed_mps = r.cor_impact_speed_mps;
    out.length_m = r.length_m;
    out.swing = r.swing;
    for (size_t i = 0; i < options.curve_positions_from_knob_m.size(); ++i) {
      const double x = options.curve_positions_from_knob_m[i];
      if (!(x >= 0.0 && x <= r.length_m)) {
        s.SetRefusal(
            Number17Refusal("curve_positions_from_knob_m[" + std::to_string(i) + "]", x,
                            "must be within the bat [0, " + FormatNumber17(r.length_m) + "]"));
        return;
      }
    }
    const CollisionModel model = ResolveExitModel(options.model, scene, &out.model_reason);
    if (!needs_exit) out.model_reason.clear();
    s.termination = Termination::kConverged;
    std::vector<std::string> messages;
    auto note = [&](Termination t, const std::string& what) {
      s.termination = Worse(s.termination, t);
      if (!what.empty()) messages.push_back(what);
    };
    // An output refused for its input: the first such refusal is the summary's.
    auto refuse = [&](Refusal why) {
      note(Termination::kInvalidInput, why.Message());
      if (!s.refusal.has_value()) s.refusal = std::move(why);
    };

    FlexibleModes flexible_modes(scene, options.flexible, &book);
    std::optional<ExitSpeedModel> exit_model;
    if (needs_exit) {
      if (model == CollisionModel::kFlexible) {
        const auto& modes = flexible_modes.Impact();
        if (FlexibleModesRefused(*modes, &s)) {
          if (s.termination == Termination::kInvalidInput) out.refused_field = "bat";
          return;
        }
        for (const auto& w : modes->summary.warnings) s.warnings.push_back("flexible_beam: " + w);
        exit_model.emplace(model, scene, r, options.hertz, &book, &options.flexible, modes);
      } else {
        exit_model.emplace(model, scene, r, options.hertz, &book);
      }
      out.exit_speed_model = exit_model->name();
    }
    const bool closed = exit_model.has_value() && exit_model->profile().has_value() &&
                        options.method == SweetSpotMethod::kClosedForm;
    const bool need_max =
        std::find(wanted.begin(), wanted.end(), SceneOutput::kMaxExitSpeed) != wanted.end() ||
        std::find(wanted.begin(), wanted.end(), SceneOutput::kSweetZone) != wanted.end();
    if (need_max) {
      MaxExitSpeedResult mx;
      if (closed) {
        const auto tm = book.Now();
        mx = ClosedFormMaxExitSpeed(*exit_model->profile(), r.length_m);
        mx.model = exit_model->name();
        mx.summary.solve_time_s = book.Since(tm);
        mx.summary.models_used = {exit_model->name()};
        book.Add(exit_model->name(), mx.summary.solve_time_s, 1);
      } else if (model == CollisionModel::kFlexible &&
                 options.method == SweetSpotMethod::kClosedForm) {
        mx = BracketMaxExitSpeed(&*exit_model, r.length_m, options.flexible.search);
        mx.summary.models_used = {exit_model->name()};
      } else {
        mx = SearchMaxExitSpeed(&*exit_model, r.length_m, options.nlopt);
        mx.summary.models_used = {exit_model->name()};
      }
      for (const auto& w : mx.summary.warnings) s.warnings.push_back("max_exit_speed: " + w);
      note(mx.summary.termination,
           mx.summary.IsSolutionUsable() ? std::string() : "max_exit_speed: " + mx.summary.message);
      const bool usable = mx.summary.IsSolutionUsable();
      const bool want_max =
          std::find(wanted.begin(), wanted.end(), SceneOutput::kMaxExitSpeed) != wanted.end();
      const bool want_zone =
          std::find(wanted.begin(), wanted.end(), SceneOutput::kSweetZone) != wanted.end();
      if (want_max && !want_zone) out.max_exit_speed = std::move(mx);  // the zone reads mx
      if (want_max && want_zone) out.max_exit_speed = mx;
      if (want_zone) {
        if (!usable) {
          note(Termination::kFailure, "sweet_zone: needs max_exit_speed, which failed");
        } else {
          const double tol =
              options.sweet_zone_unit == ToleranceUnit::kPercent
                  ? options.sweet_zone_tolerance / 100.0 * std::abs(mx.exit_speed_mps)
                  : options.sweet_zone_tolerance;
          if (closed) {
            const auto tz = book.Now();
            out.sweet_zone = ClosedFormSweetZone(*exit_model->profile(), r.length_m, mx, tol);
            book.Add(exit_model->name(), book.Since(tz), 1);
          } else {
            std::string error;
            out.sweet_zone = RootFindSweetZone(&*exit_model, r.length_m, mx, tol, &error);
            out.sweet_zone->error_estimate_m += mx.error_estimate_m;
            if (!error.empty()) {
              note(Termination::kFailure, "sweet_zone: " + error);
              out.sweet_zone.reset();
            }
          }
        }
      }
    }
    if (std::find(wanted.begin(), wanted.end(), SceneOutput::kCenterOfPercussion) != wanted.end()) {
      Refusal cop_why;
      auto cop = CenterOfPercussion(r.mass_properties, scene.swing.hands_from_knob_m, r.length_m,
                                    &cop_why);
      if (!cop.has_value()) {
        // The core message first ("swing.hands_from_knob_m = ...: rule"): it names the field.
        refuse(Noted(std::move(cop_why), " (center_of_percussion)"));
      } else {
        if (cop->placement == Placement::kBeyondTip) {
          s.warnings.push_back("center_of_percussion: beyond the tip (" +
                               FormatNumber17(cop->position_from_knob_m) + " m from the knob)");
        }
        out.center_of_percussion = cop;
      }
    }
    if (Wants(wanted, SceneOutput::kVibrationNode)) {
      const auto& modes = flexible_modes.Vibration();
      VibrationNodeResult node;
      std::string error;
      if (VibrationNodeFrom(*modes, flexible_modes.vibration_hit(), &node, &error)) {
        if (modes->summary.termination == Termination::kNoConvergence) {
          note(Termination::kNoConvergence, "vibration_node: " + modes->summary.message);
        }
        out.vibration_node = std::move(node);
      } else {
        const bool invalid = modes->summary.termination == Termination::kInvalidInput;
        // Invalid input keeps the core message first ("bat.length_m = ...: rule"): it names
        // the field.
        if (invalid && modes->summary.refusal.has_value()) {
          refuse(Noted(*modes->summary.refusal, " (vibration_node)"));
        } else {
          note(invalid ? Termination::kInvalidInput : Termination::kFailure,
               invalid ? error + " (vibration_node)" : "vibration_node: " + error);
        }
        if (invalid) out.refused_field = "bat";
      }
    }
    if (Wants(wanted, SceneOutput::kLeastStingZone)) {
      const auto& modes = flexible_modes.Impact();
      if (!modes->summary.IsSolutionUsable()) {
        const bool invalid = modes->summary.termination == Termination::kInvalidInput;
        if (invalid && modes->summary.refusal.has_value()) {
          refuse(Noted(*modes->summary.refusal, " (least_sting_zone)"));
        } else {
          note(invalid ? Termination::kInvalidInput : Termination::kFailure,
               invalid ? modes->summary.message + " (least_sting_zone)"
                       : "least_sting_zone: the bat's modes: " + modes->summary.message);
        }
        if (invalid) out.refused_field = "bat";
      } else {
        LeastStingZoneResult zone;
        std::string error;
        std::vector<std::string> warnings;
        const bool ok = StingZone(scene, r, options, *modes, &book, &warnings, &zone, &error);
        for (const auto& w : warnings) s.warnings.push_back("least_sting_zone: " + w);
        if (ok) {
          out.least_sting_zone = std::move(zone);
        } else {
          note(Termination::kFailure, "least_sting_zone: " + error);
        }
      }
    }
    if (Wants(wanted, SceneOutput::kBarrel)) {
      const auto tb = book.Now();
      BarrelOutput barrel;
      std::string error;
      if (SceneBarrel(scene, r, options.barrel, &barrel, &error)) {
        out.barrel = std::move(barrel);
      } else {
        note(Termination::kFailure, error);
      }
      book.Add(kBarrelModel, book.Since(tb), 1);
    }
    if (Wants(wanted, SceneOutput::kBbcor)) {
      const auto tb = book.Now();
      BbcorResult bbcor =
          ComputeBbcor(*scene.bat, BbcorProtocol{}, options.barrel, SceneRigidBodyProperties(r));
      if (bbcor.ok) {
        out.bbcor = std::move(bbcor);
      } else {
        note(Termination::kFailure, bbcor.message);
      }
      book.Add(kBarrelModel, book.Since(tb), 1);
    }
    if (Wants(wanted, SceneOutput::kBbcorScan)) {
      const auto& modes = flexible_modes.Impact();
      if (!modes->summary.IsSolutionUsable()) {
        const bool invalid = modes->summary.termination == Termination::kInvalidInput;
        if (invalid && modes->summary.refusal.has_value()) {
          refuse(Noted(*modes->summary.refusal, " (bbcor_scan)"));
        } else {
          note(invalid ? Termination::kInvalidInput : Termination::kFailure,
               invalid ? modes->summary.message + " (bbcor_scan)"
                       : "bbcor_scan: the bat's modes: " + modes->summary.message);
        }
        if (invalid) out.refused_field = "bat";
      } else {
        // The flexible impacts along the barrel (and, inside, the barrel model's fixed point:
        // microseconds, booked with them).
        const auto tb = book.Now();
        BbcorScan scan =
            ComputeBbcorScan(*scene.bat, *modes, BbcorProtocol{}, options.flexible.impact,
                             options.barrel, SceneRigidBodyProperties(r));
        const double seconds = book.Since(tb);
        book.Add(CollisionModelName(CollisionModel::kFlexible), seconds,
                 static_cast<int>(scan.points.size()));
        book.Add(kBarrelModel, 0.0, 1);
        for (const auto& w : scan.warnings) s.warnings.push_back("bbcor_scan: " + w);
        if (scan.ok) {
          out.bbcor_scan = std::move(scan);
        } else {
          note(Termination::kFailure, scan.message);
        }
      }
    }
    if (std::find(wanted.begin(), wanted.end(), SceneOutput::kExitSpeedCurve) != wanted.end()) {
      ExitSpeedCurveResult curve;
      curve.model = exit_model->name();
      std::vector<double> xs = options.curve_positions_from_knob_m;
      if (xs.empty()) {
        const int n = options.curve_samples;
        for (int i = 0; i < n; ++i)
          xs.push_back(i + 1 == n ? r.length_m : r.length_m * i / (n - 1));
      }
      bool ok = true;
      std::string error;
      for (double x : xs) {
        double v = 0.0, e = 0.0;
        if (IsCancelled(options.progress)) {
          ok = false;
          error = "cancelled after " + std::to_string(curve.points.size()) + " of " +
                  std::to_string(xs.size()) + " points";
          break;
        }
        if (!exit_model->Eval(x, &v, nullptr, &e, &error)) {
          ok = false;
          break;
        }
        curve.points.push_back({x, v});
        curve.error_estimate_mps = std::max(curve.error_estimate_mps, e);
      }
      if (ok) {
        out.exit_speed_curve = std::move(curve);
      } else {
        note(Termination::kFailure, "exit_speed_curve: " + error);
      }
    }
    if (exit_model.has_value()) {
      for (const auto& w : exit_model->warnings()) s.warnings.push_back(w);
    }
    if (messages.empty()) {
      s.message = "computed";
      for (SceneOutput o : wanted) s.message.append(" ").append(SceneOutputName(o));
    } else {
      for (size_t i = 0; i < messages.size(); ++i) s.message += (i ? "; " : "") + messages[i];
    }
    s.iterations = -1;
    double worst_err = 0.0;
    if (out.max_exit_speed) worst_err = std::max(worst_err, out.max_exit_speed->error_estimate_m);
    if (out.vibration_node) worst_err = std::max(worst_err, out.vibration_node->error_estimate_m);
    if (out.least_sting_zone) {
      worst_err = std::max(worst_err, out.least_sting_zone->error_estimate_m);
    }
    s.error_estimate = worst_err;
  });
  if (timed) s.solve_time_s = SecondsSince(t0);
  book.ModelsInto(&s.models_used);
  out.timings.assign(book.timings().begin(), book.timings().end());
}

}  // namespace sweetspot::core
