// barrel: implementation; the model and its sources are stated at the top of barrel.hpp.
#include "core/collision/barrel.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>

#include <Eigen/Dense>

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/collision/contact_integration.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/event_integrator.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace barrel_detail {

using TrampolineState = std::array<double, 5>;  // scaled: delta, delta', w, w', P

// The ball, the wall's modal mass and the rest of the bat on the scaled state. Scales: lengths
// by delta_s, speeds by v0, time by t_s = delta_s / v0, the impulse by p_s = v0 / c11.
struct TrampolineSystem {
  const TrampolineProblem* p = nullptr;
  BallPowerLaw law;
  ContactBranch branch;
  double delta_s = 1.0, v0 = 1.0, t_s = 1.0, p_s = 1.0;
  double rest_mass_kg = 1.0;  // M_e - m_eff
  double damping_n_s_m = 0.0;
  double peak_force_n = 0.0;
  double max_w_m = 0.0;
  double barrel_fraction = 0.0;
  TrampolineResult* out = nullptr;

  void operator()(const TrampolineState& y, TrampolineState& dy, double /*t*/) const {
    const double fc = branch.Force(law, y[0] * delta_s);
    const double fb = p->barrel_stiffness_n_m * y[2] * delta_s + damping_n_s_m * y[3] * v0;
    const double ms = p->barrel_modal_mass_kg;
    const double dd = -fc / p->ball_mass_kg - (fc - fb) / ms;
    const double ww = (fc - fb) / ms - fb / rest_mass_kg;
    dy[0] = y[1];
    dy[1] = dd * t_s / v0;
    dy[2] = y[3];
    dy[3] = ww * t_s / v0;
    dy[4] = fc * t_s / p_s;
  }

  std::span<const EventSpec> ActiveEvents() const { return ContactEvents(branch.unloading); }
  // The contact's events on the compression delta (ContactEventId).
  double EventFunction(int id, const TrampolineState& s) const {
    return ContactEventValue(id, s[0], s[1], branch.delta_max_m / delta_s);
  }
  void OnStep(const DenseStep<TrampolineState>& step) {
    const TrampolineState& y = *step.y_end;
    peak_force_n = std::max(peak_force_n, branch.Force(law, y[0] * delta_s));
    max_w_m = std::max(max_w_m, std::abs(y[2]) * delta_s);
  }
  EventAction OnEvent(int id, double te, const TrampolineState& ye) {
    if (id == kEnd) {
      out->ok = true;
      out->contact_time_s = te * t_s;
      out->ball_impulse_n_s = ye[4] * p_s;
      return EventAction::kStop;
    }
    if (id == kReload) {
      branch.unloading = false;
      return EventAction::kContinue;
    }
    const double d = std::max(0.0, ye[0]) * delta_s;
    const double f = law.LoadingForce(d);
    peak_force_n = std::max(peak_force_n, f);
    const double wb = 0.5 * p->barrel_stiffness_n_m * std::pow(ye[2] * delta_s, 2);
    const double wc = law.LoadingWork(f, d);
    if (wb + wc > 0.0) barrel_fraction = wb / (wb + wc);
    branch.StartUnloading(law, d, f, p->ball_cor);
    return EventAction::kContinue;
  }
};

// One n = 2 ring FE model: 3 DOF per node (u, v, theta), straight frame elements.
double RingFe(double e_prime, double rho, double radius, double h, int n_el) {
  const int n_dof = 3 * n_el;
  Eigen::MatrixXd kk = Eigen::MatrixXd::Zero(n_dof, n_dof);
  Eigen::MatrixXd mm = Eigen::MatrixXd::Zero(n_dof, n_dof);
  const double area = h, inertia = h * h * h / 12.0;  // per unit axial width
  const double len = 2.0 * radius * std::sin(kPi / n_el);
  const double ea = e_prime * area / len, ei = e_prime * inertia;
  const double l2 = len * len, l3 = l2 * len;
  Eigen::Matrix<double, 6, 6> kl = Eigen::Matrix<double, 6, 6>::Zero();
  kl(0, 0) = kl(3, 3) = ea;
  kl(0, 3) = kl(3, 0) = -ea;
  const int b[4] = {1, 2, 4, 5};
  const double kb[4][4] = {{12, 6 * len, -12, 6 * len},
                           {6 * len, 4 * l2, -6 * len, 2 * l2},
                           {-12, -6 * len, 12, -6 * len},
                           {6 * len, 2 * l2, -6 * len, 4 * l2}};
  const double mb[4][4] = {{156, 22 * len, 54, -13 * len},
                           {22 * len, 4 * l2, 13 * len, -3 * l2},
                           {54, 13 * len, 156, -22 * len},
                           {-13 * len, -3 * l2, -22 * len, 4 * l2}};
  Eigen::Matrix<double, 6, 6> ml = Eigen::Matrix<double, 6, 6>::Zero();
  const double mass = rho * area * len;
  ml(0, 0) = ml(3, 3) = mass / 3.0;
  ml(0, 3) = ml(3, 0) = mass / 6.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      kl(b[i], b[j]) = ei / l3 * kb[i][j];
      ml(b[i], b[j]) = mass / 420.0 * mb[i][j];
    }
  }
  for (int e = 0; e < n_el; ++e) {
    const double phi = kPi / 2.0 + kPi * (2.0 * e + 1.0) / n_el;  // chord direction
    const double c = std::cos(phi), s = std::sin(phi);
    Eigen::Matrix<double, 6, 6> t = Eigen::Matrix<double, 6, 6>::Zero();
    for (int k = 0; k < 2; ++k) {
      t(3 * k, 3 * k) = c;
      t(3 * k, 3 * k + 1) = s;
      t(3 * k + 1, 3 * k) = -s;
      t(3 * k + 1, 3 * k + 1) = c;
      t(3 * k + 2, 3 * k + 2) = 1.0;
    }
    const Eigen::Matrix<double, 6, 6> kg = t.transpose() * kl * t;
    const Eigen::Matrix<double, 6, 6> mg = t.transpose() * ml * t;
    const int nodes[2] = {e, (e + 1) % n_el};
    for (int a = 0; a < 2; ++a) {
      for (int c2 = 0; c2 < 2; ++c2) {
        kk.block<3, 3>(3 * nodes[a], 3 * nodes[c2]) += kg.block<3, 3>(3 * a, 3 * c2);
        mm.block<3, 3>(3 * nodes[a], 3 * nodes[c2]) += mg.block<3, 3>(3 * a, 3 * c2);
      }
    }
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(kk, mm, Eigen::EigenvaluesOnly);
  if (solver.info() != Eigen::Success) return 0.0;
  // Three rigid-body modes (two translations, one rotation) come first, then the n = 2 pair.
  return std::sqrt(std::max(0.0, solver.eigenvalues()(3))) / (2.0 * kPi);
}

// e_eff at one point of a hollow bat with effective mass m_e.
TrampolineResult HollowImpact(const Bat& bat, double x_m, double m_e, double ball_mass_kg,
                              double ball_radius_m, double ball_stiffness, double ball_exponent,
                              double ball_cor, double approach_speed_mps,
                              const BarrelOptions& options, BarrelWall* wall_out) {
  const BarrelWall wall = BarrelWallAt(bat, x_m, options);
  if (wall_out != nullptr) *wall_out = wall;
  TrampolineProblem p;
  p.ball_mass_kg = ball_mass_kg;
  p.ball_stiffness = ball_stiffness;
  p.ball_exponent = ball_exponent;
  p.surface_stiffness =
      BatSurfaceHertzStiffness(bat.material.youngs_modulus_pa, bat.material.poissons_ratio,
                               ball_radius_m, wall.outer_radius_m);
  p.ball_cor = ball_cor;
  p.bat_effective_mass_kg = m_e;
  p.approach_speed_mps = approach_speed_mps;
  p.barrel_stiffness_n_m = wall.stiffness_n_m;
  p.barrel_modal_mass_kg = wall.modal_mass_kg;
  p.barrel_damping_ratio = wall.damping_ratio;
  p.barrel_loss = wall.barrel_loss;
  return QuasiStaticTrampoline(p);
}

}  // namespace barrel_detail

double RingModeFrequencyHz(double youngs_modulus_pa, double poissons_ratio, double density_kg_m3,
                           double radius_m, double thickness_m, int n) {
  const double e_prime = youngs_modulus_pa / (1.0 - poissons_ratio * poissons_ratio);
  const double n2 = static_cast<double>(n) * n;
  const double r2 = radius_m * radius_m;
  const double omega2 = e_prime * thickness_m * thickness_m * n2 * (n2 - 1.0) * (n2 - 1.0) /
                        (12.0 * density_kg_m3 * r2 * r2 * (n2 + 1.0));
  return std::sqrt(omega2) / (2.0 * kPi);
}

double RingFeHoopFrequencyHz(double youngs_modulus_pa, double poissons_ratio, double density_kg_m3,
                             double radius_m, double thickness_m, int elements) {
  const double e_prime = youngs_modulus_pa / (1.0 - poissons_ratio * poissons_ratio);
  return barrel_detail::RingFe(e_prime, density_kg_m3, radius_m, thickness_m,
                               std::max(8, elements));
}

bool BarrelOptions::Validate(Refusal* why) const {
  if (!(std::isfinite(barrel_loss) && barrel_loss >= 0.0 && barrel_loss < 1.0))
    return Refuse(why, Number17Refusal("barrel.barrel_loss", barrel_loss, "must be in [0, 1)"));
  if (!(std::isfinite(shell_factor) && shell_factor > 0.0))
    return Refuse(why,
                  Number17Refusal("barrel.shell_factor", shell_factor, "must be finite and > 0"));
  if (!(std::isfinite(effective_length_m) && effective_length_m >= 0.0))
    return Refuse(why, Number17Refusal("barrel.effective_length_m", effective_length_m,
                                       "must be finite and >= 0 (0 = the default)"));
  return ContactIntegrationValidate("barrel", relative_tolerance, max_steps, why);
}

BarrelWall BarrelWallAt(const Bat& bat, double x_m, const BarrelOptions& options) {
  BarrelWall w;
  const double r_out = bat.RadiusAtM(x_m);
  const double wall = bat.WallAtM(x_m);  // the wall there (issue 35: walls per knot)
  if (!bat.IsHollow() || !(r_out > wall)) return w;
  const Material& mat = bat.material;
  w.hollow = true;
  w.outer_radius_m = r_out;
  w.thickness_m = wall;
  const double h = w.thickness_m;
  const double r = r_out - 0.5 * h;
  w.mid_radius_m = r;
  w.effective_length_m =
      options.effective_length_m > 0.0 ? options.effective_length_m : 2.0 * r * std::sqrt(r / h);
  const double l = w.effective_length_m;
  const double e_prime = mat.youngs_modulus_pa / (1.0 - mat.poissons_ratio * mat.poissons_ratio);
  w.hoop_frequency_hz =
      RingModeFrequencyHz(mat.youngs_modulus_pa, mat.poissons_ratio, mat.density_kg_m3, r, h);
  w.modal_mass_kg = 1.25 * kPi * mat.density_kg_m3 * h * r * l;
  w.ring_stiffness_n_m = 0.75 * kPi * e_prime * h * h * h * l / (r * r * r);
  w.stiffness_n_m = options.shell_factor * w.ring_stiffness_n_m;
  w.barrel_loss = options.barrel_loss;
  w.damping_ratio = -std::log1p(-options.barrel_loss) / (2.0 * kPi);
  return w;
}

TrampolineResult TrampolineImpact(const TrampolineProblem& p, const BarrelOptions& options) {
  using barrel_detail::TrampolineState;
  TrampolineResult out;
  if (Refusal why; !options.Validate(&why)) {
    out.message = why.Message();
    return out;
  }
  const double rest = p.bat_effective_mass_kg - p.barrel_modal_mass_kg;
  if (!(p.ball_mass_kg > 0.0 && p.barrel_modal_mass_kg > 0.0 && rest > 0.0 &&
        p.barrel_stiffness_n_m > 0.0 && p.approach_speed_mps > 0.0 && p.ball_cor > 0.0 &&
        p.ball_cor <= 1.0 && p.barrel_damping_ratio >= 0.0)) {
    out.message =
        "trampoline: masses, stiffness, approach speed and ball COR must be > 0 and "
        "the wall's modal mass below the bat's effective mass";
    return out;
  }
  barrel_detail::TrampolineSystem sys;
  sys.p = &p;
  sys.out = &out;
  sys.law = BallPowerLaw(p.ball_stiffness, p.ball_exponent, p.surface_stiffness);
  sys.v0 = p.approach_speed_mps;
  const double c11 = 1.0 / p.ball_mass_kg + 1.0 / p.bat_effective_mass_kg;
  sys.delta_s = ContactCompressionScaleM(c11, p.ball_stiffness, p.ball_exponent, sys.v0);
  sys.t_s = sys.delta_s / sys.v0;
  sys.p_s = sys.v0 / c11;
  sys.rest_mass_kg = rest;
  const double mu = p.barrel_modal_mass_kg * rest / p.bat_effective_mass_kg;
  sys.damping_n_s_m = 2.0 * p.barrel_damping_ratio * std::sqrt(p.barrel_stiffness_n_m * mu);
  EventIntegrator<TrampolineState> integrator(
      ContactIntegratorOptions(options.relative_tolerance, options.max_steps, sys.t_s));
  TrampolineState y{0.0, 1.0, 0.0, 0.0, 0.0};
  double t = 0.0;
  const bool stopped = integrator.Run(sys, &y, &t);
  out.steps = integrator.summary().steps;
  if (!stopped || !out.ok) {
    out.ok = false;
    out.message = integrator.summary().message;
    return out;
  }
  out.peak_force_n = sys.peak_force_n;
  out.max_barrel_deflection_m = sys.max_w_m;
  out.barrel_energy_fraction = sys.barrel_fraction;
  out.effective_cor = out.ball_impulse_n_s * (1.0 + p.ball_mass_kg / p.bat_effective_mass_kg) /
                          (p.ball_mass_kg * p.approach_speed_mps) -
                      1.0;
  return out;
}

TrampolineResult QuasiStaticTrampoline(const TrampolineProblem& p) {
  TrampolineResult out;
  if (!(p.ball_mass_kg > 0.0 && p.bat_effective_mass_kg > 0.0 && p.barrel_stiffness_n_m > 0.0 &&
        p.approach_speed_mps > 0.0 && p.ball_cor >= 0.0 && p.ball_cor <= 1.0 &&
        p.barrel_loss >= 0.0 && p.barrel_loss < 1.0 && p.ball_stiffness > 0.0)) {
    out.message =
        "trampoline: masses, stiffnesses and the approach speed must be > 0, the ball's "
        "COR in [0, 1] and the barrel's loss in [0, 1)";
    return out;
  }
  const BallPowerLaw law(p.ball_stiffness, p.ball_exponent, p.surface_stiffness);
  const double mu =
      p.ball_mass_kg * p.bat_effective_mass_kg / (p.ball_mass_kg + p.bat_effective_mass_kg);
  const double energy = 0.5 * mu * p.approach_speed_mps * p.approach_speed_mps;
  auto works = [&](double f, double* wc, double* wb) {
    *wc = law.LoadingWork(f, law.LoadingCompression(f));
    *wb = 0.5 * f * f / p.barrel_stiffness_n_m;
  };
  // W_c + W_b grows monotonically with F: bracket, then bisect.
  double lo = 0.0, hi = 1.0, wc = 0.0, wb = 0.0;
  for (works(hi, &wc, &wb); wc + wb < energy && hi < 1e30; works(hi, &wc, &wb)) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    works(mid, &wc, &wb);
    (wc + wb < energy ? lo : hi) = mid;
  }
  const double f = 0.5 * (lo + hi);
  works(f, &wc, &wb);
  const double e = p.ball_cor;
  const double lost = ((1.0 - e * e) * wc + p.barrel_loss * wb) / (wc + wb);
  out.ok = true;
  out.effective_cor = std::sqrt(std::max(0.0, 1.0 - lost));
  out.peak_force_n = f;
  out.max_barrel_deflection_m = f / p.barrel_stiffness_n_m;
  out.barrel_energy_fraction = wb / (wc + wb);
  out.ball_impulse_n_s = mu * (1.0 + out.effective_cor) * p.approach_speed_mps;
  return out;
}

double QuasiStaticTrampolineCor(const TrampolineProblem& p) {
  return QuasiStaticTrampoline(p).effective_cor;
}

TrampolineResult EffectiveCorAt(const Bat& bat, const MassProperties& mp, double x_m,
                                double ball_mass_kg, double ball_radius_m, double ball_stiffness,
                                double ball_exponent, double ball_cor, double approach_speed_mps,
                                const BarrelOptions& options) {
  if (!BarrelWallAt(bat, x_m, options).hollow) {
    TrampolineResult out;
    out.ok = true;
    out.effective_cor = ball_cor;
    return out;
  }
  const double b = x_m - mp.balance_point_m;
  const double m_e = 1.0 / (1.0 / mp.mass_kg + b * b / mp.moi_centroid_kg_m2);
  return barrel_detail::HollowImpact(bat, x_m, m_e, ball_mass_kg, ball_radius_m, ball_stiffness,
                                     ball_exponent, ball_cor, approach_speed_mps, options, nullptr);
}

BbcorResult ComputeBbcor(const Bat& bat, const BbcorProtocol& protocol,
                         const BarrelOptions& options,
                         const MassProperties* rigid_body_properties) {
  BbcorResult out;
  out.ball = protocol.ball;
  out.ball_speed_mps = protocol.ball_speed_mps;
  out.pivot_from_knob_m = protocol.pivot_from_knob_m;
  if (Refusal why; !bat.Validate(&why) || !options.Validate(&why)) {
    out.message = why.Message();
    return out;
  }
  const std::optional<BallPreset> ball = FindBallPreset(protocol.ball);
  if (!ball) {
    out.message = "bbcor: unknown ball '" + protocol.ball + "'";
    return out;
  }
  out.ball_cor = ball->cor_law.CorAt(protocol.ball_speed_mps);
  const double x = bat.LengthM() - protocol.impact_from_tip_m;
  const double z = x - protocol.pivot_from_knob_m;
  out.impact_from_knob_m = x;
  if (!(z > 0.0 && x <= bat.LengthM())) {
    out.message = "bbcor: the impact point " + FormatNumber17(x) +
                  " m from the knob is not on the bat beyond the pivot";
    return out;
  }
  if (!bat.IsHollow()) {
    // A rigid bat's BBCOR is the ball's COR by construction (BbcorStyleAt recovers e).
    out.ok = true;
    out.method = "rigid";
    out.value = out.ball_cor;
    return out;
  }
  out.method = "trampoline_quasi_static";
  const MassProperties mp =
      rigid_body_properties != nullptr ? *rigid_body_properties : ComputeMassProperties(bat);
  const double i_pivot = mp.MoiAboutKgM2(protocol.pivot_from_knob_m);
  BarrelWall wall;
  const TrampolineResult r = barrel_detail::HollowImpact(
      bat, x, i_pivot / (z * z), ball->mass_kg, ball->radius_m, ball->stiffness,
      ball->stiffness_exponent, out.ball_cor, protocol.ball_speed_mps, options, &wall);
  if (!r.ok) {
    out.message = "bbcor: " + r.message;
    return out;
  }
  out.value = r.effective_cor;
  out.hoop_frequency_hz = wall.hoop_frequency_hz;
  out.barrel_stiffness_n_m = wall.stiffness_n_m;
  out.ok = true;
  return out;
}

}  // namespace sweetspot::core
