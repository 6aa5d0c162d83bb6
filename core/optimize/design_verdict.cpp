// The verdict of a design solve (internal to core/optimize; declared in design_runs.hpp): the
// termination and message of the answer from its chosen start, the re-check's feasibility, a
// fixed constraint violated, no design at all, a multi-start cut short.
#include <string>
#include <utility>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_public.hpp"
#include "core/optimize/design_runs.hpp"

namespace sweetspot::core::design_detail {

// The answer when a constraint no variable changes is violated: infeasible, with each one.
void ReportFixedViolations(const DesignModel& model, DesignResult* result) {
  result->summary.termination = Termination::kInfeasible;
  std::string text;
  for (const FixedViolation& v : model.fixed_violations()) {
    DesignConflict d;
    d.constraints.push_back(v.constraint);
    d.requested_min = d.requested_max = d.achievable_min = d.achievable_max = kNaN;
    d.shortfall = kNaN;
    d.message = v.message;
    d.kind = ConflictKind::kFixed;
    result->conflicts.push_back(d);
    text += (text.empty() ? "" : "; ") + v.message;
  }
  result->summary.message = "infeasible: " + text;
  result->message_kind = DesignMessageKind::kInfeasible;
  result->summary.raw_status = 0;
  result->summary.error_estimate = kNaN;
}

// The answer when no local solve returned a design.
void ReportNoDesign(const std::vector<Run>& runs, DesignResult* result) {
  result->summary.termination = Termination::kFailure;
  result->summary.message = "no local solve returned a design";
  result->message_kind = DesignMessageKind::kNoDesign;
  if (!runs.empty()) {
    const LocalSolveOutcome& o = runs.front().outcome;
    result->summary.raw_status = o.raw_status;
    result->summary.message +=
        " (" + o.status_name + (o.message.empty() ? "" : ": " + o.message) + ")";
  }
  result->summary.error_estimate = kNaN;
}

// The termination and message from the chosen start, the validity of the bat and its sting.
void ClassifyChosen(const DesignOptions& options, DesignBackend backend, const Run& chosen,
                    const PublicEvaluation& pub, const Bat& bat, DesignResult* result) {
  Refusal bat_why;
  const bool bat_valid = bat.Validate(&bat_why);
  const LocalSolveOutcome& o = chosen.outcome;
  result->summary.raw_status = o.raw_status;
  result->summary.termination = o.termination;
  result->summary.message = o.status_name;
  result->message_kind = DesignMessageKind::kSolver;
  if (!o.message.empty()) result->summary.message += ": " + o.message;
  if (o.cancelled) {
    result->summary.message =
        "cancelled (" + result->summary.message + "); the best design so far is kept";
    result->message_kind = DesignMessageKind::kCancelled;
  }
  if (o.deadline_reached) {
    result->message_kind = DesignMessageKind::kTimeBudget;
    result->summary.message = "time budget max_time_s = " + FormatNumber(options.max_time_s) +
                              " s reached (" + result->summary.message +
                              "); the best design so far is kept";
  }
  if (o.raw_status == 1 && backend == DesignBackend::kIpopt) {
    result->summary.warnings.push_back("Ipopt converged to its acceptable (looser) tolerance");
  }
  if (!bat_valid) {
    result->summary.termination = Termination::kFailure;
    result->summary.message = "the optimised bat is invalid: " + bat_why.Message();
    result->message_kind = DesignMessageKind::kInvalidBat;
  }
  if (pub.sting.has_value()) {
    const StingEvaluation& st = *pub.sting;
    for (const std::string& w : st.impact.summary.warnings)
      result->summary.warnings.push_back("sting: " + w);
    if (st.ok) {
      DesignSting d;
      d.impact_from_knob_m = st.sweet_spot_from_knob_m;
      d.hands_vibration_energy_j = st.sting_j;
      d.error_estimate_j = st.impact.error_estimate_hands_energy_j;
      d.impact = st.impact;
      result->sting = std::move(d);
    } else if (result->summary.termination != Termination::kFailure) {
      result->summary.termination = Termination::kFailure;
      result->summary.message = "the sting of the optimised bat cannot be computed: " + st.message;
      result->message_kind = DesignMessageKind::kStingFailed;
    }
  }
  if (pub.distance.has_value()) {  // max_distance
    const DistanceEvaluation& d = *pub.distance;
    if (d.ok) {
      result->distance_sweet_spot = d.result;
      if (d.result.at_position_bound || d.result.at_undercut_bound) {
        result->summary.warnings.push_back(
            std::string("distance_sweet_spot: the farthest carry of the answer is at the edge of "
                        "the region searched (") +
            (d.result.at_position_bound ? "position" : "undercut") +
            "): widen options.distance's ranges to see whether it carries farther beyond");
      }
    } else if (result->summary.termination != Termination::kFailure) {
      result->summary.termination = Termination::kFailure;
      result->summary.message =
          "the distance sweet spot of the optimised bat cannot be computed: " + d.message;
      result->message_kind = DesignMessageKind::kDistanceFailed;
    }
  }
}

// A design that violates a constraint after the re-check: not converged, and infeasible when
// the solver or the explanation says so (with the conflicts).
void ClassifyFeasibility(const DesignModel& model, const DesignOptions& options,
                         Clock::time_point deadline, Progress* progress, const Run& chosen,
                         double worst, double worst_relative, DesignResult* result) {
  const LocalSolveOutcome& o = chosen.outcome;
  const bool feasible = worst_relative <= options.feasibility_tolerance;
  if (result->summary.termination == Termination::kConverged && !feasible) {
    result->summary.termination = Termination::kNoConvergence;
    result->summary.warnings.push_back(
        "the solver reported convergence but the re-checked design "
        "violates a constraint by " +
        FormatNumber(worst));
  }
  if (!feasible && result->summary.termination != Termination::kFailure &&
      result->summary.termination != Termination::kInvalidInput) {
    // No start reached a feasible design: say why.
    const bool solver_says_infeasible = result->summary.termination == Termination::kInfeasible;
    if (options.explain_infeasibility && !o.cancelled) {
      int evals = 0, iters = 0;
      result->conflicts = Explain(model, options, deadline, progress, chosen,
                                  solver_says_infeasible, &evals, &iters);
      result->summary.evaluations += evals;
      result->summary.iterations += iters;
      const bool isolated =
          !result->conflicts.empty() && std::isfinite(result->conflicts.front().achievable_min);
      const bool geometric =
          !result->conflicts.empty() && result->conflicts.front().kind == ConflictKind::kGeometric;
      if (isolated || geometric || solver_says_infeasible) {
        result->summary.termination = Termination::kInfeasible;
      }
    } else if (solver_says_infeasible) {
      result->summary.termination = Termination::kInfeasible;
    }
    if (result->summary.termination == Termination::kInfeasible) {
      std::string text;
      for (const DesignConflict& d : result->conflicts)
        text += (text.empty() ? "" : "; ") + d.message;
      result->summary.message = "infeasible: " + (text.empty() ? o.status_name : text) +
                                "; the least-violating design found is returned";
      result->message_kind = DesignMessageKind::kInfeasible;
    }
  } else if (result->summary.termination == Termination::kConverged) {
    result->summary.message = "converged (" + o.status_name + ")";
    result->message_kind = DesignMessageKind::kConverged;
  }
}

// A multi-start cut short by Progress::Cancel() (a start stopped mid-solve, or starts not begun)
// is no_convergence even when its chosen start converged: the starts not run might have found a
// better design. Infeasible and failure stand (a start that failed, e.g. in Ipopt's restoration
// phase, may be all that ran), their message saying the run was cut; invalid_input stands as it
// is. A chosen start that was itself cut is no_convergence already, its message "cancelled (...)".
void MarkCancelledMultiStart(const DesignOptions& options, const std::vector<Run>& runs,
                             const Progress* progress, DesignResult* result) {
  const bool cut =
      !runs.empty() && (runs.back().outcome.cancelled ||
                        (IsCancelled(progress) && static_cast<int>(runs.size()) < options.starts));
  Summary& summary = result->summary;
  if (!cut || summary.termination == Termination::kInvalidInput) return;
  if (summary.termination != Termination::kConverged) {
    if (result->message_kind == DesignMessageKind::kCancelled)
      return;  // the chosen start's own cut
    summary.message = "cancelled after " + std::to_string(runs.size()) + " of " +
                      std::to_string(options.starts) + " starts (the chosen start " +
                      std::to_string(result->spread.best_start) + ": " + summary.message +
                      "); the best design so far is kept";
    result->message_kind = DesignMessageKind::kCancelledStarts;
    return;
  }
  summary.termination = Termination::kNoConvergence;
  summary.message = "cancelled after " + std::to_string(runs.size()) + " of " +
                    std::to_string(options.starts) + " starts (the chosen start " +
                    std::to_string(result->spread.best_start) + ": " + summary.message +
                    "); the best design so far is kept";
  result->message_kind = DesignMessageKind::kCancelledStarts;
}

}  // namespace sweetspot::core::design_detail
