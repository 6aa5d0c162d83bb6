// The frontier: the best design at every value of one quantity (issue 36, item 3). One
// optimisation per value of a constraint (mass, length, balance point, swing weight, ...) or of
// the swing-weight objective's exponent, each started from its neighbour's solution, so the
// chart a bat designer puts on the wall (the best exit speed at every weight) costs a fraction
// of that many independent solves.
#pragma once

#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "core/optimize/design_problem.hpp"
#include "core/progress.hpp"
#include "core/refusal.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// The quantity a frontier steps through; each is a field of DesignConstraints (the constraint
/// set at each value) or of DesignProblem (an objective weight).
enum class FrontierQuantity {
  kLengthM,             ///< "length_m": constraints.length_m, m.
  kMassKg,              ///< "mass_kg": constraints.mass_kg, kg.
  kBalancePointM,       ///< "balance_point_m": constraints.balance_point_m, m from the knob.
  kMoiSixInchKgM2,      ///< "moi_six_inch_kg_m2": constraints.moi_six_inch_kg_m2 (swing weight).
  kMinFrequencyHz,      ///< "min_frequency_hz": constraints.min_frequency_hz, Hz (a lower bound).
  kMaxBarrelDiameterM,  ///< "max_barrel_diameter_m": constraints.max_barrel_diameter_m (upper).
  /// "swing_weight_exponent": problem.swing_weight_exponent, n in omega0 (I6/I6_ref)^-n
  /// (objective max_exit_speed_swing_weight only).
  kSpeedModelExponent,  // (named apart from core::kSwingWeightExponent, its default)
};

/// Stable name (quoted above).
const char* FrontierQuantityName(FrontierQuantity quantity);
/// The quantity called `name` (a name above), or nullopt.
std::optional<FrontierQuantity> ParseFrontierQuantity(std::string_view name);

/// How a range constraint takes each value.
enum class FrontierBound {
  kEqual,    ///< "equal": the quantity equals the value (the default for a range constraint).
  kAtMost,   ///< "max": the quantity is at most the value.
  kAtLeast,  ///< "min": the quantity is at least the value.
};

/// Stable name: "equal", "max", "min".
const char* FrontierBoundName(FrontierBound bound);

/// What to step through. min_frequency_hz is always a lower bound and max_barrel_diameter_m an
/// upper one (their only forms); swing_weight_exponent is a weight (the bound is ignored).
struct FrontierSpec {
  FrontierQuantity quantity = FrontierQuantity::kMassKg;  ///< The quantity stepped through.
  FrontierBound bound = FrontierBound::kEqual;            ///< Range constraints: how it holds.
  /// The values, in the quantity's SI unit, solved in this order (each from its neighbour's
  /// answer): 1 to max_values finite values, distinct.
  std::vector<double> values;
  /// Start each solve from the previous value's answer (its bat, moved along the line through
  /// the two previous answers when there are two: a secant predictor). false = every value
  /// from the base design (independent solves, the frontier's reference).
  bool warm_start = true;
  /// The continuation step's backend: each warm-started value is first solved by this from
  /// the predicted start (one local solve) and kept when it converges; otherwise the value is
  /// solved with the options' backend as an independent request would be (from the predicted
  /// start, then from the base design if that fails). Default NLopt SLSQP: near the answer it
  /// needs a few iterations and no fixed cost (Ipopt's set-up is most of a small solve;
  /// docs/optimization.md, "The frontier"). Equal to options.backend: no separate step.
  DesignBackend continuation_backend = DesignBackend::kNloptSlsqp;
  /// The most values a frontier accepts (the server's configured limit), >= 1.
  int max_values = 1000;

  /// True when the spec is usable with `problem`; else fills `refusal` (field "frontier.*").
  bool Validate(const DesignProblem& problem, Refusal* refusal) const;
};

/// One value's answer.
struct FrontierPoint {
  int index = 0;                 ///< Position in FrontierSpec::values.
  double value = 0.0;            ///< The value, SI.
  bool warm_started = false;     ///< Started from a neighbour's answer (else the base design).
  bool predicted = false;        ///< ... moved by the secant predictor.
  bool restarted = false;        ///< The warm start failed and the base design was solved too.
  bool continued = false;        ///< Answered by the continuation step (else options.backend).
  DesignResult result;           ///< The optimisation (summary, bat, objective, ...).
};

/// Receives each point as it is solved (in order); false stops the frontier (a client gone).
using FrontierSink = std::function<bool(const FrontierPoint&)>;

/// The frontier's tally.
struct FrontierSummary {
  /// converged when every value converged; no_convergence when some did not (or a cancel / the
  /// sink stopped it: `message` says which); invalid_input when the spec or problem was refused.
  Summary summary;
  int points = 0;           ///< Values solved.
  int converged = 0;        ///< ... whose termination is converged.
  int restarts = 0;         ///< Warm starts that failed and were solved from the base design.
  int continued = 0;        ///< Values answered by the continuation step.
  bool stopped = false;     ///< The sink asked to stop.
  bool cancelled = false;   ///< progress was cancelled.
  /// The Pareto front over (value, objective): indices of the converged points that no other
  /// converged point beats on both (a smaller value counts as better for `prefer_smaller`, the
  /// objective in its own sense: larger exit speed, smaller MOI, ...).
  std::vector<int> pareto;
};

/// Solves `problem` once per value of `spec` (each an OptimizeDesign with `options`, the
/// constraint or weight set to the value), calling `sink` with each point in order. A warm
/// start that ends anything but converged is solved again from the base design and the better
/// answer kept (`restarted`), so warm starting never costs an optimum the independent solve
/// finds. `progress` gets the fraction of values done and is polled between and inside solves.
/// options.max_time_s bounds each solve. Never throws.
FrontierSummary OptimizeFrontier(const DesignProblem& problem, const FrontierSpec& spec,
                                 const DesignOptions& options, bool prefer_smaller,
                                 const FrontierSink& sink, Progress* progress = nullptr);

/// The problem of one value: `problem` with the quantity set to `value` as `spec` says.
DesignProblem FrontierProblemAt(const DesignProblem& problem, const FrontierSpec& spec,
                                double value);

}  // namespace sweetspot::core
