// The table of scene outputs: each output declared once (its name, the models it needs,
// whether it needs the bat's geometry or a COR, its workload class, its slot in SceneResult and
// how it is computed) in core/scene/outputs_*.cpp and registered by one row of the table in
// output_registry.cpp. EvaluateScene is a loop over that table; ModelsFor, the output names,
// the api's workload classification and its renderers (api/outputs/) read it.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "core/flexible/modes.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/scene/output_id.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene.hpp"
#include "core/scene/scene_models.hpp"

namespace sweetspot::core {

/// Which pool a request asking for an output belongs in (the api's ClassifyWorkload).
enum class OutputWorkload {
  kLight,        ///< A closed form: microseconds.
  kCompute,      ///< An iterative model (finite elements, an ODE) whatever the options.
  kAsExitModel,  ///< Light when the scene's exit-speed model is a closed form, else compute.
};

/// The flexible beam's modes an output needs before it runs (FlexibleModes).
enum class OutputModes {
  kNone,       ///< None.
  kVibration,  ///< The two modes of vibration_node.
  kImpact,     ///< The modes of flexible impacts.
};

class OutputContext;

/// One output: everything core knows of it. Plain data and function pointers, so the table is
/// a constant and a loop over it allocates nothing.
struct SceneOutputDecl {
  SceneOutput id;    ///< Its id.
  const char* name;  ///< Its stable name, as requests and answers write it.
  /// It reads the scene's exit-speed model (max_exit_speed, sweet_zone, exit_speed_curve): its
  /// models are that model's, and model = flexible needs the bat's geometry.
  bool uses_exit_model = false;
  /// The models it runs itself, in run order (null-ended), after the exit-speed model's when it
  /// uses that (e.g. a flight output: {"flight"}).
  std::array<const char*, 5> models{};
  bool needs_geometry = false;             ///< It needs the bat (not only mass_properties).
  bool needs_cor = false;                  ///< It runs an impact (every impact model uses the COR).
  OutputModes modes = OutputModes::kNone;  ///< The modes fetched (and checked) before it runs.
  /// With modes: the words before the modes' message when they failed ("<name>: <this><message>").
  const char* modes_failure = "";
  /// An output whose result it reads (run first, its result dropped when not asked for), or
  /// itself when none.
  SceneOutput needs_output;
  OutputWorkload workload = OutputWorkload::kLight;  ///< Light or compute.
  /// Computes it into its slot of context.out, noting failures, warnings and refusals in the
  /// context. Called only when the preconditions above hold (geometry, modes usable).
  void (*compute)(OutputContext& context) = nullptr;
  /// True when its slot of `result` holds a result.
  bool (*present)(const SceneOutputResults& result) = nullptr;
  /// Empties its slot (keeping buffers is not required).
  void (*reset)(SceneOutputResults* result) = nullptr;
  /// The position error it adds to the summary's error_estimate (m), or null for none.
  double (*error_estimate_m)(const SceneOutputResults& result) = nullptr;
};

/// `present` of the output whose slot is `Slot` (e.g. &SceneOutputResults::bbcor).
template <auto Slot>
bool SlotPresent(const SceneOutputResults& result) {
  return (result.*Slot).has_value();
}
/// `reset` of the output whose slot is `Slot`.
template <auto Slot>
void ResetSlot(SceneOutputResults* result) {
  (result->*Slot).reset();
}

/// Every output, in the order they are computed (their messages and warnings follow it).
const std::vector<const SceneOutputDecl*>& SceneOutputTable();
/// The declaration of `id`.
const SceneOutputDecl& SceneOutputDeclaration(SceneOutput id);
/// "a, b, c" of every output's name, in id order (for refusals: "is not one of ...").
const std::string& SceneOutputNameList();
/// True when `model` (not kAuto) is a closed form (rigid_pivot, free_bat).
bool IsClosedFormModel(CollisionModel model);
/// The workload class of `output` with `exit_model` as the scene's exit-speed model (kAuto:
/// free_bat): kLight or kCompute.
OutputWorkload WorkloadOf(SceneOutput output, CollisionModel exit_model);

/// What an output's computation reads and writes: one evaluation of a scene.
class OutputContext {
 public:
  OutputContext(const Scene& the_scene, const SceneOptions& the_options,
                const ResolvedScene& the_resolved, TimingBook* the_book, SceneResult* the_out,
                std::vector<std::string>* messages)
      : scene(the_scene),
        options(the_options),
        resolved(the_resolved),
        book(*the_book),
        out(*the_out),
        messages_(messages) {}

  const Scene& scene;                    ///< The scene.
  const SceneOptions& options;           ///< The evaluator's options (valid).
  const ResolvedScene& resolved;         ///< Resolved once (its COR when an output needs one).
  TimingBook& book;                      ///< Where models book their time.
  SceneResult& out;                      ///< The result (each output writes its slot).
  ExitSpeedModel* exit_model = nullptr;  ///< Set when an output uses the exit-speed model.
  CollisionModel model = CollisionModel::kFreeBat;  ///< The resolved exit-speed model.
  /// The exit-speed model has a closed-form profile and the method is closed_form.
  bool closed_form = false;
  const BatModes* modes = nullptr;  ///< The declaration's modes (usable), or null.
  bool modes_cache_hit = false;     ///< They came from the cross-request cache.

  /// True when the scene asks for `output`.
  bool Wants(SceneOutput output) const { return wanted_[static_cast<std::size_t>(output)]; }
  /// Worsens the termination to `termination`; `what`, when not empty, joins the message.
  void Note(Termination termination, std::string what);
  /// An output refused for its input: the first such refusal is the summary's.
  void Refuse(Refusal why);
  /// A warning of `output`: "<name>: <warning>".
  void Warn(SceneOutput output, const std::string& warning);

 private:
  friend class SceneEvaluator;
  std::vector<std::string>* messages_;
  std::array<bool, kSceneOutputCount> wanted_{};
};

}  // namespace sweetspot::core
