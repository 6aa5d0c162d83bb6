// Internal to core/optimize: the pieces of OptimizeDesign shared by design.cpp (the
// multi-start and the answer), design_runs.cpp (local solves, the choice among them, the
// multipliers and active constraints) and design_explain.cpp (why a request is infeasible).
#pragma once

#include <chrono>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "core/optimize/certificate.hpp"
#include "core/optimize/design_backends.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/progress.hpp"

namespace sweetspot::core::design_detail {

using Clock = std::chrono::steady_clock;
/// A point is feasible when every constraint is met to this, relative to its scale.
inline constexpr double kFeasibleRelative = 1e-6;

/// One finished local solve.
struct Run {
  LocalSolveOutcome outcome;  ///< What the solver returned.
  std::vector<double> x;      ///< The point, user units, clamped into the bounds.
  double objective = std::numeric_limits<double>::quiet_NaN();  ///< Model objective at x.
  double violation = std::numeric_limits<double>::infinity();   ///< Largest scaled violation.
  bool feasible = false;  ///< violation <= the feasibility tolerance (Finish's).
  /// The solver reported convergence but the certificate failed (its termination is then
  /// no_convergence, its message what failed).
  bool uncertified = false;
  /// The certificate at x (CertifyRuns; with the uniqueness check when it is the only run),
  /// reused by the answer when x is its point.
  std::optional<DesignCertificate> certificate;
};

/// Evaluates the end of a local solve (clamped into the bounds, objective, violation).
/// `feasibility_tolerance`: DesignOptions::feasibility_tolerance (Run::feasible).
Run Finish(const DesignModel& model, LocalSolveOutcome outcome,
           double feasibility_tolerance = kFeasibleRelative);
/// Index of the run to answer with: feasible and converged by objective, then feasible by
/// objective, then the least violation (-1 when no run has a finite violation).
int ChooseRun(const DesignModel& model, const std::vector<Run>& runs);
/// One local solve from s0 with `backend`.
LocalSolveOutcome Solve(DesignBackend backend, ScaledDesignNlp& nlp, const std::vector<double>& s0,
                        const LocalSolveSettings& settings);
/// The backend of the design's local solves: min_sting has no derivative, so COBYLA whatever
/// was asked.
DesignBackend MainBackend(const DesignProblem& problem, const DesignOptions& options);
/// The backend of the infeasibility analysis (smooth sub-problems): the requested gradient
/// solver, Ipopt when COBYLA was asked.
DesignBackend SmoothBackend(const DesignOptions& options);
/// The summary's name of a backend ("ipopt", "nlopt:LD_SLSQP", "nlopt:LN_COBYLA").
const char* BackendName(DesignBackend backend);
/// The local solves' settings from the options.
LocalSolveSettings SettingsFrom(const DesignOptions& options, Clock::time_point deadline,
                                Progress* progress);
/// How far v lies outside constraint c's bounds (0 inside, +inf when not finite), its unit.
double Violation(const DesignConstraintSpec& c, double v);
/// Fills result->active_constraints (with the multipliers, sensitivities of the objective) at
/// x, the answer of solve `o`, and result->summary.error_estimate with the KKT residual (NaN
/// for min_sting, which has no derivative: a warning says so). Each verdict (satisfied) with
/// `feasibility_tolerance` (DesignOptions') of the constraint's scale.
void ReportActiveConstraints(const DesignModel& model, const std::vector<double>& x,
                             const LocalSolveOutcome& o, DesignResult* result,
                             double feasibility_tolerance = kFeasibleRelative);
/// Why no design meets the constraints: single constraints that cannot be met within the
/// variable bounds and the geometric constraints, then pairs of property constraints.
std::vector<DesignConflict> Explain(const DesignModel& model, const DesignOptions& options,
                                    Clock::time_point deadline, Progress* progress,
                                    const Run& least_violating, bool solver_says_infeasible,
                                    int* evaluations, int* iterations);

/// The spread of the starts' answers (their objectives, terminations and violations).
void FillSpread(const std::vector<Run>& runs, DesignSpread* spread_out);

/// A local solve in place of the backend's (the frontier's continuation step, frontier.cpp):
/// from s0 with the settings of the start.
using LocalSolver = std::function<LocalSolveOutcome(
    ScaledDesignNlp& nlp, const std::vector<double>& s0, const LocalSolveSettings& settings)>;

/// A model built (DesignModel::Build) and merged (MergeDuplicateConstraints) once for several
/// solves: the frontier's values (frontier.cpp), whose models differ only in the swept
/// constraint's limits (DesignModel::WithConstraintLimits).
struct PreparedModel {
  DesignModel model;                     ///< The model of the problem, merged.
  std::vector<MergedConstraint> merged;  ///< What the merge removed.
};

/// OptimizeDesign's solve of `problem` with `options` (its backend as given), in certification
/// rounds when the problem bounds the BBCOR; progress reported over [progress_from,
/// progress_to]; `shared_deadline` (when set) bounds it instead of options.max_time_s. With
/// `solver` (non-null), every start's local solve is solver's, the summary's backend
/// `solver_name`; the rest (model, certificate, re-check, answer) is unchanged. With
/// `prepared` (non-null; not with a BBCOR bound, whose rounds change the problem), its model
/// is the one of `problem` (the caller's promise), moved from instead of built again.
DesignResult Optimize(const DesignProblem& problem, const DesignOptions& options,
                      Progress* progress, double progress_from, double progress_to,
                      std::optional<Clock::time_point> shared_deadline,
                      const LocalSolver* solver = nullptr, const char* solver_name = nullptr,
                      PreparedModel* prepared = nullptr);

struct PublicEvaluation;

// The verdict of a solve (design_verdict.cpp).
/// The answer when a constraint no variable changes is violated: infeasible, with each one.
void ReportFixedViolations(const DesignModel& model, DesignResult* result);
/// The answer when no local solve returned a design.
void ReportNoDesign(const std::vector<Run>& runs, DesignResult* result);
/// The termination and message from the chosen start (with `backend`), the validity of the
/// answer's `bat`, its sting and its distance sweet spot (from the public re-check `pub`).
void ClassifyChosen(const DesignOptions& options, DesignBackend backend, const Run& chosen,
                    const PublicEvaluation& pub, const Bat& bat, DesignResult* result);
/// A design that violates a constraint after the re-check (`worst`, its unit; `worst_relative`
/// of its scale): not converged, and infeasible when the solver or the explanation (run until
/// `deadline`) says so, with the conflicts.
void ClassifyFeasibility(const DesignModel& model, const DesignOptions& options,
                         Clock::time_point deadline, Progress* progress, const Run& chosen,
                         double worst, double worst_relative, DesignResult* result);
/// A multi-start cut short by Progress::Cancel(): no_convergence even when its chosen start
/// converged (infeasible, failure and invalid_input stand, their message saying so).
void MarkCancelledMultiStart(const DesignOptions& options, const std::vector<Run>& runs,
                             const Progress* progress, DesignResult* result);

}  // namespace sweetspot::core::design_detail
