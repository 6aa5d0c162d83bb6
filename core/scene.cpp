#include "core/scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/roots.hpp>

namespace sweetspot::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kMaxCurvePoints = 10000;
using Clock = std::chrono::steady_clock;

std::string Num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

bool Fail(std::string* why, const std::string& m) {
  if (why != nullptr) *why = m;
  return false;
}

double Seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Time and calls per model, in first-use order; also the models_used list.
class TimingBook {
 public:
  void Add(const std::string& model, double time_s, int calls) {
    for (auto& t : timings_) {
      if (t.model == model) {
        t.time_s += time_s;
        t.calls += calls;
        return;
      }
    }
    timings_.push_back({model, time_s, calls});
  }
  const std::vector<ModelTiming>& timings() const { return timings_; }
  std::vector<std::string> Models() const {
    std::vector<std::string> out;
    for (const auto& t : timings_) out.push_back(t.model);
    return out;
  }

 private:
  std::vector<ModelTiming> timings_;
};

// What every output shares within one request.
struct Resolved {
  MassProperties mp;
  double length_m = 0.0;
  std::optional<double> cor;  // unset when no wanted output needs a COR
  std::string cor_source;     // "" when `cor` is unset
};

// Validates the scene, resolves the COR when `needs_cor`, computes (or takes) the mass
// properties once.
bool Resolve(const Scene& scene, bool needs_cor, TimingBook* book, Resolved* r, Summary* s) {
  std::string why;
  if (!scene.IsValid(&why)) {
    s->termination = Termination::kInvalidInput;
    s->message = why;
    return false;
  }
  if (!needs_cor) {
    // Nothing wanted uses a COR: none is resolved, so none is required.
  } else if (scene.cor.has_value()) {
    r->cor = *scene.cor;
    r->cor_source = "scene";
  } else if (scene.bat.has_value() && scene.bat->material.cor.has_value()) {
    r->cor = *scene.bat->material.cor;
    r->cor_source = "material:" + scene.bat->material.name;
  } else {
    s->termination = Termination::kInvalidInput;
    s->message =
        scene.bat.has_value()
            ? "cor: not given, and material '" + scene.bat->material.name + "' has no default COR"
            : "cor: not given, and there is no bat material to take it from";
    return false;
  }
  if (scene.mass_properties.has_value()) {
    r->mp = *scene.mass_properties;
  } else {
    const auto t0 = Clock::now();
    try {
      r->mp = ComputeMassProperties(*scene.bat, scene.inertia_model);
    } catch (const std::exception& e) {
      s->termination = Termination::kFailure;
      s->message = std::string("mass properties failed: ") + e.what();
      return false;
    }
    book->Add("mass_properties", Seconds(t0), 1);
  }
  if (!(std::isfinite(r->mp.mass_kg) && r->mp.mass_kg > 0.0 &&
        std::isfinite(r->mp.balance_point_m) && std::isfinite(r->mp.moi_centroid_kg_m2) &&
        r->mp.moi_centroid_kg_m2 > 0.0)) {
    s->termination = Termination::kFailure;
    s->message = "mass properties are not usable (mass_kg = " + Num(r->mp.mass_kg) +
                 ", moi_centroid_kg_m2 = " + Num(r->mp.moi_centroid_kg_m2) + ")";
    return false;
  }
  r->length_m = scene.bat.has_value() ? scene.bat->LengthM() : scene.length_m;
  const double h = scene.swing.hands_from_knob_m;
  if (!(h >= 0.0 && h <= r->length_m)) {
    s->termination = Termination::kInvalidInput;
    s->message = "swing.hands_from_knob_m = " + Num(h) + ": must be within the bat [0, " +
                 Num(r->length_m) + "]";
    return false;
  }
  return true;
}

RigidPivotInputs MakeRigidPivot(const Scene& scene, const Resolved& r) {
  RigidPivotInputs in;
  in.bat_mass_kg = r.mp.mass_kg;
  in.balance_point_m = r.mp.balance_point_m;
  in.pivot_from_knob_m = scene.swing.pivot_from_knob_m;
  in.moi_pivot_kg_m2 = r.mp.MoiAboutKgM2(in.pivot_from_knob_m);
  in.ball_mass_kg = scene.ball.mass_kg;
  in.ball_speed_mps = scene.ball.speed_mps;
  in.angular_speed_rad_s = scene.swing.angular_speed_rad_s;
  in.cor = *r.cor;
  return in;
}

FreeBatInputs MakeFreeBat(const Scene& scene, const Resolved& r) {
  FreeBatInputs in;
  in.bat_mass_kg = r.mp.mass_kg;
  in.balance_point_m = r.mp.balance_point_m;
  in.moi_centroid_kg_m2 = r.mp.moi_centroid_kg_m2;
  in.pivot_from_knob_m = scene.swing.pivot_from_knob_m;
  in.hands_from_knob_m = scene.swing.hands_from_knob_m;
  in.ball_mass_kg = scene.ball.mass_kg;
  in.ball_speed_mps = scene.ball.speed_mps;
  in.angular_speed_rad_s = scene.swing.angular_speed_rad_s;
  in.cor = *r.cor;
  return in;
}

HertzProblem MakeHertz(const Scene& scene, const Resolved& r, double impact_from_knob_m,
                       const HertzOptions& options, std::vector<std::string>* warnings) {
  HertzProblem p;
  const double m_bat = r.mp.mass_kg;
  const double i = r.mp.moi_centroid_kg_m2;
  const double b = impact_from_knob_m - r.mp.balance_point_m;
  const double bh = scene.swing.hands_from_knob_m - r.mp.balance_point_m;
  p.law = options.law;
  p.ball_mass_kg = scene.ball.mass_kg;
  p.ball_speed_mps = scene.ball.speed_mps;
  p.approach_speed_mps =
      scene.ball.speed_mps +
      scene.swing.angular_speed_rad_s * (impact_from_knob_m - scene.swing.pivot_from_knob_m);
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

FlexibleImpactInputs MakeFlexible(const Scene& scene, const Resolved& r, double impact_from_knob_m,
                                  const HertzOptions& hertz) {
  FlexibleImpactInputs in;
  in.impact_from_knob_m = impact_from_knob_m;
  in.hands_from_knob_m = scene.swing.hands_from_knob_m;
  in.ball_mass_kg = scene.ball.mass_kg;
  in.ball_speed_mps = scene.ball.speed_mps;
  in.approach_speed_mps =
      scene.ball.speed_mps +
      scene.swing.angular_speed_rad_s * (impact_from_knob_m - scene.swing.pivot_from_knob_m);
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

// The flexible beam's modes within one request: each set computed once (or taken from the
// caller's cross-request cache), timed under "flexible_beam".
class FlexibleModes {
 public:
  FlexibleModes(const Scene& scene, const FlexibleOptions& options, TimingBook* book)
      : scene_(scene), options_(options), book_(book) {}
  const std::shared_ptr<const BatModes>& Impact() {
    if (!impact_) impact_ = Get(options_.ImpactModes(), &impact_hit_);
    return impact_;
  }
  const std::shared_ptr<const BatModes>& Vibration() {
    if (!vibration_) vibration_ = Get(options_.VibrationModes(), &vibration_hit_);
    return vibration_;
  }
  bool impact_hit() const { return impact_hit_; }
  bool vibration_hit() const { return vibration_hit_; }

 private:
  std::shared_ptr<const BatModes> Get(const BeamModesOptions& o, bool* hit) {
    const auto t0 = Clock::now();
    auto modes = CachedBatModes(*scene_.bat, o, options_.modes_cache, hit);
    book_->Add(kFlexibleBeamModel, Seconds(t0), 1);
    // Here the mesh bound is the scene's flexible.max_elements: name it so (a refusal's
    // message starts with its field, which the API reports).
    if (modes && modes->summary.termination == Termination::kInvalidInput &&
        modes->summary.message.rfind("max_elements = ", 0) == 0) {
      auto renamed = std::make_shared<BatModes>(*modes);
      renamed->summary.message = "flexible." + renamed->summary.message;
      modes = std::move(renamed);
    }
    return modes;
  }
  const Scene& scene_;
  const FlexibleOptions& options_;
  TimingBook* book_;
  std::shared_ptr<const BatModes> impact_, vibration_;
  bool impact_hit_ = false, vibration_hit_ = false;
};

// The exit speed along the bat under one model; closed-form models carry their profile.
class ExitSpeedModel {
 public:
  ExitSpeedModel(CollisionModel model, const Scene& scene, const Resolved& r,
                 const HertzOptions& hertz, TimingBook* book,
                 const FlexibleOptions* flexible = nullptr,
                 std::shared_ptr<const BatModes> modes = nullptr)
      : model_(model),
        scene_(scene),
        r_(r),
        hertz_(hertz),
        book_(book),
        flexible_(flexible),
        modes_(std::move(modes)) {
    if (model == CollisionModel::kRigidPivot) {
      profile_ = RigidPivotProfile(MakeRigidPivot(scene, r));
    } else if (model == CollisionModel::kFreeBat) {
      profile_ = FreeBatProfile(MakeFreeBat(scene, r));
    }
  }
  const char* name() const { return CollisionModelName(model_); }
  const std::optional<ExitSpeedProfile>& profile() const { return profile_; }
  bool has_gradient() const { return profile_.has_value(); }

  // The exit speed at s (m from the knob), its derivative (closed forms) and error estimate.
  bool Eval(double s, double* v, double* grad, double* err, std::string* why) {
    const auto t0 = Clock::now();
    bool ok = true;
    if (profile_.has_value()) {
      const double x = s - profile_->origin_from_knob_m;
      *v = profile_->ExitSpeedMps(x);
      if (grad != nullptr) *grad = profile_->DerivativePerS(x);
      if (err != nullptr) *err = 8.0 * kEps * (profile_->ball_speed_mps + std::abs(*v));
    } else if (model_ == CollisionModel::kFlexible) {
      const FlexibleImpactResult fr = SolveFlexibleImpact(
          *scene_.bat, *modes_, MakeFlexible(scene_, r_, s, hertz_), flexible_->impact);
      for (auto& w : fr.summary.warnings) AddWarning(w);
      if (!fr.summary.IsSolutionUsable()) {
        ok = false;
        if (why != nullptr) {
          *why = "flexible at " + Num(s) + " m from the knob: " + fr.summary.message;
        }
      } else {
        *v = fr.exit_speed_mps;
        if (err != nullptr) *err = fr.error_estimate_exit_speed_mps;
      }
    } else {
      std::vector<std::string> warnings;
      const HertzImpact hi =
          SolveHertzImpact(MakeHertz(scene_, r_, s, hertz_, &warnings), hertz_.solver);
      for (auto& w : warnings) AddWarning(w);
      for (auto& w : hi.summary.warnings) AddWarning(w);
      if (!hi.summary.IsSolutionUsable()) {
        ok = false;
        if (why != nullptr) *why = "hertz at " + Num(s) + " m from the knob: " + hi.summary.message;
      } else {
        *v = hi.exit_speed_mps;
        if (err != nullptr) {
          *err = hertz_.solver.refine_check
                     ? hi.error_estimate_exit_speed_mps
                     : hertz_.solver.relative_tolerance * (scene_.ball.speed_mps + std::abs(*v));
        }
      }
    }
    book_->Add(name(), Seconds(t0), 1);
    return ok;
  }
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  void AddWarning(const std::string& w) {
    if (std::find(warnings_.begin(), warnings_.end(), w) == warnings_.end()) warnings_.push_back(w);
  }
  CollisionModel model_;
  const Scene& scene_;
  const Resolved& r_;
  HertzOptions hertz_;
  TimingBook* book_;
  const FlexibleOptions* flexible_;
  std::shared_ptr<const BatModes> modes_;
  std::optional<ExitSpeedProfile> profile_;
  std::vector<std::string> warnings_;
};

MaxExitSpeedResult SearchMaxExitSpeed(ExitSpeedModel* model, double length_m,
                                      const ScalarSearchOptions& options) {
  MaxExitSpeedResult out;
  out.model = model->name();
  double model_err = 0.0;
  std::string model_error;
  auto f = [&](double s, double* grad) {
    double v = 0.0, e = 0.0;
    if (!model->Eval(s, &v, grad, &e, &model_error)) {
      return std::numeric_limits<double>::quiet_NaN();  // reported by the search as a failure
    }
    model_err = std::max(model_err, e);
    return v;
  };
  const ScalarSearchResult r = MaximizeScalar(f, model->has_gradient(), 0.0, length_m, options);
  out.summary = r.summary;
  out.method = r.summary.backend;
  if (!model_error.empty()) out.summary.message += " (" + model_error + ")";
  out.position_from_knob_m = r.x;
  out.unconstrained_position_from_knob_m = r.x;
  out.exit_speed_mps = r.value;
  out.placement = r.at_upper_bound && !r.at_lower_bound   ? Placement::kBeyondTip
                  : r.at_lower_bound && !r.at_upper_bound ? Placement::kBeforeKnob
                                                          : Placement::kOnBat;
  out.error_estimate_m = r.error_estimate_x;
  out.error_estimate_mps = r.error_estimate_value + model_err;
  return out;
}

SweetZoneResult RootFindSweetZone(ExitSpeedModel* model, double length_m,
                                  const MaxExitSpeedResult& max, double tolerance_mps,
                                  std::string* error) {
  SweetZoneResult out;
  out.method = "root_finding";
  out.tolerance_mps = tolerance_mps;
  out.threshold_mps = max.exit_speed_mps - tolerance_mps;
  const double s0 = max.position_from_knob_m;
  double worst_err = 0.0;
  bool failed = false;
  auto g = [&](double s) {
    double v = 0.0, e = 0.0;
    if (!model->Eval(s, &v, nullptr, &e, error)) {
      failed = true;
      return 0.0;
    }
    worst_err = std::max(worst_err, e);
    return v - out.threshold_mps;
  };
  auto edge = [&](double end, bool* clipped) -> double {
    if (tolerance_mps == 0.0 || end == s0) return s0;
    const double g_end = g(end);
    if (failed) return s0;
    if (g_end >= 0.0) {
      *clipped = true;
      return end;
    }
    const double g0 = tolerance_mps;
    const double a = std::min(s0, end), b = std::max(s0, end);
    const double ga = a == s0 ? g0 : g_end, gb = b == s0 ? g0 : g_end;
    boost::uintmax_t iters = 200;
    try {
      const auto r = boost::math::tools::toms748_solve(
          g, a, b, ga, gb, boost::math::tools::eps_tolerance<double>(48), iters);
      const double root = 0.5 * (r.first + r.second);
      // The root moves by (model error) / |slope|; the slope from the bracket.
      const double slope = std::abs(tolerance_mps / (root - s0));
      const double e = (r.second - r.first) + (slope > 0.0 ? 2.0 * worst_err / slope : 0.0);
      out.error_estimate_m = std::max(out.error_estimate_m, e);
      return root;
    } catch (const std::exception& ex) {
      failed = true;
      *error = std::string("sweet-zone root finding failed: ") + ex.what();
      return s0;
    }
  };
  bool clip_lo = false, clip_hi = false;
  out.from_knob_m = edge(0.0, &clip_lo);
  out.to_knob_m = edge(length_m, &clip_hi);
  out.clipped_at_knob = clip_lo;
  out.clipped_at_tip = clip_hi;
  if (failed && error->empty()) *error = "sweet-zone root finding failed";
  return out;
}

Termination Worse(Termination a, Termination b) {
  auto rank = [](Termination t) {
    switch (t) {
      case Termination::kConverged:
        return 0;
      case Termination::kNoConvergence:
        return 1;
      case Termination::kInfeasible:
        return 2;
      case Termination::kFailure:
        return 3;
      case Termination::kInvalidInput:
        return 4;
    }
    return 3;
  };
  return rank(a) >= rank(b) ? a : b;
}

bool NeedsExitModel(SceneOutput o) {
  return o == SceneOutput::kMaxExitSpeed || o == SceneOutput::kSweetZone ||
         o == SceneOutput::kExitSpeedCurve;
}

// Outputs that run an impact (every impact model uses the COR): the exit-speed outputs and
// least_sting_zone's flexible impacts. center_of_percussion and vibration_node do not.
bool NeedsCor(SceneOutput o) { return NeedsExitModel(o) || o == SceneOutput::kLeastStingZone; }

bool Wants(const std::vector<SceneOutput>& wanted, SceneOutput o) {
  return std::find(wanted.begin(), wanted.end(), o) != wanted.end();
}

// vibration_node from the modes of the first two bending modes.
bool VibrationNodeFrom(const BatModes& modes, bool cache_hit, VibrationNodeResult* out,
                       std::string* error) {
  if (!modes.summary.IsSolutionUsable()) {
    *error = modes.summary.message;
    return false;
  }
  if (modes.modes.size() < 2) {
    *error = "the modes computation returned fewer than two modes";
    return false;
  }
  const BeamMode& m1 = modes.modes[0];
  const BeamMode& m2 = modes.modes[1];
  if (m1.nodes_from_knob_m.empty()) {
    *error = "the fundamental bending mode has no node on the bat";
    return false;
  }
  out->position_from_knob_m = m1.nodes_from_knob_m.back();
  out->other_node_from_knob_m = m1.nodes_from_knob_m.front();
  out->frequency_hz = m1.frequency_hz;
  out->error_estimate_hz = m1.error_estimate_hz;
  out->error_estimate_m = m1.nodes_error_estimate_m;
  out->second_mode_frequency_hz = m2.frequency_hz;
  out->second_mode_nodes_from_knob_m = m2.nodes_from_knob_m;
  out->second_mode_error_estimate_hz = m2.error_estimate_hz;
  out->relative_tolerance = modes.tolerance;
  out->elements = modes.Elements();
  out->refinement_elements = modes.refinement_elements;
  out->theory = BeamTheoryName(modes.theory);
  out->cache_hit = cache_hit;
  out->summary = modes.summary;
  return true;
}

// least_sting_zone: flexible impacts from the hands to the tip (see LeastStingZoneResult).
bool SweepSting(const Scene& scene, const Resolved& r, const SceneOptions& options,
                const BatModes& modes, TimingBook* book, std::vector<std::string>* warnings,
                LeastStingZoneResult* out, std::string* error) {
  const FlexibleOptions& fo = options.flexible;
  const double lo = scene.swing.hands_from_knob_m;
  const double hi = r.length_m;
  if (!(hi > lo)) {
    *error = "swing.hands_from_knob_m = " + Num(lo) +
             ": the sweep runs from the hands to the tip, so the hands must be before the tip";
    return false;
  }
  FlexibleImpactOptions quick = fo.impact;
  quick.refine_check = false;  // the refinement is reported on the samples
  bool failed = false;
  auto impact = [&](double s, bool refine) {
    const auto t0 = Clock::now();
    FlexibleImpactResult fr = SolveFlexibleImpact(
        *scene.bat, modes, MakeFlexible(scene, r, s, options.hertz), refine ? fo.impact : quick);
    book->Add(CollisionModelName(CollisionModel::kFlexible), Seconds(t0), 1);
    for (const auto& w : fr.summary.warnings) {
      if (std::find(warnings->begin(), warnings->end(), w) == warnings->end()) {
        warnings->push_back(w);
      }
    }
    if (!fr.summary.IsSolutionUsable() && !failed) {
      failed = true;
      *error = "flexible at " + Num(s) + " m from the knob: " + fr.summary.message;
    }
    return fr;
  };
  const int n = fo.sting_samples;
  std::vector<double> xs, es;
  double err_e = 0.0;
  for (int i = 0; i < n; ++i) {
    const double s = i + 1 == n ? hi : lo + (hi - lo) * i / (n - 1);
    const FlexibleImpactResult fr = impact(s, true);
    if (failed) return false;
    StingPoint p;
    p.position_from_knob_m = s;
    p.exit_speed_mps = fr.exit_speed_mps;
    p.rigid_exit_speed_mps = fr.rigid_exit_speed_mps;
    p.vibration_energy_j = fr.vibration_energy_j;
    p.hands_vibration_energy_j = fr.hands_vibration_energy_j;
    p.hands_peak_shear_force_n = fr.hands_peak_shear_force_n;
    p.hands_peak_bending_moment_n_m = fr.hands_peak_bending_moment_n_m;
    p.contact_time_s = fr.contact_time_s;
    p.error_estimate_exit_speed_mps = fr.error_estimate_exit_speed_mps;
    p.error_estimate_hands_energy_j = fr.error_estimate_hands_energy_j;
    out->curve.push_back(p);
    out->modes_used = std::max(out->modes_used, fr.modes_used);
    xs.push_back(s);
    es.push_back(fr.hands_vibration_energy_j);
    err_e = std::max(err_e, fr.error_estimate_hands_energy_j);
  }
  out->elements = modes.Elements();
  out->theory = BeamTheoryName(modes.theory);
  out->fraction = fo.sting_zone_fraction;
  const std::size_t i_min =
      static_cast<std::size_t>(std::min_element(es.begin(), es.end()) - es.begin());
  out->max_hands_energy_j = *std::max_element(es.begin(), es.end());
  // Refine the minimum between the neighbouring samples (Brent, ~1e-6 relative in s).
  auto energy = [&](double s) { return impact(s, false).hands_vibration_energy_j; };
  const double a = xs[i_min == 0 ? 0 : i_min - 1];
  const double b = xs[std::min(i_min + 1, xs.size() - 1)];
  double x_min = xs[i_min], e_min = es[i_min];
  double err_x = 0.5 * (b - a);
  if (b > a) {
    boost::uintmax_t iters = 60;
    const auto m = boost::math::tools::brent_find_minima(energy, a, b, 20, iters);
    if (failed) return false;
    if (m.second <= e_min) {
      x_min = m.first;
      e_min = m.second;
    }
    // Brent's bracket, widened by how far the energy's own error moves a flat minimum.
    const double h = 0.5 * (b - a);
    const double curv = (es[std::min(i_min + 1, es.size() - 1)] + es[i_min == 0 ? 0 : i_min - 1] -
                         2.0 * es[i_min]) /
                        (h * h);
    err_x = std::ldexp(std::abs(x_min), -19) +
            (curv > 0.0 ? std::sqrt(2.0 * err_e / curv) : 0.5 * (b - a));
  }
  out->min_position_from_knob_m = x_min;
  out->min_hands_energy_j = e_min;
  out->exit_speed_at_min_mps = impact(x_min, false).exit_speed_mps;
  if (failed) return false;
  out->threshold_j = e_min + fo.sting_zone_fraction * (out->max_hands_energy_j - e_min);
  auto g = [&](double s) { return energy(s) - out->threshold_j; };
  double err_edges = 0.0;
  auto edge = [&](int dir, bool* clipped) -> double {
    // The first sample beyond the threshold, walking away from the minimum.
    long j = static_cast<long>(i_min);
    while (true) {
      const long next = j + dir;
      if (next < 0 || next >= static_cast<long>(xs.size())) {
        *clipped = true;
        return dir < 0 ? lo : hi;
      }
      if (es[static_cast<std::size_t>(next)] > out->threshold_j) {
        const double inside =
            j == static_cast<long>(i_min) ? x_min : xs[static_cast<std::size_t>(j)];
        const double outside = xs[static_cast<std::size_t>(next)];
        const double ga = g(inside);
        const double gb = es[static_cast<std::size_t>(next)] - out->threshold_j;
        if (failed || !(ga <= 0.0)) return inside;
        boost::uintmax_t iters = 60;
        try {
          const double x0 = std::min(inside, outside), x1 = std::max(inside, outside);
          const auto rr = boost::math::tools::toms748_solve(
              g, x0, x1, x0 == inside ? ga : gb, x0 == inside ? gb : ga,
              boost::math::tools::eps_tolerance<double>(30), iters);
          const double root = 0.5 * (rr.first + rr.second);
          const double slope = std::abs(gb - ga) / std::abs(outside - inside);
          err_edges =
              std::max(err_edges, (rr.second - rr.first) + (slope > 0.0 ? err_e / slope : 0.0));
          return root;
        } catch (const std::exception& e) {
          failed = true;
          *error = std::string("least_sting_zone: root finding failed: ") + e.what();
          return inside;
        }
      }
      j = next;
    }
  };
  bool clip_lo = false, clip_hi = false;
  out->from_knob_m = edge(-1, &clip_lo);
  out->to_knob_m = edge(+1, &clip_hi);
  if (failed) return false;
  out->clipped_at_hands = clip_lo;
  out->clipped_at_tip = clip_hi;
  out->error_estimate_m = std::max(err_x, err_edges);
  return true;
}

}  // namespace

// ----------------------------------------------------------------------------- validation

bool Ball::IsValid(std::string* why) const {
  // Floors of 1 mg and 1 µm: smaller values are not balls, and a subnormal
  // mass made 1/m infinite in the free-bat and Hertz models (found by fuzzing).
  if (!(std::isfinite(mass_kg) && mass_kg >= kMinBallMassKg))
    return Fail(why, "ball.mass_kg = " + Num(mass_kg) + ": must be finite and >= 1e-06");
  if (!(std::isfinite(radius_m) && radius_m >= kMinBallRadiusM))
    return Fail(why, "ball.radius_m = " + Num(radius_m) + ": must be finite and >= 1e-06");
  if (!(std::isfinite(speed_mps) && speed_mps >= 0.0))
    return Fail(why, "ball.speed_mps = " + Num(speed_mps) + ": must be >= 0");
  if (!(std::isfinite(stiffness) && stiffness > 0.0))
    return Fail(why, "ball.stiffness = " + Num(stiffness) + ": must be finite and > 0");
  if (!(std::isfinite(stiffness_exponent) && stiffness_exponent >= 1.0 &&
        stiffness_exponent <= 3.0))
    return Fail(why,
                "ball.stiffness_exponent = " + Num(stiffness_exponent) + ": must be in [1, 3]");
  return true;
}

bool Swing::IsValid(std::string* why) const {
  if (!(std::isfinite(angular_speed_rad_s) && angular_speed_rad_s >= 0.0))
    return Fail(why, "swing.angular_speed_rad_s = " + Num(angular_speed_rad_s) + ": must be >= 0");
  if (!std::isfinite(pivot_from_knob_m))
    return Fail(why, "swing.pivot_from_knob_m = " + Num(pivot_from_knob_m) + ": must be finite");
  if (!std::isfinite(hands_from_knob_m))
    return Fail(why, "swing.hands_from_knob_m = " + Num(hands_from_knob_m) + ": must be finite");
  return true;
}

bool Scene::IsValid(std::string* why) const {
  if (!bat.has_value() && !mass_properties.has_value())
    return Fail(why, "bat: missing (give a bat or precomputed mass_properties)");
  if (bat.has_value()) {
    std::string inner;
    if (!bat->IsValid(&inner)) return Fail(why, "bat: " + inner);
  } else if (!(std::isfinite(length_m) && length_m > 0.0)) {
    return Fail(why, "length_m = " + Num(length_m) +
                         ": must be finite and > 0 when only mass_properties are given");
  }
  if (mass_properties.has_value()) {
    const MassProperties& mp = *mass_properties;
    if (!(std::isfinite(mp.mass_kg) && mp.mass_kg > 0.0))
      return Fail(why, "mass_properties.mass_kg = " + Num(mp.mass_kg) + ": must be finite and > 0");
    if (!std::isfinite(mp.balance_point_m))
      return Fail(
          why, "mass_properties.balance_point_m = " + Num(mp.balance_point_m) + ": must be finite");
    if (!(std::isfinite(mp.moi_centroid_kg_m2) && mp.moi_centroid_kg_m2 > 0.0))
      return Fail(why, "mass_properties.moi_centroid_kg_m2 = " + Num(mp.moi_centroid_kg_m2) +
                           ": must be finite and > 0");
    if (!std::isfinite(mp.moi_knob_kg_m2))
      return Fail(
          why, "mass_properties.moi_knob_kg_m2 = " + Num(mp.moi_knob_kg_m2) + ": must be finite");
  }
  if (!ball.IsValid(why) || !swing.IsValid(why)) return false;
  if (cor.has_value() && !(std::isfinite(*cor) && *cor >= 0.0 && *cor <= 1.0))
    return Fail(why, "cor = " + Num(*cor) + ": must be in [0, 1]");
  if (outputs.empty()) return Fail(why, "outputs: empty: name at least one output");
  return true;
}

bool SceneOptions::IsValid(std::string* why) const {
  if (!nlopt.IsValid(why)) return false;
  if (!(std::isfinite(sweet_zone_tolerance) && sweet_zone_tolerance >= 0.0))
    return Fail(why, "sweet_zone_tolerance = " + Num(sweet_zone_tolerance) + ": must be >= 0");
  if (curve_positions_from_knob_m.empty() && (curve_samples < 2 || curve_samples > kMaxCurvePoints))
    return Fail(why, "curve_samples = " + std::to_string(curve_samples) + ": must be in [2, " +
                         std::to_string(kMaxCurvePoints) + "]");
  if (curve_positions_from_knob_m.size() > static_cast<size_t>(kMaxCurvePoints))
    return Fail(
        why, "curve_positions_from_knob_m: " + std::to_string(curve_positions_from_knob_m.size()) +
                 " positions: must be at most " + std::to_string(kMaxCurvePoints));
  for (size_t i = 0; i < curve_positions_from_knob_m.size(); ++i) {
    if (!std::isfinite(curve_positions_from_knob_m[i]))
      return Fail(why, "curve_positions_from_knob_m[" + std::to_string(i) +
                           "] = " + Num(curve_positions_from_knob_m[i]) + ": must be finite");
  }
  if (!hertz.IsValid(why)) return false;
  return flexible.IsValid(why);
}

bool CollisionOptions::IsValid(std::string* why) const {
  return hertz.IsValid(why) && flexible.IsValid(why);
}

bool FlexibleOptions::IsValid(std::string* why) const {
  if (!(std::isfinite(frequency_tolerance) && frequency_tolerance >= 1e-9 &&
        frequency_tolerance <= 0.1))
    return Fail(why, "flexible.frequency_tolerance = " + Num(frequency_tolerance) +
                         ": must be in [1e-9, 0.1]");
  if (max_elements < 2 || max_elements > 4096)
    return Fail(
        why, "flexible.max_elements = " + std::to_string(max_elements) + ": must be in [2, 4096]");
  if (sting_samples < 3 || sting_samples > 1001)
    return Fail(why, "flexible.sting_samples = " + std::to_string(sting_samples) +
                         ": must be in [3, 1001]");
  if (!(std::isfinite(sting_zone_fraction) && sting_zone_fraction > 0.0 &&
        sting_zone_fraction <= 1.0))
    return Fail(
        why, "flexible.sting_zone_fraction = " + Num(sting_zone_fraction) + ": must be in (0, 1]");
  return impact.IsValid(why);
}

BeamModesOptions FlexibleOptions::VibrationModes() const {
  BeamModesOptions o;
  o.theory = theory;
  o.num_modes = 2;
  o.relative_tolerance = frequency_tolerance;
  o.max_elements = max_elements;
  return o;
}

BeamModesOptions FlexibleOptions::ImpactModes() const {
  BeamModesOptions o;
  o.theory = theory;
  o.num_modes = impact.max_modes;
  o.relative_tolerance = impact.frequency_tolerance;
  o.max_elements = max_elements;
  return o;
}

// ----------------------------------------------------------------------------- names

const char* CollisionModelName(CollisionModel model) {
  switch (model) {
    case CollisionModel::kAuto:
      return "auto";
    case CollisionModel::kRigidPivot:
      return "rigid_pivot";
    case CollisionModel::kFreeBat:
      return "free_bat";
    case CollisionModel::kHertz:
      return "hertz";
    case CollisionModel::kFlexible:
      return "flexible";
  }
  return "auto";
}

std::optional<CollisionModel> ParseCollisionModel(std::string_view name) {
  for (CollisionModel m :
       {CollisionModel::kAuto, CollisionModel::kRigidPivot, CollisionModel::kFreeBat,
        CollisionModel::kHertz, CollisionModel::kFlexible}) {
    if (name == CollisionModelName(m)) return m;
  }
  return std::nullopt;
}

std::vector<std::string> ModelsFor(SceneOutput output, CollisionModel exit_model) {
  if (exit_model == CollisionModel::kAuto) exit_model = CollisionModel::kRigidPivot;
  switch (output) {
    case SceneOutput::kCenterOfPercussion:
      return {"mass_properties"};
    case SceneOutput::kVibrationNode:
      return {kFlexibleBeamModel};
    case SceneOutput::kLeastStingZone:
      return {"mass_properties", kFlexibleBeamModel, "flexible"};
    case SceneOutput::kMaxExitSpeed:
    case SceneOutput::kSweetZone:
    case SceneOutput::kExitSpeedCurve:
      if (exit_model == CollisionModel::kFlexible) {
        return {"mass_properties", kFlexibleBeamModel, "flexible"};
      }
      return {"mass_properties", CollisionModelName(exit_model)};
  }
  return {};
}

// ----------------------------------------------------------------------------- EvaluateScene

SceneResult EvaluateScene(const Scene& scene, const SceneOptions& options) {
  const auto t0 = Clock::now();
  SceneResult out;
  Summary& s = out.summary;
  s.backend = "scene";
  s.termination = Termination::kInvalidInput;
  TimingBook book;
  auto finish = [&]() -> SceneResult& {
    out.timings = book.timings();
    s.models_used = book.Models();
    s.solve_time_s = Seconds(t0);
    return out;
  };
  try {
    std::string why;
    if (!options.IsValid(&why)) {
      s.message = why;
      return finish();
    }
    std::vector<SceneOutput> wanted;
    for (SceneOutput o : scene.outputs) {
      if (std::find(wanted.begin(), wanted.end(), o) == wanted.end()) wanted.push_back(o);
    }
    const bool needs_exit = std::any_of(wanted.begin(), wanted.end(), NeedsExitModel);
    // The flexible beam needs the bat's geometry, not only its mass properties.
    const bool flexible_exit = needs_exit && options.model == CollisionModel::kFlexible;
    if (!scene.bat.has_value()) {
      for (SceneOutput o : {SceneOutput::kVibrationNode, SceneOutput::kLeastStingZone}) {
        if (Wants(wanted, o)) {
          s.message = std::string("bat: ") + SceneOutputName(o) +
                      " needs the bat's geometry (a bat, not only mass_properties)";
          out.refused_field = "bat";
          return finish();
        }
      }
      if (flexible_exit) {
        s.message =
            "bat: model = flexible needs the bat's geometry (a bat, not only mass_properties)";
        out.refused_field = "bat";
        return finish();
      }
    }
    Resolved r;
    const bool needs_cor = std::any_of(wanted.begin(), wanted.end(), NeedsCor);
    if (!Resolve(scene, needs_cor, &book, &r, &s)) return finish();
    out.cor = r.cor;
    out.cor_source = r.cor_source;
    out.mass_properties = r.mp;
    out.length_m = r.length_m;
    for (size_t i = 0; i < options.curve_positions_from_knob_m.size(); ++i) {
      const double x = options.curve_positions_from_knob_m[i];
      if (!(x >= 0.0 && x <= r.length_m)) {
        s.termination = Termination::kInvalidInput;
        s.message = "curve_positions_from_knob_m[" + std::to_string(i) + "] = " + Num(x) +
                    ": must be within the bat [0, " + Num(r.length_m) + "]";
        return finish();
      }
    }
    CollisionModel model = options.model;
    if (model == CollisionModel::kAuto) {
      model = CollisionModel::kRigidPivot;
      out.model_reason =
          "auto: rigid_pivot, the cheapest adequate model (closed form; the swing has a fixed "
          "pivot and these outputs need only the exit speed)";
    } else {
      out.model_reason = "requested";
    }
    if (!needs_exit) out.model_reason.clear();
    s.termination = Termination::kConverged;
    std::vector<std::string> messages;
    auto note = [&](Termination t, const std::string& what) {
      s.termination = Worse(s.termination, t);
      if (!what.empty()) messages.push_back(what);
    };

    FlexibleModes flexible_modes(scene, options.flexible, &book);
    std::optional<ExitSpeedModel> exit_model;
    if (needs_exit) {
      if (model == CollisionModel::kFlexible) {
        const auto& modes = flexible_modes.Impact();
        if (!modes->summary.IsSolutionUsable()) {
          s.termination = modes->summary.termination == Termination::kInvalidInput
                              ? Termination::kInvalidInput
                              : Termination::kFailure;
          s.message = s.termination == Termination::kInvalidInput
                          ? modes->summary.message + " (model = flexible)"
                          : "model = flexible: the bat's modes: " + modes->summary.message;
          if (s.termination == Termination::kInvalidInput) out.refused_field = "bat";
          return finish();
        }
        for (const auto& w : modes->summary.warnings) s.warnings.push_back("flexible_beam: " + w);
        exit_model.emplace(model, scene, r, options.hertz, &book, &options.flexible, modes);
      } else {
        exit_model.emplace(model, scene, r, options.hertz, &book);
      }
      out.exit_speed_model = exit_model->name();
    }
    const bool closed = exit_model.has_value() && exit_model->profile().has_value() &&
                        options.method == SweetSpotMethod::kClosedForm;
    const bool need_max =
        std::find(wanted.begin(), wanted.end(), SceneOutput::kMaxExitSpeed) != wanted.end() ||
        std::find(wanted.begin(), wanted.end(), SceneOutput::kSweetZone) != wanted.end();
    if (need_max) {
      MaxExitSpeedResult mx;
      if (closed) {
        const auto tm = Clock::now();
        mx = ClosedFormMaxExitSpeed(*exit_model->profile(), r.length_m);
        mx.model = exit_model->name();
        mx.summary.solve_time_s = Seconds(tm);
        mx.summary.models_used = {exit_model->name()};
        book.Add(exit_model->name(), mx.summary.solve_time_s, 1);
      } else {
        mx = SearchMaxExitSpeed(&*exit_model, r.length_m, options.nlopt);
        mx.summary.models_used = {exit_model->name()};
      }
      for (const auto& w : mx.summary.warnings) s.warnings.push_back("max_exit_speed: " + w);
      note(mx.summary.termination,
           mx.summary.IsSolutionUsable() ? std::string() : "max_exit_speed: " + mx.summary.message);
      const bool usable = mx.summary.IsSolutionUsable();
      if (std::find(wanted.begin(), wanted.end(), SceneOutput::kMaxExitSpeed) != wanted.end()) {
        out.max_exit_speed = mx;
      }
      if (std::find(wanted.begin(), wanted.end(), SceneOutput::kSweetZone) != wanted.end()) {
        if (!usable) {
          note(Termination::kFailure, "sweet_zone: needs max_exit_speed, which failed");
        } else {
          const double tol =
              options.sweet_zone_unit == ToleranceUnit::kPercent
                  ? options.sweet_zone_tolerance / 100.0 * std::abs(mx.exit_speed_mps)
                  : options.sweet_zone_tolerance;
          if (closed) {
            const auto tz = Clock::now();
            out.sweet_zone = ClosedFormSweetZone(*exit_model->profile(), r.length_m, mx, tol);
            book.Add(exit_model->name(), Seconds(tz), 1);
          } else {
            std::string error;
            out.sweet_zone = RootFindSweetZone(&*exit_model, r.length_m, mx, tol, &error);
            out.sweet_zone->error_estimate_m += mx.error_estimate_m;
            if (!error.empty()) {
              note(Termination::kFailure, "sweet_zone: " + error);
              out.sweet_zone.reset();
            }
          }
        }
      }
    }
    if (std::find(wanted.begin(), wanted.end(), SceneOutput::kCenterOfPercussion) != wanted.end()) {
      std::string cop_why;
      auto cop = CenterOfPercussion(r.mp, scene.swing.hands_from_knob_m, r.length_m, &cop_why);
      if (!cop.has_value()) {
        // The core message first ("swing.hands_from_knob_m = ...: rule"): it names the field.
        note(Termination::kInvalidInput, cop_why + " (center_of_percussion)");
      } else {
        if (cop->placement == Placement::kBeyondTip) {
          s.warnings.push_back("center_of_percussion: beyond the tip (" +
                               Num(cop->position_from_knob_m) + " m from the knob)");
        }
        out.center_of_percussion = cop;
      }
    }
    if (Wants(wanted, SceneOutput::kVibrationNode)) {
      const auto& modes = flexible_modes.Vibration();
      VibrationNodeResult node;
      std::string error;
      if (VibrationNodeFrom(*modes, flexible_modes.vibration_hit(), &node, &error)) {
        if (modes->summary.termination == Termination::kNoConvergence) {
          note(Termination::kNoConvergence, "vibration_node: " + modes->summary.message);
        }
        out.vibration_node = std::move(node);
      } else {
        const bool invalid = modes->summary.termination == Termination::kInvalidInput;
        // Invalid input keeps the core message first ("bat.length_m = ...: rule"): it names
        // the field.
        note(invalid ? Termination::kInvalidInput : Termination::kFailure,
             invalid ? error + " (vibration_node)" : "vibration_node: " + error);
        if (invalid) out.refused_field = "bat";
      }
    }
    if (Wants(wanted, SceneOutput::kLeastStingZone)) {
      const auto& modes = flexible_modes.Impact();
      if (!modes->summary.IsSolutionUsable()) {
        const bool invalid = modes->summary.termination == Termination::kInvalidInput;
        note(invalid ? Termination::kInvalidInput : Termination::kFailure,
             invalid ? modes->summary.message + " (least_sting_zone)"
                     : "least_sting_zone: the bat's modes: " + modes->summary.message);
        if (invalid) out.refused_field = "bat";
      } else {
        LeastStingZoneResult zone;
        std::string error;
        std::vector<std::string> warnings;
        const bool ok = SweepSting(scene, r, options, *modes, &book, &warnings, &zone, &error);
        for (const auto& w : warnings) s.warnings.push_back("least_sting_zone: " + w);
        if (ok) {
          out.least_sting_zone = std::move(zone);
        } else {
          note(Termination::kFailure, "least_sting_zone: " + error);
        }
      }
    }
    if (std::find(wanted.begin(), wanted.end(), SceneOutput::kExitSpeedCurve) != wanted.end()) {
      ExitSpeedCurveResult curve;
      curve.model = exit_model->name();
      std::vector<double> xs = options.curve_positions_from_knob_m;
      if (xs.empty()) {
        const int n = options.curve_samples;
        for (int i = 0; i < n; ++i)
          xs.push_back(i + 1 == n ? r.length_m : r.length_m * i / (n - 1));
      }
      bool ok = true;
      std::string error;
      for (double x : xs) {
        double v = 0.0, e = 0.0;
        if (!exit_model->Eval(x, &v, nullptr, &e, &error)) {
          ok = false;
          break;
        }
        curve.points.push_back({x, v});
        curve.error_estimate_mps = std::max(curve.error_estimate_mps, e);
      }
      if (ok) {
        out.exit_speed_curve = std::move(curve);
      } else {
        note(Termination::kFailure, "exit_speed_curve: " + error);
      }
    }
    if (exit_model.has_value()) {
      for (const auto& w : exit_model->warnings()) s.warnings.push_back(w);
    }
    if (messages.empty()) {
      s.message = "computed";
      for (SceneOutput o : wanted) s.message += std::string(" ") + SceneOutputName(o);
    } else {
      for (size_t i = 0; i < messages.size(); ++i) s.message += (i ? "; " : "") + messages[i];
    }
    s.iterations = -1;
    double worst_err = 0.0;
    if (out.max_exit_speed) worst_err = std::max(worst_err, out.max_exit_speed->error_estimate_m);
    if (out.vibration_node) worst_err = std::max(worst_err, out.vibration_node->error_estimate_m);
    if (out.least_sting_zone) {
      worst_err = std::max(worst_err, out.least_sting_zone->error_estimate_m);
    }
    s.error_estimate = worst_err;
  } catch (const std::exception& e) {
    s.termination = Termination::kFailure;
    s.message = std::string("internal error: ") + e.what();
  } catch (...) {
    s.termination = Termination::kFailure;
    s.message = "internal error";
  }
  return finish();
}

// ----------------------------------------------------------------------------- Collide

CollisionResult Collide(const Scene& scene, double impact_from_knob_m, CollisionModel model,
                        const CollisionOptions& options) {
  const auto t0 = Clock::now();
  CollisionResult out;
  Summary& s = out.summary;
  s.termination = Termination::kInvalidInput;
  s.backend = "closed_form";
  TimingBook book;
  out.impact_from_knob_m = impact_from_knob_m;
  auto finish = [&]() -> CollisionResult& {
    out.timings = book.timings();
    s.models_used = book.Models();
    s.solve_time_s = Seconds(t0);
    return out;
  };
  try {
    std::string why;
    if (!options.IsValid(&why)) {
      s.message = why;
      return finish();
    }
    if (model == CollisionModel::kFlexible && !scene.bat.has_value()) {
      out.model = model;
      s.message =
          "bat: model = flexible needs the bat's geometry (a bat, not only mass_properties)";
      return finish();
    }
    Resolved r;
    if (!Resolve(scene, /*needs_cor=*/true, &book, &r, &s)) return finish();
    out.cor = *r.cor;
    out.mass_properties = r.mp;
    if (!(std::isfinite(impact_from_knob_m) && impact_from_knob_m >= 0.0 &&
          impact_from_knob_m <= r.length_m)) {
      s.termination = Termination::kInvalidInput;
      s.message = "impact_from_knob_m = " + Num(impact_from_knob_m) +
                  ": must be within the bat [0, " + Num(r.length_m) + "]";
      return finish();
    }
    if (model == CollisionModel::kAuto) {
      if (options.want_contact_details) {
        model = CollisionModel::kHertz;
        out.model_reason =
            "auto: hertz, the only model that knows contact time, peak force and compression";
      } else {
        model = CollisionModel::kRigidPivot;
        out.model_reason =
            "auto: rigid_pivot, the cheapest adequate model (closed form; the swing has a fixed "
            "pivot; only the exit speed and impulses were asked for)";
      }
    } else {
      out.model_reason = "requested";
    }
    out.model = model;
    const auto tm = Clock::now();
    switch (model) {
      case CollisionModel::kRigidPivot: {
        out.rigid_pivot = RigidPivotImpactAt(MakeRigidPivot(scene, r), impact_from_knob_m);
        out.exit_speed_mps = out.rigid_pivot->exit_speed_mps;
        out.approach_speed_mps = out.rigid_pivot->approach_speed_mps;
        out.error_estimate_mps = 8.0 * kEps * (scene.ball.speed_mps + std::abs(out.exit_speed_mps));
        s.termination = Termination::kConverged;
        s.message = "closed form";
        break;
      }
      case CollisionModel::kFreeBat: {
        out.free_bat = FreeBatImpactAt(MakeFreeBat(scene, r), impact_from_knob_m);
        out.exit_speed_mps = out.free_bat->exit_speed_mps;
        out.approach_speed_mps = out.free_bat->approach_speed_mps;
        out.error_estimate_mps = 8.0 * kEps * (scene.ball.speed_mps + std::abs(out.exit_speed_mps));
        s.termination = Termination::kConverged;
        s.message = "closed form";
        break;
      }
      case CollisionModel::kHertz: {
        std::vector<std::string> warnings;
        const HertzProblem p = MakeHertz(scene, r, impact_from_knob_m, options.hertz, &warnings);
        out.approach_speed_mps = p.approach_speed_mps;
        out.hertz = SolveHertzImpact(p, options.hertz.solver);
        const Summary& hs = out.hertz->summary;
        s.termination = hs.termination;
        s.message = hs.message;
        s.backend = hs.backend;
        s.iterations = hs.iterations;
        s.evaluations = hs.evaluations;
        s.warnings = warnings;
        for (const auto& w : hs.warnings) s.warnings.push_back(w);
        out.exit_speed_mps = out.hertz->exit_speed_mps;
        out.error_estimate_mps = out.hertz->error_estimate_exit_speed_mps;
        break;
      }
      case CollisionModel::kFlexible: {
        FlexibleModes flexible_modes(scene, options.flexible, &book);
        const auto& modes = flexible_modes.Impact();
        out.modes_cache_hit = flexible_modes.impact_hit();
        if (!modes->summary.IsSolutionUsable()) {
          s.termination = modes->summary.termination == Termination::kInvalidInput
                              ? Termination::kInvalidInput
                              : Termination::kFailure;
          s.message = s.termination == Termination::kInvalidInput
                          ? modes->summary.message + " (model = flexible)"
                          : "model = flexible: the bat's modes: " + modes->summary.message;
          return finish();
        }
        const auto tf = Clock::now();
        const FlexibleImpactInputs in = MakeFlexible(scene, r, impact_from_knob_m, options.hertz);
        out.approach_speed_mps = in.approach_speed_mps;
        out.flexible = SolveFlexibleImpact(*scene.bat, *modes, in, options.flexible.impact);
        const Summary& fs = out.flexible->summary;
        s.termination = fs.termination;
        if (fs.IsSolutionUsable() && modes->summary.termination == Termination::kNoConvergence) {
          s.termination = Termination::kNoConvergence;
        }
        s.message = fs.message;
        s.backend = fs.backend;
        s.iterations = fs.iterations;
        s.evaluations = fs.evaluations;
        for (const auto& w : modes->summary.warnings) s.warnings.push_back("flexible_beam: " + w);
        for (const auto& w : fs.warnings) s.warnings.push_back(w);
        out.exit_speed_mps = out.flexible->exit_speed_mps;
        out.error_estimate_mps = out.flexible->error_estimate_exit_speed_mps;
        book.Add(CollisionModelName(model), Seconds(tf), 1);
        s.objective = out.exit_speed_mps;
        s.error_estimate = out.error_estimate_mps;
        return finish();
      }
      default:
        s.termination = Termination::kFailure;
        s.message = "internal error: unknown model";
        break;
    }
    book.Add(CollisionModelName(model), Seconds(tm), 1);
    s.objective = out.exit_speed_mps;
    s.error_estimate = out.error_estimate_mps;
  } catch (const std::exception& e) {
    s.termination = Termination::kFailure;
    s.message = std::string("internal error: ") + e.what();
  } catch (...) {
    s.termination = Termination::kFailure;
    s.message = "internal error";
  }
  return finish();
}

}  // namespace sweetspot::core
