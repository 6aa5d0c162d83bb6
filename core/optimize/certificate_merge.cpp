// The merge of duplicated constraints before a design solve (MergeDuplicateConstraints): two
// constraints that are the same function up to an affine map, found at test points, become one.
// See certificate.hpp.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/certificate.hpp"
#include "core/optimize/design_model.hpp"

namespace sweetspot::core::design_detail {
namespace {

// Two constraints are the same function up to c_k = a c_l + b when, at every test point, the
// gradients agree to this (relative, max norm) and a and b stay the same to it: exact gradients
// of the same integrals agree to rounding (~1e-15).
constexpr double kDuplicateRelative = 1e-9;

// The merge's sums over a sparse row of at most this many entries have the dense sums' bits:
// two products (or squares) need one rounding in any order, and the zeros add nothing.
constexpr std::size_t kSparseExact = 2;

// A sparse row as a dense vector of n entries.
Eigen::VectorXd Dense(const DesignGradientRow& row, int n) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  for (const auto& [j, value] : row) v(j) = value;
  return v;
}

// The squared norm of a sparse row.
double SquaredNorm(const DesignGradientRow& row) {
  double s = 0.0;
  for (const auto& e : row) s += e.second * e.second;
  return s;
}

// The dot product of two sparse rows (both by increasing index).
double Dot(const DesignGradientRow& a, const DesignGradientRow& b) {
  double s = 0.0;
  for (std::size_t p = 0, q = 0; p < a.size() && q < b.size();) {
    if (a[p].first < b[q].first) {
      ++p;
    } else if (b[q].first < a[p].first) {
      ++q;
    } else {
      s += a[p++].second * b[q++].second;
    }
  }
  return s;
}

// max_j |a_j - t b_j| over two sparse rows (both by increasing index).
double MaxAbsDifference(const DesignGradientRow& a, double t, const DesignGradientRow& b) {
  double worst = 0.0;
  std::size_t p = 0, q = 0;
  while (p < a.size() || q < b.size()) {
    if (q == b.size() || (p < a.size() && a[p].first < b[q].first)) {
      worst = std::max(worst, std::abs(a[p++].second));
    } else if (p == a.size() || b[q].first < a[p].first) {
      worst = std::max(worst, std::abs(t * b[q++].second));
    } else {
      worst = std::max(worst, std::abs(a[p++].second - t * b[q++].second));
    }
  }
  return worst;
}

std::string RangeText(double lo, double hi, const std::string& unit) {
  const std::string u = unit.empty() ? "" : " " + unit;
  if (lo == hi) return "= " + FormatNumber(lo) + u;
  if (std::isfinite(lo) && std::isfinite(hi))
    return "in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]" + u;
  if (std::isfinite(hi)) return "<= " + FormatNumber(hi) + u;
  return ">= " + FormatNumber(lo) + u;
}

// Six significant digits (the relations of merged constraints).
std::string Short(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

// [lo, hi] contains [a, b] (to rounding of the affine map: `slop`).
bool Contains(double lo, double hi, double a, double b, double slop) {
  return lo <= a + slop && hi >= b - slop;
}

// The test points: the base design, the box's middle and 0.3 of the way across it.
std::vector<std::vector<double>> TestPoints(const DesignModel& model) {
  std::vector<std::vector<double>> points = {model.BaseX()};
  for (double t : {0.5, 0.3}) {
    std::vector<double> x(static_cast<std::size_t>(model.n()));
    for (std::size_t j = 0; j < x.size(); ++j) {
      const DesignVariableSpec& v = model.variables()[j];
      x[j] = v.lower + t * (v.upper - v.lower);
    }
    points.push_back(std::move(x));
  }
  return points;
}

}  // namespace

namespace {

// The merge's evaluations: the model at its test points, gradients by sparse rows.
struct MergePoints {
  std::vector<std::vector<double>> xs;  // the test points
  std::vector<DesignPoint> points;      // the evaluated ones
  std::vector<std::size_t> at;          // the x (index into xs) of each evaluated point
  const DesignGradientRow& row(std::size_t p, int k) const {
    return points[p].jacobian_rows[static_cast<std::size_t>(k)];
  }
};

// The model's own guards ("validity.*": a wall within every knot's radius, knots in order)
// are not the request's constraints: they are neither merged nor reported.
bool IsGuard(const DesignModel& model, int k) {
  return model.constraints()[static_cast<std::size_t>(k)].name.rfind("validity.", 0) == 0;
}

// A signature of each constraint's gradient direction at the first point (unit length, the
// largest entry positive, projected on a fixed vector), so that only neighbours in it are
// compared in full; sorted.
std::vector<std::pair<double, int>> Signatures(const DesignModel& model, const MergePoints& pts) {
  const int m = model.m(), n = model.n();
  Eigen::VectorXd probe(n);
  for (int j = 0; j < n; ++j) probe(j) = 1.0 + 0.5 * std::sin(1.0 + 0.7 * j);
  const double probe_norm = probe.norm();
  std::vector<std::pair<double, int>> signature;
  for (int k = 0; k < m; ++k) {
    if (IsGuard(model, k)) continue;
    const DesignGradientRow& r = pts.row(0, k);
    if (r.empty()) continue;  // fixed: no variable changes it
    if (r.size() > kSparseExact) {
      Eigen::VectorXd row = Dense(r, n);
      const double norm = row.norm();
      if (!(norm > 0.0) || !row.allFinite()) continue;
      Eigen::Index big = 0;
      row.cwiseAbs().maxCoeff(&big);
      row /= row(big) > 0 ? norm : -norm;
      signature.push_back({row.dot(probe) / probe_norm, k});
      continue;
    }
    // At most kSparseExact entries: every sum below has one rounding at most per term, in
    // any order, so the sparse sums have the dense ones' bits (the zeros add nothing).
    const double norm = std::sqrt(SquaredNorm(r));
    if (!(norm > 0.0) || !std::isfinite(norm)) continue;
    std::size_t big = 0;
    for (std::size_t e = 1; e < r.size(); ++e)
      if (std::abs(r[e].second) > std::abs(r[big].second)) big = e;
    const double divisor = r[big].second > 0 ? norm : -norm;
    double dot = 0.0;
    for (const auto& [j, v] : r) dot += (v / divisor) * probe(j);
    signature.push_back({dot / probe_norm, k});
  }
  std::sort(signature.begin(), signature.end());
  return signature;
}

// c_k = a c_l + b at every test point: *a, *b.
bool Affine(const MergePoints& pts, int n, int k, int l, double* a, double* b) {
  for (std::size_t p = 0; p < pts.points.size(); ++p) {
    const DesignGradientRow& rk = pts.row(p, k);
    const DesignGradientRow& rl = pts.row(p, l);
    double nl = 0.0, ap = 0.0, residual = 0.0, gk_max = 0.0;
    if (rk.size() > kSparseExact || rl.size() > kSparseExact) {
      const Eigen::VectorXd gk = Dense(rk, n), gl = Dense(rl, n);
      nl = gl.squaredNorm();
      if (!(nl > 0.0)) return false;
      ap = gk.dot(gl) / nl;
      residual = (gk - ap * gl).lpNorm<Eigen::Infinity>();
      gk_max = gk.lpNorm<Eigen::Infinity>();
    } else {
      nl = SquaredNorm(rl);
      if (!(nl > 0.0)) return false;
      ap = Dot(rk, rl) / nl;
      residual = MaxAbsDifference(rk, ap, rl);
      for (const auto& e : rk) gk_max = std::max(gk_max, std::abs(e.second));
    }
    if (residual > kDuplicateRelative * gk_max) return false;
    const double ck = pts.points[p].constraints[static_cast<std::size_t>(k)];
    const double cl = pts.points[p].constraints[static_cast<std::size_t>(l)];
    const double bp = ck - ap * cl;
    if (p == 0) {
      *a = ap;
      *b = bp;
    } else if (std::abs(ap - *a) > kDuplicateRelative * std::abs(*a) ||
               std::abs(bp - *b) > kDuplicateRelative * (std::abs(ck) + std::abs(ap * cl))) {
      return false;
    }
  }
  return std::isfinite(*a) && *a != 0.0 && std::isfinite(*b);
}

// Pairs of constraints on the same quantity (neighbours in the signature, affine in each other
// at every test point) that share a limit: the implied one is merged into the other.
void MergePairs(const DesignModel& model, const MergePoints& pts,
                const std::vector<std::pair<double, int>>& signature, std::vector<bool>* removed,
                std::vector<MergedConstraint>* merged) {
  const auto& cs = model.constraints();
  for (std::size_t p = 0; p < signature.size(); ++p) {
    for (std::size_t q = p + 1; q < signature.size(); ++q) {
      if (signature[q].first - signature[p].first > 1e-7) break;
      int k = signature[q].second, l = signature[p].second;
      if (k < l) std::swap(k, l);  // k the later constraint (removed on a tie)
      if ((*removed)[static_cast<std::size_t>(k)] || (*removed)[static_cast<std::size_t>(l)])
        continue;
      double a = 0.0, b = 0.0;
      if (!Affine(pts, model.n(), k, l, &a, &b)) continue;
      const DesignConstraintSpec& ck = cs[static_cast<std::size_t>(k)];
      const DesignConstraintSpec& cl = cs[static_cast<std::size_t>(l)];
      // c_k's range in c_l's quantity.
      double lo = (ck.lower - b) / a, hi = (ck.upper - b) / a;
      if (a < 0) std::swap(lo, hi);
      const double slop = 1e-12 * std::max({1.0, std::abs(cl.lower) * std::isfinite(cl.lower),
                                            std::abs(cl.upper) * std::isfinite(cl.upper)});
      // Only a pair that can be active together (a shared limit) is merged: a redundant
      // limit strictly inside the other's range never binds and changes nothing.
      const bool shares = (std::isfinite(lo) && (std::abs(lo - cl.lower) <= slop ||
                                                 std::abs(lo - cl.upper) <= slop)) ||
                          (std::isfinite(hi) &&
                           (std::abs(hi - cl.lower) <= slop || std::abs(hi - cl.upper) <= slop));
      if (!shares) continue;
      const std::string relation = ck.name + " = " + Short(a) + " " + cl.name +
                                   (b < 0 ? " - " : " + ") + Short(std::abs(b));
      int drop = -1, keep = -1;
      if (Contains(lo, hi, cl.lower, cl.upper, slop)) {
        drop = k;
        keep = l;
      } else if (Contains(cl.lower, cl.upper, lo, hi, slop)) {
        drop = l;
        keep = k;
      } else {
        continue;  // the ranges cross: both stay
      }
      const DesignConstraintSpec& d = cs[static_cast<std::size_t>(drop)];
      const DesignConstraintSpec& kept = cs[static_cast<std::size_t>(keep)];
      MergedConstraint mc;
      mc.name = d.name;
      mc.into = kept.name;
      mc.message = d.name + " (" + RangeText(d.lower, d.upper, d.unit) + ") and " + kept.name +
                   " (" + RangeText(kept.lower, kept.upper, kept.unit) +
                   ") constrain the same quantity (" + relation +
                   " for every design the "
                   "variables give) and share a limit: " +
                   kept.name + " implies " + d.name +
                   ", which is merged into it (its multiplier would not be unique)";
      merged->push_back(std::move(mc));
      (*removed)[static_cast<std::size_t>(drop)] = true;
    }
  }
}

// A constraint on one variable alone whose limit is one of the variable's bounds and whose
// range contains them: both would be active together; merged into the bounds.
void MergeIntoBounds(const DesignModel& model, const MergePoints& pts, std::vector<bool>* removed,
                     std::vector<MergedConstraint>* merged) {
  for (int k = 0; k < model.m(); ++k) {
    if ((*removed)[static_cast<std::size_t>(k)] || IsGuard(model, k)) continue;
    // One variable alone: every point's row has its one entry (the zeros are not kept).
    int var = -1;
    bool single = true;
    for (std::size_t p = 0; p < pts.points.size() && single; ++p) {
      for (const auto& e : pts.row(p, k)) {
        if (var >= 0 && var != e.first) single = false;
        var = e.first;
      }
    }
    if (!single || var < 0) continue;
    auto entry = [&pts, k](std::size_t p) {
      const DesignGradientRow& r = pts.row(p, k);
      return r.empty() ? 0.0 : r.front().second;
    };
    const double a = entry(0);
    bool linear = true;
    for (std::size_t p = 0; p < pts.points.size(); ++p)
      linear = linear && std::abs(entry(p) - a) <= kDuplicateRelative * std::abs(a);
    if (!linear) continue;
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(var)];
    const double b = pts.points.front().constraints[static_cast<std::size_t>(k)] -
                     a * pts.xs[pts.at.front()][static_cast<std::size_t>(var)];
    double lo = (c.lower - b) / a, hi = (c.upper - b) / a;
    if (a < 0) std::swap(lo, hi);
    const double slop = 1e-12 * std::max({1.0, std::abs(v.lower), std::abs(v.upper)});
    const bool shares = std::abs(lo - v.lower) <= slop || std::abs(hi - v.upper) <= slop;
    if (!shares || !Contains(lo, hi, v.lower, v.upper, slop)) continue;
    MergedConstraint mc;
    mc.name = c.name;
    mc.into = v.path;
    mc.message =
        c.name + " (" + RangeText(c.lower, c.upper, c.unit) + ") repeats a bound of " + v.path +
        " (in [" + FormatNumber(v.lower) + ", " + FormatNumber(v.upper) +
        "]) and shares a limit with them: the bounds imply it, so it is merged into them (its "
        "multiplier would not be unique)";
    merged->push_back(std::move(mc));
    (*removed)[static_cast<std::size_t>(k)] = true;
  }
}

}  // namespace

std::vector<MergedConstraint> MergeDuplicateConstraints(DesignModel* model) {
  std::vector<MergedConstraint> merged;
  const int m = model->m(), n = model->n();
  if (m == 0 || n == 0) return merged;
  try {
    MergePoints pts;
    pts.xs = TestPoints(*model);
    for (std::size_t i = 0; i < pts.xs.size(); ++i) {
      DesignPoint p;
      // The gradients by sparse rows (a knot's limit has 1 entry, the taper 2): the checks
      // below are O(entries), not O(m n), with the dense checks' bits (Row, Dot, Norm).
      if (!model->EvaluateRows(pts.xs[i].data(), &p)) continue;
      pts.points.push_back(std::move(p));
      pts.at.push_back(i);
    }
    if (pts.points.size() < 2) return merged;
    std::vector<bool> removed(static_cast<std::size_t>(m), false);
    MergePairs(*model, pts, Signatures(*model, pts), &removed, &merged);
    MergeIntoBounds(*model, pts, &removed, &merged);
    if (merged.empty()) return merged;
    std::vector<int> keep;
    for (int k = 0; k < m; ++k)
      if (!removed[static_cast<std::size_t>(k)]) keep.push_back(k);
    *model = model->WithConstraints(keep);
  } catch (const std::exception&) {
    merged.clear();
  }
  return merged;
}

}  // namespace sweetspot::core::design_detail
