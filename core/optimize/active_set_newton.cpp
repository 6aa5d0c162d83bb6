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

namespace {

// The working set of one solve and the point: constraint sides, fixed variables, the limits.
struct SetState {
  std::vector<double> lower, upper;  // the constraints' limits (scaled)
  std::vector<int> side;             // per constraint: Side
  std::vector<int> fixed;            // per variable: 0 free, 1 lower, 2 upper
  std::vector<double> s;             // the point
  double target(int k) const {
    const auto kk = static_cast<std::size_t>(k);
    return side[kk] == kAtLower ? lower[kk] : upper[kk];
  }
};

// The start: equalities always active, the guess's sides where the limit is finite, the
// guess's bounds fixed and the point moved onto them (inside the box).
SetState InitialState(const ScaledDesignNlp& nlp, const std::vector<double>& s0,
                      const ActiveSetGuess& guess) {
  SetState st;
  nlp.ConstraintBounds(&st.lower, &st.upper);
  const auto mm = static_cast<std::size_t>(nlp.m()), nn = static_cast<std::size_t>(nlp.n());
  st.side.assign(mm, kInactive);
  for (std::size_t k = 0; k < mm; ++k) {
    if (st.lower[k] == st.upper[k]) {
      st.side[k] = kEquality;
    } else if (guess.constraint_side[k] > 0.0 && std::isfinite(st.upper[k])) {
      st.side[k] = kAtUpper;
    } else if (guess.constraint_side[k] < 0.0 && std::isfinite(st.lower[k])) {
      st.side[k] = kAtLower;
    }
  }
  st.fixed = guess.bound;
  st.s = s0;
  for (std::size_t j = 0; j < nn; ++j) {
    st.s[j] = std::clamp(st.s[j], 0.0, 1.0);
    if (st.fixed[j] == 1) st.s[j] = 0.0;
    if (st.fixed[j] == 2) st.s[j] = 1.0;
  }
  return st;
}

// How Newton on one working set ended: settled, or stopped with a termination and why.
struct NewtonEnd {
  bool settled = false;
  Termination termination = Termination::kNoConvergence;
  std::string why;
};

NewtonEnd Stopped(Termination t, const std::string& why) { return {false, t, why}; }

// Newton's method on the KKT conditions of the working set (at most
// kActiveSetNewtonMaxIterations steps): settled when its constraints hold and (with free
// directions left) the Lagrangian is stationary, both well inside the requested tolerances.
NewtonEnd NewtonOnWorkingSet(ScaledDesignNlp& nlp, const LocalSolveSettings& settings,
                             SetState* st, Eigen::MatrixXd* h, LocalSolveOutcome* out) {
  const int mm = nlp.m();
  const double ctol = settings.constraint_tolerance;
  const double stol = settings.tolerance;
  const auto nn = static_cast<std::size_t>(nlp.n());
  for (int it = 0; it < kActiveSetNewtonMaxIterations; ++it) {
    if (!ContinueLocalSolve(out->iterations, settings, out)) {
      return Stopped(Termination::kNoConvergence, "stopped");
    }
    if (!nlp.Evaluate(st->s.data(), true)) {
      return Stopped(Termination::kFailure, "the model is not finite at a Newton iterate");
    }
    const Working w = WorkingOf(st->side, st->fixed);
    const auto nw = static_cast<Eigen::Index>(w.rows.size());
    const auto nf = static_cast<Eigen::Index>(w.cols.size());
    if (nw > nf)
      return Stopped(Termination::kNoConvergence, "more active constraints than free variables");
    const Eigen::MatrixXd j = JacobianOf(nlp, w);
    Eigen::VectorXd r(nw), grad_f(nf);
    for (Eigen::Index a = 0; a < nw; ++a)
      r(a) = nlp.g()[static_cast<std::size_t>(w.rows[static_cast<std::size_t>(a)])] -
             st->target(w.rows[static_cast<std::size_t>(a)]);
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
    if (residual <= 0.1 * ctol && stationarity <= 0.1 * stol) return {true, {}, {}};
    Eigen::VectorXd step;
    if (nw == nf) {
      // A vertex: the active constraints alone fix the point.
      const Eigen::PartialPivLU<Eigen::MatrixXd> lu(j);
      // rcond: LAPACK's estimate of 1 / cond_1; below 1e-12 the step carries nothing.
      if (!(lu.rcond() > 1e-12)) return Stopped(Termination::kNoConvergence, "singular active set");
      step = -lu.solve(r);
      // The point is fixed; a vertex whose stationarity cannot vanish is the set's fault,
      // found by the multipliers below.
      if (residual <= 0.1 * ctol) return {true, {}, {}};
    } else {
      std::vector<double> weights(static_cast<std::size_t>(mm), 0.0);
      for (Eigen::Index a = 0; a < nw; ++a)
        weights[static_cast<std::size_t>(w.rows[static_cast<std::size_t>(a)])] = mu(a);
      if (!nlp.Hessian(st->s.data(), 1.0, weights.data(), h)) {
        return Stopped(Termination::kFailure, "the Hessian is not finite at a Newton iterate");
      }
      Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(nf + nw, nf + nw);
      for (Eigen::Index a = 0; a < nf; ++a)
        for (Eigen::Index b = 0; b < nf; ++b)
          kkt(a, b) =
              (*h)(w.cols[static_cast<std::size_t>(a)], w.cols[static_cast<std::size_t>(b)]);
      kkt.block(0, nf, nf, nw) = j.transpose();
      kkt.block(nf, 0, nw, nf) = j;
      Eigen::VectorXd rhs(nf + nw);
      rhs.head(nf) = -(grad_f + j.transpose() * mu);
      rhs.tail(nw) = -r;
      Eigen::FullPivLU<Eigen::MatrixXd> lu(kkt);
      if (!lu.isInvertible()) return Stopped(Termination::kNoConvergence, "singular KKT matrix");
      step = lu.solve(rhs).head(nf);
    }
    if (!step.allFinite()) return Stopped(Termination::kNoConvergence, "no finite Newton step");
    for (Eigen::Index b = 0; b < nf; ++b)
      st->s[static_cast<std::size_t>(w.cols[static_cast<std::size_t>(b)])] += step(b);
    ++out->iterations;
    // Far outside the box: the guess was wrong, not a step to correct.
    for (std::size_t jj = 0; jj < nn; ++jj)
      if (st->s[jj] < -0.5 || st->s[jj] > 1.5)
        return Stopped(Termination::kNoConvergence, "the Newton step left the box");
  }
  return Stopped(Termination::kNoConvergence, "Newton did not settle on the active set");
}

// The settled working set's multipliers: mu on its rows, and the full stationarity residual
// grad f + J_W^T mu, whose fixed entries are the bounds' multipliers (z_L = r_j at a lower
// bound, z_U = -r_j at an upper one).
struct SetMultipliers {
  Working w;
  Eigen::VectorXd mu;
  Eigen::VectorXd full;
  double g_norm = 1.0;
};

SetMultipliers MultipliersAt(const ScaledDesignNlp& nlp, const SetState& st) {
  SetMultipliers sm;
  sm.w = WorkingOf(st.side, st.fixed);
  const Eigen::MatrixXd j = JacobianOf(nlp, sm.w);
  Eigen::VectorXd grad_f(static_cast<Eigen::Index>(sm.w.cols.size()));
  for (std::size_t b = 0; b < sm.w.cols.size(); ++b)
    grad_f(static_cast<Eigen::Index>(b)) = nlp.grad_f()(sm.w.cols[b]);
  sm.mu = MultipliersOf(j, grad_f);
  sm.g_norm = std::max(1.0, nlp.grad_f().lpNorm<Eigen::Infinity>());
  sm.full = nlp.grad_f();
  for (std::size_t a = 0; a < sm.w.rows.size(); ++a)
    sm.full += sm.mu(static_cast<Eigen::Index>(a)) * nlp.jacobian().row(sm.w.rows[a]).transpose();
  return sm;
}

// A change of the working set: the constraint or bound to drop (the most wrong-signed
// multiplier) and the one to add (the most violated left out), -1 where none.
struct SetChange {
  int drop_row = -1, drop_var = -1;
  int add_row = -1, add_var = -1, add_side = kInactive;
  bool add() const { return add_row >= 0 || add_var >= 0; }
  bool drop() const { return drop_row >= 0 || drop_var >= 0; }
};

// The most wrong-signed multiplier (sign-corrected value, < 0 is wrong).
void FindDrop(const SetState& st, const SetMultipliers& sm, double stol, SetChange* c) {
  double worst_dual = -stol * sm.g_norm;
  for (std::size_t a = 0; a < sm.w.rows.size(); ++a) {
    const int k = sm.w.rows[a];
    const int sd = st.side[static_cast<std::size_t>(k)];
    if (sd == kEquality) continue;
    const double v = (sd == kAtUpper ? 1.0 : -1.0) * sm.mu(static_cast<Eigen::Index>(a));
    if (v < worst_dual) {
      worst_dual = v;
      c->drop_row = k;
      c->drop_var = -1;
    }
  }
  for (std::size_t jj = 0; jj < st.fixed.size(); ++jj) {
    if (st.fixed[jj] == 0) continue;
    const double v = st.fixed[jj] == 1 ? sm.full(static_cast<Eigen::Index>(jj))
                                       : -sm.full(static_cast<Eigen::Index>(jj));
    if (v < worst_dual) {
      worst_dual = v;
      c->drop_var = static_cast<int>(jj);
      c->drop_row = -1;
    }
  }
}

// The most violated constraint or bound left out.
void FindAdd(const ScaledDesignNlp& nlp, const SetState& st, double ctol, SetChange* c) {
  double worst_primal = ctol;
  for (std::size_t k = 0; k < st.side.size(); ++k) {
    if (st.side[k] != kInactive) continue;
    const double g = nlp.g()[k];
    if (g - st.upper[k] > worst_primal) {
      worst_primal = g - st.upper[k];
      c->add_row = static_cast<int>(k);
      c->add_side = kAtUpper;
    }
    if (st.lower[k] - g > worst_primal) {
      worst_primal = st.lower[k] - g;
      c->add_row = static_cast<int>(k);
      c->add_side = kAtLower;
    }
  }
  for (std::size_t jj = 0; jj < st.fixed.size(); ++jj) {
    if (st.fixed[jj] != 0) continue;
    if (st.s[jj] > 1.0 + ctol && st.s[jj] - 1.0 > worst_primal) {
      worst_primal = st.s[jj] - 1.0;
      c->add_var = static_cast<int>(jj);
      c->add_row = -1;
      c->add_side = 2;
    }
    if (st.s[jj] < -ctol && -st.s[jj] > worst_primal) {
      worst_primal = -st.s[jj];
      c->add_var = static_cast<int>(jj);
      c->add_row = -1;
      c->add_side = 1;
    }
  }
}

// A vertex takes no constraint more without giving one up: the one that leaves is the one
// whose departure leaves the other multipliers best signed (each candidate tried: the new
// set's multipliers at this point, a square solve of n columns). False when none can leave.
bool ChooseLeaving(const ScaledDesignNlp& nlp, const SetState& st, double g_norm,
                   SetChange* change) {
  const int n = nlp.n();
  const Working now = WorkingOf(st.side, st.fixed);
  // Columns in the certificate's signs: grad f + sum_c mu_c a_c = 0, mu_c >= 0 except for
  // equalities.
  struct Col {
    int row, var, sign;
  };
  std::vector<Col> cols;
  for (int k : now.rows) {
    const int sd = st.side[static_cast<std::size_t>(k)];
    cols.push_back({k, -1, sd == kAtLower ? -1 : 1});
  }
  for (std::size_t jj = 0; jj < st.fixed.size(); ++jj)
    if (st.fixed[jj] != 0) cols.push_back({-1, static_cast<int>(jj), st.fixed[jj] == 1 ? -1 : 1});
  const Col added = change->add_row >= 0
                        ? Col{change->add_row, -1, change->add_side == kAtLower ? -1 : 1}
                        : Col{-1, change->add_var, change->add_side == 1 ? -1 : 1};
  const auto column = [&](const Col& c) {
    Eigen::VectorXd v = c.row >= 0 ? Eigen::VectorXd(nlp.jacobian().row(c.row).transpose())
                                   : Eigen::VectorXd::Unit(n, c.var);
    return Eigen::VectorXd(c.sign * v);
  };
  const auto is_equality = [&](const Col& c) {
    return c.row >= 0 && st.side[static_cast<std::size_t>(c.row)] == kEquality;
  };
  double best = -std::numeric_limits<double>::infinity();
  change->drop_row = change->drop_var = -1;
  for (std::size_t out_c = 0; out_c < cols.size(); ++out_c) {
    if (is_equality(cols[out_c])) continue;
    Eigen::MatrixXd a(n, static_cast<Eigen::Index>(cols.size()));
    std::vector<bool> equality(cols.size(), false);
    Eigen::Index c = 0;
    for (std::size_t q = 0; q < cols.size(); ++q) {
      if (q == out_c) continue;
      equality[static_cast<std::size_t>(c)] = is_equality(cols[q]);
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
      change->drop_row = cols[out_c].row;
      change->drop_var = cols[out_c].var;
    }
  }
  return change->drop();
}

void ApplyChange(const SetChange& c, SetState* st) {
  if (c.drop_row >= 0) st->side[static_cast<std::size_t>(c.drop_row)] = kInactive;
  if (c.drop_var >= 0) st->fixed[static_cast<std::size_t>(c.drop_var)] = 0;
  if (c.add_row >= 0) st->side[static_cast<std::size_t>(c.add_row)] = c.add_side;
  if (c.add_var >= 0) {
    st->fixed[static_cast<std::size_t>(c.add_var)] = c.add_side;
    st->s[static_cast<std::size_t>(c.add_var)] = c.add_side == 1 ? 0.0 : 1.0;
  }
}

// The KKT point of the active set: every multiplier in its sign, every constraint held.
void Converged(const ScaledDesignNlp& nlp, const SetState& st, const SetMultipliers& sm,
               int changes, LocalSolveOutcome* out) {
  const auto nn = static_cast<std::size_t>(nlp.n()), mm = static_cast<std::size_t>(nlp.m());
  out->s = st.s;
  out->has_point = true;
  out->lambda.assign(mm, 0.0);
  out->z_lower.assign(nn, 0.0);
  out->z_upper.assign(nn, 0.0);
  for (std::size_t a = 0; a < sm.w.rows.size(); ++a)
    out->lambda[static_cast<std::size_t>(sm.w.rows[a])] = sm.mu(static_cast<Eigen::Index>(a));
  for (std::size_t jj = 0; jj < nn; ++jj) {
    if (st.fixed[jj] == 1) out->z_lower[jj] = sm.full(static_cast<Eigen::Index>(jj));
    if (st.fixed[jj] == 2) out->z_upper[jj] = -sm.full(static_cast<Eigen::Index>(jj));
  }
  out->has_multipliers = true;
  out->termination = Termination::kConverged;
  out->raw_status = 0;
  out->evaluations = nlp.evaluations();
  out->message = std::to_string(changes) + " active-set changes";
}

}  // namespace

LocalSolveOutcome SolveWithActiveSetNewton(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                           const ActiveSetGuess& guess,
                                           const LocalSolveSettings& settings) {
  LocalSolveOutcome out;
  out.status_name = "active-set Newton";
  out.termination = Termination::kNoConvergence;
  const auto nn = static_cast<std::size_t>(nlp.n()), mm = static_cast<std::size_t>(nlp.m());
  if (s0.size() != nn || guess.constraint_side.size() != mm || guess.bound.size() != nn) {
    out.termination = Termination::kFailure;
    out.message = "the active-set guess does not fit the problem";
    return out;
  }
  try {
    SetState st = InitialState(nlp, s0, guess);
    Eigen::MatrixXd h;
    const auto fail = [&](Termination t, const std::string& why) {
      out.termination = t;
      out.message = why;
      out.s = st.s;
      out.has_point = true;
      out.evaluations = nlp.evaluations();
      return out;
    };
    for (int change = 0; change <= kActiveSetNewtonMaxChanges; ++change) {
      const NewtonEnd newton = NewtonOnWorkingSet(nlp, settings, &st, &h, &out);
      if (!newton.settled) return fail(newton.termination, newton.why);
      // Is the working set the active set? Primal: a bound or constraint left out is violated;
      // dual: a multiplier has the wrong sign.
      const SetMultipliers sm = MultipliersAt(nlp, st);
      SetChange c;
      FindDrop(st, sm, settings.tolerance, &c);
      FindAdd(nlp, st, settings.constraint_tolerance, &c);
      if (!c.add() && !c.drop()) {
        Converged(nlp, st, sm, change, &out);
        return out;
      }
      if (change == kActiveSetNewtonMaxChanges) break;
      const Working now = WorkingOf(st.side, st.fixed);
      if (c.add() && now.rows.size() + 1 > now.cols.size() - (c.add_var >= 0 ? 1 : 0) &&
          !ChooseLeaving(nlp, st, sm.g_norm, &c)) {
        return fail(Termination::kNoConvergence, "no constraint can leave for the violated one");
      }
      ApplyChange(c, &st);
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
