#include "core/scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

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
  double cor = 0.0;
  std::string cor_source;
};

// Validates the scene, resolves the COR, computes (or takes) the mass properties once.
bool Resolve(const Scene& scene, TimingBook* book, Resolved* r, Summary* s) {
  std::string why;
  if (!scene.IsValid(&why)) {
    s->termination = Termination::kInvalidInput;
    s->message = why;
    return false;
  }
  if (scene.cor.has_value()) {
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
  in.cor = r.cor;
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
  in.cor = r.cor;
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
  p.cor = r.cor;
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

// The exit speed along the bat under one model; closed-form models carry their profile.
class ExitSpeedModel {
 public:
  ExitSpeedModel(CollisionModel model, const Scene& scene, const Resolved& r,
                 const HertzOptions& hertz, TimingBook* book)
      : model_(model), scene_(scene), r_(r), hertz_(hertz), book_(book) {
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

}  // namespace

// ----------------------------------------------------------------------------- validation

bool Ball::IsValid(std::string* why) const {
  if (!(std::isfinite(mass_kg) && mass_kg > 0.0))
    return Fail(why, "ball.mass_kg = " + Num(mass_kg) + ": must be finite and > 0");
  if (!(std::isfinite(radius_m) && radius_m > 0.0))
    return Fail(why, "ball.radius_m = " + Num(radius_m) + ": must be finite and > 0");
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
  return hertz.IsValid(why);
}

bool CollisionOptions::IsValid(std::string* why) const { return hertz.IsValid(why); }

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
    case SceneOutput::kMaxExitSpeed:
    case SceneOutput::kSweetZone:
    case SceneOutput::kExitSpeedCurve:
      if (exit_model == CollisionModel::kFlexible) return {kFlexibleBeamModel};
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
    // Refusals for models that do not exist yet come first: nothing else runs.
    if (std::find(wanted.begin(), wanted.end(), SceneOutput::kVibrationNode) != wanted.end()) {
      s.message = kVibrationNodeRefusal;
      out.missing_model = kFlexibleBeamModel;
      out.refused_field = "outputs";
      return finish();
    }
    if (needs_exit && options.model == CollisionModel::kFlexible) {
      s.message = "model = flexible: needs the flexible beam model, which is not available yet";
      out.missing_model = kFlexibleBeamModel;
      out.refused_field = "model";
      return finish();
    }
    Resolved r;
    if (!Resolve(scene, &book, &r, &s)) return finish();
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

    std::optional<ExitSpeedModel> exit_model;
    if (needs_exit) {
      exit_model.emplace(model, scene, r, options.hertz, &book);
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
        note(Termination::kInvalidInput, "center_of_percussion: " + cop_why);
      } else {
        if (cop->placement == Placement::kBeyondTip) {
          s.warnings.push_back("center_of_percussion: beyond the tip (" +
                               Num(cop->position_from_knob_m) + " m from the knob)");
        }
        out.center_of_percussion = cop;
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
    if (model == CollisionModel::kFlexible) {
      out.model = model;
      s.message = "model = flexible: needs the flexible beam model, which is not available yet";
      out.missing_model = kFlexibleBeamModel;
      return finish();
    }
    Resolved r;
    if (!Resolve(scene, &book, &r, &s)) return finish();
    out.cor = r.cor;
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
