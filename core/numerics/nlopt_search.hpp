// A one-dimensional maximiser over the impact position, backed by NLopt. Used as the
// independent path for models with a closed form (rigid_pivot, free_bat) and as the only
// path for models without one (hertz). No NLopt header here or in nlopt_search.cpp.
//
// Every stage runs through the one NLopt trampoline (RunNlopt, nlopt_run.hpp: its own
// nlopt::opt, maxeval and maxtime, seeding of stochastic algorithms, the exception ladder) and
// maps NLopt's result with the one termination table (termination.hpp); a call returns a
// Summary whatever happens.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/summary.hpp"

namespace sweetspot::core {

/// NLopt algorithms offered for a 1-D search. LN_NEWUOA / LN_NEWUOA_BOUND are not offered:
/// NLopt refuses them for one-dimensional problems.
enum class NloptAlgorithm {
  kLdSlsqp,       ///< LD_SLSQP: sequential quadratic programming (gradient). The default.
  kLdLbfgs,       ///< LD_LBFGS: limited-memory BFGS (gradient).
  kLdTnewton,     ///< LD_TNEWTON_PRECOND_RESTART: truncated Newton (gradient).
  kLdMma,         ///< LD_MMA: method of moving asymptotes (gradient).
  kLdCcsaq,       ///< LD_CCSAQ: CCSA with quadratic approximations (gradient).
  kLnBobyqa,      ///< LN_BOBYQA: quadratic models (no derivatives).
  kLnCobyla,      ///< LN_COBYLA: linear approximations (no derivatives).
  kLnSbplx,       ///< LN_SBPLX: subplex (no derivatives).
  kLnNelderMead,  ///< LN_NELDERMEAD: simplex (no derivatives).
  kGnDirectL,     ///< GN_DIRECT_L: global, deterministic; then a local polish.
  kGnAgs,     ///< GN_AGS: global, deterministic (needs the C++ NLopt build); then a local polish.
  kGnCrs2Lm,  ///< GN_CRS2_LM: global, stochastic (seeded); then a local polish.
};

/// NLopt's name of `a`, e.g. "LD_SLSQP".
const char* NloptAlgorithmName(NloptAlgorithm a);
/// The algorithm called `name` (NLopt spelling, e.g. "LN_BOBYQA"), or nullopt with the reason
/// in *why (e.g. "nlopt.algorithm = LN_NEWUOA: not offered for 1-D searches (NLopt refuses
/// NEWUOA in one dimension)").
std::optional<NloptAlgorithm> ParseNloptAlgorithm(std::string_view name, std::string* why);
/// Every algorithm offered, in enum order.
const std::vector<NloptAlgorithm>& OfferedNloptAlgorithms();
/// True for LD_* algorithms (they need the objective's derivative).
bool NloptAlgorithmNeedsGradient(NloptAlgorithm a);
/// True for GN_* algorithms (run over the whole interval, then polished locally).
bool NloptAlgorithmIsGlobal(NloptAlgorithm a);
/// True when the algorithm draws random numbers (seeded with ScalarSearchOptions::seed).
bool NloptAlgorithmIsStochastic(NloptAlgorithm a);

/// Options of a 1-D maximisation.
struct ScalarSearchOptions {
  /// The algorithm; unset = LD_SLSQP when the objective has a derivative, LN_BOBYQA otherwise.
  std::optional<NloptAlgorithm> algorithm;
  double x_tolerance_m = 1e-12;      ///< Absolute tolerance on the position, m (> 0).
  int max_evaluations = 2000;        ///< Evaluation budget of one search (>= 10).
  double max_time_s = 1.0;           ///< Wall-time budget of one search, s (> 0).
  int start_samples = 9;             ///< Evenly spaced samples that pick the local start (>= 2).
  int global_max_evaluations = 400;  ///< Budget of the global stage of GN_* algorithms (>= 10).
  bool polish = true;                ///< GN_* only: polish the global result with a local method.
  unsigned seed = 1;  ///< Seed for stochastic algorithms (nlopt::srand before optimize()).

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// f(x) and, when `gradient` is not null, df/dx into *gradient. Should not throw (if it does,
/// the search stops and reports a failure).
using ScalarObjective = std::function<double(double x, double* gradient)>;

/// The result of a 1-D maximisation.
struct ScalarSearchResult {
  double x = 0.0;                 ///< The maximiser found (problem units, e.g. m from the knob).
  double value = 0.0;             ///< f(x).
  bool at_lower_bound = false;    ///< x is the lower bound.
  bool at_upper_bound = false;    ///< x is the upper bound.
  double error_estimate_x = 0.0;  ///< Estimated |x - x_true| (x units).
  double error_estimate_value = 0.0;  ///< Estimated |f(x) - f(x_true)| (f units).
  Summary summary;  ///< Backend "nlopt:<ALGORITHM>", raw NLopt status, counts, time.
};

/// Maximises f over [lower, upper]. `has_gradient` says whether f fills the derivative.
/// Never throws: invalid input, an LD_* algorithm without a gradient, NLopt errors and
/// exceptions from f are all reported in the summary.
ScalarSearchResult MaximizeScalar(const ScalarObjective& f, bool has_gradient, double lower,
                                  double upper, const ScalarSearchOptions& options);

}  // namespace sweetspot::core
