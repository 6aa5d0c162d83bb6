// hertz_contact: implementation; the model's assumptions are stated at the top of
// hertz_contact.hpp.
#include "core/collision/hertz_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "core/collision/contact_integration.hpp"
#include "core/collision/contact_law.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/event_integrator.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {
namespace {

using HertzState = std::array<double, 6>;  // scaled: delta1, delta1', delta2, delta2', P1, P_hands

struct HertzRun {
  bool ok = false;
  std::string message;
  std::vector<std::string> warnings;
  double contact_time_s = 0.0;
  double max_compression_m = 0.0;
  double peak_force_n = 0.0;
  double ball_impulse_n_s = 0.0;
  double hands_impulse_n_s = 0.0;
  double separation_speed_mps = 0.0;
  double q = 0.0;
  int steps = 0;
  long evaluations = 0;
};

// The contact as the event integrator sees it, on the scaled state. Scales: lengths by
// delta_s, speeds by v0, time by t_s = delta_s / v0, impulses by p_s = v0 / c11.
struct HertzSystem {
  const HertzProblem* p = nullptr;
  BallPowerLaw law;
  ContactBranch branch;
  bool paper = false;  // the paper's elastic constants instead of the ball's law
  double delta_s = 1.0, v0 = 1.0, t_s = 1.0, p_s = 1.0;
  double peak_d = 0.0;  // scaled
  double peak_f = 0.0;  // N
  HertzRun* out = nullptr;

  // Contact force F1 at compression d (m), N.
  double ContactForce(double d) const {
    if (d <= 0.0) return 0.0;
    if (paper) return p->paper.k1 * d * std::sqrt(d) / p->c11_per_kg;
    return branch.Force(law, d);
  }

  void operator()(const HertzState& y, HertzState& dy, double /*t*/) const {
    const double d1 = y[0] * delta_s;
    const double d2 = y[2] * delta_s;
    const double v2 = y[3] * v0;
    double a1 = 0.0, a2 = 0.0, f1 = 0.0, fh = 0.0;
    if (paper) {
      const double unit = d1 > 0.0 ? d1 * std::sqrt(d1) : 0.0;
      a1 = -p->paper.k1 * unit + p->paper.k2 * d2;
      a2 = p->paper.k3 * unit - 2.0 * p->paper.k2 * d2;
      f1 = p->paper.k1 * unit / p->c11_per_kg;
      fh = 2.0 * p->paper.k2 * d2 / p->c22_per_kg;
    } else {
      f1 = branch.Force(law, d1);
      fh = p->hands_stiffness_n_m * d2 + p->hands_damping_n_s_m * v2;
      a1 = -p->c11_per_kg * f1 + p->c12_per_kg * fh;
      a2 = p->c12_per_kg * f1 - p->c22_per_kg * fh;
    }
    dy[0] = y[1];
    dy[1] = a1 * t_s / v0;
    dy[2] = y[3];
    dy[3] = a2 * t_s / v0;
    dy[4] = f1 * t_s / p_s;
    dy[5] = fh * t_s / p_s;
  }

  std::span<const EventSpec> ActiveEvents() const { return ContactEvents(branch.unloading); }
  // The contact's events on the compression delta1 (ContactEventId).
  double EventFunction(int id, const HertzState& s) const {
    return ContactEventValue(id, s[0], s[1], branch.delta_max_m / delta_s);
  }
  void OnStep(const DenseStep<HertzState>& step) { peak_d = std::max(peak_d, (*step.y_end)[0]); }

  // Records the end of the contact at (te, ye).
  void End(double te, const HertzState& ye, double separation_scaled) {
    out->ok = true;
    out->contact_time_s = te * t_s;
    out->separation_speed_mps = separation_scaled * v0;
    out->ball_impulse_n_s = ye[4] * p_s;
    out->hands_impulse_n_s = ye[5] * p_s;
  }

  EventAction OnEvent(int id, double te, const HertzState& ye) {
    peak_d = std::max(peak_d, ye[0]);
    const double d_e = std::max(0.0, ye[0]) * delta_s;
    if (id == kEnd) {
      End(te, ye, -ye[1]);
      return EventAction::kStop;
    }
    if (id == kReload) {
      branch.unloading = false;
      return EventAction::kContinue;
    }
    const double f = ContactForce(d_e);  // maximum compression
    peak_f = std::max(peak_f, f);
    if (paper) return EventAction::kContinue;
    if (p->cor == 0.0) {
      // Perfectly plastic: no force after the maximum; the ball rides with the bat.
      End(te, ye, 0.0);
      out->warnings.push_back(
          "cor = 0: perfectly plastic, the contact ends at maximum compression");
      return EventAction::kStop;
    }
    branch.StartUnloading(law, d_e, f, p->cor);
    out->q = branch.exponent;
    return EventAction::kContinue;
  }
};

HertzRun Integrate(const HertzProblem& p, double tol, int max_steps) {
  HertzRun out;
  HertzSystem sys;
  sys.p = &p;
  sys.out = &out;
  sys.v0 = p.approach_speed_mps;
  const double v0 = sys.v0;
  if (p.law == ContactLaw::kPaperConstants) {
    sys.paper = true;
    sys.delta_s = std::pow(1.25 * v0 * v0 / p.paper.k1, 0.4);
  } else {
    sys.law = BallPowerLaw(p.ball_stiffness, p.ball_exponent, p.surface_stiffness);
    sys.delta_s = ContactCompressionScaleM(p.c11_per_kg, p.ball_stiffness, p.ball_exponent, v0);
  }
  sys.t_s = sys.delta_s / v0;
  sys.p_s = v0 / p.c11_per_kg;
  if (!(std::isfinite(sys.delta_s) && sys.delta_s > 0.0 && std::isfinite(sys.t_s) &&
        sys.t_s > 0.0)) {
    out.message = "contact scales are not finite (delta_s = " + FormatNumber17(sys.delta_s) +
                  " m, t_s = " + FormatNumber17(sys.t_s) + " s)";
    return out;
  }
  EventIntegrator<HertzState> integrator(ContactIntegratorOptions(tol, max_steps, sys.t_s));
  HertzState y{0.0, 1.0, 0.0, 0.0, 0.0, 0.0};
  double t = 0.0;
  const bool stopped = integrator.Run(sys, &y, &t);
  out.steps = integrator.summary().steps;
  out.evaluations = integrator.summary().evaluations;
  if (!stopped) {
    out.ok = false;
    out.message = integrator.summary().message;
    if (integrator.summary().termination == EventTermination::kStepBound) {
      out.message += " (delta1 = " + FormatNumber17(y[0] * sys.delta_s) + " m)";
    }
    return out;
  }
  out.max_compression_m = sys.peak_d * sys.delta_s;
  double peak_f = sys.peak_f;
  if (sys.paper) {
    peak_f = std::max(peak_f, p.paper.k1 * std::pow(out.max_compression_m, 1.5) / p.c11_per_kg);
  }
  out.peak_force_n = peak_f;
  return out;
}

}  // namespace

const char* ContactLawName(ContactLaw law) {
  switch (law) {
    case ContactLaw::kBallPowerLaw:
      return "ball_power_law";
    case ContactLaw::kPaperConstants:
      return "paper_constants";
  }
  return "ball_power_law";
}

bool HertzProblem::Validate(Refusal* why) const {
  auto finite_pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!finite_pos(approach_speed_mps))
    return Refuse(
        why,
        Number17Refusal("hertz.approach_speed_mps", approach_speed_mps,
                        "must be finite and > 0 (the ball and the bat must approach each other)"));
  if (!finite_nonneg(ball_speed_mps))
    return Refuse(
        why, Number17Refusal("hertz.ball_speed_mps", ball_speed_mps, "must be finite and >= 0"));
  if (!finite_pos(ball_mass_kg))
    return Refuse(why,
                  Number17Refusal("hertz.ball_mass_kg", ball_mass_kg, "must be finite and > 0"));
  if (!finite_pos(c11_per_kg))
    return Refuse(why, Number17Refusal("hertz.c11_per_kg", c11_per_kg, "must be finite and > 0"));
  if (!std::isfinite(c12_per_kg))
    return Refuse(why, Number17Refusal("hertz.c12_per_kg", c12_per_kg, "must be finite"));
  if (!finite_pos(c22_per_kg))
    return Refuse(why, Number17Refusal("hertz.c22_per_kg", c22_per_kg, "must be finite and > 0"));
  if (law == ContactLaw::kPaperConstants) {
    if (!finite_pos(paper.k1))
      return Refuse(why, Number17Refusal("hertz.paper.k1", paper.k1, "must be finite and > 0"));
    if (!finite_nonneg(paper.k2))
      return Refuse(why, Number17Refusal("hertz.paper.k2", paper.k2, "must be finite and >= 0"));
    if (!std::isfinite(paper.k3))
      return Refuse(why, Number17Refusal("hertz.paper.k3", paper.k3, "must be finite"));
    return true;
  }
  if (!BallLawValidate(ball_stiffness, ball_exponent, why)) return false;
  if (!finite_nonneg(surface_stiffness))
    return Refuse(why, Number17Refusal("hertz.surface_stiffness", surface_stiffness,
                                       "must be finite and >= 0"));
  if (!(std::isfinite(cor) && cor >= 0.0 && cor <= 1.0))
    return Refuse(why, Number17Refusal("cor", cor, "must be in [0, 1]"));
  if (!finite_nonneg(hands_stiffness_n_m))
    return Refuse(why, Number17Refusal("hertz.hands_stiffness_n_m", hands_stiffness_n_m,
                                       "must be finite and >= 0"));
  if (!finite_nonneg(hands_damping_n_s_m))
    return Refuse(why, Number17Refusal("hertz.hands_damping_n_s_m", hands_damping_n_s_m,
                                       "must be finite and >= 0"));
  return true;
}

bool HertzSolverOptions::Validate(Refusal* why) const {
  return ContactIntegrationValidate("hertz", relative_tolerance, max_steps, why);
}

bool HertzOptions::Validate(Refusal* why) const {
  // The ranges a request may choose (the api checks only that the numbers are numbers).
  if (!(std::isfinite(hands_stiffness_n_m) && hands_stiffness_n_m >= 0.0))
    return Refuse(why, Number17Refusal("hertz.hands_stiffness_n_m", hands_stiffness_n_m,
                                       "must be finite and >= 0"));
  if (hands_stiffness_n_m > kMaxHandsStiffnessNM)
    return Refuse(why, Number17Refusal("hertz.hands_stiffness_n_m", hands_stiffness_n_m,
                                       "must be at most 1e12"));
  if (!(std::isfinite(hands_damping_n_s_m) && hands_damping_n_s_m >= 0.0))
    return Refuse(why, Number17Refusal("hertz.hands_damping_n_s_m", hands_damping_n_s_m,
                                       "must be finite and >= 0"));
  if (hands_damping_n_s_m > kMaxHandsDampingNSM)
    return Refuse(why, Number17Refusal("hertz.hands_damping_n_s_m", hands_damping_n_s_m,
                                       "must be at most 1e12"));
  // The paper's constants are checked whatever the law, as a request's are.
  if (!(std::isfinite(paper.k1) && paper.k1 > 0.0 && paper.k1 <= kMaxPaperConstant))
    return Refuse(why, Number17Refusal("hertz.paper.k1", paper.k1, "must be in (0, 1e20]"));
  if (!(std::isfinite(paper.k2) && paper.k2 >= 0.0 && paper.k2 <= kMaxPaperConstant))
    return Refuse(why, Number17Refusal("hertz.paper.k2", paper.k2, "must be in [0, 1e20]"));
  if (!(std::isfinite(paper.k3) && paper.k3 >= 0.0 && paper.k3 <= kMaxPaperConstant))
    return Refuse(why, Number17Refusal("hertz.paper.k3", paper.k3, "must be in [0, 1e20]"));
  return solver.Validate(why);
}

HertzImpact SolveHertzImpact(const HertzProblem& problem, const HertzSolverOptions& options) {
  return TimedSolve<HertzImpact>([&](HertzImpact& out) {
    out.problem = problem;
    Summary& s = out.summary;
    if (!StartContactSolve("hertz", &s, problem, options)) return;
    const RefinedRuns<HertzRun> runs = SolveWithRefineCheck<HertzRun>(
        options.relative_tolerance, options.refine_check,
        [&](double tol) { return Integrate(problem, tol, options.max_steps); });
    out.steps = CountRefinedRuns(runs, &s);
    if (!runs.coarse.ok) return;
    const HertzRun& a = runs.coarse;
    out.contact_time_s = a.contact_time_s;
    out.max_compression_m = a.max_compression_m;
    out.peak_force_n = a.peak_force_n;
    out.ball_impulse_n_s = a.ball_impulse_n_s;
    out.hands_impulse_n_s = a.hands_impulse_n_s;
    out.separation_speed_mps = a.separation_speed_mps;
    out.apparent_cor = a.separation_speed_mps / problem.approach_speed_mps;
    out.exit_speed_mps = -problem.ball_speed_mps + a.ball_impulse_n_s / problem.ball_mass_kg;
    out.unloading_exponent = a.q;
    s.warnings = a.warnings;
    if (runs.refined) {
      const HertzRun& b = runs.fine;
      if (!b.ok) {
        s.warnings.push_back(RefineFailedWarning(b.message) +
                             "; error estimates are the tolerance only");
        out.error_estimate_contact_time_s = options.relative_tolerance * a.contact_time_s;
        out.error_estimate_exit_speed_mps =
            options.relative_tolerance * (problem.ball_speed_mps + std::abs(out.exit_speed_mps));
        out.error_estimate_peak_force_n = options.relative_tolerance * a.peak_force_n;
      } else {
        out.error_estimate_contact_time_s = std::abs(a.contact_time_s - b.contact_time_s);
        const double vb = -problem.ball_speed_mps + b.ball_impulse_n_s / problem.ball_mass_kg;
        out.error_estimate_exit_speed_mps = std::abs(out.exit_speed_mps - vb);
        out.error_estimate_peak_force_n = std::abs(a.peak_force_n - b.peak_force_n);
      }
    }
    s.termination = Termination::kConverged;
    s.message = "contact ended after " + FormatNumber17(out.contact_time_s) + " s";
    s.objective = out.exit_speed_mps;
    s.error_estimate = out.error_estimate_exit_speed_mps;
  });
}

}  // namespace sweetspot::core
