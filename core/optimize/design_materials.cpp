// OptimizeOverMaterials (core/optimize/design_problem.hpp): a discrete choice of material, one
// design solve per material under one time budget, the best usable design picked.
#include <chrono>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/numerics/limits.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/optimize/design_runs.hpp"

namespace sweetspot::core {

using design_detail::BackendName;
using design_detail::Clock;
using design_detail::MainBackend;
using design_detail::Optimize;

MaterialChoiceResult OptimizeOverMaterials(const DesignProblem& problem,
                                           const std::vector<Material>& materials,
                                           const DesignOptions& options, Progress* progress) {
  const Clock::time_point start = Clock::now();
  const Clock::time_point deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                  std::isfinite(options.max_time_s) && options.max_time_s > 0.0 ? options.max_time_s
                                                                                : 0.0));
  MaterialChoiceResult out;
  out.summary.backend = BackendName(MainBackend(problem, options));
  out.summary.iterations = 0;
  out.summary.evaluations = 0;
  out.summary.objective = kNaN;
  if (materials.empty()) {
    out.summary.SetRefusal(TextRefusal("materials", "give at least one material"));
    out.summary.solve_time_s = 0.0;
    return out;
  }
  const bool maximize = problem.objective != DesignObjective::kMinMoi &&
                        problem.objective != DesignObjective::kMinSting &&
                        problem.objective != DesignObjective::kLeastSquares;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (IsCancelled(progress)) {
      out.summary.warnings.push_back("cancelled after " + std::to_string(i) + " materials");
      break;
    }
    DesignProblem p = problem;
    p.bat.material = materials[i];
    p.base_mass_properties.reset();  // another bat's
    MaterialDesignResult r;
    r.material = materials[i].name;
    const double n = static_cast<double>(materials.size());
    r.result = Optimize(p, options, progress, i / n, (i + 1.0) / n, deadline);
    out.summary.iterations += std::max(r.result.summary.iterations, 0);
    out.summary.evaluations += std::max(r.result.summary.evaluations, 0);
    out.per_material.push_back(std::move(r));
  }
  auto rank = [](const DesignResult& r) {
    if (r.summary.termination == Termination::kConverged) return 0;
    if (r.summary.termination == Termination::kNoConvergence) return 1;
    return 2;
  };
  for (std::size_t i = 0; i < out.per_material.size(); ++i) {
    const DesignResult& r = out.per_material[i].result;
    if (rank(r) == 2 || !std::isfinite(r.objective_value)) continue;
    if (out.best < 0) {
      out.best = static_cast<int>(i);
      continue;
    }
    const DesignResult& b = out.per_material[static_cast<std::size_t>(out.best)].result;
    if (rank(r) < rank(b) ||
        (rank(r) == rank(b) && (maximize ? r.objective_value > b.objective_value
                                         : r.objective_value < b.objective_value))) {
      out.best = static_cast<int>(i);
    }
  }
  if (out.best >= 0) {
    const MaterialDesignResult& b = out.per_material[static_cast<std::size_t>(out.best)];
    out.summary.termination = b.result.summary.termination;
    out.summary.raw_status = b.result.summary.raw_status;
    out.summary.objective = b.result.objective_value;
    out.summary.constraint_violation = b.result.summary.constraint_violation;
    out.summary.error_estimate = b.result.summary.error_estimate;
    out.summary.models_used = b.result.summary.models_used;
    out.summary.message = "best material: " + b.material + " (" + b.result.summary.message + ")";
  } else {
    bool all_infeasible = !out.per_material.empty();
    bool all_invalid = !out.per_material.empty();
    for (const auto& r : out.per_material) {
      all_infeasible = all_infeasible && r.result.summary.termination == Termination::kInfeasible;
      all_invalid = all_invalid && r.result.summary.termination == Termination::kInvalidInput;
    }
    out.summary.termination = all_infeasible ? Termination::kInfeasible
                              : all_invalid  ? Termination::kInvalidInput
                                             : Termination::kFailure;
    std::string text;
    for (const auto& r : out.per_material) {
      text += (text.empty() ? "" : "; ") + r.material + ": " + r.result.summary.message;
    }
    out.summary.message = "no material gives a usable design: " + text;
  }
  out.summary.solve_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace sweetspot::core
