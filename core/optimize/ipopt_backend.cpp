// The Ipopt backend: a TNLP per solve over ScaledDesignNlp, the status mapping, the lock.
//
// The lock: Ipopt 3.11.9 with the sequential MUMPS of Debian 12 is not thread-safe, and
// guarding OptimizeTNLP alone is not enough (MUMPS aborted the process with exit status 0 in
// that configuration; shared/docs/pitfalls.md). One process-wide mutex is therefore held from
// creating the IpoptApplication to destroying it and the TNLP. It is the only mutable global
// of core (a function-local static, constructed thread-safely on first use). Ipopt solves of
// one process run one at a time: scale constrained solves with processes or replicas.
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>

#include <coin/IpIpoptApplication.hpp>
#include <coin/IpJournalist.hpp>
#include <coin/IpSolveStatistics.hpp>
#include <coin/IpTNLP.hpp>

#include "core/numerics/termination.hpp"
#include "core/optimize/design_backends.hpp"
#include "core/optimize/lifted_nlp.hpp"
#include "core/optimize/tapered_nlp.hpp"

namespace sweetspot::core {
namespace {

std::mutex& IpoptMutex() {
  static std::mutex mutex;  // the one allowed global: see the file comment
  return mutex;
}

constexpr double kIpoptInfinity = 1e20;  // beyond nlp_lower/upper_bound_inf (1e19)

using Ipopt::Index;
using Ipopt::Number;

class DesignTnlp : public Ipopt::TNLP {
 public:
  DesignTnlp(ScaledDesignNlp& nlp, const std::vector<double>& s0,
             const LocalSolveSettings& settings, LocalSolveOutcome* out)
      : nlp_(nlp), s0_(s0), settings_(settings), out_(out) {}

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = nlp_.n();
    m = nlp_.m();
    nnz_jac_g = 0;
    for (const auto& row : nlp_.structure()) nnz_jac_g += static_cast<Index>(row.size());
    nnz_h_lag = n * (n + 1) / 2;
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    for (Index j = 0; j < n; ++j) {
      x_l[j] = 0.0;
      x_u[j] = 1.0;
    }
    std::vector<double> lower, upper;
    nlp_.ConstraintBounds(&lower, &upper);
    for (Index k = 0; k < m; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      g_l[k] = std::isfinite(lower[kk]) ? lower[kk] : -kIpoptInfinity;
      g_u[k] = std::isfinite(upper[kk]) ? upper[kk] : kIpoptInfinity;
    }
    return true;
  }

  bool get_starting_point(Index n, bool init_x, Number* x, bool init_z, Number* /*z_L*/,
                          Number* /*z_U*/, Index /*m*/, bool init_lambda,
                          Number* /*lambda*/) override {
    if (init_z || init_lambda || !init_x) return false;
    for (Index j = 0; j < n; ++j) x[j] = s0_[static_cast<std::size_t>(j)];
    return true;
  }

  bool eval_f(Index /*n*/, const Number* x, bool /*new_x*/, Number& obj_value) override {
    try {
      if (!nlp_.Evaluate(x, false)) return false;
      obj_value = nlp_.f();
      return std::isfinite(obj_value);
    } catch (...) {
      return false;
    }
  }

  bool eval_grad_f(Index n, const Number* x, bool /*new_x*/, Number* grad_f) override {
    try {
      if (!nlp_.Evaluate(x, true)) return false;
      for (Index j = 0; j < n; ++j) {
        grad_f[j] = nlp_.grad_f()(j);
        if (!std::isfinite(grad_f[j])) return false;
      }
      return true;
    } catch (...) {
      return false;
    }
  }

  bool eval_g(Index /*n*/, const Number* x, bool /*new_x*/, Index m, Number* g) override {
    try {
      if (!nlp_.Evaluate(x, false)) return false;
      for (Index k = 0; k < m; ++k) {
        g[k] = nlp_.g()[static_cast<std::size_t>(k)];
        if (!std::isfinite(g[k])) return false;
      }
      return true;
    } catch (...) {
      return false;
    }
  }

  bool eval_jac_g(Index /*n*/, const Number* x, bool /*new_x*/, Index /*m*/, Index /*nele_jac*/,
                  Index* i_row, Index* j_col, Number* values) override {
    try {
      const auto& structure = nlp_.structure();
      if (values == nullptr) {
        Index e = 0;
        for (std::size_t k = 0; k < structure.size(); ++k) {
          for (int j : structure[k]) {
            i_row[e] = static_cast<Index>(k);
            j_col[e] = j;
            ++e;
          }
        }
        return true;
      }
      if (!nlp_.Evaluate(x, true)) return false;
      Index e = 0;
      for (std::size_t k = 0; k < structure.size(); ++k) {
        for (int j : structure[k]) {
          values[e] = nlp_.jacobian()(static_cast<Eigen::Index>(k), j);
          if (!std::isfinite(values[e])) return false;
          ++e;
        }
      }
      return true;
    } catch (...) {
      return false;
    }
  }

  bool eval_h(Index n, const Number* x, bool /*new_x*/, Number obj_factor, Index /*m*/,
              const Number* lambda, bool /*new_lambda*/, Index /*nele_hess*/, Index* i_row,
              Index* j_col, Number* values) override {
    try {
      if (values == nullptr) {
        Index e = 0;
        for (Index i = 0; i < n; ++i) {
          for (Index j = 0; j <= i; ++j) {
            i_row[e] = i;
            j_col[e] = j;
            ++e;
          }
        }
        return true;
      }
      if (!nlp_.Hessian(x, obj_factor, lambda, &hessian_)) return false;
      Index e = 0;
      for (Index i = 0; i < n; ++i) {
        for (Index j = 0; j <= i; ++j) values[e++] = hessian_(i, j);
      }
      return true;
    } catch (...) {
      return false;
    }
  }

  void finalize_solution(Ipopt::SolverReturn /*status*/, Index n, const Number* x,
                         const Number* z_L, const Number* z_U, Index m, const Number* /*g*/,
                         const Number* lambda, Number /*obj_value*/,
                         const Ipopt::IpoptData* /*ip_data*/,
                         Ipopt::IpoptCalculatedQuantities* /*ip_cq*/) override {
    if (x == nullptr) return;
    out_->s.assign(x, x + n);
    out_->has_point = true;
    if (z_L != nullptr && z_U != nullptr && (m == 0 || lambda != nullptr)) {
      out_->z_lower.assign(z_L, z_L + n);
      out_->z_upper.assign(z_U, z_U + n);
      out_->lambda.assign(lambda, lambda + m);
      out_->has_multipliers = true;
    }
  }

  bool intermediate_callback(Ipopt::AlgorithmMode /*mode*/, Index iter, Number /*obj_value*/,
                             Number /*inf_pr*/, Number /*inf_du*/, Number /*mu*/, Number /*d_norm*/,
                             Number /*regularization_size*/, Number /*alpha_du*/,
                             Number /*alpha_pr*/, Index /*ls_trials*/,
                             const Ipopt::IpoptData* /*ip_data*/,
                             Ipopt::IpoptCalculatedQuantities* /*ip_cq*/) override {
    return ContinueLocalSolve(iter, settings_, out_);
  }

 private:
  ScaledDesignNlp& nlp_;
  std::vector<double> s0_;
  const LocalSolveSettings& settings_;
  LocalSolveOutcome* out_;
  Eigen::MatrixXd hessian_;  // eval_h's scratch, kept between calls (no allocation per call)
};

// Counts the errors in the derivative checker's output ("Derivative checker detected 3
// error(s)." / "No errors detected by derivative checker."); -1 when neither line is there.
int DerivativeCheckErrors(const std::string& report) {
  if (report.find("No errors detected by derivative checker") != std::string::npos) return 0;
  const std::string key = "Derivative checker detected ";
  const std::size_t at = report.find(key);
  if (at == std::string::npos) return -1;
  return std::atoi(report.c_str() + at + key.size());
}

// The options of every design solve, and the lifted formulation's (lifted: true); false when
// Ipopt refused one.
bool SetIpoptOptions(const LocalSolveSettings& settings, bool lifted,
                     Ipopt::OptionsList* options) {
  bool ok = true;
  ok = ok && options->SetStringValue("sb", "yes");
  ok = ok && options->SetIntegerValue("print_level", 0);
  ok = ok && options->SetIntegerValue("max_iter", settings.max_iterations);
  ok = ok && options->SetNumericValue("tol", settings.tolerance);
  ok = ok && options->SetNumericValue("constr_viol_tol", settings.constraint_tolerance);
  ok = ok && options->SetStringValue(
                 "hessian_approximation",
                 settings.hessian == HessianMode::kExact || lifted ? "exact" : "limited-memory");
  ok = ok && options->SetStringValue("mu_strategy", "adaptive");
  // Less work that is not the solve (bench/ipopt_phases.sh; docs/benchmarks.md, "Ipopt's
  // overhead"). The probing oracle picks the adaptive barrier parameter from one affine
  // step; the default quality-function oracle runs a golden-section search per iteration
  // whose every trial Ipopt 3.11 times with getrusage (three fifths of a 16-knot solve).
  // MUMPS's workspace is its estimate plus 10 % instead of plus 1000 %: that allocation,
  // its page faults and its release came every factorisation. When MUMPS needs more, it
  // says so and Ipopt raises the percentage and factorises again.
  ok = ok && options->SetStringValue("mu_oracle", "probing");
  ok = ok && options->SetIntegerValue("mumps_mem_percent", 10);
  // No relaxation of the bounds: a design at a bound (a variable or a constraint) then meets
  // it to round-off, not to 1e-8 of its scale (Ipopt's default relaxes both).
  ok = ok && options->SetNumericValue("bound_relax_factor", 0.0);
  if (lifted) {
    // The lifted problem's iterations cost mostly MUMPS's per-call work (its KKT matrix is
    // banded, ~3n rows; bench/ipopt_phases.sh): no iterative-refinement step unless the
    // residual asks for one, no MC64/row scaling analysis of a matrix that needs none, and
    // the start pushed 1e-5 (not 1e-2) into the bounds, which saves an iteration or two, and
    // no least-squares estimate of the first multipliers (a factorisation of its own; they
    // start at 0). Together -30 % CPU at 16 to 256 knots (docs/benchmarks.md, issue 36).
    ok = ok && options->SetIntegerValue("min_refinement_steps", 0);
    ok = ok && options->SetIntegerValue("mumps_permuting_scaling", 0);
    ok = ok && options->SetIntegerValue("mumps_scaling", 0);
    ok = ok && options->SetNumericValue("bound_push", 1e-5);
    ok = ok && options->SetNumericValue("bound_frac", 1e-5);
    ok = ok && options->SetNumericValue("constr_mult_init_max", 0.0);
    // Fewer MUMPS calls: each costs ~1-1.7 M instructions at 64 knots, MUMPS 5.5's own
    // bookkeeping and per-front work on this ~3n-row banded matrix, not its arithmetic.
    // The adaptive barrier (set above) factorises once and solves twice per iteration (the
    // probing oracle's affine step, then the step); the monotone (Fiacco-McCormick) barrier
    // solves once. Started at mu = 1e-4 (the start is pushed 1e-5 into its bounds, so the
    // default 0.1 would first pull it back to the centre), each barrier problem solved to
    // 1000 mu (barrier_tol_factor) and mu cut by 20 (or superlinearly): 12 / 13 / 13
    // iterations at 64 / 128 / 256 knots against the adaptive barrier's 11 / 12 / 14, with
    // 2 MUMPS calls each instead of 3, -14 % instructions per solve (callgrind; the optima
    // agree with SciPy's to 2.5e-10). fast_step_computation: no residual of the step is computed (no
    // refinement is asked for above), -1 %. docs/benchmarks.md, "Issue 36".
    ok = ok && options->SetStringValue("mu_strategy", "monotone");
    ok = ok && options->SetNumericValue("mu_init", 1e-4);
    ok = ok && options->SetNumericValue("barrier_tol_factor", 1000.0);
    ok = ok && options->SetNumericValue("mu_linear_decrease_factor", 0.05);
    ok = ok && options->SetStringValue("fast_step_computation", "yes");
  }
  if (settings.max_cpu_time_s > 0.0) {
    ok = ok && options->SetNumericValue("max_cpu_time", settings.max_cpu_time_s);
  }
  return ok;
}

}  // namespace

LocalSolveOutcome SolveWithIpopt(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                 const LocalSolveSettings& settings) {
  LocalSolveOutcome out;
  const int evaluations_before = nlp.evaluations();
  // The lifted formulation when the problem qualifies (lifted_nlp.hpp): the sparse exact
  // Hessian of the problem with the mass integrals as variables.
  std::unique_ptr<LiftedDesignNlp> lifted;
  // With the taper's steps as variables when the knots form one taper chain (tapered_nlp.hpp):
  // ~n KKT rows instead of ~3n.
  std::unique_ptr<TaperedLiftedNlp> tapered;
  try {
    if (settings.lift && LiftedDesignNlp::Qualifies(nlp.model(), nullptr)) {
      lifted = std::make_unique<LiftedDesignNlp>(nlp);
      if (settings.taper_steps) {
        tapered = std::make_unique<TaperedLiftedNlp>(*lifted, s0, kTaperBlockSize);
        if (!tapered->ok()) tapered.reset();
      }
    }
    std::ostringstream journal_text;
    // Held until the application and the TNLP are gone (declared first, destroyed last).
    std::lock_guard<std::mutex> lock(IpoptMutex());
    Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
    Ipopt::SmartPtr<Ipopt::TNLP> tnlp =
        tapered  ? NewTaperedTnlp(*tapered, s0, settings, &out)
        : lifted ? NewLiftedTnlp(*lifted, s0, settings, &out)
               : static_cast<Ipopt::TNLP*>(new DesignTnlp(nlp, s0, settings, &out));
    out.lifted = lifted != nullptr;
    out.taper_steps = tapered != nullptr;
    Ipopt::SmartPtr<Ipopt::OptionsList> options = app->Options();
    bool ok = SetIpoptOptions(settings, lifted != nullptr, Ipopt::GetRawPtr(options));
    if (settings.derivative_check != DerivativeCheck::kNone) {
      ok = ok && options->SetStringValue("derivative_test",
                                         settings.derivative_check == DerivativeCheck::kSecondOrder
                                             ? "second-order"
                                             : "first-order");
      if (settings.derivative_test_perturbation > 0.0) {
        ok = ok && options->SetNumericValue("derivative_test_perturbation",
                                            settings.derivative_test_perturbation);
      }
      // The checker prints to the journals only: capture its lines in a string (the console
      // journal stays at print_level 0).
      Ipopt::SmartPtr<Ipopt::StreamJournal> journal =
          new Ipopt::StreamJournal("sweetspot-derivative-check", Ipopt::J_WARNING);
      journal->SetOutputStream(&journal_text);
      journal->SetAllPrintLevels(Ipopt::J_NONE);
      journal->SetPrintLevel(Ipopt::J_NLP, Ipopt::J_WARNING);
      app->Jnlst()->AddJournal(Ipopt::GetRawPtr(journal));
    }
    if (!ok) {
      out.raw_status = Ipopt::Invalid_Option;
    } else {
      std::istringstream no_options_file;  // never read ./ipopt.opt
      Ipopt::ApplicationReturnStatus status = app->Initialize(no_options_file);
      if (status == Ipopt::Solve_Succeeded) status = app->OptimizeTNLP(tnlp);
      out.raw_status = static_cast<int>(status);
      if (Ipopt::IsValid(app->Statistics())) {
        out.iterations = app->Statistics()->IterationCount();
      }
    }
    if (settings.derivative_check != DerivativeCheck::kNone) {
      out.derivative_check_report = journal_text.str();
      out.derivative_check_errors = DerivativeCheckErrors(out.derivative_check_report);
    }
  } catch (const std::exception& e) {
    out.raw_status = Ipopt::NonIpopt_Exception_Thrown;
    out.message = std::string("exception: ") + e.what();
  } catch (...) {
    out.raw_status = Ipopt::NonIpopt_Exception_Thrown;
    out.message = "unknown exception";
  }
  out.termination = TerminationFromIpoptStatus(out.raw_status);
  out.status_name = IpoptStatusName(out.raw_status);
  out.evaluations = nlp.evaluations() - evaluations_before + (lifted ? lifted->evaluations() : 0);
  if (!out.has_point) out.s = s0;
  return out;
}

}  // namespace sweetspot::core
