// The flexible impact's modal system, shared by its two sources (flexible_impact.cpp: the
// contact on the event integrator; flexible_free_flight.cpp: the exact free motion between
// contacts). Internal to core/collision/: not part of core's API.
#pragma once

#include <string>
#include <vector>

#include "core/collision/contact_law.hpp"

namespace sweetspot::core::flexible_detail {

/// The impact's state (scaled): ball position and speed, the modal coordinates and their
/// rates, the ball's impulse and the work of the contact force.
using State = std::vector<double>;

// The modes in the superposition and what each contributes at the impact point and the hands.
struct Model {
  int n = 0;                      // modes, the 2 rigid ones first
  std::vector<double> omega_hat;  // omega_k t_s (0 for the rigid modes)
  std::vector<double> phi_hat;    // phi_k(s) sqrt(m)
  std::vector<double> shear;      // S_k = int_0^h rho A phi_k dx, kg^0.5
  std::vector<double> moment;     // T_k = int_0^h rho A phi_k (x - h) + rho I theta_k dx, kg^0.5 m
  std::vector<double> grip;       // G_k = int_grip rho A phi_k^2 + rho I theta_k^2 dx
  double residual_compliance = 0.0;  // sum over the modes left out of phi_k(s)^2 / omega_k^2, m/N
  double force_sign_hands = 0.0;     // 1 when the ball strikes the knob-side segment [0, h)
  double arm_hands_m = 0.0;          // s - h
};

// Scales and the contact state shared by the right-hand side and the driver.
struct Rhs {
  const Model* model = nullptr;
  const BallPowerLaw* law = nullptr;
  double delta_s = 1.0, v0 = 1.0, t_s = 1.0, m = 1.0;
  ContactBranch branch;             // the contact's own compression (ball + surface), m
  double total_delta_max = 0.0;     // branch.delta_max_m plus the residual spring's share, m
  mutable double last_force = 0.0;  // warm start of Force's Newton iteration (a cache only)

  int Q(int k) const { return 2 + k; }
  int QD(int k) const { return 2 + model->n + k; }
  int P() const { return 2 + 2 * model->n; }
  int W() const { return 3 + 2 * model->n; }
  int Size() const { return 4 + 2 * model->n; }

  // Scaled compression (ball surface to the bat's modal surface) and its rate.
  double Delta(const State& y) const {
    double w = 0.0;
    for (int k = 0; k < model->n; ++k) {
      w += model->phi_hat[static_cast<std::size_t>(k)] * y[static_cast<std::size_t>(Q(k))];
    }
    return y[0] - w;
  }
  double DeltaRate(const State& y) const {
    double w = 0.0;
    for (int k = 0; k < model->n; ++k) {
      w += model->phi_hat[static_cast<std::size_t>(k)] * y[static_cast<std::size_t>(QD(k))];
    }
    return y[1] - w;
  }
  // Force (N) at scaled total compression d: the contact in series with the residual spring
  // (the static compliance of the modes left out; contact_law.hpp's SeriesContactForce).
  double Force(double d_scaled) const {
    return SeriesContactForce(*law, branch, model->residual_compliance, d_scaled * delta_s,
                              &last_force);
  }
  void operator()(const State& y, State& dy, double /*t*/) const {
    const double f = Force(Delta(y));
    const double fh = f * t_s / (m * v0);
    dy[0] = y[1];
    dy[1] = -fh;
    const int n = model->n;
    for (int k = 0; k < n; ++k) {
      const std::size_t ks = static_cast<std::size_t>(k);
      const double om = model->omega_hat[ks];
      dy[static_cast<std::size_t>(Q(k))] = y[static_cast<std::size_t>(QD(k))];
      dy[static_cast<std::size_t>(QD(k))] =
          -om * om * y[static_cast<std::size_t>(Q(k))] + model->phi_hat[ks] * fh;
    }
    dy[static_cast<std::size_t>(P())] = fh;
    dy[static_cast<std::size_t>(W())] = fh * DeltaRate(y);
  }
  // Shear force and bending moment at the hands (N, N m) for state y with contact force f.
  void HandsLoads(const State& y, double f, double* shear, double* moment) const {
    const double scale = delta_s * std::sqrt(m) / (t_s * t_s);  // scaled q'' -> physical
    const double fh = f * t_s / (m * v0);
    double v = 0.0, mo = 0.0;
    for (int k = 0; k < model->n; ++k) {
      const std::size_t ks = static_cast<std::size_t>(k);
      const double om = model->omega_hat[ks];
      const double acc =
          scale * (-om * om * y[static_cast<std::size_t>(Q(k))] + model->phi_hat[ks] * fh);
      v += model->shear[ks] * acc;
      mo += model->moment[ks] * acc;
    }
    v -= model->force_sign_hands * f;
    mo -= model->force_sign_hands * f * model->arm_hands_m;
    *shear = v;
    *moment = mo;
  }
};

/// What one run of the impact (its contacts and the free flight between them) produced.
struct RawRun {
  bool ok = false;
  std::string message;
  std::vector<std::string> warnings;
  State final_state;
  double contact_time_s = 0.0;
  int contacts = 0;
  double peak_force_n = 0.0;
  double max_compression_m = 0.0;
  double loss_j = 0.0;
  double released_j = 0.0;  // residual-spring energy released by an abrupt (plastic) end, J
  double peak_shear_n = 0.0;
  double peak_moment_n_m = 0.0;
  int steps = 0;
  long evaluations = 0;
};

/// Exact free motion over dtau (scaled): ballistic ball, rigid modes linear, flexible harmonic.
void FreeAdvance(const Rhs& rhs, double dtau, State* y);

/// Samples the hands' loads along free motion from y over [0, window] (scaled, step dtau) and
/// updates run's peaks.
void FreeHandsPeaks(const Rhs& rhs, const State& y, double window, double dtau, RawRun* run);

/// The first time (scaled, > 0) the free motion from y closes the gap again, or a negative
/// value; warnings get what limited the search.
double FindRecontact(const Rhs& rhs, const State& y, std::vector<std::string>* warnings);

/// Free flight is scanned with this many samples per period of the highest mode (a touch
/// shorter than 1/32 of that period can be missed; its impulse is negligible).
inline constexpr int kSamplesPerPeriod = 32;

}  // namespace sweetspot::core::flexible_detail
