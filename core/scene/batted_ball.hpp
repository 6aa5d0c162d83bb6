// The batted ball of a scene at any impact point and undercut (issue 34, part 3): the oblique
// impact (core/collision/oblique_impact.hpp), its normal part from the scene's collision model,
// then the flight (core/flight/flight.hpp) with the scene's environment and aero. On top of it,
// the two searches of the outputs distance_sweet_spot and carry_map: the impact position and
// undercut that carry the ball farthest (a coarse scan, then NLopt's LN_BOBYQA in the best
// cell's neighbourhood) and the carry over a grid of positions x undercuts.
//
// The normal part per model (the interface note at the end of oblique_impact.hpp):
//  - rigid_pivot, free_bat: NormalImpactLaw{M_n(x), e}, closed form (M_n: J_pivot / z^2, or
//    1 / (1/M + b^2/I_cm)).
//  - hertz, flexible: the model's own answer at the normal approach speed v_n:
//    NormalImpactLaw::ball_normal_impulse_n_s runs the ODE model (SolveHertzImpact,
//    SolveFlexibleImpact) with the bat at rest and approach speed v_n and returns its
//    ball_impulse_n_s; M_n is the free bat's (what the bat recoils with, and what the tangential
//    part uses). Head-on (D = 0, level paths, no spin) this is exactly the model's own impact.
//    The searches instead tabulate the model's effective COR e(x, v_n) = J_n (1/m + 1/M_n(x)) /
//    v_n - 1 on a grid of positions x Chebyshev speeds spanning every v_n the region can give,
//    and interpolate it (a cubic through the four nearest positions in x, barycentric Lagrange in
//    v_n): J_n is smooth in
//    both, so a few impacts per position replace one per (x, D) evaluation
//    (BattedBallModel::TabulateNormalLaw; the error at the optimum is reported as the exact
//    law's carry there minus the table's).
//
// Domain: a ball whose centre passes farther from the bat's axis than kGrazeFraction (R + r)
// barely touches the bat (the oblique impact's header); such points, and a ball driven back
// toward the catcher (launch angle beyond +-90 deg) or not landing, have no carry (NaN in the
// map; a penalty in the search).
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/collision/oblique_impact.hpp"
#include "core/flexible/modes.hpp"
#include "core/flight/flight.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// The largest |undercut| / (ball radius + bat radius) searched or mapped: beyond it the ball
/// barely touches the bat (oblique_impact.hpp, its interface note).
inline constexpr double kGrazeFraction = 0.9;

/// The batted ball at one impact point and undercut: the oblique impact, then its flight.
struct BattedBallResult {
  double impact_from_knob_m = 0.0;       ///< Where the bat met the ball, m from the knob.
  double undercut_m = 0.0;               ///< The undercut, m (+ backspin).
  double bat_speed_at_impact_mps = 0.0;  ///< The bat's axis speed there, m/s.
  double bat_radius_m = 0.0;             ///< The bat's radius there (the default without a bat), m.
  double bat_effective_mass_kg = 0.0;    ///< M_n of the normal model there, kg.
  double normal_cor = 0.0;  ///< e of the normal model: the scene's COR (closed forms), or the
                            ///< COR the ODE model's impulse implies at this v_n (hertz, flexible).
  /// hertz or flexible: the model whose own impulse gave the normal part; null for a closed form.
  const char* normal_model = nullptr;
  flight::AeroModel aero_model = flight::AeroModel::kNathan2016;  ///< The scene's aero model.
  bool default_environment = true;  ///< The scene's environment is the flight's default.
  ObliqueImpactResult impact;       ///< The oblique impact (SolveObliqueImpact).
  flight::FlightResult flight;      ///< Its flight (Fly, the scene's environment and aero).
};

/// The batted ball of a resolved scene under one collision model, at any (x, D). Not
/// thread-safe (the table, the timing book); cheap to build (nothing is computed until asked).
class BattedBallModel {
 public:
  /// `model`: the resolved exit-speed model (not kAuto). `modes`: the flexible impact modes
  /// (needed for kFlexible, else ignored). Every reference must outlive this object; `book`
  /// books "oblique_impact", "flight" and the normal model's impacts (may be null).
  BattedBallModel(const Scene& scene, const ResolvedScene& resolved, CollisionModel model,
                  const HertzOptions& hertz, const FlexibleOptions& flexible, const BatModes* modes,
                  TimingBook* book);

  /// The collision model of the normal part.
  CollisionModel model() const { return model_; }
  /// True for hertz and flexible (an ODE per normal impulse).
  bool integrated() const { return integrated_; }
  /// The bat's radius at x (the oblique impact's default without a bat's geometry), m.
  double BatRadiusAtM(double x) const;
  /// kGrazeFraction (R + r(x)): the largest |undercut| searched at x, m.
  double UndercutReachAtM(double x) const;
  /// M_n(x): the bat's effective mass along the line of centres at x, kg (rigid_pivot:
  /// J_pivot / z^2; the others the free bat's 1 / (1/M + b^2/I_cm)).
  double EffectiveMassAtKg(double x) const;

  /// The oblique impact's inputs at x (m from the knob) with undercut D (m): the scene's ball,
  /// swing and bat, the normal law closed form (M_n(x), e) for rigid_pivot and free_bat, the
  /// model's own impulse (ball_normal_impulse_n_s) for hertz and flexible.
  ObliqueImpactInputs InputsAt(double x, double undercut_m) const;

  /// One batted ball at (x, D) with the model's own normal law, into *out (its impact and
  /// flight filled also when the flight did not land). False with the refusal in *refusal (an
  /// input refused, named as the scene names it: "contact.undercut_m") or the failure's message
  /// in *failure (the impact model or the flight failed).
  /// `flight_options`: the flight's tolerances (the defaults: 0.1 ft).
  bool Evaluate(double x, double undercut_m, BattedBallResult* out, Refusal* refusal,
                std::string* failure, const flight::FlightOptions& flight_options = {});

  /// hertz and flexible: tabulates the effective COR at `positions` evenly spaced positions over
  /// [x_lo, x_hi] (one position: x_lo) x `speeds` Chebyshev speeds spanning every normal
  /// approach speed of undercuts in [d_lo, d_hi] there. A closed-form model: nothing to do, true.
  /// False with the model's failure in *failure.
  bool TabulateNormalLaw(double x_lo, double x_hi, int positions, double d_lo, double d_hi,
                         int speeds, std::string* failure);
  /// True once a table is in place (hertz, flexible after TabulateNormalLaw).
  bool tabulated() const { return !table_e_.empty(); }
  /// Normal-model impacts the table took.
  int table_impacts() const { return table_impacts_; }

  /// The carry at (x, D), m: the closed-form law, or the table (hertz, flexible; it must have
  /// been built over a region holding x); NaN when (x, D) is outside the graze limit, the ball
  /// leaves backward or does not land. `flight_options` sets the flight's tolerances. With
  /// `point` non-null, the impact and flight are written there.
  double CarryAt(double x, double undercut_m, const flight::FlightOptions& flight_options,
                 BattedBallResult* point = nullptr);

  /// The flight options of the searches: the default's, with relative tolerance 1e-8 (the
  /// carry smooth in (x, D) to ~1e-7 m, below what the local search resolves).
  static flight::FlightOptions SearchFlightOptions();

 private:
  double TableCor(double x, double v_n) const;
  bool ModelImpulse(double x, double v_n, double* j_n, std::string* failure);

  const Scene& scene_;
  const ResolvedScene& r_;
  CollisionModel model_;
  const HertzOptions& hertz_;
  const FlexibleOptions& flexible_;
  const BatModes* modes_;
  TimingBook* book_;
  bool integrated_ = false;
  double roll_moi_kg_m2_ = kDefaultBatRollMoiKgM2;
  // The table: positions (uniform from x0_ with step dx_), Chebyshev speeds over [v_lo_, v_hi_].
  double table_x0_ = 0.0, table_dx_ = 0.0, table_v_lo_ = 0.0, table_v_hi_ = 0.0;
  int table_positions_ = 0;
  std::vector<double> table_nodes_;    // the speeds, m/s
  std::vector<double> table_weights_;  // barycentric weights
  std::vector<double> table_e_;        // [position][speed]
  int table_impacts_ = 0;
  bool tabulating_ = false;  // the table's impacts skip the refinement check (and hands' loads)
};

/// distance_sweet_spot: where along the bat, and how far under the ball's centre, the ball
/// carries farthest.
struct DistanceSweetSpotResult {
  double position_from_knob_m = 0.0;      ///< The impact position, m from the knob.
  double undercut_m = 0.0;                ///< The undercut, m.
  double distance_m = 0.0;                ///< The carry there, m (the model's own normal law).
  double exit_speed_mps = 0.0;            ///< The exit speed there, m/s.
  double launch_angle_deg = 0.0;          ///< The launch angle there, deg.
  double backspin_rpm = 0.0;              ///< The backspin there, rpm.
  BattedBallResult ball;                  ///< The batted ball at the optimum (exact normal law).
  double position_min_from_knob_m = 0.0;  ///< The position range searched, m from the knob.
  double position_max_from_knob_m = 0.0;  ///< Its upper end, m.
  double undercut_min_m = 0.0;            ///< The undercut range searched, m.
  double undercut_max_m = 0.0;            ///< Its upper end, m.
  double position_tolerance_m = 0.0;      ///< The local search's tolerance on x, m.
  double undercut_tolerance_m = 0.0;      ///< Its tolerance on D, m.
  bool at_position_bound = false;         ///< The optimum is at an end of the position range.
  bool at_undercut_bound = false;         ///< The optimum is at an end of the undercut range (or at
                                          ///< the graze limit).
  int coarse_positions = 0;               ///< The coarse scan's grid.
  int coarse_undercuts = 0;               ///< Its undercuts.
  int evaluations = 0;                    ///< Carries computed (scan + local search).
  /// "closed_form", or "tabulated" (hertz, flexible: the table's effective COR).
  std::string normal_law;
  int normal_table_positions = 0;  ///< The table's positions (0 for a closed form).
  int normal_table_speeds = 0;     ///< Its speeds per position.
  /// Tabulated: the exact law's carry at the optimum minus the table's, m (0 for a closed form).
  double normal_table_error_m = 0.0;
  Summary summary;  ///< "nlopt:LN_BOBYQA", termination, evaluations, message.
};

/// Searches `options`' region of `model`'s scene for the longest carry: a coarse scan of
/// coarse_positions x coarse_undercuts, then LN_BOBYQA within one coarse cell of the best point
/// (variables scaled to the cells, stopping at the tolerances), then the exact batted ball at
/// the optimum. `length_m`: the bat's length. Never throws.
DistanceSweetSpotResult DistanceSweetSpot(BattedBallModel& model, double length_m,
                                          const DistanceOptions& options,
                                          const Progress* progress = nullptr);

/// carry_map: the carry over a grid of positions x undercuts.
struct CarryMapResult {
  std::vector<double> positions_from_knob_m;  ///< The grid's positions, m from the knob.
  std::vector<double> undercuts_m;            ///< Its undercuts, m.
  /// distance_m[i * undercuts + j] at (positions[i], undercuts[j]), m; NaN where the ball has
  /// no carry (beyond the graze limit, driven back, or not landing).
  std::vector<double> distance_m;
  double best_distance_m = 0.0;            ///< The largest carry of the grid, m.
  double best_position_from_knob_m = 0.0;  ///< Where, m from the knob.
  double best_undercut_m = 0.0;            ///< With which undercut, m.
  std::string normal_law;                  ///< "closed_form" or "tabulated".
  int normal_table_speeds = 0;             ///< Tabulated: speeds per grid position.
  Summary summary;                         ///< termination, evaluations, message.
};

/// The carry over map_positions x map_undercuts evenly spaced over `options`' region (hertz,
/// flexible: the normal law tabulated at the grid's own positions). Never throws.
CarryMapResult CarryMap(BattedBallModel& model, double length_m, const DistanceOptions& options,
                        const Progress* progress = nullptr);

/// The position range of `options` on a bat `length_m` long: [min or L/2, max or L].
void DistancePositionRange(const DistanceOptions& options, double length_m, double* lo, double* hi);

}  // namespace sweetspot::core
