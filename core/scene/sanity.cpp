#include "core/scene/sanity.hpp"

#include <algorithm>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"

namespace sweetspot::core {
std::vector<std::string> SanityWarnings(const Bat* bat, const MassProperties* bat_properties,
                                        const Ball* ball, const Swing* swing,
                                        const SanityBounds& b) {
  std::vector<std::string> out;
  double length_m = 0.0;
  if (bat != nullptr && !bat->knots.empty()) {
    length_m = bat->LengthM();
    if (length_m > b.max_bat_length_m) {
      out.push_back("bat length = " + FormatNumber(length_m) + " m: no bat is longer than " +
                    FormatNumber(b.max_bat_length_m) + " m (47 in); inches given as metres?");
    }
    double widest = 0.0;
    for (const ProfileKnot& k : bat->knots) widest = std::max(widest, k.radius_m);
    if (widest > b.max_bat_radius_m) {
      out.push_back("bat radius = " + FormatNumber(widest) + " m: no barrel is wider than " +
                    FormatNumber(b.max_bat_radius_m) +
                    " m in radius (3.9 in diameter); a diameter given as a radius, or inches?");
    }
    // The mass is the same under both inertia models: the request's properties serve.
    const double mass_kg = bat_properties != nullptr ? bat_properties->mass_kg : kNaN;
    if (mass_kg > b.max_bat_mass_kg) {
      out.push_back("bat mass = " + FormatNumber(mass_kg) + " kg: no bat weighs more than " +
                    FormatNumber(b.max_bat_mass_kg) +
                    " kg (71 oz); lengths in inches, or diameters given as radii?");
    } else if (mass_kg < b.min_bat_mass_kg) {
      out.push_back("bat mass = " + FormatNumber(mass_kg) + " kg: no bat weighs less than " +
                    FormatNumber(b.min_bat_mass_kg) + " kg (11 oz); a density or a wall too small?");
    }
  }
  if (ball != nullptr) {
    if (ball->speed_mps > b.max_ball_speed_mps) {
      out.push_back("ball.speed_mps = " + FormatNumber(ball->speed_mps) + ": no pitch is faster than " +
                    FormatNumber(b.max_ball_speed_mps) + " m/s (134 mph); mph given as m/s?");
    }
    if (ball->mass_kg > b.max_ball_mass_kg) {
      out.push_back("ball.mass_kg = " + FormatNumber(ball->mass_kg) + ": no ball weighs more than " +
                    FormatNumber(b.max_ball_mass_kg) + " kg (8.8 oz); ounces given as kilograms?");
    }
    if (ball->radius_m > b.max_ball_radius_m) {
      out.push_back("ball.radius_m = " + FormatNumber(ball->radius_m) + ": no ball's radius exceeds " +
                    FormatNumber(b.max_ball_radius_m) + " m; a diameter, or inches?");
    }
  }
  if (swing != nullptr && swing->bat_speed_mps.has_value()) {
    // A swing given by its bat speed (omega follows from it): the speed itself is checked, at
    // the point it is given for, against the fastest tip (a point nearer the knob is slower).
    if (*swing->bat_speed_mps > b.max_bat_tip_speed_mps) {
      out.push_back("swing.bat_speed_mps = " + FormatNumber(*swing->bat_speed_mps) +
                    ": no swing is faster than " + FormatNumber(b.max_bat_tip_speed_mps) +
                    " m/s (134 mph) at the tip; mph given as m/s?");
    }
  } else if (swing != nullptr && length_m > 0.0) {
    const double tip_speed = swing->angular_speed_rad_s * (length_m - swing->pivot_from_knob_m);
    if (tip_speed > b.max_bat_tip_speed_mps) {
      out.push_back("swing.angular_speed_rad_s = " + FormatNumber(swing->angular_speed_rad_s) +
                    ": the tip moves at " + FormatNumber(tip_speed) + " m/s, and no swing is faster than " +
                    FormatNumber(b.max_bat_tip_speed_mps) + " m/s (134 mph) at the tip; rpm or deg/s?");
    }
  }
  return out;
}

std::vector<std::string> SceneSanityWarnings(const Scene& scene,
                                             const MassProperties& bat_properties) {
  return SanityWarnings(scene.bat ? &*scene.bat : nullptr, &bat_properties, &scene.ball,
                        &scene.swing);
}

}  // namespace sweetspot::core
