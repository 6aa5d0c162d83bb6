// The Ipopt side of the lifted formulation (lifted_nlp.hpp): a TNLP over LiftedDesignNlp with
// its sparse Jacobian and sparse exact Hessian. SolveWithIpopt (ipopt_backend.cpp) creates it,
// under the Ipopt lock, when the problem qualifies.
#include <chrono>
#include <cmath>
#include <vector>

#include <coin/IpTNLP.hpp>

#include "core/optimize/lifted_nlp.hpp"
#include "core/optimize/tapered_nlp.hpp"

namespace sweetspot::core {
namespace {

constexpr double kLiftedIpoptInfinity = 1e20;  // beyond nlp_lower/upper_bound_inf (1e19)

using Ipopt::Index;
using Ipopt::Number;

// The design's point of a lifted (z = (s, q)) or tapered (w = (y, q)) point.
std::vector<double> DesignPointOf(const LiftedDesignNlp& nlp, const double* x) {
  return std::vector<double>(x, x + nlp.design_variables());
}
std::vector<double> DesignPointOf(const TaperedLiftedNlp& nlp, const double* x) {
  std::vector<double> z = nlp.LiftedPoint(x);
  z.resize(static_cast<std::size_t>(nlp.design_variables()));
  return z;
}

template <class Nlp>
class LiftedTnlp : public Ipopt::TNLP {
 public:
  LiftedTnlp(Nlp& nlp, const std::vector<double>& s0,
             const LocalSolveSettings& settings, LocalSolveOutcome* out)
      : nlp_(nlp), s0_(s0), settings_(settings), out_(out) {}

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = nlp_.n();
    m = nlp_.m();
    nnz_jac_g = static_cast<Index>(nlp_.jacobian_structure().size());
    nnz_h_lag = static_cast<Index>(nlp_.hessian_structure().size());
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    std::vector<double> zl, zu, gl, gu;
    nlp_.Bounds(&zl, &zu, &gl, &gu);
    auto finite = [](double v) {
      return std::isfinite(v) ? v : (v > 0 ? kLiftedIpoptInfinity : -kLiftedIpoptInfinity);
    };
    for (Index j = 0; j < n; ++j) {
      x_l[j] = finite(zl[static_cast<std::size_t>(j)]);
      x_u[j] = finite(zu[static_cast<std::size_t>(j)]);
    }
    for (Index k = 0; k < m; ++k) {
      g_l[k] = finite(gl[static_cast<std::size_t>(k)]);
      g_u[k] = finite(gu[static_cast<std::size_t>(k)]);
    }
    return true;
  }

  bool get_starting_point(Index n, bool init_x, Number* x, bool init_z, Number* /*z_L*/,
                          Number* /*z_U*/, Index /*m*/, bool init_lambda,
                          Number* /*lambda*/) override {
    if (init_z || init_lambda || !init_x) return false;
    std::vector<double> z;
    if (!nlp_.Start(s0_, &z) || static_cast<Index>(z.size()) != n) return false;
    for (Index j = 0; j < n; ++j) x[j] = z[static_cast<std::size_t>(j)];
    return true;
  }

  bool eval_f(Index /*n*/, const Number* x, bool /*new_x*/, Number& obj_value) override {
    try {
      if (!nlp_.Evaluate(x, false)) return false;
      obj_value = nlp_.f();
      return true;
    } catch (...) {
      return false;
    }
  }

  bool eval_grad_f(Index n, const Number* x, bool /*new_x*/, Number* grad_f) override {
    try {
      if (!nlp_.Evaluate(x, true)) return false;
      for (Index j = 0; j < n; ++j) grad_f[j] = nlp_.grad_f()[static_cast<std::size_t>(j)];
      return true;
    } catch (...) {
      return false;
    }
  }

  bool eval_g(Index /*n*/, const Number* x, bool /*new_x*/, Index m, Number* g) override {
    try {
      if (!nlp_.Evaluate(x, false)) return false;
      for (Index k = 0; k < m; ++k) g[k] = nlp_.g()[static_cast<std::size_t>(k)];
      return true;
    } catch (...) {
      return false;
    }
  }

  bool eval_jac_g(Index /*n*/, const Number* x, bool /*new_x*/, Index /*m*/, Index nele_jac,
                  Index* i_row, Index* j_col, Number* values) override {
    try {
      const auto& structure = nlp_.jacobian_structure();
      if (values == nullptr) {
        for (Index e = 0; e < nele_jac; ++e) {
          i_row[e] = structure[static_cast<std::size_t>(e)].first;
          j_col[e] = structure[static_cast<std::size_t>(e)].second;
        }
        return true;
      }
      if (!nlp_.Evaluate(x, true)) return false;
      for (Index e = 0; e < nele_jac; ++e) {
        values[e] = nlp_.jacobian_values()[static_cast<std::size_t>(e)];
      }
      return true;
    } catch (...) {
      return false;
    }
  }

  bool eval_h(Index /*n*/, const Number* x, bool /*new_x*/, Number obj_factor, Index /*m*/,
              const Number* lambda, bool /*new_lambda*/, Index nele_hess, Index* i_row,
              Index* j_col, Number* values) override {
    try {
      if (values == nullptr) {
        const auto& structure = nlp_.hessian_structure();
        for (Index e = 0; e < nele_hess; ++e) {
          i_row[e] = structure[static_cast<std::size_t>(e)].first;
          j_col[e] = structure[static_cast<std::size_t>(e)].second;
        }
        return true;
      }
      return nlp_.Hessian(x, obj_factor, lambda, values);
    } catch (...) {
      return false;
    }
  }

  void finalize_solution(Ipopt::SolverReturn /*status*/, Index /*n*/, const Number* x,
                         const Number* z_L, const Number* z_U, Index /*m*/, const Number* /*g*/,
                         const Number* lambda, Number /*obj_value*/,
                         const Ipopt::IpoptData* /*ip_data*/,
                         Ipopt::IpoptCalculatedQuantities* /*ip_cq*/) override {
    if (x == nullptr) return;
    // The design's part: s, its bounds' multipliers and the model's constraints' (the first
    // rows, scaled as the dense problem's); q and the definitions' multipliers are dropped.
    out_->s = DesignPointOf(nlp_, x);
    out_->has_point = true;
    if (z_L != nullptr && z_U != nullptr && lambda != nullptr) {
      nlp_.DesignMultipliers(z_L, z_U, lambda, &out_->lambda, &out_->z_lower, &out_->z_upper);
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
  Nlp& nlp_;
  std::vector<double> s0_;
  const LocalSolveSettings& settings_;
  LocalSolveOutcome* out_;
};

}  // namespace

Ipopt::TNLP* NewLiftedTnlp(LiftedDesignNlp& nlp, const std::vector<double>& s0,
                           const LocalSolveSettings& settings, LocalSolveOutcome* out) {
  return new LiftedTnlp<LiftedDesignNlp>(nlp, s0, settings, out);
}

Ipopt::TNLP* NewTaperedTnlp(TaperedLiftedNlp& nlp, const std::vector<double>& s0,
                            const LocalSolveSettings& settings, LocalSolveOutcome* out) {
  return new LiftedTnlp<TaperedLiftedNlp>(nlp, s0, settings, out);
}

}  // namespace sweetspot::core
