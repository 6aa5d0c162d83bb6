// The batter's side of a swing: how fast a bat is swung as a function of its swing weight (the
// one relation the scenes' swing.speed_model "swing_weight" and the optimiser's objective
// max_exit_speed_swing_weight share), and the reference bat that relation is anchored to.
//
// Source: R. Cross and R. Bower, "Effects of swing-weight on swing speed and racket power",
// J. Sports Sci. 24(1), 23-30 (2006), abstract: swinging with maximum effort, the swing speed
// V = C / I^n, C a constant per player, n = 0.27 for swing weights I above 0.03 kg·m²; the
// same paper quotes n = 0.25 for softball bats and 0.26 for golf clubs from earlier studies.
// So a batter who swings a bat of swing weight I_ref at V_ref swings one of swing weight I at
// V_ref (I / I_ref)^-n. docs/models.md "Bat speed", docs/validation.md.
#pragma once

#include "core/numerics/jet.hpp"

namespace sweetspot::core {

/// n in V = C / I^n (Cross & Bower 2006, swing weight above 0.03 kg·m²), dimensionless.
inline constexpr double kSwingWeightExponent = 0.27;
/// Largest n a swing or a design problem accepts (dimensionless): at n = 0.5 the bat's kinetic
/// energy no longer grows with its swing weight.
inline constexpr double kMaxSwingWeightExponent = 0.5;
/// Smallest swing weight Cross & Bower's power law was measured above, kg·m² (below it their
/// swing speed levels off).
inline constexpr double kSwingWeightLawMinMoiKgM2 = 0.03;
/// The reference bat of swing.speed_model "swing_weight" when swing.reference_moi_kg_m2 is not
/// given: the catalogue's "wood-34-ash" (34 in, rigid-body inertia), the one the batter swings
/// at the given bat speed.
inline constexpr const char* kSwingWeightReferenceBat = "wood-34-ash";
/// Its MOI about the 6-in point (the standard grip), kg·m²: pinned against the preset's
/// computed mass properties by SwingSpeedTest.ReferenceMoiIsTheReferenceBats (1e-9 relative).
inline constexpr double kSwingWeightReferenceMoiKgM2 = 0.22753881320292296;

/// The relation's source, as answers quote it.
inline constexpr const char* kSwingWeightSource =
    "Cross & Bower, J. Sports Sci. 24, 23 (2006): V = C / I^n, n = 0.27 (I > 0.03 kg m^2)";

/// (moi / moi_ref)^-exponent: the factor on the reference bat's swing speed (or angular speed)
/// for a bat whose swing weight is `moi` (kg·m², > 0) when the reference swing weight is
/// `moi_ref` (kg·m², > 0). T is double or a jet (exact derivatives for the optimiser).
template <typename T>
T SwingWeightSpeedFactor(const T& moi, double moi_ref, double exponent) {
  return jet::Pow(moi * (1.0 / moi_ref), -exponent);
}

}  // namespace sweetspot::core
