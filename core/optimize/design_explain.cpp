// Why a design request is infeasible: the reach of each constraint's function within the
// variable bounds and the other constraints, and the conflicting pairs. See design_runs.hpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_runs.hpp"

namespace sweetspot::core::design_detail {
namespace {

std::string WithUnit(double v, const std::string& unit) {
  return FormatNumber(v) + (unit.empty() ? "" : " " + unit);
}

// Words for the ends of a property's range in the conflict messages.
struct RangeWords {
  const char* least;
  const char* most;
};

RangeWords WordsFor(const DesignConstraintSpec& c) {
  switch (c.f.function) {
    case DesignFunction::kMass:
      return {"the lightest bat", "the heaviest bat"};
    case DesignFunction::kBalancePoint:
      return {"the balance point nearest the knob", "the balance point farthest from the knob"};
    case DesignFunction::kMoiSixInch:
      return {"the least MOI about the 6-in point", "the largest MOI about the 6-in point"};
    case DesignFunction::kDrop:
      return {"the least length_in - weight_oz", "the largest length_in - weight_oz"};
    case DesignFunction::kFirstFrequency:
      return {"the lowest first bending frequency", "the highest first bending frequency"};
    case DesignFunction::kBbcor:
      return {"the least BBCOR", "the largest BBCOR"};
    default:
      if (c.name.rfind("length_m", 0) == 0 || c.name.find(".length") != std::string::npos) {
        return {"the shortest bat", "the longest bat"};
      }
      return {"the least value", "the largest value"};
  }
}

// "mass_kg = 0.5", "balance_point_m in [0.56, 0.6]", "rules.bbcor.drop <= 3".
std::string Requested(const DesignConstraintSpec& c) {
  if (c.lower == c.upper) return c.name + " = " + WithUnit(c.lower, c.unit);
  if (!std::isfinite(c.lower)) return c.max_name + " = " + WithUnit(c.upper, c.unit);
  if (!std::isfinite(c.upper)) return c.min_name + " = " + WithUnit(c.lower, c.unit);
  return c.name + " in [" + FormatNumber(c.lower) + ", " + WithUnit(c.upper, c.unit) + "]";
}

// Least and largest value of constraint k's function under the constraints `keep`.
struct Reach {
  bool known = false;
  double least = kNaN;
  double most = kNaN;
};

Reach ReachOf(const DesignModel& model, int k, const std::vector<int>& keep,
              const DesignOptions& options, Clock::time_point deadline, Progress* progress,
              int* evaluations, int* iterations) {
  Reach out;
  const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
  const DesignModel restricted = model.WithConstraints(keep);
  double ends[2] = {kNaN, kNaN};
  for (int side = 0; side < 2; ++side) {
    if (Clock::now() >= deadline || IsCancelled(progress)) return out;
    const DesignModel m = restricted.WithObjective(c.f, side == 1, c.scale, c.unit);
    ScaledDesignNlp nlp(m);
    LocalSolveSettings settings = SettingsFrom(options, deadline, progress);
    const LocalSolveOutcome o =
        Solve(SmoothBackend(options), nlp, nlp.ToScaled(m.BaseX()), settings);
    *evaluations += o.evaluations;
    *iterations += o.iterations;
    const Run run = Finish(m, o);
    if (o.termination != Termination::kConverged || !run.feasible) return out;
    ends[side] = run.objective;
  }
  out.known = true;
  out.least = ends[0];
  out.most = ends[1];
  return out;
}

// Adds constraint k to d->constraints, and "name (off by v unit)" to *names, when x violates
// it beyond the feasibility tolerance.
void NoteViolation(const DesignModel& model, int k, const std::vector<double>& x, DesignConflict* d,
                   std::string* names) {
  const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
  const double viol = Violation(c, model.Value(c.f, x.data()));
  if (!(viol > kFeasibleRelative * c.scale)) return;
  d->constraints.push_back(c.name);
  if (!names->empty()) *names += ", ";
  *names += c.name + " (off by " + WithUnit(viol, c.unit) + ")";
}

}  // namespace

// Why no design meets the constraints: single constraints that cannot be met within the
// variable bounds and the geometric constraints, then pairs of property constraints.
std::vector<DesignConflict> Explain(const DesignModel& model, const DesignOptions& options,
                                    Clock::time_point deadline, Progress* progress,
                                    const Run& least_violating, bool solver_says_infeasible,
                                    int* evaluations, int* iterations) {
  std::vector<DesignConflict> out;
  std::vector<int> property, structural;
  for (int k = 0; k < model.m(); ++k) {
    (model.constraints()[static_cast<std::size_t>(k)].property ? property : structural)
        .push_back(k);
  }
  const bool has_structural = !structural.empty();
  const std::string within = has_structural
                                 ? "within the variable bounds and the geometric constraints"
                                 : "within the variable bounds";
  auto conflict = [&](ConflictKind kind, const std::vector<int>& names, int k, const Reach& r,
                      const std::string& context) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    DesignConflict d;
    d.kind = kind;
    for (int q : names)
      d.constraints.push_back(model.constraints()[static_cast<std::size_t>(q)].name);
    d.unit = c.unit;
    d.requested_min = c.lower;
    d.requested_max = c.upper;
    d.achievable_min = r.least;
    d.achievable_max = r.most;
    const RangeWords words = WordsFor(c);
    if (c.lower > r.most) {
      d.shortfall = c.lower - r.most;
      d.message = Requested(c) + " is above " + words.most + " " + context + ": " +
                  WithUnit(r.most, c.unit) + " (short by " + WithUnit(d.shortfall, c.unit) + ")";
    } else {
      d.shortfall = r.least - c.upper;
      d.message = Requested(c) + " is below " + words.least + " " + context + ": " +
                  WithUnit(r.least, c.unit) + " (over by " + WithUnit(d.shortfall, c.unit) + ")";
    }
    out.push_back(std::move(d));
  };
  auto excluded = [](const DesignConstraintSpec& c, const Reach& r) {
    const double tol = kFeasibleRelative * c.scale;
    return r.known && (c.lower > r.most + tol || c.upper < r.least - tol);
  };

  // 1. The geometric constraints alone.
  if (has_structural && !(Clock::now() >= deadline)) {
    DesignFunctionSpec zero;  // kLinear, no terms: a constant objective
    const DesignModel m = model.WithConstraints(structural).WithObjective(zero, false, 1.0, "");
    ScaledDesignNlp nlp(m);
    const LocalSolveOutcome o = Solve(SmoothBackend(options), nlp, nlp.ToScaled(m.BaseX()),
                                      SettingsFrom(options, deadline, progress));
    *evaluations += o.evaluations;
    *iterations += o.iterations;
    const Run run = Finish(m, o);
    if (!run.feasible && o.termination == Termination::kInfeasible) {
      DesignConflict d;
      d.kind = ConflictKind::kGeometric;
      std::string names;
      for (int k : structural) NoteViolation(model, k, run.x, &d, &names);
      d.achievable_min = d.achievable_max = d.requested_min = d.requested_max = kNaN;
      d.shortfall = run.violation;
      d.message =
          "the variable bounds and the geometric constraints admit no design; at the "
          "least-violating design found: " +
          names;
      out.push_back(std::move(d));
      return out;
    }
  }
  // 2. Each property constraint against the bounds and the geometric constraints.
  for (int k : property) {
    const Reach r =
        ReachOf(model, k, structural, options, deadline, progress, evaluations, iterations);
    if (excluded(model.constraints()[static_cast<std::size_t>(k)], r))
      conflict(ConflictKind::kUnreachable, {k}, k, r, within);
  }
  if (!out.empty()) return out;
  // 3. Pairs of property constraints.
  for (std::size_t a = 0; a < property.size(); ++a) {
    for (std::size_t b = a + 1; b < property.size(); ++b) {
      const int k = property[a], l = property[b];
      std::vector<int> keep = structural;
      keep.push_back(l);
      const Reach r = ReachOf(model, k, keep, options, deadline, progress, evaluations, iterations);
      if (excluded(model.constraints()[static_cast<std::size_t>(k)], r)) {
        conflict(
            ConflictKind::kPair, {k, l}, k, r,
            "with " + Requested(model.constraints()[static_cast<std::size_t>(l)]) + " " + within);
      }
    }
  }
  if (!out.empty() || !solver_says_infeasible) return out;
  // 4. The solver found no feasible point and nothing smaller explains it: name what the
  // least-violating design breaks.
  DesignConflict d;
  d.kind = ConflictKind::kNotIsolated;
  std::string names;
  for (int k = 0; k < model.m(); ++k) NoteViolation(model, k, least_violating.x, &d, &names);
  d.achievable_min = d.achievable_max = d.requested_min = d.requested_max = kNaN;
  d.shortfall = least_violating.violation;
  d.message = names.empty() ? "no conflict could be isolated"
                            : "no smaller conflict could be isolated; the least-violating design "
                              "found misses: " +
                                  names;
  out.push_back(std::move(d));
  return out;
}

}  // namespace sweetspot::core::design_detail
