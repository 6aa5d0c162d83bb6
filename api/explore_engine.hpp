// The sweep engine of /v1/explore: a validated sweep (the template resolved once) and
// RunSweep, which evaluates its designs on up to `threads` threads and hands their rows on in
// index order, bit for bit the rows of a one-thread run.
//
// Per design, the engine applies only the swept values to the resolved template (a
// DesignBinder: ball, swing, cor, the three-segment shape, profile knots, material, wall and
// fill numbers) and recomputes only what they change: a sweep that leaves the bat alone
// computes its mass properties once. A design's row is written straight into its block's
// text when the columns and objectives are values the engine reads from the models' results
// (DirectColumns), and rendered as the JSON row otherwise. What the binder cannot bind (a
// swept path it does not know), and a design whose bound values fail a check, go through the
// JSON path (the design's JSON, parsed as /v1/sweet-spot parses it), so every row and error
// is the one that path gives; tests/api/explore_engine_test.cpp checks the two agree.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "api/explore_columns.hpp"
#include "api/explore_design.hpp"
#include "api/explore_shards.hpp"
#include "api/json_path.hpp"
#include "api/limits.hpp"
#include "api/router.hpp"
#include "api/thread_budget.hpp"
#include "core/mass_properties.hpp"
#include "core/progress.hpp"
#include "core/sampling.hpp"
#include "core/scene/closed_form_designs.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::api {

/// A swept parameter: its path as written, its steps from the template root.
struct SweepParameter {
  /// Its name in rows ("parameters.<name>"): "path" as written ("three_segment.taper_start_m"),
  /// or for linked fields "name" (default: the paths joined with "+").
  std::string path;
  std::vector<PathStep> steps;  ///< The first field, from the template root ("bat", ...).
  /// Every field the value sets ("paths": all set to the value; "scale_paths": each the
  /// template's value times the swept value), in order; one for "path".
  std::vector<std::vector<PathStep>> targets;
  /// For "scale_paths": the template's value of each target (the value multiplies them).
  std::vector<double> scale_bases;
  /// Per target, the factor from the swept value to the target's SI field: 1, or for a path
  /// written in a trade unit ("ball.speed_mph", whose target is "ball.speed_mps") its TradeForm's
  /// (0.44704). Not used by "scale_paths" (the value is a ratio).
  std::vector<double> to_si;
  bool scale = false;  ///< True for "scale_paths".

  /// The value of target `t` in a design whose swept value is `value`.
  double TargetValue(std::size_t t, double value) const {
    if (scale) return scale_bases[t] * value;
    return t < to_si.size() ? value * to_si[t] : value;
  }
};

/// Sets a design's swept values on the template's scene without JSON. Made once per sweep.
class DesignBinder {
 public:
  /// The binder of `parameters` on `base` (the template: bat and scene fields), or nullopt
  /// when a path is not one it binds (the sweep then runs on the JSON path).
  /// `template_properties`: the template bat's mass properties as the request's ParseBat
  /// computed them (BatSpec::properties), used when no parameter changes the bat; null:
  /// computed here.
  static std::optional<DesignBinder> Compile(
      const nlohmann::json& base, const std::vector<SweepParameter>& parameters,
      const RowOutputs& outputs, const ApiLimits& limits,
      const core::MassPropertiesOfBothModels* template_properties = nullptr);
  /// The template's scene (outputs set; mass properties preset when no parameter changes the
  /// bat): a worker's starting scene, which Bind then changes in place.
  const core::Scene& base_scene() const { return scene_; }
  /// Sets `values` (one per parameter) on *scene (base_scene() or a scene Bind has bound
  /// before). True when the design passes every check the JSON path makes; false when it
  /// does not (its row is then the JSON path's).
  bool Bind(const std::vector<double>& values, core::Scene* scene) const;
  /// The parts of the scene Bind changes (the checks the lean path runs again per design).
  const core::SceneChanges& changes() const { return changes_; }

 private:
  enum class Target;
  struct Binding {
    Target target;
    std::size_t index = 0;      // a knot's
    std::size_t parameter = 0;  // whose value it takes
    std::size_t target_index = 0;  // which of that parameter's targets (SweepParameter)
  };
  std::vector<SweepParameter> parameters_;  // the values' meaning (linked and scaled paths)
  std::vector<Binding> bindings_;
  core::Scene scene_;
  std::optional<core::ThreeSegmentShape> shape_;  // the template's, when one is swept
  bool bat_swept_ = false;                        // some parameter changes the bat
  bool materials_swept_ = false;   // some parameter is a number of the material or the fill
  bool only_shape_swept_ = false;  // the bat is swept only through its three-segment shape
  core::SceneChanges changes_;     // which parts of the scene the bindings change
};

/// A validated sweep: everything needed to evaluate its designs, owned, so a streamed answer
/// can run it after the handler has returned.
struct Sweep {
  nlohmann::json base;                          ///< The design template (bat + scene fields).
  std::vector<SweepParameter> parameters;       ///< The swept fields.
  core::SweepPlan plan;                         ///< Sampling, dimensions, seed.
  /// The plan's designs on demand (each worker evaluates from its own copy).
  std::optional<core::DesignSequence> designs;
  RowOutputs outputs;                           ///< What each row reports.
  core::SceneOptions options;                   ///< The models' settings.
  std::string exit_speed_model;  ///< The exit-speed model options.model resolves to (summary).
  std::string model_reason;      ///< Why that model ("requested", or "auto: ...").
  ApiLimits limits;                             ///< The request limits (the JSON path's parser).
  std::vector<ParetoObjective> objectives;      ///< Pareto objectives (may be empty).
  core::Shard shard;                            ///< Which designs this run evaluates.
  std::uint64_t total = 0;                      ///< Designs in the whole sweep.
  nlohmann::json provenance;                    ///< The summary's provenance.
  std::chrono::steady_clock::time_point start;  ///< When the request arrived (timing_s).
  std::optional<DesignBinder> binder;           ///< Set when every swept path binds without JSON.
  /// "report_units": "imperial": a full row's output blocks carry their trade-unit fields
  /// (AddImperialToRow), and the summary says "report_units": "imperial". Rows of "columns"
  /// hold the columns named, whatever this says.
  bool imperial = false;
  int threads = 1;                              ///< Threads to evaluate designs on (>= 1).
  /// Pareto objective values kept before they are first cut to their front (then at each
  /// 8-fold growth); tests lower it to exercise the cuts on small sweeps.
  std::size_t pareto_cut_min = 65536;
  ThreadBudget* budget = nullptr;  ///< Where threads beyond the first come from (or none).
};

/// A parsed /v1/explore request: the sweep, ready to run, and the answer's format.
struct ExploreRequest {
  std::shared_ptr<Sweep> sweep;        ///< The sweep (shared with a streamed answer).
  std::string format;                  ///< "json", "ndjson" or "csv".
  std::vector<ExploreColumn> columns;  ///< "columns" (csv: the default set when not given).
};

/// Parses and validates a /v1/explore body (api/handlers_explore.cpp); nullopt with the
/// error naming the field otherwise. Never throws.
std::optional<ExploreRequest> ParseExploreRequest(const nlohmann::json& body,
                                                  const Context& context, ApiError* error);

/// How a run writes its rows.
enum class RowFormat {
  kJson,    ///< JSON values, collected (BlockRows::rows).
  kNdjson,  ///< One JSON text line per row (BlockRows::text).
  kCsv,     ///< One RFC 4180 line per row (BlockRows::text), the values of `columns`.
};

/// The rows of consecutive designs, in index order.
struct BlockRows {
  std::vector<nlohmann::json> rows;  ///< kJson.
  std::string text;                  ///< kNdjson, kCsv.
  std::uint64_t count = 0;           ///< Rows in this block.
};

/// How a sweep ended.
struct SweepOutcome {
  bool cancelled = false;  ///< Progress::Cancel() (message says after how many designs).
  bool stopped = false;    ///< The row sink refused a block (a streaming client went away).
  /// An exception ended the sweep (out of memory: std::bad_alloc, or a thread that could not
  /// start), in any of its threads; message says which and after how many designs.
  bool failed = false;
  std::string message;     ///< Why it was cancelled or failed.
  nlohmann::json summary;  ///< Set when none of the three.
};

/// Evaluates the shard's designs on up to sweep.threads threads in blocks of consecutive
/// designs, handing each block to `emit` in index order (false from it stops the sweep),
/// and returns the summary. With `columns`, a row is the flat object (or CSV line) of
/// those columns. Never throws: an exception in any of its threads (std::bad_alloc) ends the
/// sweep with SweepOutcome::failed, after every thread it started has been joined.
SweepOutcome RunSweep(const Sweep& sweep, RowFormat format,
                      const std::vector<ExploreColumn>& columns, core::Progress* progress,
                      const std::function<bool(BlockRows&)>& emit);

}  // namespace sweetspot::api
