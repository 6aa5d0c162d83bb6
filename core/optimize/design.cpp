// OptimizeDesign and OptimizeOverMaterials: validation, seeded multi-start, the independent
// re-check of the answer through the public mass properties and closed-form sweet spot, the
// active constraints and their multipliers, and the explanation of infeasible requests.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "core/collision/rigid_pivot.hpp"
#include "core/flexible/modes.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/bbcor_constraint.hpp"
#include "core/optimize/certificate_runs.hpp"
#include "core/optimize/backend_choice.hpp"
#include "core/optimize/design_backends.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/optimize/design_public.hpp"
#include "core/optimize/design_runs.hpp"
#include "core/optimize/least_squares_polish.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
namespace {

using design_detail::BackendName;
using design_detail::ClassifyChosen;
using design_detail::ClassifyFeasibility;
using design_detail::MarkCancelledMultiStart;
using design_detail::ReportFixedViolations;
using design_detail::ReportNoDesign;
using design_detail::ChooseRun;
using design_detail::Clock;
using design_detail::Explain;
using design_detail::Finish;
using design_detail::MainBackend;
using design_detail::ReportActiveConstraints;
using design_detail::Run;
using design_detail::SettingsFrom;
using design_detail::Solve;
using design_detail::Violation;
using design_detail::AnswerAt;
using design_detail::PublicEvaluation;
using design_detail::RecheckConstraints;
using design_detail::RigidBodyPropertiesOrNull;

// A uniform double in [0, 1) from the generator's top 53 bits (the same on every platform,
// unlike std::uniform_real_distribution).
double Uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// A random start: every variable uniform in its bounds, then knot positions pushed apart so
// the profile's knots stay in order where the bounds allow (the model is finite everywhere;
// this only helps the solver start from a sensible bat).
std::vector<double> RandomStart(const DesignModel& model, std::mt19937_64& rng, double gap) {
  const auto& vars = model.variables();
  std::vector<double> x(vars.size());
  for (std::size_t j = 0; j < vars.size(); ++j) {
    x[j] = vars[j].lower + Uniform(rng) * (vars[j].upper - vars[j].lower);
  }
  // Profile positions in knot order; three-segment x1 <= x2 <= L.
  std::vector<std::pair<int, std::size_t>> positions;  // (knot, variable)
  int taper_start = -1, taper_end = -1, length = -1;
  for (std::size_t j = 0; j < vars.size(); ++j) {
    if (vars[j].scale) continue;  // a factor of several fields, none ordered here
    if (vars[j].ref.kind == DesignVariableKind::kKnotPosition)
      positions.push_back({vars[j].ref.knot, j});
    if (vars[j].ref.kind == DesignVariableKind::kTaperStart) taper_start = static_cast<int>(j);
    if (vars[j].ref.kind == DesignVariableKind::kTaperEnd) taper_end = static_cast<int>(j);
    if (vars[j].ref.kind == DesignVariableKind::kLength) length = static_cast<int>(j);
  }
  std::sort(positions.begin(), positions.end());
  for (std::size_t q = 1; q < positions.size(); ++q) {
    if (positions[q].first != positions[q - 1].first + 1) continue;
    const std::size_t a = positions[q - 1].second, b = positions[q].second;
    if (x[b] < x[a] + gap) x[b] = std::min(x[a] + gap, vars[b].upper);
  }
  if (taper_start >= 0 && taper_end >= 0 &&
      x[static_cast<std::size_t>(taper_start)] > x[static_cast<std::size_t>(taper_end)]) {
    std::swap(x[static_cast<std::size_t>(taper_start)], x[static_cast<std::size_t>(taper_end)]);
    for (int j : {taper_start, taper_end}) {
      const auto jj = static_cast<std::size_t>(j);
      x[jj] = std::clamp(x[jj], vars[jj].lower, vars[jj].upper);
    }
  }
  if (taper_end >= 0 && length >= 0) {
    const auto e = static_cast<std::size_t>(taper_end), l = static_cast<std::size_t>(length);
    if (x[l] < x[e]) x[l] = std::clamp(x[e], vars[l].lower, vars[l].upper);
  }
  return x;
}

void FillBase(const DesignProblem& problem, DesignResult* result) {
  result->bat = problem.bat;
  if (problem.three_segment.has_value()) {
    result->three_segment = problem.three_segment;
    if (problem.three_segment->Validate(nullptr))
      result->bat.knots = problem.three_segment->Knots();
  }
  result->properties = ComputeMassProperties(result->bat, problem.inertia_model);
  result->objective_value = kNaN;
  result->sweet_spot_from_knob_m = kNaN;
  result->max_exit_speed_mps = kNaN;
  result->angular_speed_rad_s = problem.swing.angular_speed_rad_s;
  if (problem.swing.bat_speed_mps.has_value()) {
    // The base design's omega when its bat speed resolves (NaN when the request cannot say).
    Swing resolved;
    const bool known = problem.swing.Validate(nullptr) && result->bat.Validate(nullptr) &&
                       ResolveSwing(problem.swing, result->bat.LengthM(), &resolved, nullptr);
    result->angular_speed_rad_s = known ? resolved.angular_speed_rad_s : kNaN;
  }
  for (const DesignVariable& v : problem.variables) {
    result->variables.push_back({v.path, kNaN, !v.scale_paths.empty()});
  }
  result->spread.objective_min = result->spread.objective_max = result->spread.objective_median =
      kNaN;
}

const char* ObjectiveUnit(DesignObjective objective) {
  switch (objective) {
    case DesignObjective::kMinMoi:
      return "kg_m2";
    case DesignObjective::kWidestSweetZone:
      return "m";
    case DesignObjective::kMinSting:
      return "j";
    case DesignObjective::kMaxDistance:
      return "m";
    case DesignObjective::kLeastSquares:
      return "";
    default:
      return "mps";
  }
}

// The starts of the multi-start (start 0 from the base design, the others random but the
// same design for any budget), until the budget, cancellation or the last start; counts and
// warnings go to result->summary.
std::vector<Run> RunStarts(const DesignModel& model, const DesignOptions& options,
                           DesignBackend backend, Clock::time_point deadline, Progress* progress,
                           double progress_from, double progress_to, DesignResult* result,
                           const design_detail::LocalSolver* solver) {
  std::vector<Run> runs;
  std::mt19937_64 rng(options.seed);
  const std::vector<double> x0 = model.BaseX();
  for (int i = 0; i < options.starts; ++i) {
    // Draw every start's point whether or not it runs, so start i is the same design for
    // any budget (reproducible).
    const std::vector<double> x =
        design_detail::GivenStartOr(model, options.start_points, i,
                                    i == 0 ? x0 : RandomStart(model, rng, options.min_knot_gap_m));
    if (i > 0 && (Clock::now() >= deadline || IsCancelled(progress))) {
      result->summary.warnings.push_back(
          std::string(IsCancelled(progress) ? "cancelled" : "time budget reached") + " after " +
          std::to_string(i) + " of " + std::to_string(options.starts) + " starts");
      break;
    }
    ScaledDesignNlp nlp(model);
    LocalSolveSettings settings = SettingsFrom(options, deadline, progress);
    if (i == 0) {
      settings.derivative_check = options.derivative_check;
      // The frequency's round-off (~1e-11 relative) needs a larger forward-difference step
      // than Ipopt's 1e-8: 1e-6 keeps round-off (1e-5) and truncation (1e-6) below the
      // checker's tolerance 1e-4 (design_backends.hpp).
      if (model.frequency_elements() > 0) settings.derivative_test_perturbation = 1e-6;
    }
    LocalSolveOutcome o = solver != nullptr ? (*solver)(nlp, nlp.ToScaled(x), settings)
                                            : Solve(backend, nlp, nlp.ToScaled(x), settings);
    result->summary.iterations += o.iterations;
    result->summary.evaluations += o.evaluations;
    if (i == 0) {
      result->derivative_check_errors = o.derivative_check_errors;
      result->derivative_check_report = o.derivative_check_report;
    }
    runs.push_back(Finish(model, std::move(o), options.feasibility_tolerance));
    if (progress != nullptr) {
      progress->Report(progress_from + (progress_to - progress_from) * (i + 1.0) / options.starts);
    }
    if (runs.back().outcome.cancelled || runs.back().outcome.deadline_reached) break;
  }
  return runs;
}

// The bbcor rule set on a hollow answer, by the public model: a design over its limit is
// infeasible.
void CheckBbcorRule(const DesignProblem& problem, const PublicEvaluation& pub,
                    double feasibility_tolerance, DesignResult* result) {
  const std::optional<double> bound = BbcorBoundOf(problem);  // bbcor_constraint.hpp
  if (!result->bat.IsHollow() || !bound.has_value()) return;
  std::string bbcor_why;
  // The constraint's own acceptance: the feasibility tolerance of the limit (the re-check
  // above).
  const double limit = *LimitsOf(RuleSet::kBbcor).max_bbcor;
  if (!BbcorRuleHolds(result->bat, &result->bbcor.emplace(), &bbcor_why,
                      feasibility_tolerance * limit, RigidBodyPropertiesOrNull(pub.properties),
                      *bound)) {
    result->summary.termination = Termination::kInfeasible;
    result->summary.message = bbcor_why;
    result->message_kind = DesignMessageKind::kInfeasible;
  }
}

// The summary's backend, models and counts before the solve.
void StartSummary(const DesignProblem& problem, DesignBackend backend,
                  const design_detail::LocalSolver* solver, const char* solver_name,
                  DesignResult* result) {
  Summary& summary = result->summary;
  summary.backend =
      solver != nullptr && solver_name != nullptr ? solver_name : BackendName(backend);
  summary.models_used = {"mass_properties"};
  if (problem.objective != DesignObjective::kMinMoi &&
      problem.objective != DesignObjective::kLeastSquares) {
    summary.models_used.push_back(CollisionModelName(problem.model));
  }
  const bool sting = problem.objective == DesignObjective::kMinSting;
  if (sting || problem.constraints.min_frequency_hz.has_value()) {
    summary.models_used.push_back(kFlexibleBeamModel);
  }
  if (sting) summary.models_used.push_back("flexible");
  // max_distance: the oblique impact and the flight of every design's distance sweet spot.
  if (problem.objective == DesignObjective::kMaxDistance) {
    summary.models_used.push_back("oblique_impact");
    summary.models_used.push_back("flight");
  }
  summary.iterations = 0;
  summary.evaluations = 0;
  result->objective_unit = ObjectiveUnit(problem.objective);
}

// The model of the request (or the caller's prepared one); false with the refusal in *why.
bool ModelOf(const DesignProblem& problem, const DesignOptions& options, bool values_only,
             design_detail::PreparedModel* prepared, DesignModel* model, Refusal* why) {
  if (!options.Validate(why)) {
    *why = Prefixed("options.", std::move(*why));
    return false;
  }
  if (values_only && options.derivative_check != DerivativeCheck::kNone) {
    *why = TextRefusal("options.derivative_check",
                       std::string("objective = ") + DesignObjectiveName(problem.objective) +
                           " has no derivatives to check (it is solved derivative-free by COBYLA)");
    return false;
  }
  if (!design_detail::SlsqpSizeAllowed(problem, options, why)) return false;
  if (prepared != nullptr) {
    *model = std::move(prepared->model);  // built and merged by the caller (moved from)
    return true;
  }
  return DesignModel::Build(problem, options, model, why);
}

// Why the objectives without a derivative run COBYLA whatever was asked.
void WarnDerivativeFree(const DesignProblem& problem, const DesignOptions& options,
                        Summary* summary) {
  if (problem.objective == DesignObjective::kMaxDistance &&
      options.backend != DesignBackend::kNloptCobyla) {
    summary->warnings.push_back(
        std::string("objective = max_distance: solved by NLopt LN_COBYLA, not ") +
        BackendName(options.backend) +
        ": the carry comes from an adaptive flight integration inside an iterative search over "
        "the impact point and undercut (piecewise smooth at the 1e-7 m level, no usable "
        "derivative: docs/optimization.md), so a derivative-free solver is used");
  }
  if (problem.objective == DesignObjective::kMinSting &&
      options.backend != DesignBackend::kNloptCobyla) {
    summary->warnings.push_back(
        std::string("objective = min_sting: solved by NLopt LN_COBYLA, not ") +
        BackendName(options.backend) +
        ": the sting comes from an adaptive FE mesh and an adaptive ODE integration (piecewise "
        "smooth, no derivative), so a derivative-free solver is used");
  }
}

// The starts, their certificates and the answer: the chosen start's design, re-checked,
// classified and certified.
void SolveAndAnswer(const DesignProblem& problem, const DesignOptions& options,
                    const DesignModel& model, DesignBackend backend, bool cor_known,
                    Clock::time_point deadline, Progress* progress, double progress_from,
                    double progress_to, const design_detail::LocalSolver* solver,
                    DesignResult* result) {
  Summary& summary = result->summary;
  std::vector<Run> runs = model.fixed_violations().empty()
                              ? RunStarts(model, options, backend, deadline, progress,
                                          progress_from, progress_to, result, solver)
                              : std::vector<Run>{};
  design_detail::CertifyRuns(model, options, &runs);
  FillSpread(runs, &result->spread);
  // Which formulation Ipopt solved: "lifted_integrals" when the lifted one (lifted_nlp.hpp),
  if (std::any_of(runs.begin(), runs.end(), [](const Run& r) { return r.outcome.lifted; })) {
    summary.models_used.push_back("lifted_integrals");
  }
  // ... and "taper_steps" when with the taper's steps as its variables (tapered_nlp.hpp).
  if (std::any_of(runs.begin(), runs.end(), [](const Run& r) { return r.outcome.taper_steps; })) {
    summary.models_used.push_back("taper_steps");
  }

  // The answer.
  const int best = ChooseRun(model, runs);
  result->spread.best_start = best;
  std::vector<double> x = best >= 0 ? runs[static_cast<std::size_t>(best)].x : model.BaseX();
  if (best >= 0) design_detail::PolishLeastSquares(model, &x, &summary);  // least squares only
  const PublicEvaluation pub = AnswerAt(problem, model, x, cor_known, result);
  // Independent re-check of every constraint (public mass properties).
  double worst = 0.0, worst_relative = 0.0;
  RecheckConstraints(model, pub, result->bat, x, &worst, &worst_relative);
  summary.constraint_violation = worst;
  if (!model.fixed_violations().empty() || best < 0) {
    if (!model.fixed_violations().empty()) {
      ReportFixedViolations(model, result);
    } else {
      ReportNoDesign(runs, result);
    }
    return;
  }
  const Run& chosen = runs[static_cast<std::size_t>(best)];
  ClassifyChosen(options, backend, chosen, pub, result->bat, result);
  ClassifyFeasibility(model, options, deadline, progress, chosen, worst, worst_relative, result);
  ReportActiveConstraints(model, x,
                          design_detail::WithCertifiedMultipliers(model, options, x,
                                                                  chosen.outcome, result, &chosen),
                          result, options.feasibility_tolerance);
  // The shape fit (a least-squares objective) reports no multipliers: no warning about them.
  design_detail::FinishCertificate(chosen, problem.objective != DesignObjective::kLeastSquares,
                                   result);
  MarkCancelledMultiStart(options, runs, progress, result);
  CheckBbcorRule(problem, pub, options.feasibility_tolerance, result);
}

// The optimisation, with the progress it reports mapped into [progress_from, progress_to]
// and an overall deadline (OptimizeOverMaterials shares one budget between materials).
DesignResult OptimizeOneRound(const DesignProblem& problem, const DesignOptions& options,
                              Progress* progress, double progress_from, double progress_to,
                              std::optional<Clock::time_point> shared_deadline,
                              const design_detail::LocalSolver* solver, const char* solver_name,
                              design_detail::PreparedModel* prepared) {
  const Clock::time_point start = Clock::now();
  const auto elapsed_s = [&start] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  DesignResult result;
  Summary& summary = result.summary;
  const DesignBackend backend = MainBackend(problem, options);
  StartSummary(problem, backend, solver, solver_name, &result);
  // The objectives without a derivative (COBYLA whatever was asked).
  const bool values_only = problem.objective == DesignObjective::kMinSting ||
                           problem.objective == DesignObjective::kMaxDistance;
  Refusal why;
  DesignModel model;
  if (!ModelOf(problem, options, values_only, prepared, &model, &why)) {
    FillBase(problem, &result);
    summary.SetRefusal(std::move(why));
    summary.objective = kNaN;
    summary.constraint_violation = kNaN;
    summary.error_estimate = kNaN;
    summary.solve_time_s = elapsed_s();
    return result;
  }
  // Constraints that repeat another are merged before the solve (certificate.hpp).
  result.merged_constraints = prepared != nullptr
                                  ? std::move(prepared->merged)
                                  : design_detail::MergeDuplicateConstraints(&model);
  const bool cor_known =
      problem.cor.has_value() || problem.bat.material.cor.has_value() || model.cor_from_barrel();
  result.cor = cor_known ? model.cor() : kNaN;
  WarnDerivativeFree(problem, options, &summary);
  try {
    const Clock::time_point deadline =
        shared_deadline.value_or(start + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(options.max_time_s)));
    SolveAndAnswer(problem, options, model, backend, cor_known, deadline, progress,
                   progress_from, progress_to, solver, &result);
  } catch (const std::bad_alloc&) {
    summary.termination = Termination::kFailure;
    summary.message = "out of memory";
    result.message_kind = DesignMessageKind::kFailure;
  } catch (const std::exception& e) {
    summary.termination = Termination::kFailure;
    summary.message = std::string("failure: ") + e.what();
    result.message_kind = DesignMessageKind::kFailure;
  }
  summary.solve_time_s = elapsed_s();
  return result;
}

}  // namespace

namespace design_detail {

// The optimisation, in certification rounds when the problem bounds the BBCOR
// (bbcor_constraint.hpp): the rounds share one deadline.
DesignResult Optimize(const DesignProblem& problem, const DesignOptions& options,
                      Progress* progress, double progress_from, double progress_to,
                      std::optional<Clock::time_point> shared_deadline, const LocalSolver* solver,
                      const char* solver_name, PreparedModel* prepared) {
  if (!BbcorBoundOf(problem).has_value()) {
    return OptimizeOneRound(problem, options, progress, progress_from, progress_to, shared_deadline,
                            solver, solver_name, prepared);
  }
  const Clock::time_point start = Clock::now();
  const Clock::time_point deadline = shared_deadline.value_or(
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                  std::isfinite(options.max_time_s) && options.max_time_s > 0.0 ? options.max_time_s
                                                                                : 0.0)));
  DesignResult r = OptimizeWithCertifiedBbcor(problem, [&](const DesignProblem& p) {
    return OptimizeOneRound(p, options, progress, progress_from, progress_to, deadline, solver,
                            solver_name, nullptr);
  });
  r.summary.solve_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

}  // namespace design_detail

using design_detail::Optimize;

DesignResult OptimizeDesign(const DesignProblem& problem, const DesignOptions& options,
                            Progress* progress) {
  if (!options.choose_backend) return Optimize(problem, options, progress, 0.0, 1.0, std::nullopt);
  // The optimiser chooses (backend_choice.hpp): SLSQP's answer only when certified, otherwise
  // Ipopt's from the start again.
  DesignOptions chosen = options;
  chosen.choose_backend = false;
  chosen.backend = design_detail::ChooseBackend(problem, options);
  DesignResult first = Optimize(problem, chosen, progress, 0.0, 1.0, std::nullopt);
  if (chosen.backend != DesignBackend::kNloptSlsqp || design_detail::ChosenAnswerCertified(first)) {
    return first;
  }
  chosen.backend = DesignBackend::kIpopt;
  DesignResult again = Optimize(problem, chosen, progress, 0.0, 1.0, std::nullopt);
  again.summary.warnings.push_back(
      "the chosen backend NLopt SLSQP's answer was not certified (" + first.summary.message +
      ", KKT residual " + FormatNumber(first.summary.error_estimate) +
      "): solved again by Ipopt");
  again.summary.iterations += std::max(first.summary.iterations, 0);
  again.summary.evaluations += std::max(first.summary.evaluations, 0);
  again.summary.solve_time_s += std::max(first.summary.solve_time_s, 0.0);
  return again;
}

}  // namespace sweetspot::core
