// bbcor_scan: implementation; the model and its assumptions are stated in bbcor_scan.hpp.
#include "core/collision/bbcor_scan.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/collision/contact_law.hpp"
#include "core/geometry_format.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {
namespace {

constexpr int kMaxScanPoints = 201;
// The polish: at most this many impacts, stopped when the vertex moves less than 0.002 in
// (the value's error there, curvature ~40 per m^2 on the presets, is ~1e-7).
constexpr int kMaxPolishImpacts = 6;
constexpr double kPolishTolM = 0.002 * 0.0254;

// The scan's positions from the tip: first, first + step, ... up to last (inclusive within a
// millionth of a step).
std::vector<double> ScanPositionsFromTip(const BbcorProtocol& p) {
  std::vector<double> xs;
  const double span = p.scan_last_from_tip_m - p.scan_first_from_tip_m;
  const int n = static_cast<int>(std::floor(span / p.scan_step_m + 1e-6)) + 1;
  for (int i = 0; i < n; ++i) xs.push_back(p.scan_first_from_tip_m + i * p.scan_step_m);
  return xs;
}

// The protocol's impacts on one bat: the ball of `protocol` at its speed onto the bat at rest,
// pivoted at protocol.pivot_from_knob_m, each solved by the flexible model. Every impact adds
// its steps, its warnings (once each) and its error estimate to *out, and tells whether the
// modes fell short of its cutoff (short_of_cutoff).
struct BbcorStriker {
  const Bat* bat = nullptr;
  const BatModes* modes = nullptr;
  const BbcorProtocol* protocol = nullptr;
  const BarrelOptions* barrel = nullptr;
  const BallPreset* ball = nullptr;
  FlexibleImpactOptions o;  // the impact's options, hands' loads off
  double length_m = 0.0;    // the bat's length
  double i_pivot = 0.0;     // the bat's moment of inertia about the pivot, kg m^2
  BbcorScan* out = nullptr;
  bool short_of_cutoff = false;  // the modes fall short of an impact's cutoff

  // One protocol impact `from_tip` m from the barrel end into *p: false (out->message) on a
  // failure.
  bool Strike(double from_tip, BbcorScanPoint* p) {
    const double u = protocol->ball_speed_mps;
    const double m = ball->mass_kg;
    const double x = length_m - from_tip;
    const double z = x - protocol->pivot_from_knob_m;
    if (!(x >= 0.0 && z > 0.0)) {
      out->message = "bbcor_scan: the scan point " + FormatNumber17(from_tip) +
                     " m from the tip is not on the bat beyond the pivot";
      return false;
    }
    const BarrelWall wall = BarrelWallAt(*bat, x, *barrel);
    FlexibleImpactInputs in;
    in.impact_from_knob_m = x;
    in.hands_from_knob_m = protocol->pivot_from_knob_m;
    in.ball_mass_kg = m;
    in.ball_speed_mps = u;
    in.approach_speed_mps = u;  // the bat at rest
    in.ball_stiffness = ball->stiffness;
    in.ball_exponent = ball->stiffness_exponent;
    const double radius = bat->RadiusAtM(x);
    if (radius > 0.0) {
      in.surface_stiffness = BatSurfaceHertzStiffness(
          bat->material.youngs_modulus_pa, bat->material.poissons_ratio, ball->radius_m, radius);
    }
    in.cor = out->ball_cor;
    if (wall.hollow) in.barrel_compliance_m_n = 1.0 / wall.stiffness_n_m;
    const FlexibleImpactResult fr = SolveFlexibleImpact(*bat, *modes, in, o);
    out->steps += fr.steps;
    // Every computed mode used and the cutoff well above them (SolveFlexibleImpact's warning).
    short_of_cutoff =
        short_of_cutoff ||
        (!modes->modes.empty() && fr.modes_used == static_cast<int>(modes->modes.size()) &&
         (!o.static_correction || modes->modes.back().frequency_hz < 0.5 * fr.cutoff_hz));
    for (const auto& w : fr.summary.warnings) {
      if (std::find(out->warnings.begin(), out->warnings.end(), w) == out->warnings.end())
        out->warnings.push_back(w);
    }
    if (!fr.summary.IsSolutionUsable()) {
      out->message = "bbcor_scan: the impact " + FormatNumber17(from_tip) +
                     " m from the tip: " + fr.summary.message;
      return false;
    }
    const double r = m * z * z / i_pivot;
    p->position_from_tip_m = from_tip;
    p->position_from_knob_m = x;
    p->apparent_cor = fr.exit_speed_mps / u;
    p->value = p->apparent_cor * (1.0 + r) + r;
    p->rigid_value = fr.rigid_exit_speed_mps / u * (1.0 + r) + r;
    p->barrel_stiffness_n_m = wall.hollow ? wall.stiffness_n_m : 0.0;
    p->error_estimate = fr.error_estimate_exit_speed_mps / u * (1.0 + r);
    p->modes_used = fr.modes_used;
    out->error_estimate = std::max(out->error_estimate, p->error_estimate);
    return true;
  }
};

// Successive parabolic interpolation on the model inside the grid's bracket (a, b, c), b the
// largest: strike at the vertex of the parabola through the three, keep the bracket around the
// largest, until the vertex moves less than kPolishTolM (m) or after kMaxPolishImpacts. Every
// value reported is a struck point's, never an interpolation. Returns the largest point in
// *best; false when an impact failed (striker->out->message).
bool PolishBbcorMaximum(BbcorStriker* striker, BbcorScanPoint a, BbcorScanPoint b, BbcorScanPoint c,
                        BbcorScanPoint* best) {
  for (int it = 0; it < kMaxPolishImpacts; ++it) {
    const double xa = a.position_from_tip_m, xb = b.position_from_tip_m, xc = c.position_from_tip_m;
    const double num =
        (xb - xa) * (xb - xa) * (b.value - c.value) - (xb - xc) * (xb - xc) * (b.value - a.value);
    const double den = (xb - xa) * (b.value - c.value) - (xb - xc) * (b.value - a.value);
    if (!(den != 0.0)) break;
    const double v = xb - 0.5 * num / den;
    if (!(v > xa && v < xc) || std::abs(v - xb) < kPolishTolM) break;
    BbcorScanPoint pv;
    if (!striker->Strike(v, &pv)) return false;
    ++striker->out->polish_impacts;
    if (pv.value > b.value) {
      if (v < xb) {
        c = b;
      } else {
        a = b;
      }
      b = pv;
    } else if (v < xb) {
      a = pv;
    } else {
      c = pv;
    }
  }
  *best = b;
  return true;
}

// The scan's inputs: the bat, the barrel and impact options, the scan range, the ball's speed
// (m/s) and name (its preset in *ball) and the modes; false with the message in *message.
bool BbcorScanInputsValid(const Bat& bat, const BatModes& modes, const BbcorProtocol& protocol,
                          const FlexibleImpactOptions& impact, const BarrelOptions& barrel,
                          std::optional<BallPreset>* ball, std::string* message) {
  Refusal why;
  if (!bat.Validate(&why) || !barrel.Validate(&why) || !impact.Validate(&why) ||
      !BbcorScanRangeValidate(protocol, &why)) {
    *message = "bbcor_scan: " + why.Message();
    return false;
  }
  if (!(std::isfinite(protocol.ball_speed_mps) && protocol.ball_speed_mps > 0.0)) {
    *message = "bbcor_scan: protocol.ball_speed_mps = " + FormatNumber17(protocol.ball_speed_mps) +
               ": must be finite and > 0";
    return false;
  }
  *ball = FindBallPreset(protocol.ball);
  if (!*ball) {
    *message = "bbcor_scan: unknown ball '" + protocol.ball + "'";
    return false;
  }
  if (!modes.summary.IsSolutionUsable()) {
    *message = "bbcor_scan: the bat's modes are not usable: " + modes.summary.message;
    return false;
  }
  return true;
}

// The largest of the scanned points in *out (its index, the point, polished between its
// neighbours when they bracket a maximum; else a warning when it is at an end of the range),
// then the maximum's value and position (m from the tip and from the knob). False when a
// polishing impact failed (out->message).
bool FindBbcorMaximum(BbcorStriker* striker, BbcorScan* out) {
  const auto& pts = out->points;
  std::size_t best = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (pts[i].value > pts[best].value) best = i;
  }
  out->max_index = static_cast<int>(best);
  out->max_point = pts[best];
  out->refinement = "none";
  if (best > 0 && best + 1 < pts.size() &&
      pts[best - 1].value - 2.0 * pts[best].value + pts[best + 1].value < 0.0) {
    if (!PolishBbcorMaximum(striker, pts[best - 1], pts[best], pts[best + 1], &out->max_point)) {
      return false;
    }
    out->refinement = "polished";
  } else if (best == 0 || best + 1 == pts.size()) {
    out->warnings.push_back("the largest BBCOR is at an end of the scan range (" +
                            FormatNumber17(pts[best].position_from_tip_m) +
                            " m from the tip): the maximum may lie outside it");
  }
  out->max_value = out->max_point.value;
  out->max_from_tip_m = out->max_point.position_from_tip_m;
  out->max_from_knob_m = striker->length_m - out->max_from_tip_m;
  return true;
}

}  // namespace

bool BbcorScanRangeValidate(const BbcorProtocol& p, Refusal* why) {
  if (!(std::isfinite(p.scan_first_from_tip_m) && p.scan_first_from_tip_m >= 0.0))
    return Refuse(why, Number17Refusal("protocol.scan_first_from_tip_m", p.scan_first_from_tip_m,
                                       "must be finite and >= 0"));
  if (!(std::isfinite(p.scan_last_from_tip_m) && p.scan_last_from_tip_m >= p.scan_first_from_tip_m))
    return Refuse(why, Number17Refusal("protocol.scan_last_from_tip_m", p.scan_last_from_tip_m,
                                       "must be finite and >= scan_first_from_tip_m"));
  if (!(std::isfinite(p.scan_step_m) && p.scan_step_m > 0.0))
    return Refuse(why,
                  Number17Refusal("protocol.scan_step_m", p.scan_step_m, "must be finite and > 0"));
  if ((p.scan_last_from_tip_m - p.scan_first_from_tip_m) / p.scan_step_m + 1.0 > kMaxScanPoints)
    return Refuse(why, Number17Refusal("protocol.scan_step_m", p.scan_step_m,
                                       "gives more than 201 scan points"));
  return true;
}

BbcorScan ComputeBbcorScan(const Bat& bat, const BatModes& modes, const BbcorProtocol& protocol,
                           const FlexibleImpactOptions& impact, const BarrelOptions& barrel,
                           const MassProperties* rigid_body_properties) {
  const auto t0 = std::chrono::steady_clock::now();
  BbcorScan out;
  bool short_of_cutoff = false;  // the modes fall short of the protocol's impact
  out.ball = protocol.ball;
  out.ball_speed_mps = protocol.ball_speed_mps;
  out.pivot_from_knob_m = protocol.pivot_from_knob_m;
  Summary guard;
  CatchInternalError(&guard, [&] {
    std::optional<BallPreset> ball;
    if (!BbcorScanInputsValid(bat, modes, protocol, impact, barrel, &ball, &out.message)) return;
    // The bat's mass properties once: the caller's, or computed here for both uses below.
    const MassProperties properties =
        rigid_body_properties != nullptr ? *rigid_body_properties : ComputeMassProperties(bat);
    const BbcorResult fixed = ComputeBbcor(bat, protocol, barrel, &properties);
    if (!fixed.ok) {
      out.message = fixed.message;
      return;
    }
    out.fixed_point_value = fixed.value;
    out.fixed_point_from_tip_m = protocol.impact_from_tip_m;
    out.fixed_point_method = fixed.method;
    out.ball_cor = fixed.ball_cor;
    out.elements = modes.Elements();

    BbcorStriker striker;
    striker.bat = &bat;
    striker.modes = &modes;
    striker.protocol = &protocol;
    striker.barrel = &barrel;
    striker.ball = &*ball;
    striker.o = impact;
    striker.o.hands_loads = false;  // only the exit speed is read
    striker.length_m = bat.LengthM();
    striker.i_pivot = properties.MoiAboutKgM2(protocol.pivot_from_knob_m);
    striker.out = &out;
    for (double from_tip : ScanPositionsFromTip(protocol)) {
      BbcorScanPoint p;
      if (!striker.Strike(from_tip, &p)) return;
      out.points.push_back(p);
    }
    if (!FindBbcorMaximum(&striker, &out)) return;
    short_of_cutoff = striker.short_of_cutoff;  // read below only when the scan is ok
    out.ok = true;
    out.message = "scanned " + std::to_string(out.points.size()) + " points, " +
                  std::to_string(out.polish_impacts) + " polishing impacts";
  });
  if (!guard.message.empty()) {
    out.ok = false;
    out.message = "bbcor_scan: " + guard.message;
  }
  // The protocol's impact (a 136 mph ball onto a bat at rest) is shorter than a game's: on a
  // solid wood bat its cutoff (cutoff_factor / contact time: ~22 kHz on wood-34-ash) lies far
  // above the modes a scene computes by default (12, up to 7.3 kHz on wood-34-ash), and every
  // impact warned "raise flexible.max_modes". The scan then computes the modes it needs (twice
  // as many, at most 50, on the same theory and tolerance) and scans again: its value
  // converges (wood-34-ash: 0.46599 with 12 modes, 0.46612 with 24, 0.46614 with 50), and the
  // warning stays only when even 50 modes fall short.
  if (out.ok && short_of_cutoff && !modes.modes.empty() && modes.modes.size() < 50) {
    BeamModesOptions more;
    more.theory = modes.theory;
    more.num_modes = std::min(50, 2 * static_cast<int>(modes.modes.size()));
    more.relative_tolerance = impact.frequency_tolerance;
    more.max_elements = std::max(more.max_elements, modes.Elements());
    const BatModes more_modes = ComputeBatModes(bat, more);
    if (more_modes.summary.IsSolutionUsable()) {
      BbcorScan again =
          ComputeBbcorScan(bat, more_modes, protocol, impact, barrel, rigid_body_properties);
      if (again.ok) {
        again.steps += out.steps;  // the first scan's too
        out = std::move(again);
      }
    }
  }
  out.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

BbcorResult CertifiedBbcorOf(const BbcorScan& scan) {
  BbcorResult out;
  out.ball = scan.ball;
  out.ball_speed_mps = scan.ball_speed_mps;
  out.ball_cor = scan.ball_cor;
  out.pivot_from_knob_m = scan.pivot_from_knob_m;
  out.method = kCertifiedBbcorMethod;
  out.warnings = scan.warnings;
  if (!scan.ok) {
    out.message = scan.message;
    return out;
  }
  out.ok = true;
  out.value = scan.max_value;
  out.impact_from_knob_m = scan.max_from_knob_m;
  out.impact_from_tip_m = scan.max_from_tip_m;
  out.refinement = scan.refinement;
  out.error_estimate = scan.error_estimate;
  out.barrel_stiffness_n_m = scan.max_point.barrel_stiffness_n_m;
  out.estimate_value = scan.fixed_point_value;
  out.estimate_from_tip_m = scan.fixed_point_from_tip_m;
  out.estimate_method = scan.fixed_point_method;
  out.estimate_error = scan.fixed_point_value - scan.max_value;
  out.solve_time_s = scan.solve_time_s;
  return out;
}

}  // namespace sweetspot::core
