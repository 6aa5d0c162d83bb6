// hertz_contact: implementation; the model's assumptions are stated at the top of hertz_contact.hpp.
#include "core/collision/hertz_contact.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint.hpp>

namespace sweetspot::core {
namespace {

namespace odeint = boost::numeric::odeint;
using State = std::array<double, 6>;  // scaled: delta1, delta1', delta2, delta2', P1, P_hands

std::string Num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

enum class Phase { kLoading, kUnloading, kElastic };

// The right-hand side on the scaled state. Scales: lengths by delta_s, speeds by v0, time by
// t_s = delta_s / v0, impulses by p_s = v0 / c11.
struct Rhs {
  const HertzProblem* p = nullptr;
  double delta_s = 1.0, v0 = 1.0, t_s = 1.0, p_s = 1.0;
  Phase phase = Phase::kLoading;
  double delta_max = 0.0;  // m, start of the current unloading branch
  double force_max = 0.0;  // N, force there
  double q = 1.5;          // unloading exponent
  double k_eff = 0.0;      // series stiffness when p = 3/2
  long* evaluations = nullptr;

  // Force along the virgin loading curve (ball in series with the bat surface), N.
  double LoadingForce(double d) const {
    if (d <= 0.0) return 0.0;
    const double k = p->ball_stiffness;
    const double pe = p->ball_exponent;
    const double kk = p->surface_stiffness;
    if (kk <= 0.0) return k * std::pow(d, pe);
    if (pe == 1.5) return k_eff * d * std::sqrt(d);
    // Solve db + (k db^p / K)^{2/3} = d for the ball's share db (monotone; safeguarded Newton).
    const double a = std::cbrt((k / kk) * (k / kk));
    const double e = 2.0 * pe / 3.0;
    double lo = 0.0, hi = d, db = d / (1.0 + a * std::pow(d, e - 1.0));
    for (int it = 0; it < 60; ++it) {
      const double g = db + a * std::pow(db, e) - d;
      if (g > 0.0)
        hi = db;
      else
        lo = db;
      const double dg = 1.0 + a * e * std::pow(db, e - 1.0);
      double next = db - g / dg;
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - db) <= 1e-15 * d) {
        db = next;
        break;
      }
      db = next;
    }
    return k * std::pow(db, pe);
  }

  // Work done along the virgin loading curve up to force fm at compression dm, J.
  double LoadingWork(double fm, double dm) const {
    const double pe = p->ball_exponent;
    double comp = pe / (pe + 1.0) * std::pow(fm / p->ball_stiffness, 1.0 / pe) * fm;
    if (p->surface_stiffness > 0.0) {
      comp += 0.6 * std::cbrt((fm / p->surface_stiffness) * (fm / p->surface_stiffness)) * fm;
    }
    return fm * dm - comp;
  }

  // Contact force F1 in newtons and the unit-law value for the paper's form.
  double ContactForce(double d) const {
    if (d <= 0.0) return 0.0;
    switch (phase) {
      case Phase::kLoading:
        return LoadingForce(d);
      case Phase::kUnloading:
        return d >= delta_max ? force_max : force_max * std::pow(d / delta_max, q);
      case Phase::kElastic:
        return p->paper.k1 * d * std::sqrt(d) / p->c11_per_kg;
    }
    return 0.0;
  }

  void operator()(const State& y, State& dy, double /*t*/) const {
    if (evaluations != nullptr) ++*evaluations;
    const double d1 = y[0] * delta_s;
    const double d2 = y[2] * delta_s;
    const double v2 = y[3] * v0;
    double a1 = 0.0, a2 = 0.0, f1 = 0.0, fh = 0.0;
    if (p->law == ContactLaw::kPaperConstants) {
      const double unit = d1 > 0.0 ? d1 * std::sqrt(d1) : 0.0;
      a1 = -p->paper.k1 * unit + p->paper.k2 * d2;
      a2 = p->paper.k3 * unit - 2.0 * p->paper.k2 * d2;
      f1 = p->paper.k1 * unit / p->c11_per_kg;
      fh = 2.0 * p->paper.k2 * d2 / p->c22_per_kg;
    } else {
      f1 = ContactForce(d1);
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
};

struct RawRun {
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

enum class Event { kNone, kMaxCompression, kEnd, kReload };

RawRun Integrate(const HertzProblem& p, double tol, int max_steps) {
  RawRun out;
  Rhs rhs;
  rhs.p = &p;
  rhs.evaluations = &out.evaluations;
  rhs.v0 = p.approach_speed_mps;
  const double v0 = rhs.v0;
  if (p.law == ContactLaw::kPaperConstants) {
    rhs.phase = Phase::kElastic;
    rhs.delta_s = std::pow(1.25 * v0 * v0 / p.paper.k1, 0.4);
  } else {
    rhs.phase = Phase::kLoading;
    const double pe = p.ball_exponent;
    if (p.surface_stiffness > 0.0 && pe == 1.5) {
      const double kb = std::cbrt(1.0 / (p.ball_stiffness * p.ball_stiffness));
      const double ks = std::cbrt(1.0 / (p.surface_stiffness * p.surface_stiffness));
      rhs.k_eff = std::pow(kb + ks, -1.5);
    }
    rhs.delta_s =
        std::pow((pe + 1.0) * v0 * v0 / (2.0 * p.c11_per_kg * p.ball_stiffness), 1.0 / (pe + 1.0));
  }
  rhs.t_s = rhs.delta_s / v0;
  rhs.p_s = v0 / p.c11_per_kg;
  if (!(std::isfinite(rhs.delta_s) && rhs.delta_s > 0.0 && std::isfinite(rhs.t_s) &&
        rhs.t_s > 0.0)) {
    out.message = "contact scales are not finite (delta_s = " + Num(rhs.delta_s) +
                  " m, t_s = " + Num(rhs.t_s) + " s)";
    return out;
  }

  State y{0.0, 1.0, 0.0, 0.0, 0.0, 0.0};
  double t = 0.0;
  double dt = 1e-2;
  auto stepper = odeint::make_dense_output(tol, tol, 0.25, odeint::runge_kutta_dopri5<State>());
  double peak_d = 0.0;
  double peak_f = 0.0;
  try {
    stepper.initialize(y, t, dt);
    while (true) {
      if (out.steps >= max_steps) {
        const State& c = stepper.current_state();
        out.message = "the contact did not end within max_steps = " + std::to_string(max_steps) +
                      " integrator steps (t = " + Num(stepper.current_time() * rhs.t_s) +
                      " s, delta1 = " + Num(c[0] * rhs.delta_s) +
                      " m): too stiff for the explicit integrator at this tolerance";
        return out;
      }
      const State ya = stepper.current_state();
      // Not a structured binding: clang 14 cannot capture one in the lambdas below.
      const std::pair<double, double> step = stepper.do_step(std::ref(rhs));
      const double ta = step.first;
      const double tb = step.second;
      ++out.steps;
      const State& yb = stepper.current_state();
      for (double v : yb) {
        if (!std::isfinite(v)) {
          out.message = "the integrated state became non-finite at t = " + Num(tb * rhs.t_s) + " s";
          return out;
        }
      }
      peak_d = std::max(peak_d, yb[0]);
      // Event functions of the current phase (each crosses from > 0 to <= 0).
      const double dm_scaled = rhs.delta_max / rhs.delta_s;
      auto g_max = [](const State& s) { return s[1]; };  // delta1' falls through 0
      auto g_end = [](const State& s) { return s[0]; };  // delta1 falls through 0
      auto g_reload = [dm_scaled](const State& s) {
        return dm_scaled - s[0];
      };  // back above delta_max
      Event ev = Event::kNone;
      double te = tb;
      auto locate = [&](auto g, Event kind) {
        if (!(g(ya) > 0.0 && g(yb) <= 0.0)) return;
        State tmp;
        auto fn = [&](double tt) {
          stepper.calc_state(tt, tmp);
          return g(tmp);
        };
        double root = tb;
        if (fn(tb) == 0.0) {
          root = tb;
        } else {
          boost::uintmax_t iters = 100;
          const auto r = boost::math::tools::toms748_solve(
              fn, ta, tb, g(ya), g(yb), boost::math::tools::eps_tolerance<double>(52), iters);
          root = 0.5 * (r.first + r.second);
        }
        if (ev == Event::kNone || root < te) {
          ev = kind;
          te = root;
        }
      };
      if (rhs.phase == Phase::kUnloading) {
        locate(g_end, Event::kEnd);
        locate(g_reload, Event::kReload);
      } else {
        locate(g_max, Event::kMaxCompression);
        locate(g_end, Event::kEnd);
      }
      if (ev == Event::kNone) continue;
      State ye;
      stepper.calc_state(te, ye);
      peak_d = std::max(peak_d, ye[0]);
      const double d_e = std::max(0.0, ye[0]) * rhs.delta_s;
      if (ev == Event::kEnd) {
        out.ok = true;
        out.contact_time_s = te * rhs.t_s;
        out.separation_speed_mps = -ye[1] * v0;
        out.ball_impulse_n_s = ye[4] * rhs.p_s;
        out.hands_impulse_n_s = ye[5] * rhs.p_s;
        break;
      }
      if (ev == Event::kMaxCompression) {
        const double f = rhs.ContactForce(d_e);
        peak_f = std::max(peak_f, f);
        if (rhs.phase == Phase::kLoading) {
          if (p.cor == 0.0) {
            // Perfectly plastic: no force after the maximum; the ball rides with the bat.
            out.ok = true;
            out.contact_time_s = te * rhs.t_s;
            out.separation_speed_mps = 0.0;
            out.ball_impulse_n_s = ye[4] * rhs.p_s;
            out.hands_impulse_n_s = ye[5] * rhs.p_s;
            out.warnings.push_back(
                "cor = 0: perfectly plastic, the contact ends at maximum compression");
            break;
          }
          rhs.phase = Phase::kUnloading;
          rhs.delta_max = d_e;
          rhs.force_max = f;
          rhs.q = f * d_e / (p.cor * p.cor * rhs.LoadingWork(f, d_e)) - 1.0;
          out.q = rhs.q;
        }
      } else if (ev == Event::kReload) {
        rhs.phase = Phase::kLoading;
      }
      t = te;
      stepper.initialize(ye, t, std::max(1e-6, (tb - ta) * 0.5));
    }
  } catch (const std::exception& e) {
    out.ok = false;
    out.message = std::string("the integrator failed: ") + e.what();
    return out;
  }
  out.max_compression_m = peak_d * rhs.delta_s;
  if (p.law == ContactLaw::kPaperConstants) {
    peak_f = std::max(peak_f, p.paper.k1 * std::pow(out.max_compression_m, 1.5) / p.c11_per_kg);
  }
  out.peak_force_n = peak_f;
  return out;
}

bool Fail(std::string* why, const std::string& m) {
  if (why != nullptr) *why = m;
  return false;
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

double BatSurfaceHertzStiffness(double youngs_modulus_pa, double poissons_ratio,
                                double ball_radius_m, double bat_radius_m) {
  const double e_star = youngs_modulus_pa / (1.0 - poissons_ratio * poissons_ratio);
  const double r1 = ball_radius_m;
  const double r2 = 1.0 / (1.0 / ball_radius_m + 1.0 / bat_radius_m);
  return 4.0 / 3.0 * e_star * std::sqrt(std::sqrt(r1 * r2));
}

bool HertzProblem::IsValid(std::string* why) const {
  auto finite_pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!finite_pos(approach_speed_mps))
    return Fail(why,
                "hertz.approach_speed_mps = " + Num(approach_speed_mps) +
                    ": must be finite and > 0 (the ball and the bat must approach each other)");
  if (!finite_nonneg(ball_speed_mps))
    return Fail(why, "hertz.ball_speed_mps = " + Num(ball_speed_mps) + ": must be finite and >= 0");
  if (!finite_pos(ball_mass_kg))
    return Fail(why, "hertz.ball_mass_kg = " + Num(ball_mass_kg) + ": must be finite and > 0");
  if (!finite_pos(c11_per_kg))
    return Fail(why, "hertz.c11_per_kg = " + Num(c11_per_kg) + ": must be finite and > 0");
  if (!std::isfinite(c12_per_kg))
    return Fail(why, "hertz.c12_per_kg = " + Num(c12_per_kg) + ": must be finite");
  if (!finite_pos(c22_per_kg))
    return Fail(why, "hertz.c22_per_kg = " + Num(c22_per_kg) + ": must be finite and > 0");
  if (law == ContactLaw::kPaperConstants) {
    if (!finite_pos(paper.k1))
      return Fail(why, "hertz.paper.k1 = " + Num(paper.k1) + ": must be finite and > 0");
    if (!finite_nonneg(paper.k2))
      return Fail(why, "hertz.paper.k2 = " + Num(paper.k2) + ": must be finite and >= 0");
    if (!std::isfinite(paper.k3))
      return Fail(why, "hertz.paper.k3 = " + Num(paper.k3) + ": must be finite");
    return true;
  }
  if (!finite_pos(ball_stiffness))
    return Fail(why, "ball.stiffness = " + Num(ball_stiffness) + ": must be finite and > 0");
  if (!(std::isfinite(ball_exponent) && ball_exponent >= 1.0 && ball_exponent <= 3.0))
    return Fail(why, "ball.stiffness_exponent = " + Num(ball_exponent) + ": must be in [1, 3]");
  if (!finite_nonneg(surface_stiffness))
    return Fail(
        why, "hertz.surface_stiffness = " + Num(surface_stiffness) + ": must be finite and >= 0");
  if (!(std::isfinite(cor) && cor >= 0.0 && cor <= 1.0))
    return Fail(why, "cor = " + Num(cor) + ": must be in [0, 1]");
  if (!finite_nonneg(hands_stiffness_n_m))
    return Fail(why, "hertz.hands_stiffness_n_m = " + Num(hands_stiffness_n_m) +
                         ": must be finite and >= 0");
  if (!finite_nonneg(hands_damping_n_s_m))
    return Fail(why, "hertz.hands_damping_n_s_m = " + Num(hands_damping_n_s_m) +
                         ": must be finite and >= 0");
  return true;
}

bool HertzSolverOptions::IsValid(std::string* why) const {
  if (!(std::isfinite(relative_tolerance) && relative_tolerance >= 1e-13 &&
        relative_tolerance <= 1e-2))
    return Fail(why, "hertz.relative_tolerance = " + Num(relative_tolerance) +
                         ": must be in [1e-13, 1e-2]");
  if (max_steps < 10)
    return Fail(why, "hertz.max_steps = " + std::to_string(max_steps) + ": must be >= 10");
  return true;
}

bool HertzOptions::IsValid(std::string* why) const {
  if (!(std::isfinite(hands_stiffness_n_m) && hands_stiffness_n_m >= 0.0))
    return Fail(why, "hertz.hands_stiffness_n_m = " + Num(hands_stiffness_n_m) +
                         ": must be finite and >= 0");
  if (!(std::isfinite(hands_damping_n_s_m) && hands_damping_n_s_m >= 0.0))
    return Fail(why, "hertz.hands_damping_n_s_m = " + Num(hands_damping_n_s_m) +
                         ": must be finite and >= 0");
  if (law == ContactLaw::kPaperConstants) {
    if (!(std::isfinite(paper.k1) && paper.k1 > 0.0))
      return Fail(why, "hertz.paper.k1 = " + Num(paper.k1) + ": must be finite and > 0");
    if (!(std::isfinite(paper.k2) && paper.k2 >= 0.0))
      return Fail(why, "hertz.paper.k2 = " + Num(paper.k2) + ": must be finite and >= 0");
    if (!std::isfinite(paper.k3))
      return Fail(why, "hertz.paper.k3 = " + Num(paper.k3) + ": must be finite");
  }
  return solver.IsValid(why);
}

HertzImpact SolveHertzImpact(const HertzProblem& problem, const HertzSolverOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  HertzImpact out;
  out.problem = problem;
  Summary& s = out.summary;
  s.backend = "odeint:runge_kutta_dopri5";
  s.models_used = {"hertz"};
  s.termination = Termination::kInvalidInput;
  auto finish = [&]() -> HertzImpact& {
    s.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  std::string why;
  if (!problem.IsValid(&why) || !options.IsValid(&why)) {
    s.message = why;
    return finish();
  }
  RawRun a = Integrate(problem, options.relative_tolerance, options.max_steps);
  s.iterations = a.steps;
  s.evaluations = static_cast<int>(a.evaluations);
  out.steps = a.steps;
  if (!a.ok) {
    s.termination = Termination::kFailure;
    s.message = a.message;
    return finish();
  }
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
  if (options.refine_check) {
    RawRun b = Integrate(problem, options.relative_tolerance / 16.0, options.max_steps);
    out.steps += b.steps;
    s.iterations = out.steps;
    s.evaluations += static_cast<int>(b.evaluations);
    if (!b.ok) {
      s.warnings.push_back("the refinement run at tolerance / 16 failed: " + b.message +
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
  s.message = "contact ended after " + Num(out.contact_time_s) + " s";
  s.objective = out.exit_speed_mps;
  s.error_estimate = out.error_estimate_exit_speed_mps;
  return finish();
}

}  // namespace sweetspot::core
