// The lifted formulation with the taper's steps as variables: see tapered_nlp.hpp.
#include "core/optimize/tapered_nlp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sweetspot::core {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// A variable's bound is implied by the chain when it is at most this (scaled units) beyond
// what the chain's bounds already force.
constexpr double kImpliedSlack = 1e-12;

}  // namespace

TaperedLiftedNlp::TaperedLiftedNlp(LiftedDesignNlp& lifted, const std::vector<double>& s0,
                                   int block_size)
    : lifted_(lifted), k_(lifted.design_variables()) {
  const int nx = k_, ml = lifted_.m();
  lifted_.Bounds(&z_lower_, &z_upper_, &lg_lower_, &lg_upper_);
  std::vector<double> z0;
  if (nx < 2 || block_size < 1 || !lifted_.Start(s0, &z0) || !lifted_.Evaluate(z0.data(), true))
    return;
  // Per lifted row: its entries on design variables and on q.
  RowEntries entries;
  entries.design.resize(static_cast<std::size_t>(ml));
  entries.q.resize(static_cast<std::size_t>(ml));
  const auto& jac = lifted_.jacobian_structure();
  for (std::size_t e = 0; e < jac.size(); ++e) {
    (jac[e].second < nx ? entries.design : entries.q)[static_cast<std::size_t>(jac[e].first)]
        .push_back(static_cast<int>(e));
  }
  if (!FindChain(entries)) return;
  std::vector<bool> bound_row;
  const ChainRows chain = SetSteps(block_size, entries, z0, &bound_row);
  KeepRows(chain, bound_row);
  BuildStructures(entries);
  g_.assign(rows_.size(), 0.0);
  grad_f_.assign(static_cast<std::size_t>(n()), 0.0);
  ok_ = true;
}

bool TaperedLiftedNlp::FindChain(const RowEntries& entries) {
  const int nx = k_, ml = lifted_.m();
  const auto& jac = lifted_.jacobian_structure();
  // The taper rows: two design entries, one positive (the later knot), one negative, >= lo.
  std::vector<int> incoming(static_cast<std::size_t>(nx), -1),
      outgoing(static_cast<std::size_t>(nx), -1);
  std::vector<int> to(static_cast<std::size_t>(ml), -1);
  for (int r = 0; r < ml; ++r) {
    const auto& de = entries.design[static_cast<std::size_t>(r)];
    if (de.size() != 2 || !entries.q[static_cast<std::size_t>(r)].empty()) continue;
    if (!std::isfinite(lg_lower_[static_cast<std::size_t>(r)]) ||
        std::isfinite(lg_upper_[static_cast<std::size_t>(r)]))
      continue;
    const double v0 = lifted_.jacobian_values()[static_cast<std::size_t>(de[0])];
    const double v1 = lifted_.jacobian_values()[static_cast<std::size_t>(de[1])];
    if (!(v0 * v1 < 0.0)) continue;
    const int plus = jac[static_cast<std::size_t>(v0 > 0.0 ? de[0] : de[1])].second;
    const int minus = jac[static_cast<std::size_t>(v0 > 0.0 ? de[1] : de[0])].second;
    if (incoming[static_cast<std::size_t>(plus)] >= 0 ||
        outgoing[static_cast<std::size_t>(minus)] >= 0)
      return false;  // not one chain
    incoming[static_cast<std::size_t>(plus)] = r;
    outgoing[static_cast<std::size_t>(minus)] = r;
    to[static_cast<std::size_t>(r)] = plus;
  }
  int first = -1;
  for (int j = 0; j < nx; ++j) {
    if (incoming[static_cast<std::size_t>(j)] >= 0) continue;
    if (first >= 0) return false;  // two heads
    first = j;
  }
  if (first < 0) return false;
  for (int j = first; j >= 0;) {
    var_.push_back(j);
    const int r = outgoing[static_cast<std::size_t>(j)];
    chain_row_.push_back(var_.size() == 1 ? -1 : incoming[static_cast<std::size_t>(j)]);
    j = r >= 0 ? to[static_cast<std::size_t>(r)] : -1;
    if (static_cast<int>(var_.size()) > nx) return false;
  }
  if (static_cast<int>(var_.size()) != nx) return false;
  pos_.assign(static_cast<std::size_t>(nx), -1);
  for (int i = 0; i < nx; ++i)
    pos_[static_cast<std::size_t>(var_[static_cast<std::size_t>(i)])] = i;
  return true;
}

TaperedLiftedNlp::ChainRows TaperedLiftedNlp::SetSteps(int block_size, const RowEntries& entries,
                                                       const std::vector<double>& z0,
                                                       std::vector<bool>* bound_row) {
  const int nx = k_;
  const auto nn = static_cast<std::size_t>(nx);
  const auto& jac = lifted_.jacobian_structure();
  // s_i = a_i y_i + c_i s_(i-1) + e_i from t_i = p s_i + q s_(i-1) + c = y_i; a head: s_i = y_i.
  a_.assign(nn, 1.0);
  c_.assign(nn, 0.0);
  e_.assign(nn, 0.0);
  y_lower_.assign(nn, -kInfinity);
  y_upper_.assign(nn, kInfinity);
  // Blocks of block_size chain positions: a block's head keeps its own s as its variable (its
  // bounds its own, the taper row into it a row), the others their taper step.
  block_start_.assign(nn, 0);
  for (int i = 0; i < nx; ++i) block_start_[static_cast<std::size_t>(i)] = i - i % block_size;
  ChainRows chain;
  chain.p.assign(nn, 1.0);
  chain.q.assign(nn, 0.0);
  chain.c.assign(nn, 0.0);
  chain.lo.assign(nn, 0.0);
  bound_row->assign(static_cast<std::size_t>(lifted_.m()), false);
  for (int i = 0; i < nx; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    if (i > 0) {
      const int r = chain_row_[ii];
      for (int e : entries.design[static_cast<std::size_t>(r)]) {
        const double v = lifted_.jacobian_values()[static_cast<std::size_t>(e)];
        (jac[static_cast<std::size_t>(e)].second == var_[ii] ? chain.p[ii] : chain.q[ii]) = v;
      }
      chain.c[ii] = lifted_.g()[static_cast<std::size_t>(r)] -
                    chain.p[ii] * z0[static_cast<std::size_t>(var_[ii])] -
                    chain.q[ii] * z0[static_cast<std::size_t>(var_[ii - 1])];
      chain.lo[ii] = lg_lower_[static_cast<std::size_t>(r)];
    }
    if (IsHead(i)) {
      y_lower_[ii] = z_lower_[static_cast<std::size_t>(var_[ii])];
      y_upper_[ii] = z_upper_[static_cast<std::size_t>(var_[ii])];
      continue;
    }
    a_[ii] = 1.0 / chain.p[ii];
    c_[ii] = -chain.q[ii] / chain.p[ii];
    e_[ii] = -chain.c[ii] / chain.p[ii];
    y_lower_[ii] = chain.lo[ii];
    (*bound_row)[static_cast<std::size_t>(chain_row_[ii])] = true;
  }
  return chain;
}

void TaperedLiftedNlp::KeepRows(const ChainRows& chain, const std::vector<bool>& bound_row) {
  const int nx = k_, ml = lifted_.m();
  // The variables' own bounds the taper rows do not imply become rows (a head's are its y's):
  // lower bounds forward, upper bounds backward. p s_i + q s_(i-1) + c >= lo with p > 0 > q.
  std::vector<bool> lower_row(static_cast<std::size_t>(nx), false),
      upper_row(static_cast<std::size_t>(nx), false);
  double forced = z_lower_[static_cast<std::size_t>(var_[0])];
  for (int i = 1; i < nx; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    const double implied = (chain.lo[ii] - chain.c[ii] - chain.q[ii] * forced) / chain.p[ii];
    const double own = z_lower_[static_cast<std::size_t>(var_[ii])];
    lower_row[ii] = !IsHead(i) && own > implied + kImpliedSlack;
    forced = std::max(own, implied);
  }
  forced = z_upper_[static_cast<std::size_t>(var_[static_cast<std::size_t>(nx - 1)])];
  upper_row[static_cast<std::size_t>(nx - 1)] = !IsHead(nx - 1);
  for (int i = nx - 2; i >= 1; --i) {
    const auto ii = static_cast<std::size_t>(i), next = ii + 1;
    const double implied =
        (chain.p[next] * forced + chain.c[next] - chain.lo[next]) / -chain.q[next];
    const double own = z_upper_[static_cast<std::size_t>(var_[ii])];
    upper_row[ii] = !IsHead(i) && own < implied - kImpliedSlack;
    forced = std::min(own, implied);
  }
  // Rows: the lifted ones but the taper rows made bounds, then the variables' bounds kept.
  lifted_to_row_.assign(static_cast<std::size_t>(ml), -1);
  for (int r = 0; r < ml; ++r) {
    if (bound_row[static_cast<std::size_t>(r)]) continue;
    lifted_to_row_[static_cast<std::size_t>(r)] = static_cast<int>(rows_.size());
    rows_.push_back(r);
    row_lower_.push_back(lg_lower_[static_cast<std::size_t>(r)]);
    row_upper_.push_back(lg_upper_[static_cast<std::size_t>(r)]);
  }
  for (int i = 1; i < nx; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    if (!lower_row[ii] && !upper_row[ii]) continue;
    rows_.push_back(-(1 + i));
    row_lower_.push_back(lower_row[ii] ? z_lower_[static_cast<std::size_t>(var_[ii])] : -kInfinity);
    row_upper_.push_back(upper_row[ii] ? z_upper_[static_cast<std::size_t>(var_[ii])] : kInfinity);
  }
}

void TaperedLiftedNlp::BuildStructures(const RowEntries& entries) {
  const int nx = k_;
  const auto& jac = lifted_.jacobian_structure();
  // The Jacobian: s_p depends on y from its block's head to p, so a row's entries are the
  // union of those ranges over its design entries, then its q entries.
  std::vector<char> used(static_cast<std::size_t>(nx));
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const int lr = rows_[r];
    std::fill(used.begin(), used.end(), 0);
    const auto mark = [&](int p) {
      for (int i = block_start_[static_cast<std::size_t>(p)]; i <= p; ++i)
        used[static_cast<std::size_t>(i)] = 1;
    };
    if (lr < 0) {
      mark(-lr - 1);
    } else {
      for (int e : entries.design[static_cast<std::size_t>(lr)])
        mark(pos_[static_cast<std::size_t>(jac[static_cast<std::size_t>(e)].second)]);
    }
    for (int i = 0; i < nx; ++i)
      if (used[static_cast<std::size_t>(i)]) jac_.push_back({static_cast<int>(r), i});
    if (lr >= 0) {
      for (int e : entries.q[static_cast<std::size_t>(lr)])
        jac_.push_back({static_cast<int>(r), k_ + jac[static_cast<std::size_t>(e)].second - nx});
    }
  }
  jac_values_.assign(jac_.size(), 0.0);
  // The Hessian's lower triangle over y: each block's, and a head's row against the previous
  // block (H_s couples the previous block's last s, which all of that block's y move, to it).
  hess_index_.assign(static_cast<std::size_t>(nx) * static_cast<std::size_t>(nx), -1);
  for (int r = 0; r < k_; ++r) {
    const int from_col = IsHead(r) && r > 0 ? block_start_[static_cast<std::size_t>(r - 1)]
                                            : block_start_[static_cast<std::size_t>(r)];
    for (int c = from_col; c <= r; ++c) {
      hess_index_[static_cast<std::size_t>(r) * static_cast<std::size_t>(nx) +
                  static_cast<std::size_t>(c)] = static_cast<int>(hess_.size());
      hess_.push_back({r, c});
    }
  }
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b <= a; ++b) hess_.push_back({k_ + a, k_ + b});
  // The lifted Hessian's design entries per chain column (both halves), and q's block.
  const auto& lh = lifted_.hessian_structure();
  column_entries_.assign(static_cast<std::size_t>(nx), {});
  for (std::size_t e = 0; e < lh.size(); ++e) {
    if (lh[e].first >= nx || lh[e].second >= nx) continue;
    const int pa = pos_[static_cast<std::size_t>(lh[e].first)];
    const int pb = pos_[static_cast<std::size_t>(lh[e].second)];
    column_entries_[static_cast<std::size_t>(pb)].push_back({static_cast<int>(e), pa});
    if (pa != pb)
      column_entries_[static_cast<std::size_t>(pa)].push_back({static_cast<int>(e), pb});
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b <= a; ++b) {
      int found = -1;
      for (std::size_t e = 0; e < lh.size(); ++e)
        if (lh[e].first == nx + a && lh[e].second == nx + b) found = static_cast<int>(e);
      q_block_entries_.push_back(found);
    }
  }
}

void TaperedLiftedNlp::Bounds(std::vector<double>* w_lower, std::vector<double>* w_upper,
                              std::vector<double>* g_lower, std::vector<double>* g_upper) const {
  *w_lower = y_lower_;
  *w_upper = y_upper_;
  for (int a = 0; a < 3; ++a) {
    w_lower->push_back(z_lower_[static_cast<std::size_t>(k_ + a)]);
    w_upper->push_back(z_upper_[static_cast<std::size_t>(k_ + a)]);
  }
  *g_lower = row_lower_;
  *g_upper = row_upper_;
}

bool TaperedLiftedNlp::Start(const std::vector<double>& s0, std::vector<double>* w) const {
  std::vector<double> z;
  if (!lifted_.Start(s0, &z)) return false;
  w->assign(static_cast<std::size_t>(n()), 0.0);
  for (int i = 0; i < k_; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    const double s = z[static_cast<std::size_t>(var_[ii])];
    const double prev = i == 0 ? 0.0 : z[static_cast<std::size_t>(var_[ii - 1])];
    (*w)[ii] = (s - c_[ii] * prev - e_[ii]) / a_[ii];  // a head: a = 1, c = e = 0
  }
  for (int a = 0; a < 3; ++a)
    (*w)[static_cast<std::size_t>(k_ + a)] = z[static_cast<std::size_t>(k_ + a)];
  return std::all_of(w->begin(), w->end(), [](double v) { return std::isfinite(v); });
}

std::vector<double> TaperedLiftedNlp::LiftedPoint(const double* w) const {
  std::vector<double> z(static_cast<std::size_t>(k_ + 3));
  double prev = 0.0;
  for (int i = 0; i < k_; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    prev = a_[ii] * w[i] + c_[ii] * prev + e_[ii];
    z[static_cast<std::size_t>(var_[ii])] = prev;
  }
  for (int a = 0; a < 3; ++a) z[static_cast<std::size_t>(k_ + a)] = w[k_ + a];
  return z;
}

void TaperedLiftedNlp::ApplyAT(std::vector<double>* v) const {
  double acc = 0.0;
  for (int i = k_ - 1; i >= 0; --i) {
    const auto ii = static_cast<std::size_t>(i);
    acc = (*v)[ii] + (i + 1 < k_ ? c_[ii + 1] * acc : 0.0);
    (*v)[ii] = a_[ii] * acc;
  }
}

void TaperedLiftedNlp::ColumnOfA(int i, std::vector<double>* u) const {
  std::fill(u->begin(), u->end(), 0.0);
  (*u)[static_cast<std::size_t>(i)] = a_[static_cast<std::size_t>(i)];
  for (int k = i + 1; k < k_; ++k)
    (*u)[static_cast<std::size_t>(k)] =
        c_[static_cast<std::size_t>(k)] * (*u)[static_cast<std::size_t>(k - 1)];
}

bool TaperedLiftedNlp::Evaluate(const double* w, bool with_gradients) {
  const auto nw = static_cast<std::size_t>(n());
  const bool same = have_values_ && std::equal(last_w_.begin(), last_w_.end(), w);
  if (same && (!with_gradients || have_gradients_)) return true;
  if (!same) {
    last_w_.assign(w, w + nw);
    have_values_ = have_gradients_ = false;
  }
  const std::vector<double> z = LiftedPoint(w);
  if (!lifted_.Evaluate(z.data(), with_gradients)) return false;
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const int lr = rows_[r];
    g_[r] = lr >= 0 ? lifted_.g()[static_cast<std::size_t>(lr)]
                    : z[static_cast<std::size_t>(var_[static_cast<std::size_t>(-lr - 1)])];
  }
  have_values_ = true;
  if (!with_gradients) return true;
  const auto ks = static_cast<std::size_t>(k_);
  std::vector<double> v(ks);
  for (std::size_t i = 0; i < ks; ++i) v[i] = lifted_.grad_f()[static_cast<std::size_t>(var_[i])];
  ApplyAT(&v);
  std::copy(v.begin(), v.end(), grad_f_.begin());
  for (int a = 0; a < 3; ++a)
    grad_f_[static_cast<std::size_t>(k_ + a)] = lifted_.grad_f()[static_cast<std::size_t>(k_ + a)];
  // Per row: its gradient over s (chain order), A^T of it, then its q entries.
  const auto& ljac = lifted_.jacobian_structure();
  const auto& lval = lifted_.jacobian_values();
  std::vector<std::vector<double>> grad_s(rows_.size());
  std::vector<std::vector<double>> grad_q(rows_.size());
  for (std::size_t e = 0; e < ljac.size(); ++e) {
    const int r = lifted_to_row_[static_cast<std::size_t>(ljac[e].first)];
    if (r < 0) continue;
    const auto rr = static_cast<std::size_t>(r);
    if (ljac[e].second < k_) {
      if (grad_s[rr].empty()) grad_s[rr].assign(ks, 0.0);
      grad_s[rr][static_cast<std::size_t>(pos_[static_cast<std::size_t>(ljac[e].second)])] +=
          lval[e];
    } else {
      grad_q[rr].push_back(lval[e]);
    }
  }
  std::size_t at = 0;
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const int lr = rows_[r];
    if (lr < 0) {
      grad_s[r].assign(ks, 0.0);
      grad_s[r][static_cast<std::size_t>(-lr - 1)] = 1.0;
    }
    if (!grad_s[r].empty()) ApplyAT(&grad_s[r]);
    for (; at < jac_.size() && jac_[at].first == static_cast<int>(r) && jac_[at].second < k_; ++at)
      jac_values_[at] = grad_s[r][static_cast<std::size_t>(jac_[at].second)];
    for (double v_q : grad_q[r]) jac_values_[at++] = v_q;
  }
  have_gradients_ = true;
  return true;
}

bool TaperedLiftedNlp::Hessian(const double* w, double sigma_f, const double* lambda,
                               double* values) {
  const std::vector<double> z = LiftedPoint(w);
  std::vector<double> lifted_lambda(static_cast<std::size_t>(lifted_.m()), 0.0);
  for (std::size_t r = 0; r < lifted_lambda.size(); ++r) {
    const int t = lifted_to_row_[r];
    if (t >= 0) lifted_lambda[r] = lambda[t];
  }
  const auto& lh = lifted_.hessian_structure();
  std::vector<double> lv(lh.size());
  if (!lifted_.Hessian(z.data(), sigma_f, lifted_lambda.data(), lv.data())) return false;
  const auto ks = static_cast<std::size_t>(k_);
  // H_y = A^T H_s A. B = H_s A column by column from the last: A's columns satisfy
  // u_i = a_i e_i + rho_i u_(i+1) (rho_i = a_i c_(i+1) / a_(i+1)), so
  // B_i = a_i H_s e_i + rho_i B_(i+1); then each column of H_y is A^T B_i (ApplyAT): O(k^2).
  b_.assign(ks * ks, 0.0);
  for (int i = k_ - 1; i >= 0; --i) {
    const auto ii = static_cast<std::size_t>(i);
    double* bi = &b_[ii * ks];
    if (i + 1 < k_) {
      const double rho = a_[ii] * c_[ii + 1] / a_[ii + 1];
      const double* next = &b_[(ii + 1) * ks];
      for (std::size_t r = 0; r < ks; ++r) bi[r] = rho * next[r];
    }
    for (const auto& [e, other] : column_entries_[ii])
      bi[static_cast<std::size_t>(other)] += a_[ii] * lv[static_cast<std::size_t>(e)];
  }
  column_.resize(ks);
  for (int i = 0; i < k_; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    std::copy(&b_[ii * ks], &b_[ii * ks] + ks, column_.begin());
    ApplyAT(&column_);
    for (int r = i; r < k_; ++r) {
      const int e = hess_index_[static_cast<std::size_t>(r) * ks + ii];
      if (e >= 0) {
        values[static_cast<std::size_t>(e)] = column_[static_cast<std::size_t>(r)];
      } else if (column_[static_cast<std::size_t>(r)] != 0.0) {
        return false;  // outside the declared structure: H_s coupled more than adjacent knots
      }
    }
  }
  std::size_t at = hess_.size() - 6;
  for (int e : q_block_entries_) values[at++] = e >= 0 ? lv[static_cast<std::size_t>(e)] : 0.0;
  return std::all_of(values, values + hess_.size(), [](double v) { return std::isfinite(v); });
}

void TaperedLiftedNlp::DesignMultipliers(const double* w_lower, const double* w_upper,
                                         const double* lambda, std::vector<double>* design_lambda,
                                         std::vector<double>* design_z_lower,
                                         std::vector<double>* design_z_upper) const {
  // The lifted problem's multipliers: its rows' (a chain row's from its y bound: the row is
  // y_i itself), its variables' bounds (the head's from y_0's, the others' from their rows).
  const auto nz = static_cast<std::size_t>(k_ + 3);
  std::vector<double> zl(nz, 0.0), zu(nz, 0.0);
  std::vector<double> ll(static_cast<std::size_t>(lifted_.m()), 0.0);
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const int lr = rows_[r];
    if (lr >= 0) {
      ll[static_cast<std::size_t>(lr)] = lambda[r];
    } else {
      const auto j = static_cast<std::size_t>(var_[static_cast<std::size_t>(-lr - 1)]);
      if (lambda[r] < 0.0) zl[j] = -lambda[r];
      if (lambda[r] > 0.0) zu[j] = lambda[r];
    }
  }
  for (int i = 0; i < k_; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    if (block_start_[ii] == i) {  // a head: y is s, its bounds s's
      zl[static_cast<std::size_t>(var_[ii])] += w_lower[i];
      zu[static_cast<std::size_t>(var_[ii])] += w_upper[i];
    } else {
      ll[static_cast<std::size_t>(chain_row_[ii])] = w_upper[i] - w_lower[i];
    }
  }
  lifted_.DesignMultipliers(zl.data(), zu.data(), ll.data(), design_lambda, design_z_lower,
                            design_z_upper);
}

}  // namespace sweetspot::core
