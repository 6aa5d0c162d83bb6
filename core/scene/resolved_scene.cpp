#include "core/scene/resolved_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <utility>

#include "core/collision/barrel.hpp"
#include "core/geometry_format.hpp"

namespace sweetspot::core {

bool BallCorApplies(const Scene& scene) {
  if (!scene.ball.cor_law.has_value()) return false;
  if (!scene.bat.has_value()) return true;
  return scene.bat->wall_thickness_m <= 0.0 || !scene.bat->material.cor.has_value();
}

namespace resolved_scene {
namespace {

// The refusal of `field` = `value` as the scene writes it (17 significant digits).
bool Refuse17(Refusal* out, std::string_view field, double value, std::string_view rule) {
  return out == nullptr ? false : Refuse(out, Number17Refusal(field, value, rule));
}

// The angular speed at which the max-exit-speed point of `profile` (its own omega ignored) moves
// at `v` m/s about `pivot`, rad/s, on the unbounded bat. With d = origin - pivot, K = J / m and
// the approach speed w = u + omega d, the maximiser is x* = (-w + sqrt(w^2 + omega^2 K)) / omega
// (ExitSpeedProfile::Maximum), so omega (d + x*) = -u + sqrt((u + omega d)^2 + omega^2 K) = v
// is the quadratic (d^2 + K) omega^2 + 2 u d omega - v (v + 2u) = 0, whose positive root is
// taken in the form that does not cancel. Exact: the COR (the gain) does not enter.
double SweetSpotAngularSpeed(const ExitSpeedProfile& profile, double pivot, double v) {
  const double u = profile.ball_speed_mps;
  const double d = profile.origin_from_knob_m - pivot;
  const double a = d * d + profile.inertia_kg_m2 / profile.ball_mass_kg;
  const double c = v * (v + 2.0 * u);
  const double ud = u * d;
  const double root = std::sqrt(ud * ud + a * c);
  return ud >= 0.0 ? c / (ud + root) : (root - ud) / a;
}

}  // namespace
}  // namespace resolved_scene

bool ResolveSceneSwing(const Ball& ball, const Swing& swing, const MassProperties& mp,
                       double length_m, CollisionModel point_model, Swing* resolved,
                       Refusal* refusal) {
  using resolved_scene::Refuse17;
  if (!swing.bat_speed_mps.has_value()) return ResolveSwing(swing, length_m, resolved, refusal);
  SwingResolution how;
  how.given_bat_speed_mps = *swing.bat_speed_mps;
  how.moi_hands_kg_m2 = mp.MoiAboutKgM2(swing.hands_from_knob_m);
  if (swing.speed_model == SwingSpeedModel::kSwingWeight) {
    how.reference_moi_kg_m2 = swing.reference_moi_kg_m2.value_or(kSwingWeightReferenceMoiKgM2);
    if (!(how.moi_hands_kg_m2 > 0.0)) {
      return Refuse17(refusal, "swing.hands_from_knob_m", swing.hands_from_knob_m,
                      "swing.speed_model = swing_weight needs the bat's MOI about the hands > 0 "
                      "(it is " + FormatNumber17(how.moi_hands_kg_m2) + " kg·m²)");
    }
    how.swing_weight_factor = SwingWeightSpeedFactor(how.moi_hands_kg_m2, how.reference_moi_kg_m2,
                                                     swing.swing_weight_exponent);
  }
  const double v = how.given_bat_speed_mps * how.swing_weight_factor;
  how.bat_speed_mps = v;
  Swing at_point = swing;
  at_point.bat_speed_mps = v;
  if (swing.bat_speed_point == BatSpeedPoint::kSweetSpot) {
    // The closed form's max-exit-speed point at the angular speed that point moves at v:
    // exact (SweetSpotAngularSpeed); when that point is off the bat, the end the maximum on the
    // bat lies at, the speed given there.
    how.point_model = CollisionModelName(point_model);
    const double pivot = swing.pivot_from_knob_m;
    ExitSpeedProfile profile = ClosedFormProfileFor(point_model, mp, ball, swing, /*cor=*/0.0);
    double omega = v > 0.0 ? resolved_scene::SweetSpotAngularSpeed(profile, pivot, v) : 0.0;
    double x = pivot + (omega > 0.0 ? v / omega : 0.0);
    profile.angular_speed_rad_s = omega;
    profile.approach_mps = profile.ball_speed_mps + omega * (profile.origin_from_knob_m - pivot);
    ClosedFormMaximum mx = ClosedFormMaximumOnBat(profile, length_m);
    if (v > 0.0 && mx.placement != Placement::kOnBat) {
      x = mx.position_from_knob_m;  // an end of the bat
      if (!(x - pivot > 0.0)) {
        return Refuse17(refusal, "swing.pivot_from_knob_m", pivot,
                        "the max-exit-speed point for swing.bat_speed_from_tip_m = sweet_spot "
                        "(an end of the bat, " + FormatNumber17(x) +
                            " m from the knob) must lie beyond the pivot");
      }
      omega = v / (x - pivot);
    } else if (v > 0.0) {
      x = std::clamp(x, 0.0, length_m);
    } else {
      x = mx.position_from_knob_m;  // no bat speed: the profile's own maximum
    }
    at_point.bat_speed_from_tip_m = std::max(0.0, length_m - x);
    if (!(omega <= kMaxSwingAngularSpeedRadS)) {
      return Refuse17(refusal, "swing.bat_speed_mps", *swing.bat_speed_mps,
                      "gives angular_speed_rad_s = " + FormatNumber17(omega) + " over " +
                          FormatNumber17(kMaxSwingAngularSpeedRadS) +
                          " at the sweet spot (" + FormatNumber17(x) + " m from the knob)");
    }
    *resolved = at_point;
    resolved->angular_speed_rad_s = omega;
    how.position_from_knob_m = x;
  } else {
    if (!ResolveSwing(at_point, length_m, resolved, refusal)) return false;
    how.position_from_knob_m = length_m - swing.bat_speed_from_tip_m;
  }
  how.from_tip_m = resolved->bat_speed_from_tip_m;
  resolved->resolution = std::move(how);
  return true;
}

bool ResolveScene(const Scene& scene, bool needs_cor, TimingBook* book, ResolvedScene* r,
                  Summary* s, std::optional<double> cor_impact_from_knob_m,
                  CollisionModel exit_model) {
  if (Refusal refusal; !scene.Validate(&refusal)) {
    s->SetRefusal(std::move(refusal));
    return false;
  }
  if (scene.bat.has_value()) {
    // A custom material given without G, nu or a base: nu = 0.3 is an assumption, said so.
    const auto note = [s](const char* field, const Material& m) {
      if (!m.poissons_ratio_assumed) return;
      s->warnings.push_back(std::string(field) +
                            ": neither shear_modulus_pa nor poissons_ratio given (nor a base): "
                            "poissons_ratio = 0.3 assumed, G = E / 2.6 = " +
                            FormatNumber(m.EffectiveShearModulusPa()) +
                            " Pa (wood's G is nearer E / 10; give G, nu or a base)");
    };
    note("bat.material", scene.bat->material);
    if (scene.bat->fill.has_value()) note("bat.fill.material", scene.bat->fill->material);
  }
  // The ball's law needs the bat's length: evaluated below, once the length is known.
  // A hollow bat hit by a ball with a COR law: the trampoline's effective COR (barrel.hpp).
  const bool barrel_cor = needs_cor && !scene.cor.has_value() && scene.ball.cor_law.has_value() &&
                          scene.bat.has_value() && scene.bat->IsHollow();
  const bool ball_cor =
      needs_cor && !scene.cor.has_value() && (barrel_cor || BallCorApplies(scene));
  if (!needs_cor || ball_cor) {
    // Nothing wanted uses a COR (none is resolved, so none is required), or the ball's law.
  } else if (scene.cor.has_value()) {
    r->cor = *scene.cor;
    r->cor_source = "scene";
    r->cor_origin = CorOrigin::kScene;
  } else if (scene.bat.has_value() && scene.bat->material.cor.has_value()) {
    r->cor = *scene.bat->material.cor;
    r->cor_source = "material:" + scene.bat->material.name;
    r->cor_origin = CorOrigin::kMaterial;
  } else {
    // About the scene's COR and the bat's material together, so no one field: the api names
    // the part of the request it was evaluating (the bat, a compared variant).
    s->SetRefusal(TextRefusal(
        "",
        scene.bat.has_value()
            ? "cor: not given, and material '" + scene.bat->material.name + "' has no default COR"
            : "cor: not given, and there is no bat material to take it from"));
    return false;
  }
  if (scene.mass_properties.has_value()) {
    r->mass_properties = *scene.mass_properties;
  } else {
    const auto t0 = book->Now();
    try {
      r->mass_properties = ComputeMassProperties(*scene.bat, scene.inertia_model);
    } catch (const std::exception& e) {
      s->termination = Termination::kFailure;
      s->message = std::string("mass properties failed: ") + e.what();
      return false;
    }
    book->Add("mass_properties", book->Since(t0), 1);
  }
  const MassProperties& mp = r->mass_properties;
  if (!(std::isfinite(mp.mass_kg) && mp.mass_kg > 0.0 && std::isfinite(mp.balance_point_m) &&
        std::isfinite(mp.moi_centroid_kg_m2) && mp.moi_centroid_kg_m2 > 0.0)) {
    s->termination = Termination::kFailure;
    s->message = "mass properties are not usable (mass_kg = " + FormatNumber17(mp.mass_kg) +
                 ", moi_centroid_kg_m2 = " + FormatNumber17(mp.moi_centroid_kg_m2) + ")";
    return false;
  }
  r->length_m = scene.bat.has_value() ? scene.bat->LengthM() : scene.length_m;
  const double h = scene.swing.hands_from_knob_m;
  if (!(h >= 0.0 && h <= r->length_m)) {
    s->SetRefusal(
        Number17Refusal("swing.hands_from_knob_m", h,
                        "must be within the bat [0, " + FormatNumber17(r->length_m) + "]"));
    return false;
  }
  // The bat-speed point "sweet_spot" is a closed form's maximum: the exit model's, or for the
  // ODE models (hertz, flexible) free_bat's (EvaluateScene then iterates to the model's own:
  // SolveSweetSpotSwing; the resolution's point_model says which).
  std::string reason;
  CollisionModel point_model = ResolveExitModel(exit_model, scene, &reason);
  if (point_model != CollisionModel::kRigidPivot && point_model != CollisionModel::kFreeBat) {
    point_model = CollisionModel::kFreeBat;
  }
  if (Refusal refusal; !ResolveSceneSwing(scene.ball, scene.swing, r->mass_properties, r->length_m,
                                          point_model, &r->swing, &refusal)) {
    s->SetRefusal(std::move(refusal));
    return false;
  }
  if (ball_cor) {
    const double x = cor_impact_from_knob_m.has_value() && std::isfinite(*cor_impact_from_knob_m)
                         ? std::clamp(*cor_impact_from_knob_m, 0.0, r->length_m)
                         : std::max(0.0, r->length_m - kCorReferenceFromTipM);
    const double v =
        scene.ball.speed_mps + r->swing.angular_speed_rad_s * (x - r->swing.pivot_from_knob_m);
    r->cor = scene.ball.cor_law->CorAt(v);
    const std::string ball_name = scene.ball.preset.empty() ? "custom" : scene.ball.preset;
    r->cor_source = "ball:" + ball_name;
    r->cor_origin = CorOrigin::kBall;
    r->cor_impact_speed_mps = v;
    if (barrel_cor && v > 0.0) {
      const Ball& b = scene.ball;
      const TrampolineResult t = EffectiveCorAt(*scene.bat, r->mass_properties, x, b.mass_kg,
                                                b.radius_m, b.stiffness, b.stiffness_exponent,
                                                *r->cor, v);
      if (!t.ok) {
        s->termination = Termination::kFailure;
        s->message = "barrel: " + t.message;
        return false;
      }
      r->cor = t.effective_cor;
      r->cor_source = "barrel:" + ball_name;
      r->cor_origin = CorOrigin::kBarrel;
    }
  }
  return true;
}

RigidPivotInputs RigidPivotInputsFor(const MassProperties& mass_properties, const Ball& ball,
                                     const Swing& swing, double cor) {
  RigidPivotInputs in;
  in.bat_mass_kg = mass_properties.mass_kg;
  in.balance_point_m = mass_properties.balance_point_m;
  in.pivot_from_knob_m = swing.pivot_from_knob_m;
  in.moi_pivot_kg_m2 = mass_properties.MoiAboutKgM2(swing.pivot_from_knob_m);
  in.ball_mass_kg = ball.mass_kg;
  in.ball_speed_mps = ball.speed_mps;
  in.angular_speed_rad_s = swing.angular_speed_rad_s;
  in.cor = cor;
  return in;
}

ExitSpeedProfile ClosedFormProfileFor(CollisionModel model, const MassProperties& mass_properties,
                                      const Ball& ball, const Swing& swing, double cor) {
  if (model != CollisionModel::kFreeBat) {
    return RigidPivotProfile(RigidPivotInputsFor(mass_properties, ball, swing, cor));
  }
  return FreeBatProfile(FreeBatInputsFor(mass_properties, ball, swing, cor));
}

RigidPivotInputs RigidPivotInputsFor(const Scene& scene, const ResolvedScene& r) {
  return RigidPivotInputsFor(r.mass_properties, scene.ball, r.swing, *r.cor);
}

FreeBatInputs FreeBatInputsFor(const MassProperties& mass_properties, const Ball& ball,
                               const Swing& swing, double cor) {
  FreeBatInputs in;
  in.bat_mass_kg = mass_properties.mass_kg;
  in.balance_point_m = mass_properties.balance_point_m;
  in.moi_centroid_kg_m2 = mass_properties.moi_centroid_kg_m2;
  in.pivot_from_knob_m = swing.pivot_from_knob_m;
  in.hands_from_knob_m = swing.hands_from_knob_m;
  in.ball_mass_kg = ball.mass_kg;
  in.ball_speed_mps = ball.speed_mps;
  in.angular_speed_rad_s = swing.angular_speed_rad_s;
  in.cor = cor;
  return in;
}

FreeBatInputs FreeBatInputsFor(const Scene& scene, const ResolvedScene& r) {
  return FreeBatInputsFor(r.mass_properties, scene.ball, r.swing, *r.cor);
}

HertzProblem HertzProblemFor(const Scene& scene, const ResolvedScene& r, double impact_from_knob_m,
                             const HertzOptions& options, std::vector<std::string>* warnings) {
  HertzProblem p;
  const double m_bat = r.mass_properties.mass_kg;
  const double i = r.mass_properties.moi_centroid_kg_m2;
  const double b = impact_from_knob_m - r.mass_properties.balance_point_m;
  const double bh = scene.swing.hands_from_knob_m - r.mass_properties.balance_point_m;
  p.law = options.law;
  p.ball_mass_kg = scene.ball.mass_kg;
  p.ball_speed_mps = scene.ball.speed_mps;
  p.approach_speed_mps =
      scene.ball.speed_mps +
      r.swing.angular_speed_rad_s * (impact_from_knob_m - r.swing.pivot_from_knob_m);
  p.c11_per_kg = 1.0 / scene.ball.mass_kg + 1.0 / m_bat + b * b / i;
  p.c12_per_kg = 1.0 / m_bat + b * bh / i;
  p.c22_per_kg = 1.0 / m_bat + bh * bh / i;
  p.ball_stiffness = scene.ball.stiffness;
  p.ball_exponent = scene.ball.stiffness_exponent;
  p.cor = *r.cor;
  p.hands_stiffness_n_m = options.hands_stiffness_n_m;
  p.hands_damping_n_s_m = options.hands_damping_n_s_m;
  p.paper = options.paper;
  p.surface_stiffness = 0.0;
  if (options.law == ContactLaw::kBallPowerLaw && options.bat_surface_compliance) {
    if (!scene.bat.has_value()) {
      if (warnings != nullptr)
        warnings->push_back("no bat geometry in the scene: the bat surface is taken as rigid");
    } else {
      const double radius = scene.bat->RadiusAtM(impact_from_knob_m);
      if (radius > 0.0) {
        p.surface_stiffness = BatSurfaceHertzStiffness(scene.bat->material.youngs_modulus_pa,
                                                       scene.bat->material.poissons_ratio,
                                                       scene.ball.radius_m, radius);
      }
      if (scene.bat->wall_thickness_m > 0.0 && warnings != nullptr) {
        warnings->push_back(
            "hollow bat: the local contact is computed as for a solid surface (no trampoline "
            "effect; that needs the flexible shell model)");
      }
    }
  }
  return p;
}

FlexibleImpactInputs FlexibleImpactInputsFor(const Scene& scene, const ResolvedScene& r,
                                             double impact_from_knob_m, const HertzOptions& hertz) {
  FlexibleImpactInputs in;
  in.impact_from_knob_m = impact_from_knob_m;
  in.hands_from_knob_m = scene.swing.hands_from_knob_m;
  in.ball_mass_kg = scene.ball.mass_kg;
  in.ball_speed_mps = scene.ball.speed_mps;
  in.approach_speed_mps =
      scene.ball.speed_mps +
      r.swing.angular_speed_rad_s * (impact_from_knob_m - r.swing.pivot_from_knob_m);
  in.ball_stiffness = scene.ball.stiffness;
  in.ball_exponent = scene.ball.stiffness_exponent;
  in.cor = *r.cor;
  in.surface_stiffness = 0.0;
  if (hertz.bat_surface_compliance && scene.bat.has_value()) {
    const double radius = scene.bat->RadiusAtM(impact_from_knob_m);
    if (radius > 0.0) {
      in.surface_stiffness =
          BatSurfaceHertzStiffness(scene.bat->material.youngs_modulus_pa,
                                   scene.bat->material.poissons_ratio, scene.ball.radius_m, radius);
    }
  }
  return in;
}

}  // namespace sweetspot::core
