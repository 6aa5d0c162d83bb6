// The batted ball of a scene at any (x, D) (the distance searches are in distance_search.cpp);
// the model, the normal law per collision model and the table are described at the top of
// batted_ball.hpp.
#include "core/scene/batted_ball.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/numerics/termination.hpp"

namespace sweetspot::core {
namespace batted_ball {
namespace {

constexpr double kDegPerRad = 180.0 / kPi;

// The scene's name of an oblique-impact input the impact refused ("undercut_m" ->
// "contact.undercut_m"); others as they are.
std::string SceneFieldOf(const std::string& field) {
  if (field == "undercut_m") return "contact.undercut_m";
  if (field == "attack_angle_deg") return "swing.attack_angle_deg";
  if (field == "descent_angle_deg") return "ball.descent_angle_deg";
  if (field == "ball_backspin_rad_s") return "ball.spin_rpm";
  return field;
}

// The launch of the ball the impact gives (a 2-D impact: no sidespin).
flight::Launch LaunchOf(const ObliqueImpactResult& impact) {
  flight::Launch launch;
  launch.exit_speed_mps = impact.exit_speed_mps;
  launch.launch_angle_deg = impact.launch_angle_deg;
  launch.backspin_rpm = impact.backspin_rpm;
  launch.sidespin_rpm = 0.0;
  return launch;
}

// True when `e` is the flight's default environment.
bool IsDefault(const flight::Environment& e) {
  const flight::Environment d;
  return e.temperature_c == d.temperature_c && e.elevation_m == d.elevation_m &&
         e.relative_humidity_pct == d.relative_humidity_pct &&
         e.sea_level_pressure_pa == d.sea_level_pressure_pa &&
         e.wind.speed_mps == d.wind.speed_mps && e.wind.direction_deg == d.wind.direction_deg;
}

}  // namespace
}  // namespace batted_ball

BattedBallModel::BattedBallModel(const Scene& scene, const ResolvedScene& resolved,
                                 CollisionModel model, const HertzOptions& hertz,
                                 const FlexibleOptions& flexible, const BatModes* modes,
                                 TimingBook* book)
    : scene_(scene),
      r_(resolved),
      model_(model),
      hertz_(hertz),
      flexible_(flexible),
      modes_(modes),
      book_(book) {
  integrated_ = model == CollisionModel::kHertz || model == CollisionModel::kFlexible;
  if (scene.bat.has_value()) roll_moi_kg_m2_ = BatRollMoiKgM2(*scene.bat);
}

double BattedBallModel::BatRadiusAtM(double x) const {
  return scene_.bat.has_value() ? scene_.bat->RadiusAtM(x) : ObliqueImpactInputs{}.bat_radius_m;
}

double BattedBallModel::UndercutReachAtM(double x) const {
  return kGrazeFraction * (scene_.ball.radius_m + BatRadiusAtM(x));
}

double BattedBallModel::EffectiveMassAtKg(double x) const {
  const MassProperties& mp = r_.mass_properties;
  double inverse_mass = 0.0;
  if (model_ == CollisionModel::kRigidPivot) {
    const RigidPivotInputs pivot = RigidPivotInputsFor(scene_, r_);
    const double z = x - pivot.pivot_from_knob_m;
    inverse_mass = z * z / pivot.moi_pivot_kg_m2;
  } else {
    const double b = x - mp.balance_point_m;
    inverse_mass = 1.0 / mp.mass_kg + b * b / mp.moi_centroid_kg_m2;
  }
  return inverse_mass > 0.0 ? 1.0 / inverse_mass : std::numeric_limits<double>::infinity();
}

ObliqueImpactInputs BattedBallModel::InputsAt(double x, double undercut_m) const {
  const Scene& s = scene_;
  ObliqueImpactInputs in;
  in.ball_speed_mps = s.ball.speed_mps;
  in.descent_angle_deg = s.ball.descent_angle_deg;
  in.ball_backspin_rad_s = RpmToRadPerSecond(s.ball.spin_rpm);
  in.bat_speed_mps = r_.swing.angular_speed_rad_s * (x - r_.swing.pivot_from_knob_m);
  in.attack_angle_deg = r_.swing.attack_angle_deg;
  in.undercut_m = undercut_m;
  in.ball_mass_kg = s.ball.mass_kg;
  in.ball_radius_m = s.ball.radius_m;
  in.bat_radius_m = BatRadiusAtM(x);
  in.bat_roll_moi_kg_m2 = roll_moi_kg_m2_;
  in.normal.bat_effective_mass_kg = EffectiveMassAtKg(x);
  in.normal.cor = *r_.cor;
  return in;
}

bool BattedBallModel::ModelImpulse(double x, double v_n, double* j_n, std::string* failure) {
  const auto t0 = book_ != nullptr ? book_->Now() : std::chrono::steady_clock::time_point{};
  const bool fast = tabulating_;
  bool ok = false;
  if (model_ == CollisionModel::kHertz) {
    HertzProblem p = HertzProblemFor(scene_, r_, x, hertz_, nullptr);
    p.approach_speed_mps = v_n;
    HertzSolverOptions solver = hertz_.solver;
    if (fast) solver.refine_check = false;
    const HertzImpact hi = SolveHertzImpact(p, solver);
    ok = hi.summary.IsSolutionUsable();
    if (ok) {
      *j_n = hi.ball_impulse_n_s;
    } else if (failure != nullptr) {
      *failure = "hertz at " + FormatNumber17(x) + " m from the knob, normal approach speed " +
                 FormatNumber17(v_n) + " m/s: " + hi.summary.message;
    }
  } else if (modes_ != nullptr && scene_.bat.has_value()) {
    FlexibleImpactInputs in = FlexibleImpactInputsFor(scene_, r_, x, hertz_);
    in.approach_speed_mps = v_n;
    FlexibleImpactOptions o = flexible_.impact;
    if (fast) {
      o.refine_check = false;
      o.hands_loads = false;
    }
    const FlexibleImpactResult fr = SolveFlexibleImpact(*scene_.bat, *modes_, in, o);
    ok = fr.summary.IsSolutionUsable();
    if (ok) {
      *j_n = fr.ball_impulse_n_s;
    } else if (failure != nullptr) {
      *failure = "flexible at " + FormatNumber17(x) + " m from the knob, normal approach speed " +
                 FormatNumber17(v_n) + " m/s: " + fr.summary.message;
    }
  } else if (failure != nullptr) {
    *failure = "flexible: no modes (internal error)";
  }
  if (book_ != nullptr) book_->Add(CollisionModelName(model_), book_->Since(t0), 1);
  return ok;
}

bool BattedBallModel::Evaluate(double x, double undercut_m, BattedBallResult* out, Refusal* refusal,
                               std::string* failure, const flight::FlightOptions& flight_options) {
  using namespace batted_ball;
  *out = BattedBallResult{};
  ObliqueImpactInputs in = InputsAt(x, undercut_m);
  out->impact_from_knob_m = x;
  out->undercut_m = undercut_m;
  out->bat_speed_at_impact_mps = in.bat_speed_mps;
  out->bat_radius_m = in.bat_radius_m;
  out->bat_effective_mass_kg = in.normal.bat_effective_mass_kg;
  out->normal_cor = in.normal.cor;
  out->normal_model = integrated_ ? CollisionModelName(model_) : nullptr;
  out->aero_model = scene_.aero.model;
  out->default_environment = IsDefault(scene_.environment);
  std::string model_failure;
  if (integrated_) {
    in.normal.ball_normal_impulse_n_s = [this, x, &model_failure](double v_n) {
      double j = 0.0;
      if (!ModelImpulse(x, v_n, &j, &model_failure)) return kNaN;
      return j;
    };
  }
  // (A closed form's model is listed by its caller: max_exit_speed, Collide.)
  const auto ti = book_ != nullptr ? book_->Now() : std::chrono::steady_clock::time_point{};
  out->impact = SolveObliqueImpact(in);
  if (book_ != nullptr) book_->Add("oblique_impact", book_->Since(ti), 1);
  const Summary& is = out->impact.summary;
  if (is.refusal.has_value()) {
    Refusal why = *is.refusal;
    why.field = SceneFieldOf(why.field);
    if (refusal != nullptr) *refusal = std::move(why);
    return false;
  }
  if (!is.IsSolutionUsable()) {
    if (failure != nullptr) *failure = model_failure.empty() ? is.message : model_failure;
    return false;
  }
  if (integrated_) out->normal_cor = out->impact.normal_cor;
  const auto tf = book_ != nullptr ? book_->Now() : std::chrono::steady_clock::time_point{};
  out->flight = flight::Fly(LaunchOf(out->impact), scene_.environment, scene_.aero, flight_options);
  if (book_ != nullptr) book_->Add("flight", book_->Since(tf), 1);
  if (!out->flight.Landed()) {
    if (failure != nullptr) {
      const std::string why = out->flight.refusal.has_value()
                                  ? out->flight.refusal->Message()
                                  : flight::FlightTerminationName(out->flight.termination);
      *failure = "the ball's launch cannot be flown (exit speed " +
                 FormatNumber(out->impact.exit_speed_mps) + " m/s, launch angle " +
                 FormatNumber(out->impact.launch_angle_deg) + " deg): " + why;
    }
    return false;
  }
  return true;
}

bool BattedBallModel::TabulateNormalLaw(double x_lo, double x_hi, int positions, double d_lo,
                                        double d_hi, int speeds, std::string* failure) {
  table_e_.clear();
  table_impacts_ = 0;
  if (!integrated_) return true;
  positions = std::max(1, positions);
  speeds = std::max(2, speeds);
  const double dx = positions > 1 ? (x_hi - x_lo) / (positions - 1) : 0.0;
  // The normal approach speeds the region gives: |w|(x) cos psi, psi from the undercut.
  double v_lo = kInf, v_hi = 0.0;
  for (int i = 0; i < positions; ++i) {
    const double x = x_lo + i * dx;
    const ObliqueImpactInputs in = InputsAt(x, 0.0);
    const double delta = in.descent_angle_deg / batted_ball::kDegPerRad;
    const double attack = in.attack_angle_deg / batted_ball::kDegPerRad;
    const double wx = -in.ball_speed_mps * std::cos(delta) - in.bat_speed_mps * std::cos(attack);
    const double wy = -in.ball_speed_mps * std::sin(delta) - in.bat_speed_mps * std::sin(attack);
    const double w = std::hypot(wx, wy);
    const double reach = scene_.ball.radius_m + in.bat_radius_m;
    const double d_far = std::min(std::max(std::abs(d_lo), std::abs(d_hi)), kGrazeFraction * reach);
    const double d_near =
        (d_lo <= 0.0 && d_hi >= 0.0) ? 0.0 : std::min(std::abs(d_lo), std::abs(d_hi));
    const auto cos_of = [reach](double d) {
      const double s = std::min(1.0, d / reach);
      return std::sqrt((1.0 - s) * (1.0 + s));
    };
    v_lo = std::min(v_lo, w * cos_of(d_far));
    v_hi = std::max(v_hi, w * cos_of(std::min(d_near, d_far)));
  }
  // 1 % margins: a position between two of the table's may reach slightly beyond their speeds.
  const double margin = 0.01 * (v_hi - v_lo) + 1e-6 * v_hi;
  v_lo = std::max(1e-6, v_lo - margin);
  v_hi = v_hi + margin;
  table_nodes_.resize(speeds);
  table_weights_.resize(speeds);
  for (int k = 0; k < speeds; ++k) {
    // Chebyshev points of the second kind (the ends included) and their barycentric weights.
    table_nodes_[k] = 0.5 * (v_lo + v_hi) + 0.5 * (v_hi - v_lo) * std::cos(kPi * k / (speeds - 1));
    table_weights_[k] = ((k % 2) ? -1.0 : 1.0) * ((k == 0 || k == speeds - 1) ? 0.5 : 1.0);
  }
  std::vector<double> e(static_cast<std::size_t>(positions) * speeds);
  tabulating_ = true;
  for (int i = 0; i < positions; ++i) {
    const double x = x_lo + i * dx;
    const double inv_reduced = 1.0 / scene_.ball.mass_kg + 1.0 / EffectiveMassAtKg(x);
    for (int k = 0; k < speeds; ++k) {
      double j = 0.0;
      if (!ModelImpulse(x, table_nodes_[k], &j, failure)) {
        tabulating_ = false;
        return false;
      }
      ++table_impacts_;
      e[static_cast<std::size_t>(i) * speeds + k] = j * inv_reduced / table_nodes_[k] - 1.0;
    }
  }
  tabulating_ = false;
  table_e_ = std::move(e);
  table_x0_ = x_lo;
  table_dx_ = dx;
  table_positions_ = positions;
  table_v_lo_ = v_lo;
  table_v_hi_ = v_hi;
  return true;
}

double BattedBallModel::TableCor(double x, double v_n) const {
  const int speeds = static_cast<int>(table_nodes_.size());
  // The barycentric Lagrange interpolant in v_n of position row i.
  const auto row = [&](int i) {
    const double* e = &table_e_[static_cast<std::size_t>(i) * speeds];
    double num = 0.0, den = 0.0;
    for (int k = 0; k < speeds; ++k) {
      const double d = v_n - table_nodes_[k];
      if (d == 0.0) return e[k];
      const double w = table_weights_[k] / d;
      num += w * e[k];
      den += w;
    }
    return num / den;
  };
  if (table_positions_ == 1) return row(0);
  // A cubic through the four positions around x (three for a 3-position table; the window
  // shifted inward at the ends): Lagrange on the uniform grid, in grid units.
  const double u = (x - table_x0_) / table_dx_;
  const int window = std::min(4, table_positions_);
  const int first = std::clamp(static_cast<int>(std::floor(u)) - 1, 0, table_positions_ - window);
  double value = 0.0;
  for (int a = 0; a < window; ++a) {
    double basis = 1.0;
    for (int b = 0; b < window; ++b) {
      if (b != a) basis *= (u - (first + b)) / static_cast<double>(a - b);
    }
    if (basis != 0.0) value += basis * row(first + a);
  }
  return value;
}

double BattedBallModel::CarryAt(double x, double undercut_m,
                                const flight::FlightOptions& flight_options,
                                BattedBallResult* point) {
  if (!(std::abs(undercut_m) <= UndercutReachAtM(x))) return kNaN;
  ObliqueImpactInputs in = InputsAt(x, undercut_m);
  if (integrated_) {
    if (!tabulated()) return kNaN;
    const double inv_reduced = 1.0 / in.ball_mass_kg + 1.0 / in.normal.bat_effective_mass_kg;
    in.normal.ball_normal_impulse_n_s = [this, x, inv_reduced](double v_n) {
      const double e = std::clamp(TableCor(x, v_n), 0.0, 1.0);
      return (1.0 + e) * v_n / inv_reduced;
    };
  }
  // A closed form's normal part is computed inside the oblique impact: listed, not timed.
  if (!integrated_ && book_ != nullptr) book_->Add(CollisionModelName(model_), 0.0, 1);
  const auto ti = book_ != nullptr ? book_->Now() : std::chrono::steady_clock::time_point{};
  ObliqueImpactResult impact = SolveObliqueImpact(in);
  if (book_ != nullptr) book_->Add("oblique_impact", book_->Since(ti), 1);
  if (!impact.summary.IsSolutionUsable()) return kNaN;
  // A ball driven back toward the catcher (or straight up or down) has no carry.
  if (!(std::abs(impact.launch_angle_deg) < 90.0)) return kNaN;
  const auto tf = book_ != nullptr ? book_->Now() : std::chrono::steady_clock::time_point{};
  flight::FlightResult f =
      flight::Fly(batted_ball::LaunchOf(impact), scene_.environment, scene_.aero, flight_options);
  if (book_ != nullptr) book_->Add("flight", book_->Since(tf), 1);
  const double carry = f.Landed() ? f.distance_m : kNaN;
  if (point != nullptr) {
    point->impact_from_knob_m = x;
    point->undercut_m = undercut_m;
    point->bat_speed_at_impact_mps = in.bat_speed_mps;
    point->bat_radius_m = in.bat_radius_m;
    point->bat_effective_mass_kg = in.normal.bat_effective_mass_kg;
    point->normal_cor = integrated_ ? impact.normal_cor : in.normal.cor;
    point->normal_model = integrated_ ? CollisionModelName(model_) : nullptr;
    point->aero_model = scene_.aero.model;
    point->default_environment = batted_ball::IsDefault(scene_.environment);
    point->impact = std::move(impact);
    point->flight = std::move(f);
  }
  return carry;
}

flight::FlightOptions BattedBallModel::SearchFlightOptions() {
  flight::FlightOptions o;
  o.relative_tolerance = 1e-8;
  return o;
}

}  // namespace sweetspot::core
