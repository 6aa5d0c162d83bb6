// The backend OptimizeDesign chooses, and the size limit of NLopt SLSQP: see backend_choice.hpp.
#include "core/optimize/backend_choice.hpp"

#include <cmath>

#include "core/optimize/design_model.hpp"
#include "core/optimize/lifted_nlp.hpp"

namespace sweetspot::core::design_detail {

DesignBackend ChooseBackend(const DesignProblem& problem, const DesignOptions& options) {
  if (!options.choose_backend) return options.backend;
  if (problem.variables.size() > static_cast<std::size_t>(kChosenSlsqpMaxVariables)) {
    return DesignBackend::kIpopt;
  }
  // SLSQP only where its derivatives are the lifted problem's (functions of P, knot radii):
  // the problems it was measured on. A model that does not build goes to Ipopt, whose run
  // refuses it with the reason.
  DesignModel model;
  if (!DesignModel::Build(problem, options, &model, nullptr)) return DesignBackend::kIpopt;
  return LiftedDesignNlp::Qualifies(model, nullptr) ? DesignBackend::kNloptSlsqp
                                                    : DesignBackend::kIpopt;
}

bool ChosenAnswerCertified(const DesignResult& result) {
  return result.summary.termination == Termination::kConverged &&
         std::isfinite(result.summary.error_estimate) &&
         result.summary.error_estimate <= kChosenSlsqpMaxKkt;
}

bool SlsqpSizeAllowed(const DesignProblem& problem, const DesignOptions& options, Refusal* why) {
  if (options.choose_backend || options.backend != DesignBackend::kNloptSlsqp ||
      problem.variables.size() <= static_cast<std::size_t>(kSlsqpMaxVariables)) {
    return true;
  }
  if (why != nullptr) {
    *why = TextRefusal(
        "options.backend",
        "nlopt_slsqp is run with at most " + std::to_string(kSlsqpMaxVariables) +
            " variables (this problem has " + std::to_string(problem.variables.size()) +
            "): with 62 it reported convergence 0.5 % short of the optimum (issue 36, "
            "bench/optimize_scaling.sh); use backend ipopt");
  }
  return false;
}

}  // namespace sweetspot::core::design_detail
