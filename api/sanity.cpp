#include "api/sanity.hpp"

#include <algorithm>

#include "core/geometry_format.hpp"
#include "core/mass_properties.hpp"

namespace sweetspot::api {
namespace {

std::string N(double v) { return core::FormatNumber(v); }

}  // namespace

std::vector<std::string> SanityWarnings(const core::Bat* bat, const core::Ball* ball,
                                        const core::Swing* swing, const SanityBounds& b) {
  std::vector<std::string> out;
  double length_m = 0.0;
  if (bat != nullptr && !bat->knots.empty()) {
    length_m = bat->LengthM();
    if (length_m > b.max_bat_length_m) {
      out.push_back("bat length = " + N(length_m) + " m: no bat is longer than " +
                    N(b.max_bat_length_m) + " m (47 in); inches given as metres?");
    }
    double widest = 0.0;
    for (const core::ProfileKnot& k : bat->knots) widest = std::max(widest, k.radius_m);
    if (widest > b.max_bat_radius_m) {
      out.push_back("bat radius = " + N(widest) + " m: no barrel is wider than " +
                    N(b.max_bat_radius_m) +
                    " m in radius (3.9 in diameter); a diameter given as a radius, or inches?");
    }
    const core::MassProperties p = core::ComputeMassProperties(*bat);
    if (p.mass_kg > b.max_bat_mass_kg) {
      out.push_back("bat mass = " + N(p.mass_kg) + " kg: no bat weighs more than " +
                    N(b.max_bat_mass_kg) +
                    " kg (71 oz); lengths in inches, or diameters given as radii?");
    } else if (p.mass_kg < b.min_bat_mass_kg) {
      out.push_back("bat mass = " + N(p.mass_kg) + " kg: no bat weighs less than " +
                    N(b.min_bat_mass_kg) + " kg (11 oz); a density or a wall too small?");
    }
  }
  if (ball != nullptr) {
    if (ball->speed_mps > b.max_ball_speed_mps) {
      out.push_back("ball.speed_mps = " + N(ball->speed_mps) + ": no pitch is faster than " +
                    N(b.max_ball_speed_mps) + " m/s (134 mph); mph given as m/s?");
    }
    if (ball->mass_kg > b.max_ball_mass_kg) {
      out.push_back("ball.mass_kg = " + N(ball->mass_kg) + ": no ball weighs more than " +
                    N(b.max_ball_mass_kg) + " kg (8.8 oz); ounces given as kilograms?");
    }
    if (ball->radius_m > b.max_ball_radius_m) {
      out.push_back("ball.radius_m = " + N(ball->radius_m) + ": no ball's radius exceeds " +
                    N(b.max_ball_radius_m) + " m; a diameter, or inches?");
    }
  }
  if (swing != nullptr && swing->bat_speed_mps.has_value()) {
    // A swing given by its bat speed (omega follows from it): the speed itself is checked, at
    // the point it is given for, against the fastest tip (a point nearer the knob is slower).
    if (*swing->bat_speed_mps > b.max_bat_tip_speed_mps) {
      out.push_back("swing.bat_speed_mps = " + N(*swing->bat_speed_mps) +
                    ": no swing is faster than " + N(b.max_bat_tip_speed_mps) +
                    " m/s (134 mph) at the tip; mph given as m/s?");
    }
  } else if (swing != nullptr && length_m > 0.0) {
    const double tip_speed = swing->angular_speed_rad_s * (length_m - swing->pivot_from_knob_m);
    if (tip_speed > b.max_bat_tip_speed_mps) {
      out.push_back("swing.angular_speed_rad_s = " + N(swing->angular_speed_rad_s) +
                    ": the tip moves at " + N(tip_speed) + " m/s, and no swing is faster than " +
                    N(b.max_bat_tip_speed_mps) + " m/s (134 mph) at the tip; rpm or deg/s?");
    }
  }
  return out;
}

std::vector<std::string> SceneSanityWarnings(const core::Scene& scene) {
  return SanityWarnings(scene.bat ? &*scene.bat : nullptr, &scene.ball, &scene.swing);
}

}  // namespace sweetspot::api
