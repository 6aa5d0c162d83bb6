// The certificate applied to OptimizeDesign's runs and answer. See certificate_runs.hpp.
#include "core/optimize/certificate_runs.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "core/numerics/limits.hpp"

namespace sweetspot::core::design_detail {

CertificateTolerances TolerancesFrom(const DesignOptions& options) {
  CertificateTolerances t;
  t.stationarity = options.stationarity_tolerance;
  t.feasibility = options.feasibility_tolerance;
  t.complementarity = options.complementarity_tolerance;
  return t;
}

void CertifyRuns(const DesignModel& model, const DesignOptions& options, std::vector<Run>* runs) {
  if (model.derivative_free()) return;  // no gradient: nothing to certify
  const CertificateTolerances tolerances = TolerancesFrom(options);
  // One run: it is the answer's, whose certificate checks uniqueness too (kept in the run).
  const bool only = runs->size() == 1;
  for (Run& run : *runs) {
    if (run.outcome.termination != Termination::kConverged || run.x.empty()) continue;
    const DesignCertificate cert = Certify(model, run.x, tolerances, only);
    if (only) run.certificate = cert;
    run.outcome.certificate = cert;  // the answer's certificate reuses its fit at this point
    run.outcome.certificate_x = run.x;
    if (!cert.checked || cert.certified) continue;
    run.uncertified = true;
    run.outcome.termination = Termination::kNoConvergence;
    run.outcome.message =
        (run.outcome.message.empty() ? "" : run.outcome.message + "; ") +
        "reported convergence, but the first-order conditions do not hold: " + cert.failed;
  }
}

LocalSolveOutcome WithCertifiedMultipliers(const DesignModel& model, const DesignOptions& options,
                                           const std::vector<double>& x, const LocalSolveOutcome& o,
                                           DesignResult* result, const Run* chosen) {
  // The chosen run's whole certificate when it was the only run (uniqueness checked) and the
  // answer is its point; otherwise the run's fit at this point, when it is the answer's (not
  // moved by a polish), with the uniqueness check made here.
  const bool cached = chosen != nullptr && chosen->certificate.has_value() && chosen->x == x;
  const bool same = o.certificate.checked && o.certificate_x == x;
  result->certificate =
      cached ? *chosen->certificate
             : Certify(model, x, TolerancesFrom(options), true, same ? &o.certificate : nullptr);
  LocalSolveOutcome out = o;
  const DesignCertificate& c = result->certificate;
  if (!c.checked) return out;
  out.lambda = c.lambda;
  out.z_lower = c.z_lower;
  out.z_upper = c.z_upper;
  out.has_multipliers = true;
  return out;
}

void FinishCertificate(const Run& chosen, bool reports_multipliers, DesignResult* result) {
  for (const MergedConstraint& m : result->merged_constraints) {
    result->summary.warnings.push_back(m.message);
  }
  const DesignCertificate& c = result->certificate;
  if (!c.checked) return;
  result->summary.error_estimate = c.stationarity;
  if (!c.multipliers_unique && !result->active_constraints.empty()) {
    for (DesignActiveConstraint& a : result->active_constraints) a.multiplier = kNaN;
    if (reports_multipliers) {
      result->summary.warnings.push_back(
          "the active constraints' gradients are linearly dependent, so their multipliers are "
          "not unique and are not reported (null)");
    }
  }
  if (chosen.uncertified && result->message_kind == DesignMessageKind::kSolver &&
      result->summary.termination == Termination::kNoConvergence) {
    result->summary.message = "not certified: " + chosen.outcome.status_name +
                              " reported convergence, but the first-order conditions do not "
                              "hold at its design (" +
                              c.failed + "); the design is kept";
    result->message_kind = DesignMessageKind::kNotCertified;
  }
}

}  // namespace sweetspot::core::design_detail
