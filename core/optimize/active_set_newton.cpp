// The frontier's continuation step: Newton's method on the KKT conditions of an active set.
// See active_set_newton.hpp.
#include "core/optimize/active_set_newton.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace sweetspot::core {
namespace {

// The side a working-set constraint is held at.
enum Side : int { kInactive = 0, kAtUpper = 1, kAtLower = -1, kEquality = 2 };

// The working set's linear algebra at one point: rows of the active constraints, columns of
// the free variables.
struct Working {
  std::vector<int> rows;  // constraint indices in the working set
  std::vector<int> cols;  // free variables
};

Working WorkingOf(const std::vector<int>& side, const std::vector<int>& fixed) {
  Working w;
  for (std::size_t k = 0; k < side.size(); ++k)
    if (side[k] != kInactive) w.rows.push_back(static_cast<int>(k));
  for (std::size_t j = 0; j < fixed.size(); ++j)
    if (fixed[j] == 0) w.cols.push_back(static_cast<int>(j));
  return w;
}

// The active constraints' Jacobian on the free variables (|rows| x |cols|).
Eigen::MatrixXd JacobianOf(const ScaledDesignNlp& nlp, const Working& w) {
  Eigen::MatrixXd j(static_cast<Eigen::Index>(w.rows.size()),
                    static_cast<Eigen::Index>(w.cols.size()));
  for (std::size_t a = 0; a < w.rows.size(); ++a)
    for (std::size_t b = 0; b < w.cols.size(); ++b)
      j(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) =
          nlp.jacobian()(w.rows[a], w.cols[b]);
  return j;
}

// Least-squares multipliers of the working set: J_WF^T mu = -grad_F (Ipopt's signs).
Eigen::VectorXd MultipliersOf(const Eigen::MatrixXd& j, const Eigen::VectorXd& grad_free) {
  if (j.rows() == 0) return Eigen::VectorXd();
  return j.transpose().colPivHouseholderQr().solve(-grad_free);
}

}  // namespace

ActiveSetGuess GuessFromMultipliers(const std::vector<double>& lambda,
                                    const std::vector<double>& z_lower,
                                    const std::vector<double>& z_upper) {
  ActiveSetGuess g;
  g.constraint_side.assign(lambda.size(), 0.0);
  for (std::size_t k = 0; k < lambda.size(); ++k)
    g.constraint_side[k] = lambda[k] > 0.0 ? 1.0 : (lambda[k] < 0.0 ? -1.0 : 0.0);
  g.bound.assign(z_lower.size(), 0);
  for (std::size_t j = 0; j < z_lower.size() && j < z_upper.size(); ++j) {
    if (z_lower[j] > 0.0) g.bound[j] = 1;
    if (z_upper[j] > 0.0) g.bound[j] = 2;
  }
  return g;
}

LocalSolveOutcome SolveWithActiveSetNewton(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                           const ActiveSetGuess& guess,
                                           const LocalSolveSettings& settings) {
  LocalSolveOutcome out;
  out.status_name = "active-set Newton";
  out.termination = Termination::kNoConvergence;
  const int n = nlp.n(), m = nlp.m();
  const auto nn = static_cast<std::size_t>(n), mm = static_cast<std::size_t>(m);
  if (s0.size() != nn || guess.constraint_side.size() != mm || guess.bound.size() != nn) {
    out.termination = Termination::kFailure;
    out.message = "the active-set guess does not fit the problem";
    return out;
  }
  try {
    std::vector<double> lower, upper;
    nlp.ConstraintBounds(&lower, &upper);
    std::vector<int> side(mm, kInactive);
    for (std::size_t k = 0; k < mm; ++k) {
      if (lower[k] == upper[k]) {
        side[k] = kEquality;
      } else if (guess.constraint_side[k] > 0.0 && std::isfinite(upper[k])) {
        side[k] = kAtUpper;
      } else if (guess.constraint_side[k] < 0.0 && std::isfinite(lower[k])) {
        side[k] = kAtLower;
      }
    }
    std::vector<int> fixed = guess.bound;
    std::vector<double> s = s0;
    for (std::size_t j = 0; j < nn; ++j) {
      s[j] = std::clamp(s[j], 0.0, 1.0);
      if (fixed[j] == 1) s[j] = 0.0;
      if (fixed[j] == 2) s[j] = 1.0;
    }
    const auto target = [&](int k) {
      const auto kk = static_cast<std::size_t>(k);
      return side[kk] == kAtLower ? lower[kk] : upper[kk];
    };
    const double ctol = settings.constraint_tolerance;
    const double stol = settings.tolerance;
    Eigen::MatrixXd h;
    const auto fail = [&](Termination t, const std::string& why) {
      out.termination = t;
      out.message = why;
      out.s = s;
      out.has_point = true;
      out.evaluations = nlp.evaluations();
      return out;
    };

    for (int change = 0; change <= kActiveSetNewtonMaxChanges; ++change) {
      // Newton on the working set.
      bool settled = false;
      for (int it = 0; it < kActiveSetNewtonMaxIterations; ++it) {
        if (!ContinueLocalSolve(out.iterations, settings, &out)) {
          return fail(Termination::kNoConvergence, "stopped");
        }
        if (!nlp.Evaluate(s.data(), true)) {
          return fail(Termination::kFailure, "the model is not finite at a Newton iterate");
        }
        const Working w = WorkingOf(side, fixed);
        const auto nw = static_cast<Eigen::Index>(w.rows.size());
        const auto nf = static_cast<Eigen::Index>(w.cols.size());
        if (nw > nf)
          return fail(Termination::kNoConvergence, "more active constraints than free variables");
        const Eigen::MatrixXd j = JacobianOf(nlp, w);
        Eigen::VectorXd r(nw), grad_f(nf);
        for (Eigen::Index a = 0; a < nw; ++a)
          r(a) = nlp.g()[static_cast<std::size_t>(w.rows[static_cast<std::size_t>(a)])] -
                 target(w.rows[static_cast<std::size_t>(a)]);
        for (Eigen::Index b = 0; b < nf; ++b)
          grad_f(b) = nlp.grad_f()(w.cols[static_cast<std::size_t>(b)]);
        const double g_norm = std::max(1.0, nlp.grad_f().lpNorm<Eigen::Infinity>());
        const double residual = nw == 0 ? 0.0 : r.lpNorm<Eigen::Infinity>();
        // A vertex (as many active constraints as free variables) is fixed by its constraints
        // alone: its multipliers are needed only at the end (below).
        Eigen::VectorXd mu;
        double stationarity = 0.0;
        if (nw < nf) {
          mu = MultipliersOf(j, grad_f);
          stationarity = (grad_f + j.transpose() * mu).lpNorm<Eigen::Infinity>() / g_norm;
        }
        // Settled: the working set's constraints hold and (with free directions left) the
        // Lagrangian is stationary, both well inside the requested tolerances.
        if (residual <= 0.1 * ctol && stationarity <= 0.1 * stol) {
          settled = true;
          break;
        }
        Eigen::VectorXd step;
        if (nw == nf) {
          // A vertex: the active constraints alone fix the point.
          const Eigen::PartialPivLU<Eigen::MatrixXd> lu(j);
          // rcond: LAPACK's estimate of 1 / cond_1; below 1e-12 the step carries nothing.
          if (!(lu.rcond() > 1e-12))
            return fail(Termination::kNoConvergence, "singular active set");
          step = -lu.solve(r);
          // The point is fixed; a vertex whose stationarity cannot vanish is the set's fault,
          // found by the multipliers below.
          if (residual <= 0.1 * ctol) {
            settled = true;
            break;
          }
        } else {
          std::vector<double> weights(mm, 0.0);
          for (Eigen::Index a = 0; a < nw; ++a)
            weights[static_cast<std::size_t>(w.rows[static_cast<std::size_t>(a)])] = mu(a);
          if (!nlp.Hessian(s.data(), 1.0, weights.data(), &h)) {
            return fail(Termination::kFailure, "the Hessian is not finite at a Newton iterate");
          }
          Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(nf + nw, nf + nw);
          for (Eigen::Index a = 0; a < nf; ++a)
            for (Eigen::Index b = 0; b < nf; ++b)
              kkt(a, b) =
                  h(w.cols[static_cast<std::size_t>(a)], w.cols[static_cast<std::size_t>(b)]);
          kkt.block(0, nf, nf, nw) = j.transpose();
          kkt.block(nf, 0, nw, nf) = j;
          Eigen::VectorXd rhs(nf + nw);
          rhs.head(nf) = -(grad_f + j.transpose() * mu);
          rhs.tail(nw) = -r;
          Eigen::FullPivLU<Eigen::MatrixXd> lu(kkt);
          if (!lu.isInvertible()) return fail(Termination::kNoConvergence, "singular KKT matrix");
          step = lu.solve(rhs).head(nf);
        }
        if (!step.allFinite()) return fail(Termination::kNoConvergence, "no finite Newton step");
        for (Eigen::Index b = 0; b < nf; ++b)
          s[static_cast<std::size_t>(w.cols[static_cast<std::size_t>(b)])] += step(b);
        ++out.iterations;
        // Far outside the box: the guess was wrong, not a step to correct.
        for (std::size_t jj = 0; jj < nn; ++jj)
          if (s[jj] < -0.5 || s[jj] > 1.5)
            return fail(Termination::kNoConvergence, "the Newton step left the box");
      }
      if (!settled)
        return fail(Termination::kNoConvergence, "Newton did not settle on the active set");

      // Is the working set the active set? Primal: a bound or constraint left out is violated;
      // dual: a multiplier has the wrong sign.
      const Working w = WorkingOf(side, fixed);
      const Eigen::MatrixXd j = JacobianOf(nlp, w);
      Eigen::VectorXd grad_f(static_cast<Eigen::Index>(w.cols.size()));
      for (std::size_t b = 0; b < w.cols.size(); ++b)
        grad_f(static_cast<Eigen::Index>(b)) = nlp.grad_f()(w.cols[b]);
      const Eigen::VectorXd mu = MultipliersOf(j, grad_f);
      const double g_norm = std::max(1.0, nlp.grad_f().lpNorm<Eigen::Infinity>());
      // The full stationarity residual: grad f + J_W^T mu, whose fixed entries are the bounds'
      // multipliers (z_L = r_j at a lower bound, z_U = -r_j at an upper one).
      Eigen::VectorXd full = nlp.grad_f();
      for (std::size_t a = 0; a < w.rows.size(); ++a)
        full += mu(static_cast<Eigen::Index>(a)) * nlp.jacobian().row(w.rows[a]).transpose();
      // The most wrong-signed multiplier (sign-corrected value, < 0 is wrong).
      double worst_dual = -stol * g_norm;
      int drop_row = -1, drop_var = -1;
      for (std::size_t a = 0; a < w.rows.size(); ++a) {
        const int k = w.rows[a];
        const int sd = side[static_cast<std::size_t>(k)];
        if (sd == kEquality) continue;
        const double v = (sd == kAtUpper ? 1.0 : -1.0) * mu(static_cast<Eigen::Index>(a));
        if (v < worst_dual) {
          worst_dual = v;
          drop_row = k;
          drop_var = -1;
        }
      }
      for (std::size_t jj = 0; jj < nn; ++jj) {
        if (fixed[jj] == 0) continue;
        const double v = fixed[jj] == 1 ? full(static_cast<Eigen::Index>(jj))
                                        : -full(static_cast<Eigen::Index>(jj));
        if (v < worst_dual) {
          worst_dual = v;
          drop_var = static_cast<int>(jj);
          drop_row = -1;
        }
      }
      // The most violated constraint or bound left out.
      double worst_primal = ctol;
      int add_row = -1, add_var = -1, add_side = kInactive;
      for (std::size_t k = 0; k < mm; ++k) {
        if (side[k] != kInactive) continue;
        const double g = nlp.g()[k];
        if (g - upper[k] > worst_primal) {
          worst_primal = g - upper[k];
          add_row = static_cast<int>(k);
          add_side = kAtUpper;
        }
        if (lower[k] - g > worst_primal) {
          worst_primal = lower[k] - g;
          add_row = static_cast<int>(k);
          add_side = kAtLower;
        }
      }
      for (std::size_t jj = 0; jj < nn; ++jj) {
        if (fixed[jj] != 0) continue;
        if (s[jj] > 1.0 + ctol && s[jj] - 1.0 > worst_primal) {
          worst_primal = s[jj] - 1.0;
          add_var = static_cast<int>(jj);
          add_row = -1;
          add_side = 2;
        }
        if (s[jj] < -ctol && -s[jj] > worst_primal) {
          worst_primal = -s[jj];
          add_var = static_cast<int>(jj);
          add_row = -1;
          add_side = 1;
        }
      }
      const bool add = add_row >= 0 || add_var >= 0;
      const bool drop = drop_row >= 0 || drop_var >= 0;
      if (!add && !drop) {
        // The KKT point of the active set: every multiplier in its sign, every constraint held.
        out.s = s;
        out.has_point = true;
        out.lambda.assign(mm, 0.0);
        out.z_lower.assign(nn, 0.0);
        out.z_upper.assign(nn, 0.0);
        for (std::size_t a = 0; a < w.rows.size(); ++a)
          out.lambda[static_cast<std::size_t>(w.rows[a])] = mu(static_cast<Eigen::Index>(a));
        for (std::size_t jj = 0; jj < nn; ++jj) {
          if (fixed[jj] == 1) out.z_lower[jj] = full(static_cast<Eigen::Index>(jj));
          if (fixed[jj] == 2) out.z_upper[jj] = -full(static_cast<Eigen::Index>(jj));
        }
        out.has_multipliers = true;
        out.termination = Termination::kConverged;
        out.raw_status = 0;
        out.evaluations = nlp.evaluations();
        out.message = std::to_string(change) + " active-set changes";
        return out;
      }
      if (change == kActiveSetNewtonMaxChanges) break;
      // A vertex takes no constraint more without giving one up: the one that leaves is the
      // one whose departure leaves the other multipliers best signed (each candidate tried:
      // the new set's multipliers at this point, a square solve of n columns).
      const Working now = WorkingOf(side, fixed);
      if (add && now.rows.size() + 1 > now.cols.size() - (add_var >= 0 ? 1 : 0)) {
        // Columns in the certificate's signs: grad f + sum_c mu_c a_c = 0, mu_c >= 0 except
        // for equalities.
        struct Col {
          int row, var, sign;
        };
        std::vector<Col> cols;
        for (int k : now.rows) {
          const int sd = side[static_cast<std::size_t>(k)];
          cols.push_back({k, -1, sd == kAtLower ? -1 : 1});
        }
        for (std::size_t jj = 0; jj < nn; ++jj)
          if (fixed[jj] != 0) cols.push_back({-1, static_cast<int>(jj), fixed[jj] == 1 ? -1 : 1});
        const Col added = add_row >= 0 ? Col{add_row, -1, add_side == kAtLower ? -1 : 1}
                                       : Col{-1, add_var, add_side == 1 ? -1 : 1};
        const auto column = [&](const Col& c) {
          Eigen::VectorXd v = c.row >= 0 ? Eigen::VectorXd(nlp.jacobian().row(c.row).transpose())
                                         : Eigen::VectorXd::Unit(n, c.var);
          return Eigen::VectorXd(c.sign * v);
        };
        double best = -std::numeric_limits<double>::infinity();
        drop_row = drop_var = -1;
        for (std::size_t out_c = 0; out_c < cols.size(); ++out_c) {
          if (cols[out_c].row >= 0 && side[static_cast<std::size_t>(cols[out_c].row)] == kEquality)
            continue;
          Eigen::MatrixXd a(n, static_cast<Eigen::Index>(cols.size()));
          std::vector<bool> equality(cols.size(), false);
          Eigen::Index c = 0;
          for (std::size_t q = 0; q < cols.size(); ++q) {
            if (q == out_c) continue;
            equality[static_cast<std::size_t>(c)] =
                cols[q].row >= 0 && side[static_cast<std::size_t>(cols[q].row)] == kEquality;
            a.col(c++) = column(cols[q]);
          }
          a.col(c++) = column(added);
          const Eigen::MatrixXd sq = a.leftCols(c);
          const Eigen::VectorXd mu_new = sq.colPivHouseholderQr().solve(-nlp.grad_f());
          if (!mu_new.allFinite() ||
              (sq * mu_new + nlp.grad_f()).lpNorm<Eigen::Infinity>() > 1e-6 * g_norm) {
            continue;  // the set without it cannot be stationary here
          }
          double least = std::numeric_limits<double>::infinity();
          for (Eigen::Index q = 0; q < c; ++q)
            if (!equality[static_cast<std::size_t>(q)]) least = std::min(least, mu_new(q));
          if (least > best) {
            best = least;
            drop_row = cols[out_c].row;
            drop_var = cols[out_c].var;
          }
        }
        if (drop_row < 0 && drop_var < 0) {
          return fail(Termination::kNoConvergence, "no constraint can leave for the violated one");
        }
      }
      if (drop_row >= 0) side[static_cast<std::size_t>(drop_row)] = kInactive;
      if (drop_var >= 0) fixed[static_cast<std::size_t>(drop_var)] = 0;
      if (add_row >= 0) side[static_cast<std::size_t>(add_row)] = add_side;
      if (add_var >= 0) {
        fixed[static_cast<std::size_t>(add_var)] = add_side;
        s[static_cast<std::size_t>(add_var)] = add_side == 1 ? 0.0 : 1.0;
      }
    }
    return fail(Termination::kNoConvergence, "the active set did not settle");
  } catch (const std::exception& e) {
    out.termination = Termination::kFailure;
    out.message = std::string("failure: ") + e.what();
    out.has_point = false;
    return out;
  }
}

}  // namespace sweetspot::core
