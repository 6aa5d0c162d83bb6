// flexible_impact: implementation; the assumptions are stated at the top of flexible_impact.hpp.
#include "core/collision/flexible_impact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "core/collision/contact_integration.hpp"
#include "core/collision/contact_law.hpp"
#include "core/collision/flexible_modal_system.hpp"
#include "core/flexible/static_flexibility.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/event_integrator.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/refusal.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

using flexible_detail::FindRecontact;
using flexible_detail::FreeAdvance;
using flexible_detail::FreeHandsPeaks;
using flexible_detail::kSamplesPerPeriod;
using flexible_detail::Model;
using flexible_detail::RawRun;
using flexible_detail::Rhs;
using flexible_detail::State;

constexpr double kTwoPi = 2.0 * kPi;

// One contact as the event integrator sees it: the right-hand side of Rhs, its events, the
// hands' loads sampled on every step and the branch changes at the events.
struct FlexibleSystem {
  Rhs* rhs = nullptr;
  double cor = 0.5;
  RawRun* out = nullptr;
  State sample;  // dense-output samples for the hands' loads
  double peak_d = 0.0, peak_f = 0.0;
  bool plastic = false;
  bool hands_loads = true;  // sample the hands' loads on every step

  void operator()(const State& y, State& dy, double t) const { (*rhs)(y, dy, t); }
  std::span<const EventSpec> ActiveEvents() const { return ContactEvents(rhs->branch.unloading); }
  double EventFunction(int id, const State& s) const {
    switch (id) {
      case kMaxCompression:
        return rhs->DeltaRate(s);
      case kEnd:
        return rhs->Delta(s);
      default:
        return rhs->total_delta_max / rhs->delta_s - rhs->Delta(s);
    }
  }
  void SampleHands(const State& s) {
    double v = 0.0, mo = 0.0;
    rhs->HandsLoads(s, rhs->Force(rhs->Delta(s)), &v, &mo);
    out->peak_shear_n = std::max(out->peak_shear_n, std::abs(v));
    out->peak_moment_n_m = std::max(out->peak_moment_n_m, std::abs(mo));
  }
  // The hands' loads at the end and the quarter points of each step, backwards: the end first,
  // where the step's last right-hand side left the force's warm start (one Newton iteration),
  // then each point from its neighbour a quarter step away. The warm start is put back for the
  // next step's stages, which start at the end.
  void OnStep(const DenseStep<State>& step) {
    if (!hands_loads) return;
    SampleHands(*step.y_end);
    const double force_at_end = rhs->last_force;
    for (int j = 3; j >= 1; --j) {
      step.StateAt(step.t_start + (step.t_end - step.t_start) * j / 4.0, &sample);
      SampleHands(sample);
    }
    rhs->last_force = force_at_end;
  }
  EventAction OnEvent(int id, double /*t*/, const State& ye) {
    if (id == kEnd) return EventAction::kStop;
    if (id == kReload) {
      rhs->branch.unloading = false;
      return EventAction::kContinue;
    }
    // Maximum compression: d_e (total) = the contact's share dc + the residual spring's.
    const double d_e = std::max(0.0, rhs->Delta(ye)) * rhs->delta_s;
    rhs->branch.unloading = false;
    const double f = rhs->Force(rhs->Delta(ye));
    const double dc = rhs->law->LoadingCompression(f);
    peak_f = std::max(peak_f, f);
    peak_d = std::max(peak_d, dc);
    if (cor == 0.0) {
      // Perfectly plastic: the stored energy is lost, the contact ends here; the static
      // deflection of the modes left out (the residual spring) is released into them.
      out->loss_j += rhs->law->LoadingWork(f, dc);
      out->released_j += 0.5 * rhs->model->residual_compliance * f * f;
      plastic = true;
      out->warnings.push_back(
          "cor = 0: perfectly plastic, the contact ends at maximum compression and later "
          "contacts are not followed");
      return EventAction::kStop;
    }
    rhs->branch.StartUnloading(*rhs->law, dc, f, cor);
    rhs->total_delta_max = d_e;
    return EventAction::kContinue;
  }
};

RawRun Integrate(const Model& model, const BallPowerLaw& law, const FlexibleImpactInputs& in,
                 double delta_s, double tol, const FlexibleImpactOptions& o,
                 double sting_window_s) {
  RawRun out;
  Rhs rhs;
  rhs.model = &model;
  rhs.law = &law;
  rhs.v0 = in.approach_speed_mps;
  rhs.delta_s = delta_s;
  rhs.t_s = delta_s / rhs.v0;
  rhs.m = in.ball_mass_kg;
  const std::size_t size = static_cast<std::size_t>(rhs.Size());
  State y(size, 0.0);
  y[1] = 1.0;
  double tau = 0.0;
  double om_max = 0.0;
  for (double om : model.omega_hat) om_max = std::max(om_max, om);
  FlexibleSystem sys;
  sys.rhs = &rhs;
  sys.cor = in.cor;
  sys.out = &out;
  sys.hands_loads = o.hands_loads;
  sys.sample.assign(size, 0.0);
  EventIntegrator<State> integrator(ContactIntegratorOptions(tol, o.max_steps, rhs.t_s));
  while (true) {
    ++out.contacts;
    rhs.branch = ContactBranch{};
    rhs.total_delta_max = 0.0;
    const bool stopped = integrator.Run(sys, &y, &tau);
    out.steps = integrator.summary().steps;
    out.evaluations = integrator.summary().evaluations;
    if (!stopped) {
      out.message = integrator.summary().message;
      return out;
    }
    if (!sys.plastic && rhs.branch.force_max_n > 0.0) {
      out.loss_j +=
          (1.0 - in.cor * in.cor) * law.LoadingWork(rhs.branch.force_max_n, rhs.branch.delta_max_m);
    }
    out.contact_time_s = tau * rhs.t_s;
    if (sys.plastic) break;
    if (out.contacts >= o.max_contacts) {
      out.warnings.push_back("max_contacts = " + std::to_string(o.max_contacts) +
                             " reached: further contacts are not followed");
      break;
    }
    const double dt_r = FindRecontact(rhs, y, &out.warnings);
    if (!(dt_r > 0.0)) break;
    FreeAdvance(rhs, dt_r, &y);
    tau += dt_r;
  }
  // The hands' loads over the free ringing that follows.
  if (om_max > 0.0 && o.hands_loads) {
    FreeHandsPeaks(rhs, y, sting_window_s / rhs.t_s, kTwoPi / (kSamplesPerPeriod * om_max), &out);
  }
  out.peak_force_n = sys.peak_f;
  out.max_compression_m = sys.peak_d;
  out.final_state = std::move(y);
  out.ok = true;
  return out;
}

// Calls f(x, weight) at 5-point Gauss points of every piece of [a, b] between mesh nodes and
// section breakpoints (exact for the piecewise polynomials of the FE fields and sections).
template <typename F>
void IntegrateAlong(const BatModes& modes, double a, double b, F&& f) {
  if (!(b > a)) return;
  static constexpr double kX[5] = {-0.9061798459386639927976269, -0.5384693101056830910363144, 0.0,
                                   0.5384693101056830910363144, 0.9061798459386639927976269};
  static constexpr double kW[5] = {0.2369268850561890875142640, 0.4786286704993664680412915,
                                   0.5688888888888888888888889, 0.4786286704993664680412915,
                                   0.2369268850561890875142640};
  std::vector<double> cuts = {a, b};
  for (double x : modes.nodes_m) {
    if (x > a && x < b) cuts.push_back(x);
  }
  for (double x : modes.breakpoints_m) {
    if (x > a && x < b) cuts.push_back(x);
  }
  std::sort(cuts.begin(), cuts.end());
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double half = 0.5 * (cuts[i + 1] - cuts[i]);
    const double mid = 0.5 * (cuts[i + 1] + cuts[i]);
    if (!(half > 0.0)) continue;
    for (int g = 0; g < 5; ++g) f(mid + half * kX[g], half * kW[g]);
  }
}

// The modes usable and the impact point and the hands within the bat [0, modes.length_m]:
// false with the failure in *s.
bool FlexibleImpactOnBat(const BatModes& modes, const FlexibleImpactInputs& in, Summary* s) {
  if (!modes.summary.IsSolutionUsable() || modes.modes.empty() || modes.nodes_m.size() < 2) {
    s->termination = Termination::kFailure;
    s->message = "the bat's modes are not usable: " + modes.summary.message;
    return false;
  }
  const double length = modes.length_m;
  if (!(in.impact_from_knob_m >= 0.0 && in.impact_from_knob_m <= length)) {
    s->message = "impact_from_knob_m = " + FormatNumber17(in.impact_from_knob_m) +
                 ": must be within the bat [0, " + FormatNumber17(length) + "]";
    return false;
  }
  if (!(in.hands_from_knob_m >= 0.0 && in.hands_from_knob_m <= length)) {
    s->message = "swing.hands_from_knob_m = " + FormatNumber17(in.hands_from_knob_m) +
                 ": must be within the bat [0, " + FormatNumber17(length) + "]";
    return false;
  }
  return true;
}

// How many of the computed modes (lowest first) are at or below f_cut_hz (Hz).
int ModesAtOrBelow(const BatModes& modes, double f_cut_hz) {
  const int available = static_cast<int>(modes.modes.size());
  int n = 0;
  while (n < available && modes.modes[static_cast<std::size_t>(n)].frequency_hz <= f_cut_hz) ++n;
  return n;
}

// The scaled model of the impact at in.impact_from_knob_m with the modes' FE vectors `vecs`
// (the two rigid modes first): omega_k t_s (t_s, s: the contact's time scale; 0 for the rigid
// modes) and phi_k(s) sqrt(m) (m: the ball's mass, kg); the hands' coefficients zero, the
// residual compliance left to the caller.
Model ScaledModalModel(const BatModes& modes, const std::vector<Eigen::VectorXd>& vecs,
                       const FlexibleImpactInputs& in, double t_s) {
  const double m = in.ball_mass_kg;
  const double h = in.hands_from_knob_m;
  const int n_all = static_cast<int>(vecs.size());
  Model full;
  full.n = n_all;
  full.omega_hat.assign(static_cast<std::size_t>(n_all), 0.0);
  full.phi_hat.resize(static_cast<std::size_t>(n_all));
  full.shear.assign(static_cast<std::size_t>(n_all), 0.0);
  full.moment.assign(static_cast<std::size_t>(n_all), 0.0);
  full.grip.assign(static_cast<std::size_t>(n_all), 0.0);
  full.force_sign_hands = in.impact_from_knob_m < h ? 1.0 : 0.0;
  full.arm_hands_m = in.impact_from_knob_m - h;
  for (int k = 0; k < n_all; ++k) {
    const std::size_t ks = static_cast<std::size_t>(k);
    if (k >= 2) full.omega_hat[ks] = kTwoPi * modes.modes[ks - 2].frequency_hz * t_s;
    full.phi_hat[ks] = modes.Displacement(vecs[ks], in.impact_from_knob_m) * std::sqrt(m);
  }
  return full;
}

// The residual flexibility (m/N) of the modes left out when the first n_flex bending modes are
// used: G(s) (`flexibility`, the inertia-relief flexibility at the impact point) less each used
// mode's phi_k(s)^2 / omega_k^2, at least 0; 0 without the static correction. `full`'s phi_hat
// is phi_k(s) sqrt(m), m = ball_mass_kg (kg).
double ResidualFlexibility(const BatModes& modes, const Model& full, double ball_mass_kg,
                           double flexibility, int n_flex, bool static_correction) {
  if (!static_correction) return 0.0;
  double used = 0.0;
  for (int k = 0; k < n_flex; ++k) {
    const double om = kTwoPi * modes.modes[static_cast<std::size_t>(k)].frequency_hz;
    const double phi = full.phi_hat[static_cast<std::size_t>(k + 2)] / std::sqrt(ball_mass_kg);
    used += phi * phi / (om * om);
  }
  return std::max(0.0, flexibility - used);
}

// The hands' coefficients of *full from the modes' fields `vecs`: the shear and moment
// integrals over the knob-side segment [0, h] (only when the hands' loads are asked for) and
// the grip's energy weights over the grip, o.hands_grip_length_m (m) centred on h (m).
void AddHandsIntegrals(const Bat& bat, const BatModes& modes,
                       const std::vector<Eigen::VectorXd>& vecs, double h,
                       const FlexibleImpactOptions& o, Model* full) {
  const int n_all = full->n;
  const bool rotary = modes.rotary_inertia;
  // Every mode's field at a quadrature point, the element's shapes evaluated once.
  std::vector<BeamField> fields(static_cast<std::size_t>(n_all));
  if (o.hands_loads)
    IntegrateAlong(modes, 0.0, h, [&](double x, double wgt) {
      const BeamSection sec = SectionAt(bat, x);
      EvaluateFields(modes.theory, modes.nodes_m, vecs, x, fields.data());
      for (int k = 0; k < n_all; ++k) {
        const std::size_t ks = static_cast<std::size_t>(k);
        const BeamField& f = fields[ks];
        const double w = f.bending_m + f.shear_m;
        full->shear[ks] += wgt * sec.mass_per_length_kg_m * w;
        full->moment[ks] += wgt * (sec.mass_per_length_kg_m * w * (x - h) +
                                   (rotary ? sec.rotary_inertia_kg_m * f.rotation : 0.0));
      }
    });
  const double g_lo = std::max(0.0, h - 0.5 * o.hands_grip_length_m);
  const double g_hi = std::min(modes.length_m, h + 0.5 * o.hands_grip_length_m);
  IntegrateAlong(modes, g_lo, g_hi, [&](double x, double wgt) {
    const BeamSection sec = SectionAt(bat, x);
    EvaluateFields(modes.theory, modes.nodes_m, vecs, x, fields.data());
    for (int k = 2; k < n_all; ++k) {
      const std::size_t ks = static_cast<std::size_t>(k);
      const BeamField& f = fields[ks];
      const double w = f.bending_m + f.shear_m;
      full->grip[ks] += wgt * (sec.mass_per_length_kg_m * w * w +
                               (rotary ? sec.rotary_inertia_kg_m * f.rotation * f.rotation : 0.0));
    }
  });
}

// The model with only the rigid modes and the first n_flex bending modes of `full`, its series
// spring `residual_compliance` (m/N).
Model FirstModes(const Model& full, int n_flex, double residual_compliance) {
  Model md = full;
  const std::size_t n = static_cast<std::size_t>(2 + n_flex);
  md.n = 2 + n_flex;
  md.omega_hat.resize(n);
  md.phi_hat.resize(n);
  md.shear.resize(n);
  md.moment.resize(n);
  md.grip.resize(n);
  md.residual_compliance = residual_compliance;
  return md;
}

// Energies and sting of one run: the ball's exit speed (m/s), the bending modes' energy and
// its grip-weighted share (J).
struct FlexibleOutcome {
  double exit = 0.0, vib = 0.0, hands = 0.0;
  // |this - other| per quantity: the change between two runs.
  FlexibleOutcome DistanceTo(const FlexibleOutcome& other) const {
    return {std::abs(exit - other.exit), std::abs(vib - other.vib), std::abs(hands - other.hands)};
  }
};

// The outcome of the run `r` of model `md`: u the ball's speed, v0 the approach speed (m/s),
// e_scale = m v0^2 (J per unit of scaled energy).
FlexibleOutcome FlexibleOutcomeOf(const Model& md, const RawRun& r, double u, double v0,
                                  double e_scale) {
  FlexibleOutcome oc;
  const State& y = r.final_state;
  const int n = md.n;
  oc.exit = -u + y[static_cast<std::size_t>(2 + 2 * n)] * v0;
  for (int k = 2; k < n; ++k) {
    const double om = md.omega_hat[static_cast<std::size_t>(k)];
    const double q = y[static_cast<std::size_t>(2 + k)];
    const double qd = y[static_cast<std::size_t>(2 + n + k)];
    const double ek = 0.5 * e_scale * (qd * qd + om * om * q * q);
    oc.vib += ek;
    oc.hands += ek * md.grip[static_cast<std::size_t>(k)];
  }
  return oc;
}

// The full model's run `a` (outcome `oa`) into *out: speeds (m/s), impulse (N s), contact (s, N,
// m), hands' peaks (N, N m), energies (J) and each bending mode's energy and frequency (Hz);
// m the ball's mass (kg), v0 the approach speed (m/s), e_scale = m v0^2 (J).
void TakeFullRun(const RawRun& a, const FlexibleOutcome& oa, const Model& full,
                 const BatModes& modes, double m, double v0, double e_scale,
                 FlexibleImpactResult* out) {
  const int n_all = full.n;
  const State& y = a.final_state;
  out->exit_speed_mps = oa.exit;
  out->vibration_energy_j = oa.vib + a.released_j;
  out->hands_vibration_energy_j = oa.hands;
  out->ball_impulse_n_s = y[static_cast<std::size_t>(2 + 2 * n_all)] * m * v0;
  out->contact_time_s = a.contact_time_s;
  out->contacts = a.contacts;
  out->peak_force_n = a.peak_force_n;
  out->max_compression_m = a.max_compression_m;
  out->hands_peak_shear_force_n = a.peak_shear_n;
  out->hands_peak_bending_moment_n_m = a.peak_moment_n_m;
  out->ball_energy_j = 0.5 * e_scale * y[1] * y[1];
  for (int k = 0; k < 2; ++k) {
    const double qd = y[static_cast<std::size_t>(2 + n_all + k)];
    out->rigid_body_energy_j += 0.5 * e_scale * qd * qd;
  }
  for (int k = 2; k < n_all; ++k) {
    const double om = full.omega_hat[static_cast<std::size_t>(k)];
    const double q = y[static_cast<std::size_t>(2 + k)];
    const double qd = y[static_cast<std::size_t>(2 + n_all + k)];
    out->modal_energies_j.push_back(0.5 * e_scale * (qd * qd + om * om * q * q));
    out->mode_frequencies_hz.push_back(modes.modes[static_cast<std::size_t>(k - 2)].frequency_hz);
  }
  out->contact_loss_j = a.loss_j;
  out->contact_work_j = y[static_cast<std::size_t>(3 + 2 * n_all)] * e_scale;
  out->energy_balance_error_j =
      out->initial_energy_j - (out->ball_energy_j + out->rigid_body_energy_j +
                               out->vibration_energy_j + out->contact_loss_j);
}

// What every run of one impact shares: the inputs, the contact law, the compression scale
// delta_s (m) and the window (s) over which the hands' loads are followed after the contact.
struct FlexibleRuns {
  const BallPowerLaw* law = nullptr;
  const FlexibleImpactInputs* in = nullptr;
  const FlexibleImpactOptions* o = nullptr;
  double delta_s = 1.0;
  double window_s = 0.0;
  // A run of model `md` to the relative tolerance `tol`.
  RawRun Run(const Model& md, double tol) const {
    return Integrate(md, *law, *in, delta_s, tol, *o, window_s);
  }
};

// The answer's error estimates into *out (exit speed: m/s; energies: J). With the refinement
// check: the change with the finer tolerance (runs.fine) plus the change with half the cutoff
// (a run of the modes below it, their residual from `flexibility`, m/N), each against the full
// model's outcome `oa`; without it, the tolerance's share only.
void EstimateFlexibleErrors(const RefinedRuns<RawRun>& runs, const FlexibleOutcome& oa,
                            const Model& full, const FlexibleRuns& runner, const BatModes& modes,
                            double flexibility, int n_used, FlexibleImpactResult* out) {
  Summary& s = out->summary;
  const FlexibleImpactInputs& in = *runner.in;
  const FlexibleImpactOptions& o = *runner.o;
  const double m = in.ball_mass_kg;
  const double u = in.ball_speed_mps;
  const double v0 = in.approach_speed_mps;
  const double e_scale = m * v0 * v0;  // scaled energy -> J
  if (!runs.refined) {
    // Without the refinement check: the integration tolerance's share only.
    out->error_estimate_exit_speed_mps = o.relative_tolerance * (u + std::abs(oa.exit));
    out->error_estimate_vibration_energy_j = o.relative_tolerance * out->vibration_energy_j;
    out->error_estimate_hands_energy_j = o.relative_tolerance * out->hands_vibration_energy_j;
    return;
  }
  const RawRun& fine = runs.fine;
  FlexibleOutcome integration;  // the change with the finer tolerance
  if (fine.ok) {
    integration = FlexibleOutcomeOf(full, fine, u, v0, e_scale).DistanceTo(oa);
  } else {
    s.warnings.push_back(RefineFailedWarning(fine.message));
    integration.exit = o.relative_tolerance * (u + std::abs(oa.exit));
  }
  out->integration_error_exit_speed_mps = integration.exit;
  const int n_half = ModesAtOrBelow(modes, 0.5 * out->cutoff_hz);
  FlexibleOutcome truncation;  // the change with half the cutoff
  if (n_half < n_used) {
    const double residual =
        ResidualFlexibility(modes, full, m, flexibility, n_half, o.static_correction);
    const Model half = FirstModes(full, n_half, residual + in.barrel_compliance_m_n);
    RawRun hr = runner.Run(half, o.relative_tolerance);
    out->steps += hr.steps;
    s.evaluations += static_cast<int>(hr.evaluations);
    if (hr.ok) {
      truncation = FlexibleOutcomeOf(half, hr, u, v0, e_scale).DistanceTo(oa);
    } else {
      s.warnings.push_back("the truncation check with half the cutoff failed: " + hr.message);
    }
  }
  out->truncation_error_exit_speed_mps = truncation.exit;
  out->error_estimate_exit_speed_mps = integration.exit + truncation.exit;
  out->error_estimate_vibration_energy_j = integration.vib + truncation.vib;
  out->error_estimate_hands_energy_j = integration.hands + truncation.hands;
}

}  // namespace

bool FlexibleImpactOptions::Validate(Refusal* why) const {
  if (max_modes < 1 || max_modes > 50)
    return Refuse(why, IntegerRefusal("flexible.max_modes", max_modes, "must be in [1, 50]"));
  if (!(std::isfinite(frequency_tolerance) && frequency_tolerance >= 1e-9 &&
        frequency_tolerance <= 0.1))
    return Refuse(why, Number17Refusal("flexible.impact.frequency_tolerance", frequency_tolerance,
                                       "must be in [1e-9, 0.1]"));
  if (!(std::isfinite(cutoff_factor) && cutoff_factor >= 1.0 && cutoff_factor <= 1000.0))
    return Refuse(why,
                  Number17Refusal("flexible.cutoff_factor", cutoff_factor, "must be in [1, 1000]"));
  if (!ContactIntegrationValidate("flexible", relative_tolerance, max_steps, why)) return false;
  if (max_contacts < 1 || max_contacts > 1000)
    return Refuse(why,
                  IntegerRefusal("flexible.max_contacts", max_contacts, "must be in [1, 1000]"));
  if (!(std::isfinite(hands_grip_length_m) && hands_grip_length_m >= 0.0 &&
        hands_grip_length_m <= 10.0))
    return Refuse(why, Number17Refusal("flexible.hands_grip_length_m", hands_grip_length_m,
                                       "must be in [0, 10]"));
  if (!(std::isfinite(sting_window_s) && sting_window_s >= 0.0 && sting_window_s <= 1.0))
    return Refuse(why,
                  Number17Refusal("flexible.sting_window_s", sting_window_s, "must be in [0, 1]"));
  return true;
}

bool FlexibleImpactInputs::Validate(Refusal* why) const {
  auto finite_pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!std::isfinite(impact_from_knob_m))
    return Refuse(why, Number17Refusal("impact_from_knob_m", impact_from_knob_m, "must be finite"));
  if (!std::isfinite(hands_from_knob_m))
    return Refuse(why,
                  Number17Refusal("swing.hands_from_knob_m", hands_from_knob_m, "must be finite"));
  if (!finite_pos(ball_mass_kg))
    return Refuse(why, Number17Refusal("ball.mass_kg", ball_mass_kg, "must be finite and > 0"));
  if (!(std::isfinite(ball_speed_mps) && ball_speed_mps >= 0.0))
    return Refuse(why,
                  Number17Refusal("ball.speed_mps", ball_speed_mps, "must be finite and >= 0"));
  if (!finite_pos(approach_speed_mps))
    return Refuse(
        why,
        Number17Refusal("approach_speed_mps", approach_speed_mps,
                        "must be finite and > 0 (the ball and the bat must approach each other)"));
  if (!BallLawValidate(ball_stiffness, ball_exponent, why)) return false;
  if (!(std::isfinite(surface_stiffness) && surface_stiffness >= 0.0))
    return Refuse(
        why, Number17Refusal("surface_stiffness", surface_stiffness, "must be finite and >= 0"));
  if (!(std::isfinite(cor) && cor >= 0.0 && cor <= 1.0))
    return Refuse(why, Number17Refusal("cor", cor, "must be in [0, 1]"));
  if (!(std::isfinite(barrel_compliance_m_n) && barrel_compliance_m_n >= 0.0))
    return Refuse(why, Number17Refusal("barrel_compliance_m_n", barrel_compliance_m_n,
                                       "must be finite and >= 0"));
  return true;
}

FlexibleImpactResult SolveFlexibleImpact(const Bat& bat, const BatModes& modes,
                                         const FlexibleImpactInputs& in,
                                         const FlexibleImpactOptions& o) {
  return TimedSolve<FlexibleImpactResult>([&](FlexibleImpactResult& out) {
    Summary& s = out.summary;
    if (!StartContactSolve("flexible", &s, o, in)) return;
    if (!FlexibleImpactOnBat(modes, in, &s)) return;
    out.theory = modes.theory;
    out.elements = modes.Elements();
    const double m = in.ball_mass_kg;
    const double u = in.ball_speed_mps;
    const double v0 = in.approach_speed_mps;
    const double e = in.cor;
    const double big_m = modes.mass_kg;
    const double i_cm = modes.moi_centroid_kg_m2;
    const double b = in.impact_from_knob_m - modes.balance_point_m;
    const double c11 = 1.0 / m + 1.0 / big_m + b * b / i_cm;
    const double recoil = m * (1.0 / big_m + b * b / i_cm);
    out.rigid_exit_speed_mps = -u + (1.0 + e) * v0 / (1.0 + recoil);
    out.initial_energy_j = 0.5 * m * v0 * v0;

    const BallPowerLaw law(in.ball_stiffness, in.ball_exponent, in.surface_stiffness);
    const double delta_s = ContactCompressionScaleM(c11, in.ball_stiffness, in.ball_exponent, v0);
    out.contact_time_estimate_s = ElasticContactTimeS(c11, in.ball_stiffness, in.ball_exponent, v0);
    out.cutoff_hz = o.cutoff_factor / out.contact_time_estimate_s;
    if (!(std::isfinite(delta_s) && delta_s > 0.0 && std::isfinite(out.cutoff_hz))) {
      s.termination = Termination::kFailure;
      s.message = "contact scales are not finite (delta_s = " + FormatNumber17(delta_s) + " m)";
      return;
    }
    const double t_s = delta_s / v0;
    const int n_used = ModesAtOrBelow(modes, out.cutoff_hz);
    const int available = static_cast<int>(modes.modes.size());
    // Every computed mode below the cutoff: harmless with the static correction unless the
    // computed modes stop well short of it.
    if (n_used == available &&
        (!o.static_correction || modes.modes.back().frequency_hz < 0.5 * out.cutoff_hz)) {
      s.warnings.push_back(
          "the mode cutoff (cutoff_factor / contact time) is above the highest "
          "computed mode (" +
          std::to_string(available) + " modes, up to " +
          FormatNumber17(modes.modes.back().frequency_hz) +
          " Hz): every computed mode is used, the static correction stands for "
          "the rest; raise flexible.max_modes to include more");
    }

    // Every mode's coefficients (rigid ones first), computed once.
    const double h = in.hands_from_knob_m;
    std::vector<Eigen::VectorXd> vecs = {modes.TranslationMode(), modes.RotationMode()};
    for (int k = 0; k < n_used; ++k)
      vecs.push_back(modes.modes[static_cast<std::size_t>(k)].vector);
    Model full = ScaledModalModel(modes, vecs, in, t_s);
    // Residual flexibility of the modes left out: G(s) - sum over the modes used.
    double flexibility = 0.0;
    if (o.static_correction) {
      flexibility = InertiaReliefFlexibility(bat, modes, in.impact_from_knob_m);
      if (!std::isfinite(flexibility)) {
        s.termination = Termination::kFailure;
        s.message = "the static flexibility at the impact point could not be computed";
        return;
      }
    }
    const double residual =
        ResidualFlexibility(modes, full, m, flexibility, n_used, o.static_correction);
    // The contact's series spring: the modes left out and the barrel's wall (both elastic).
    full.residual_compliance = residual + in.barrel_compliance_m_n;
    out.residual_compliance_m_n = residual;
    // The knob-side segment's inertia (only the hands' loads need it) and the grip's weights.
    AddHandsIntegrals(bat, modes, vecs, h, o, &full);
    double window = o.sting_window_s;
    if (window == 0.0) window = 1.0 / modes.modes.front().frequency_hz;

    const double e_scale = m * v0 * v0;  // scaled energy -> J
    const FlexibleRuns runner{&law, &in, &o, delta_s, window};
    const RefinedRuns<RawRun> runs = SolveWithRefineCheck<RawRun>(
        o.relative_tolerance, o.refine_check, [&](double tol) { return runner.Run(full, tol); });
    out.steps = CountRefinedRuns(runs, &s);
    if (!runs.coarse.ok) return;
    const RawRun& a = runs.coarse;
    const FlexibleOutcome oa = FlexibleOutcomeOf(full, a, u, v0, e_scale);
    TakeFullRun(a, oa, full, modes, m, v0, e_scale, &out);
    out.modes_used = n_used;
    s.warnings.insert(s.warnings.end(), a.warnings.begin(), a.warnings.end());
    EstimateFlexibleErrors(runs, oa, full, runner, modes, flexibility, n_used, &out);
    s.iterations = out.steps;
    s.termination = Termination::kConverged;
    s.message = "contact ended after " + FormatNumber17(out.contact_time_s) + " s (" +
                std::to_string(out.contacts) + (out.contacts == 1 ? " contact" : " contacts") +
                ", " + std::to_string(n_used) + " bending modes)";
    s.objective = out.exit_speed_mps;
    s.error_estimate = out.error_estimate_exit_speed_mps;
  });
}

}  // namespace sweetspot::core
