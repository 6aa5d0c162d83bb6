#include "core/optimize/frontier.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/optimize/active_set_newton.hpp"
#include "core/optimize/bbcor_constraint.hpp"
#include "core/optimize/design_runs.hpp"

namespace sweetspot::core {
namespace {

struct QuantityName {
  FrontierQuantity quantity;
  const char* name;
};
constexpr QuantityName kQuantityNames[] = {
    {FrontierQuantity::kLengthM, "length_m"},
    {FrontierQuantity::kMassKg, "mass_kg"},
    {FrontierQuantity::kBalancePointM, "balance_point_m"},
    {FrontierQuantity::kMoiSixInchKgM2, "moi_six_inch_kg_m2"},
    {FrontierQuantity::kMinFrequencyHz, "min_frequency_hz"},
    {FrontierQuantity::kMaxBarrelDiameterM, "max_barrel_diameter_m"},
    {FrontierQuantity::kSpeedModelExponent, "swing_weight_exponent"},
};

bool IsRange(FrontierQuantity q) {
  return q == FrontierQuantity::kLengthM || q == FrontierQuantity::kMassKg ||
         q == FrontierQuantity::kBalancePointM || q == FrontierQuantity::kMoiSixInchKgM2;
}

DesignRange RangeOf(FrontierBound bound, double value) {
  switch (bound) {
    case FrontierBound::kAtMost:
      return DesignRange::AtMost(value);
    case FrontierBound::kAtLeast:
      return DesignRange::AtLeast(value);
    case FrontierBound::kEqual:
      break;
  }
  return DesignRange::Equal(value);
}

// True when the objective of `a` is better than `b`'s in the problem's sense.
bool Better(DesignObjective objective, double a, double b) {
  const bool minimise =
      objective == DesignObjective::kMinMoi || objective == DesignObjective::kMinSting;
  return minimise ? a < b : a > b;
}

// A usable answer ranks above an unusable one; converged above no_convergence; then the
// objective. True when `a` is the better answer.
bool BetterAnswer(DesignObjective objective, const DesignResult& a, const DesignResult& b) {
  const auto rank = [](const DesignResult& r) {
    switch (r.summary.termination) {
      case Termination::kConverged:
        return 3;
      case Termination::kNoConvergence:
        return 2;
      case Termination::kInfeasible:
        return 1;
      default:
        return 0;
    }
  };
  if (rank(a) != rank(b)) return rank(a) > rank(b);
  return Better(objective, a.objective_value, b.objective_value);
}

// The start of value k: the previous answer, moved along the secant through the two previous
// answers (profile radii and three-segment fields, the only fields a value moves smoothly);
// nullopt when the moved bat is not valid (the previous answer is used instead).
struct Start {
  Bat bat;
  std::optional<ThreeSegmentShape> shape;
  bool predicted = false;
};

Start PredictStart(const FrontierPoint* before, const FrontierPoint& last, double value) {
  Start start{last.result.bat, last.result.three_segment, false};
  if (before == nullptr || before->value == last.value) return start;
  const DesignResult& a = before->result;
  const DesignResult& b = last.result;
  const double t = (value - last.value) / (last.value - before->value);
  const auto move = [t](double from, double to) { return to + t * (to - from); };
  if (b.three_segment && a.three_segment) {
    ThreeSegmentShape s = *b.three_segment;
    s.length_m = move(a.three_segment->length_m, s.length_m);
    s.handle_radius_m = move(a.three_segment->handle_radius_m, s.handle_radius_m);
    s.barrel_radius_m = move(a.three_segment->barrel_radius_m, s.barrel_radius_m);
    s.taper_start_m = move(a.three_segment->taper_start_m, s.taper_start_m);
    s.taper_end_m = move(a.three_segment->taper_end_m, s.taper_end_m);
    if (!s.Validate(nullptr)) return start;
    start.shape = s;
    start.predicted = true;
    return start;
  }
  if (a.bat.knots.size() != b.bat.knots.size() || b.bat.knots.empty()) return start;
  Bat moved = b.bat;
  for (std::size_t i = 0; i < moved.knots.size(); ++i) {
    moved.knots[i].x_m = move(a.bat.knots[i].x_m, b.bat.knots[i].x_m);
    moved.knots[i].radius_m = move(a.bat.knots[i].radius_m, b.bat.knots[i].radius_m);
  }
  if (!moved.Validate(nullptr)) return start;
  start.bat = std::move(moved);
  start.predicted = true;
  return start;
}

// The model of every value built once (issue 36: the fixed work of a continuation step): the
// model of the first value, merged, and the swept constraint's index in it. Only for a
// property constraint (mass, balance point, swing weight), whose limits and scale are all that
// Build makes differently from one value to the next (DesignModel::WithConstraintLimits), and
// which no other constraint repeats, so that the merge (MergeDuplicateConstraints) does not
// depend on the value: no other constraint on the same property (the rules' drop repeats the
// mass when the length is fixed), not a function of one variable (merged into its bounds), and
// not linear in the variables (a linear constraint could repeat it). Otherwise nullopt: each
// value builds its own.
struct FrontierModel {
  design_detail::PreparedModel prepared;  // the first value's model, merged
  int index = -1;                         // the swept constraint in it
};

std::optional<FrontierModel> PrepareFrontierModel(const DesignProblem& problem,
                                                  const FrontierSpec& spec,
                                                  const DesignOptions& options) {
  DesignFunction function = DesignFunction::kMass;
  switch (spec.quantity) {
    case FrontierQuantity::kMassKg:
      break;
    case FrontierQuantity::kBalancePointM:
      function = DesignFunction::kBalancePoint;
      break;
    case FrontierQuantity::kMoiSixInchKgM2:
      function = DesignFunction::kMoiSixInch;
      break;
    default:
      return std::nullopt;
  }
  if (BbcorBoundOf(problem).has_value() || spec.values.empty()) return std::nullopt;
  FrontierModel out;
  DesignModel& model = out.prepared.model;
  if (!DesignModel::Build(FrontierProblemAt(problem, spec, spec.values.front()), options, &model,
                          nullptr) ||
      !model.fixed_violations().empty() || model.derivative_free()) {
    return std::nullopt;
  }
  int index = -1;
  for (int k = 0; k < model.m(); ++k) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    if (c.f.function == DesignFunction::kDrop) return std::nullopt;
    if (c.f.function != function) continue;
    if (index >= 0) return std::nullopt;  // two on the same property
    index = k;
  }
  if (index < 0) return std::nullopt;
  const std::vector<double> x0 = model.BaseX();
  DesignPoint at;
  if (!model.Evaluate(x0.data(), true, &at)) return std::nullopt;
  int depends = 0;
  for (int j = 0; j < model.n(); ++j) depends += at.jacobian(index, j) != 0.0 ? 1 : 0;
  std::vector<double> weights(static_cast<std::size_t>(model.m()), 0.0);
  weights[static_cast<std::size_t>(index)] = 1.0;
  Eigen::MatrixXd h;
  if (depends < 2 || !model.Hessian(x0.data(), 0.0, weights.data(), &h) ||
      !(h.cwiseAbs().maxCoeff() > 0.0)) {
    return std::nullopt;
  }
  const std::string name = model.constraints()[static_cast<std::size_t>(index)].name;
  out.prepared.merged = design_detail::MergeDuplicateConstraints(&model);
  for (int k = 0; k < model.m(); ++k) {
    if (model.constraints()[static_cast<std::size_t>(k)].name == name) out.index = k;
  }
  if (out.index < 0) return std::nullopt;
  return out;
}

// The prepared model of `value` (its limits as FrontierProblemAt sets them), or nullopt when
// Build would refuse the value (a limit outside (0, cap]): that value builds its own model.
std::optional<design_detail::PreparedModel> PreparedAt(const FrontierModel& f,
                                                       const FrontierSpec& spec, double value) {
  const double cap = spec.quantity == FrontierQuantity::kMassKg          ? kMaxDesignMassKg
                     : spec.quantity == FrontierQuantity::kBalancePointM ? kMaxBatLengthM
                                                                         : kMaxDesignMoiKgM2;
  if (!(value > 0.0 && value <= cap)) return std::nullopt;
  const double inf = std::numeric_limits<double>::infinity();
  const double lower = spec.bound == FrontierBound::kAtMost ? -inf : value;
  const double upper = spec.bound == FrontierBound::kAtLeast ? inf : value;
  design_detail::PreparedModel p;
  p.model = f.prepared.model.WithConstraintLimits(f.index, lower, upper);
  p.merged = f.prepared.merged;
  return p;
}

// The variables' values of an answer (the problem's variables, in order), from its variables
// (which list linked and scaled fields too); empty when one is missing.
std::vector<double> VariablesOf(const DesignProblem& problem, const DesignResult& r) {
  std::vector<double> x;
  for (const DesignVariable& v : problem.variables) {
    const auto it = std::find_if(r.variables.begin(), r.variables.end(),
                                 [&v](const DesignValue& e) { return e.path == v.path; });
    if (it == r.variables.end() || !std::isfinite(it->value)) return {};
    x.push_back(it->value);
  }
  return x;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

const char* FrontierQuantityName(FrontierQuantity quantity) {
  for (const QuantityName& q : kQuantityNames) {
    if (q.quantity == quantity) return q.name;
  }
  return "?";
}

std::optional<FrontierQuantity> ParseFrontierQuantity(std::string_view name) {
  for (const QuantityName& q : kQuantityNames) {
    if (name == q.name) return q.quantity;
  }
  return std::nullopt;
}

const char* FrontierBoundName(FrontierBound bound) {
  switch (bound) {
    case FrontierBound::kAtMost:
      return "max";
    case FrontierBound::kAtLeast:
      return "min";
    case FrontierBound::kEqual:
      break;
  }
  return "equal";
}

bool FrontierSpec::Validate(const DesignProblem& problem, Refusal* refusal) const {
  const auto refuse = [refusal](Refusal why) {
    if (refusal != nullptr) *refusal = std::move(why);
    return false;
  };
  if (max_values < 1) {
    return refuse(IntegerRefusal("frontier.max_values", max_values, "must be at least 1"));
  }
  if (values.empty()) return refuse(TextRefusal("frontier.values", "must give at least one value"));
  if (values.size() > static_cast<std::size_t>(max_values)) {
    return refuse(IntegerRefusal("frontier.values", static_cast<long long>(values.size()),
                                 "gives more values than the limit of " +
                                     std::to_string(max_values) + " (--max-frontier-values)"));
  }
  std::set<double> seen;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::string field = "frontier.values[" + std::to_string(i) + "]";
    if (!std::isfinite(values[i])) return refuse(NumberRefusal(field, values[i], "must be finite"));
    if (!seen.insert(values[i]).second) {
      return refuse(NumberRefusal(field, values[i], "repeats an earlier value"));
    }
  }
  if (quantity == FrontierQuantity::kSpeedModelExponent &&
      problem.objective != DesignObjective::kMaxExitSpeedSwingWeight) {
    return refuse(TextRefusal("frontier.constraint",
                              "swing_weight_exponent weights the objective "
                              "max_exit_speed_swing_weight only (it would change nothing)"));
  }
  if (!IsRange(quantity) && bound != FrontierBound::kEqual) {
    return refuse(QuotedRefusal("frontier.bound", FrontierBoundName(bound),
                                std::string("does not apply to ") + FrontierQuantityName(quantity) +
                                    " (it has one form: leave bound out)"));
  }
  if (problem.objective == DesignObjective::kMinSting) {
    return refuse(TextRefusal("objective",
                              "min_sting has no frontier: each solve is a derivative-free search "
                              "over the flexible beam (seconds per value)"));
  }
  if (problem.objective == DesignObjective::kMaxDistance) {
    return refuse(TextRefusal("objective",
                              "max_distance has no frontier: each solve is a derivative-free "
                              "search, and the frontier's continuation needs the objective's "
                              "multipliers"));
  }
  return true;
}

DesignProblem FrontierProblemAt(const DesignProblem& problem, const FrontierSpec& spec,
                                double value) {
  DesignProblem p = problem;
  DesignConstraints& c = p.constraints;
  switch (spec.quantity) {
    case FrontierQuantity::kLengthM:
      c.length_m = RangeOf(spec.bound, value);
      break;
    case FrontierQuantity::kMassKg:
      c.mass_kg = RangeOf(spec.bound, value);
      break;
    case FrontierQuantity::kBalancePointM:
      c.balance_point_m = RangeOf(spec.bound, value);
      break;
    case FrontierQuantity::kMoiSixInchKgM2:
      c.moi_six_inch_kg_m2 = RangeOf(spec.bound, value);
      break;
    case FrontierQuantity::kMinFrequencyHz:
      c.min_frequency_hz = value;
      break;
    case FrontierQuantity::kMaxBarrelDiameterM:
      c.max_barrel_diameter_m = value;
      break;
    case FrontierQuantity::kSpeedModelExponent:
      p.swing_weight_exponent = value;
      break;
  }
  return p;
}

namespace {

// The Pareto front (indices of candidate_index): a point is dominated when another is at least
// as good on both the value (in the preferred direction) and the objective, and better on one.
std::vector<int> ParetoFront(DesignObjective objective, bool prefer_smaller,
                             const std::vector<std::pair<double, double>>& front_candidates,
                             const std::vector<int>& candidate_index) {
  std::vector<int> pareto;
  for (std::size_t i = 0; i < front_candidates.size(); ++i) {
    bool dominated = false;
    for (std::size_t j = 0; j < front_candidates.size() && !dominated; ++j) {
      if (i == j) continue;
      const double vi = front_candidates[i].first, vj = front_candidates[j].first;
      const double fi = front_candidates[i].second, fj = front_candidates[j].second;
      const bool value_ok = prefer_smaller ? vj <= vi : vj >= vi;
      const bool value_better = prefer_smaller ? vj < vi : vj > vi;
      const bool f_ok = !Better(objective, fi, fj);
      const bool f_better = Better(objective, fj, fi);
      dominated = value_ok && f_ok && (value_better || f_better);
    }
    if (!dominated) pareto.push_back(candidate_index[i]);
  }
  return pareto;
}

// The summary's termination and message from the counts.
void FinishFrontierSummary(std::size_t values, FrontierSummary* out) {
  const std::string of =
      std::to_string(out->points) + " of " + std::to_string(values) + " values";
  if (out->cancelled) {
    out->summary.termination = Termination::kNoConvergence;
    out->summary.message = "cancelled after " + of;
  } else if (out->stopped) {
    out->summary.termination = Termination::kNoConvergence;
    out->summary.message = "stopped by the reader after " + of;
  } else if (out->converged == out->points) {
    out->summary.termination = Termination::kConverged;
    out->summary.message = "every value converged (" + of + ", " +
                           std::to_string(out->restarts) + " warm starts solved again cold)";
  } else {
    out->summary.termination = Termination::kNoConvergence;
    out->summary.message = std::to_string(out->points - out->converged) + " of " +
                           std::to_string(out->points) + " values did not converge";
  }
}

// The frontier's Newton step at `value`: the neighbour's active set (its certificate's
// multipliers), Newton's method on its KKT conditions from the predicted start
// (active_set_newton.hpp); `p` is the value's problem with the predicted bat.
DesignResult NewtonStep(const DesignProblem& problem, const FrontierSpec& spec,
                        const DesignOptions& options,
                        const std::optional<FrontierModel>& frontier_model,
                        const std::vector<FrontierPoint>& solved,
                        const DesignCertificate& neighbour, const DesignProblem& p,
                        double value) {
  const ActiveSetGuess guess =
      GuessFromMultipliers(neighbour.lambda, neighbour.z_lower, neighbour.z_upper);
  // With the model built once, the problem keeps its base design (the model's) and the
  // predicted start is given as the variables' values (the secant through the two
  // previous answers' variables, as PredictStart moves the bat).
  std::optional<design_detail::PreparedModel> prepared;
  std::vector<double> x_start;
  if (frontier_model.has_value()) {
    prepared = PreparedAt(*frontier_model, spec, value);
    x_start = VariablesOf(problem, solved.back().result);
    if (solved.size() >= 2 && !x_start.empty()) {
      const FrontierPoint& a = solved[solved.size() - 2];
      const FrontierPoint& b = solved.back();
      const std::vector<double> x_before = VariablesOf(problem, a.result);
      if (x_before.size() == x_start.size() && b.value != a.value) {
        const double t = (value - b.value) / (b.value - a.value);
        for (std::size_t j = 0; j < x_start.size(); ++j)
          x_start[j] += t * (x_start[j] - x_before[j]);
      }
    }
  }
  const design_detail::LocalSolver newton = [&guess, &x_start](
                                                ScaledDesignNlp& nlp,
                                                const std::vector<double>& s0,
                                                const LocalSolveSettings& settings) {
    const bool given = x_start.size() == static_cast<std::size_t>(nlp.n());
    return SolveWithActiveSetNewton(nlp, given ? nlp.ToScaled(x_start) : s0, guess, settings);
  };
  DesignOptions step = options;
  step.choose_backend = false;
  step.starts = 1;
  step.derivative_check = DerivativeCheck::kNone;
  step.explain_infeasibility = false;  // a failed step is solved again below
  return prepared.has_value()
                     ? design_detail::Optimize(FrontierProblemAt(problem, spec, value),
                                               step, nullptr, 0.0, 1.0, std::nullopt, &newton,
                                               kActiveSetNewtonName, &*prepared)
                     : design_detail::Optimize(p, step, nullptr, 0.0, 1.0, std::nullopt,
                                               &newton, kActiveSetNewtonName);
}

}  // namespace

FrontierSummary OptimizeFrontier(const DesignProblem& problem, const FrontierSpec& spec,
                                 const DesignOptions& options, bool prefer_smaller,
                                 const FrontierSink& sink, Progress* progress) {
  FrontierSummary out;
  const auto started = std::chrono::steady_clock::now();
  out.summary.backend = "frontier";
  CatchInternalError(&out.summary, [&] {
    Refusal why;
    if (!spec.Validate(problem, &why)) {
      out.summary.SetRefusal(std::move(why));
      return;
    }
    // The continuation backend differs from the requested one (else the requested solve is
    // the step); min_frequency_hz needs limited-memory Ipopt or SLSQP either way.
    const bool continuation = spec.warm_start && spec.continuation_backend != options.backend;
    // The continuation steps' model, built once when the swept quantity allows it.
    const std::optional<FrontierModel> frontier_model =
        spec.warm_start && spec.values.size() > 1 ? PrepareFrontierModel(problem, spec, options)
                                                  : std::nullopt;
    std::vector<FrontierPoint> solved;  // the converged answers, for the predictor
    solved.reserve(2);
    int iterations = 0, evaluations = 0;
    std::vector<std::pair<double, double>> front_candidates;  // (value, objective) per index
    std::vector<int> candidate_index;
    for (std::size_t k = 0; k < spec.values.size(); ++k) {
      if (IsCancelled(progress)) {
        out.cancelled = true;
        break;
      }
      FrontierPoint point;
      point.index = static_cast<int>(k);
      point.value = spec.values[k];
      DesignProblem p = FrontierProblemAt(problem, spec, point.value);
      if (spec.warm_start && !solved.empty()) {
        const FrontierPoint* before = solved.size() >= 2 ? &solved[solved.size() - 2] : nullptr;
        Start start = PredictStart(before, solved.back(), point.value);
        p.bat = std::move(start.bat);
        if (start.shape) p.three_segment = start.shape;
        point.warm_started = true;
        point.predicted = start.predicted;
      }
      const auto count = [&](const DesignResult& r) {
        iterations += std::max(0, r.summary.iterations);
        evaluations += std::max(0, r.summary.evaluations);
      };
      const DesignCertificate* neighbour =
          point.warm_started ? &solved.back().result.certificate : nullptr;
      if (neighbour != nullptr && neighbour->checked && neighbour->certified) {
        // The Newton step: the neighbour's active set, Newton's method on its KKT conditions
        // from the predicted start (active_set_newton.hpp), kept when certified.
        point.result = NewtonStep(problem, spec, options, frontier_model, solved, *neighbour, p,
                                  point.value);
        point.continued = point.result.summary.termination == Termination::kConverged &&
                          point.result.certificate.certified;
        if (!point.continued) count(point.result);
      }
      if (point.warm_started && continuation && !point.continued) {
        // The continuation step: a local solve from the predicted start, kept when converged.
        DesignOptions step = options;
        step.backend = spec.continuation_backend;
        step.choose_backend = false;  // the continuation's own backend, not the chosen one
        step.starts = 1;
        point.result = OptimizeDesign(p, step, nullptr);
        point.continued = point.result.summary.termination == Termination::kConverged;
        if (!point.continued) count(point.result);
      }
      if (!point.continued) {
        DesignResult warm = OptimizeDesign(p, options, nullptr);
        if (point.warm_started && warm.summary.termination != Termination::kConverged &&
            !IsCancelled(progress)) {
          // The warm start did not converge: the base design's solve decides (never worse
          // than an independent solve).
          count(warm);
          DesignResult cold = OptimizeDesign(FrontierProblemAt(problem, spec, point.value),
                                             options, nullptr);
          point.restarted = true;
          ++out.restarts;
          if (BetterAnswer(problem.objective, cold, warm)) warm = std::move(cold);
        }
        point.result = std::move(warm);
      }
      iterations += std::max(0, point.result.summary.iterations);
      evaluations += std::max(0, point.result.summary.evaluations);
      ++out.points;
      if (point.result.summary.termination == Termination::kConverged) {
        ++out.converged;
        if (point.continued) ++out.continued;
        front_candidates.emplace_back(point.value, point.result.objective_value);
        candidate_index.push_back(point.index);
        if (solved.size() == 2) solved.erase(solved.begin());
        solved.push_back(point);
      }
      if (progress != nullptr) {
        progress->Report(static_cast<double>(k + 1) / static_cast<double>(spec.values.size()));
      }
      if (!sink(point)) {
        out.stopped = true;
        break;
      }
    }
    out.pareto = ParetoFront(problem.objective, prefer_smaller, front_candidates, candidate_index);
    out.summary.iterations = iterations;
    out.summary.evaluations = evaluations;
    FinishFrontierSummary(spec.values.size(), &out);
  });
  out.summary.solve_time_s = Seconds(started);
  return out;
}

}  // namespace sweetspot::core
