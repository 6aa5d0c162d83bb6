// The scene outputs of the barrel model: implementation (scene_barrel.hpp).
#include "core/scene/scene_barrel.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include "core/collision/contact_law.hpp"
#include "core/flexible/modes.hpp"
#include "core/flexible/modes_cache.hpp"
#include "core/units.hpp"

namespace sweetspot::core {

bool SceneBarrel(const Scene& scene, const ResolvedScene& r, const BarrelOptions& options,
                 BarrelOutput* out, std::string* error) {
  const Bat& bat = *scene.bat;
  const Ball& ball = scene.ball;
  const double length = r.length_m;
  auto point = [&](double x, BarrelCorPoint* p, TrampolineResult* tr) {
    p->position_from_knob_m = x;
    p->approach_speed_mps =
        ball.speed_mps + r.swing.angular_speed_rad_s * (x - r.swing.pivot_from_knob_m);
    p->ball_cor = ball.cor_law ? ball.cor_law->CorAt(p->approach_speed_mps) : r.cor.value_or(0.5);
    if (!(p->approach_speed_mps > 0.0)) {
      *error = "barrel: the ball and the bat do not approach at " + std::to_string(x) +
               " m from the knob";
      return false;
    }
    *tr = EffectiveCorAt(bat, r.mass_properties, x, ball.mass_kg, ball.radius_m, ball.stiffness,
                         ball.stiffness_exponent, p->ball_cor, p->approach_speed_mps, options);
    if (!tr->ok) {
      *error = "barrel: " + tr->message;
      return false;
    }
    p->effective_cor = tr->effective_cor;
    return true;
  };
  out->position_from_knob_m = std::clamp(length - kCorReferenceFromTipM, 0.0, length);
  out->wall = BarrelWallAt(bat, out->position_from_knob_m, options);
  out->hollow = bat.IsHollow();
  out->method = out->hollow ? "trampoline_quasi_static" : "solid";
  out->shell_factor = out->hollow ? options.shell_factor : 0.0;
  BarrelCorPoint ref;
  TrampolineResult tr;
  if (!point(out->position_from_knob_m, &ref, &tr)) return false;
  out->effective_cor = ref.effective_cor;
  out->barrel_energy_fraction = out->hollow ? tr.barrel_energy_fraction : 0.0;
  out->effective_cor_curve.clear();
  for (int inch = 10; inch >= 1; --inch) {
    const double x = length - inch * kMetresPerInch;
    if (x < 0.0) continue;
    BarrelCorPoint p;
    if (!point(x, &p, &tr)) return false;
    out->effective_cor_curve.push_back(p);
  }
  return true;
}

BbcorResult ComputeCertifiedBbcor(const Bat& bat, const FlexibleOptions& flexible,
                                  const BarrelOptions& barrel,
                                  const MassProperties* rigid_body_properties,
                                  const BatModes* modes, BbcorScan* scan) {
  std::shared_ptr<const BatModes> own;
  if (modes == nullptr) {
    own = CachedBatModes(bat, flexible.ImpactModes(), flexible.modes_cache);
    modes = own.get();
  }
  BbcorScan s = ComputeBbcorScan(bat, *modes, BbcorProtocol{}, flexible.impact, barrel,
                                 rigid_body_properties);
  BbcorResult out = CertifiedBbcorOf(s);
  if (scan != nullptr) *scan = std::move(s);
  return out;
}

}  // namespace sweetspot::core
