// The derivative check shared by the lifted and the tapered formulations' tests
// (optimize_lifted_test.cpp, optimize_tapered_test.cpp): an NLP's exact gradient, Jacobian and
// Lagrangian Hessian against central differences of its values.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace sweetspot::core::nlp_derivative_check {

/// At `at`, with multipliers `lambda` (one per row) and objective factor `sigma_f`: the
/// gradient of f, each Jacobian entry and each entry of the Lagrangian's Hessian (lower
/// triangle mirrored; a value outside its structure makes Hessian() fail the test) against
/// central differences with step `h`, each within abs_tol + rel_tol·|difference|. `Nlp` has
/// n(), m(), Evaluate(x, with_derivatives), f(), g(), grad_f(), jacobian_values(),
/// jacobian_structure(), hessian_structure() and Hessian(x, sigma_f, lambda, values).
template <class Nlp>
void ExpectDerivativesMatchCentralDifferences(Nlp& nlp, const std::vector<double>& at,
                                              const std::vector<double>& lambda, double sigma_f,
                                              double h, double abs_tol, double rel_tol) {
  const int n = nlp.n(), m = nlp.m();
  const auto idx = [](int i) { return static_cast<std::size_t>(i); };
  ASSERT_TRUE(nlp.Evaluate(at.data(), true));
  const std::vector<double> grad = nlp.grad_f();
  const std::vector<double> jac = nlp.jacobian_values();
  std::vector<double> hess(nlp.hessian_structure().size());
  ASSERT_TRUE(nlp.Hessian(at.data(), sigma_f, lambda.data(), hess.data()));
  // Dense copies of the Jacobian and the Hessian.
  std::vector<std::vector<double>> jd(idx(m), std::vector<double>(idx(n), 0.0));
  for (std::size_t e = 0; e < jac.size(); ++e) {
    const auto [r, c] = nlp.jacobian_structure()[e];
    jd[idx(r)][idx(c)] += jac[e];
  }
  std::vector<std::vector<double>> hd(idx(n), std::vector<double>(idx(n), 0.0));
  for (std::size_t e = 0; e < hess.size(); ++e) {
    const auto [r, c] = nlp.hessian_structure()[e];
    hd[idx(r)][idx(c)] += hess[e];
    if (r != c) hd[idx(c)][idx(r)] += hess[e];
  }
  // The Lagrangian's gradient sigma_f grad f + J^T lambda at a point.
  const auto lagrangian_gradient = [&](const std::vector<double>& x) {
    EXPECT_TRUE(nlp.Evaluate(x.data(), true));
    std::vector<double> out(idx(n));
    for (int j = 0; j < n; ++j) out[idx(j)] = sigma_f * nlp.grad_f()[idx(j)];
    for (std::size_t e = 0; e < nlp.jacobian_values().size(); ++e) {
      const auto [r, c] = nlp.jacobian_structure()[e];
      out[idx(c)] += lambda[idx(r)] * nlp.jacobian_values()[e];
    }
    return out;
  };
  const auto tol = [&](double v) { return abs_tol + rel_tol * std::abs(v); };
  for (int j = 0; j < n; ++j) {
    std::vector<double> plus = at, minus = at;
    plus[idx(j)] += h;
    minus[idx(j)] -= h;
    ASSERT_TRUE(nlp.Evaluate(plus.data(), false));
    const double f_plus = nlp.f();
    const std::vector<double> g_plus = nlp.g();
    ASSERT_TRUE(nlp.Evaluate(minus.data(), false));
    const double f_minus = nlp.f();
    const std::vector<double> g_minus = nlp.g();
    const double df = (f_plus - f_minus) / (2 * h);
    EXPECT_NEAR(grad[idx(j)], df, tol(df)) << "df/dx" << j;
    for (int k = 0; k < m; ++k) {
      const double dg = (g_plus[idx(k)] - g_minus[idx(k)]) / (2 * h);
      EXPECT_NEAR(jd[idx(k)][idx(j)], dg, tol(dg)) << "dg" << k << "/dx" << j;
    }
    const std::vector<double> lp = lagrangian_gradient(plus), lm = lagrangian_gradient(minus);
    for (int i = 0; i < n; ++i) {
      const double dh = (lp[idx(i)] - lm[idx(i)]) / (2 * h);
      EXPECT_NEAR(hd[idx(i)][idx(j)], dh, tol(dh)) << "H(" << i << ", " << j << ")";
    }
  }
}

}  // namespace sweetspot::core::nlp_derivative_check
