// Internal to core/optimize: the certificate (certificate.hpp) applied to OptimizeDesign's
// local solves and to its answer: a run whose backend reported convergence is converged only
// when its certificate holds, and the answer's multipliers are the certificate's own.
#pragma once

#include <vector>

#include "core/optimize/certificate.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/optimize/design_runs.hpp"

namespace sweetspot::core::design_detail {

/// The certificate's tolerances from the options.
CertificateTolerances TolerancesFrom(const DesignOptions& options);

/// Certifies every run at its point; a run that reported convergence and fails its certificate
/// becomes no_convergence (uncertified, its message saying what failed), so that the choice
/// among the runs (ChooseRun) prefers certified designs.
void CertifyRuns(const DesignModel& model, const DesignOptions& options, std::vector<Run>* runs);

/// The answer's certificate at x (with the uniqueness check) into result->certificate, and the
/// solve `o` with the certificate's multipliers in place of the backend's (for
/// ReportActiveConstraints); `o` unchanged when no certificate could be made (min_sting).
/// `chosen` (may be null): the run whose certificate (CertifyRuns') is reused when x is its point.
LocalSolveOutcome WithCertifiedMultipliers(const DesignModel& model, const DesignOptions& options,
                                           const std::vector<double>& x, const LocalSolveOutcome& o,
                                           DesignResult* result, const Run* chosen = nullptr);

/// After ReportActiveConstraints: error_estimate is the certificate's stationarity; multipliers
/// that are not unique become NaN (with a warning when `reports_multipliers`: the shape fit
/// reports none, so it gets no warning about them); the message of a chosen run that reported
/// convergence without a certificate says so (message_kind kNotCertified); merged constraints
/// get a warning each.
void FinishCertificate(const Run& chosen, bool reports_multipliers, DesignResult* result);

}  // namespace sweetspot::core::design_detail
