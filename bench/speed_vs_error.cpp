// sweetspot-speed-vs-error: the speed-versus-error report.
//
//   sweetspot-speed-vs-error [--out-dir DIR] [--command TEXT] [--quick] [--strict]
//
// For one fixed scene (the "paper-wood" preset with the defaults of core::Ball and core::Swing:
// the paper's Table 3 kinematics; impacts at kImpactFromKnobM) and for every model and numeric
// setting the service offers, measures the wall time of one evaluation through core's public
// entry points (ComputeMassProperties, EvaluateScene, Collide, OptimizeDesign: what a request
// runs) and its error against a reference: the closed form where one exists, otherwise the same
// model run at much tighter settings. Writes DIR/speed-vs-error.json (the data), .md (tables
// and how to choose) and .svg (time against relative error, log-log). scripts/speed-vs-error.sh
// builds this program (Release) and runs it into docs/.
//
// Timing (TimePerEvaluation): std::chrono::steady_clock wall time; one warm-up call, a
// calibration that sets the batch size n so one batch lasts >= 10 ms, then batches of n calls
// until there are >= 7 batches and >= 100 ms in total; the time per evaluation is the median over
// the batches of (batch time / n). The thread's CPU time is measured alongside (less sensitive
// to other processes on a shared machine). --quick shortens all of that (a smoke run, numbers
// noisy).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <sched.h>
#include <time.h>

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/collision/barrel.hpp"
#include "core/flight/flight.hpp"
#include "core/numerics/nlopt_search.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/version.hpp"

#ifndef SWEETSPOT_BUILD_TYPE
#define SWEETSPOT_BUILD_TYPE "unknown"
#endif

namespace sweetspot::bench {
namespace {

using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

/// The preset every row uses.
constexpr char kPreset[] = "paper-wood";
/// Impact position of the collision rows (hertz, flexible), m from the knob.
constexpr double kImpactFromKnobM = 0.70;
/// Relative errors at or below this are "meets 1e-6" in the how-to-choose text (dimensionless).
constexpr double kTightRelative = 1e-6;
/// A looser accuracy for the how-to-choose text (dimensionless).
constexpr double kLooseRelative = 1e-3;

// ------------------------------------------------------------------------------------ timing

/// How long to time each row.
struct TimingOptions {
  double min_batch_s = 0.010;  ///< A batch lasts at least this long, s.
  double min_total_s = 0.100;  ///< All batches together last at least this long, s.
  int min_batches = 7;         ///< At least this many batches.
};

/// The measured time of one evaluation.
struct Timing {
  double per_eval_s = 0.0;      ///< Median over batches of batch time / batch size, s.
  double cpu_per_eval_s = 0.0;  ///< The same with the thread's CPU time, s.
  double min_per_eval_s = 0.0;  ///< Fastest batch, s per evaluation.
  double max_per_eval_s = 0.0;  ///< Slowest batch, s per evaluation.
  int batches = 0;              ///< Batches timed.
  long long batch_size = 0;     ///< Evaluations per batch.
};

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// CPU time of the calling thread, s.
double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Wall time of n calls, s; the thread's CPU time for them into *cpu_s (if not null).
double RunBatch(const std::function<void()>& evaluate, long long n, double* cpu_s = nullptr) {
  const double c0 = ThreadCpuSeconds();
  const auto t0 = Clock::now();
  for (long long i = 0; i < n; ++i) evaluate();
  const double wall = SecondsSince(t0);
  if (cpu_s != nullptr) *cpu_s = ThreadCpuSeconds() - c0;
  return wall;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Wall time of one call of `evaluate` (see the file comment for the method).
Timing TimePerEvaluation(const std::function<void()>& evaluate, const TimingOptions& o) {
  evaluate();  // warm-up: first-touch allocations, caches, lazy statics
  long long k = 1;
  double t = RunBatch(evaluate, k);
  while (t < 0.2 * o.min_batch_s && k < (1LL << 40)) {
    k *= 4;
    t = RunBatch(evaluate, k);
  }
  Timing out;
  out.batch_size = std::max(1LL, static_cast<long long>(std::ceil(
                                     o.min_batch_s * static_cast<double>(k) / std::max(t, 1e-12))));
  std::vector<double> per_eval, cpu_per_eval;
  double total = 0.0;
  const double size = static_cast<double>(out.batch_size);
  while (static_cast<int>(per_eval.size()) < o.min_batches || total < o.min_total_s) {
    double cpu = 0.0;
    const double dt = RunBatch(evaluate, out.batch_size, &cpu);
    per_eval.push_back(dt / size);
    cpu_per_eval.push_back(cpu / size);
    total += dt;
  }
  out.per_eval_s = Median(per_eval);
  out.cpu_per_eval_s = Median(cpu_per_eval);
  out.min_per_eval_s = *std::min_element(per_eval.begin(), per_eval.end());
  out.max_per_eval_s = *std::max_element(per_eval.begin(), per_eval.end());
  out.batches = static_cast<int>(per_eval.size());
  return out;
}

// -------------------------------------------------------------------------------- rows, models

/// One compared quantity of a row: error = |value - reference|.
struct Quantity {
  std::string name;        ///< e.g. "position_from_knob_m".
  std::string unit;        ///< e.g. "m".
  double value = 0.0;      ///< This setting's value, unit.
  double reference = 0.0;  ///< The reference's value, unit.

  double Error() const { return std::abs(value - reference); }
  double Relative() const {
    return reference != 0.0 ? Error() / std::abs(reference) : (Error() == 0.0 ? 0.0 : Error());
  }
};

/// One model at one setting.
struct Row {
  std::string model;                 ///< Series name (ModelInfo::name).
  std::string setting;               ///< Short human description of the setting.
  Json parameters = Json::object();  ///< The settings (and what they resolved to), by field.
  Timing timing;                     ///< Time per evaluation.
  std::vector<Quantity> quantities;  ///< Compared quantities; the first is the primary error.
  bool is_auto = false;              ///< The service's default setting for this model.
  std::string termination;           ///< The solve's termination ("converged", ...).

  double Error() const { return quantities.front().Error(); }
  /// The largest relative error over the quantities (dimensionless).
  double RelativeError() const {
    double worst = 0.0;
    for (const Quantity& q : quantities) worst = std::max(worst, q.Relative());
    return worst;
  }
};

/// What a series measures and against what.
struct ModelInfo {
  std::string name;          ///< Series name, e.g. "hertz_impact".
  std::string title;         ///< Heading.
  std::string what;          ///< What one evaluation is (the entry point called).
  std::string reference;     ///< The reference the errors are measured against.
  std::string auto_setting;  ///< The service's default setting, and where that is in code.
};

/// Everything the report holds.
struct Report {
  std::vector<ModelInfo> models;  ///< In output order.
  std::vector<Row> rows;          ///< In output order (grouped by model).
  Json skipped = Json::array();   ///< Settings that did not give a usable result.
};

std::string Sci(double v, int digits = 2) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*e", digits, v);
  return buffer;
}

std::string Fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

/// "1e-08" style for tolerances.
std::string Tol(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.0e", v);
  return buffer;
}

/// A duration with a unit chosen for it: "83.1 ns", "1.25 ms".
std::string Duration(double s) {
  const char* unit = "s";
  double v = s;
  if (s < 1e-6) {
    v = s * 1e9;
    unit = "ns";
  } else if (s < 1e-3) {
    v = s * 1e6;
    unit = "µs";
  } else if (s < 1.0) {
    v = s * 1e3;
    unit = "ms";
  }
  const int digits = v >= 100.0 ? 0 : v >= 10.0 ? 1 : 2;
  return Fixed(v, digits) + " " + unit;
}

core::Scene PaperScene() {
  core::Scene scene;
  scene.bat = core::FindPreset(kPreset)->bat;
  return scene;
}

void Progress(const Report& report) {
  const Row& r = report.rows.back();
  std::cerr << "  " << r.model << " | " << r.setting << " | " << Duration(r.timing.per_eval_s)
            << " | rel " << Sci(r.RelativeError()) << (r.is_auto ? " | auto" : "") << "\n";
}

void Skip(Report* report, const std::string& model, const std::string& setting,
          const core::Summary& summary) {
  report->skipped.push_back({{"model", model},
                             {"setting", setting},
                             {"termination", core::TerminationName(summary.termination)},
                             {"message", summary.message}});
  std::cerr << "  SKIPPED " << model << " | " << setting << ": " << summary.message << "\n";
}

// ------------------------------------------------------------------------------ mass properties

void MassPropertiesRows(const TimingOptions& timing, Report* report) {
  const std::string model = "mass_properties";
  report->models.push_back(
      {model, "Mass properties: inertia model",
       "one core::ComputeMassProperties(bat, inertia_model) call (exact integrals of the "
       "piecewise-linear profile; there is no quadrature setting)",
       "inertia_model = rigid_body (exact: each section's own moment included)",
       "inertia_model = rigid_body: core::Scene::inertia_model = InertiaModel::kRigidBody "
       "(core/scene/scene.hpp), request default \"rigid_body\" (api/scene_json.cpp)"});
  const core::Bat bat = core::FindPreset(kPreset)->bat;
  const core::MassProperties ref = core::ComputeMassProperties(bat, core::InertiaModel::kRigidBody);
  const core::InertiaModel default_model = core::Scene{}.inertia_model;
  for (const auto& [inertia, name, label] :
       {std::tuple{core::InertiaModel::kRigidBody, "rigid_body", "rigid_body (exact integrals)"},
        std::tuple{core::InertiaModel::kSlenderRod, "slender_rod",
                   "slender_rod (the paper's ∫ρπr²x²dx)"}}) {
    core::MassProperties r;
    Row row;
    row.model = model;
    row.setting = label;
    row.parameters = {{"inertia_model", name}};
    row.timing = TimePerEvaluation([&] { r = core::ComputeMassProperties(bat, inertia); }, timing);
    row.quantities = {
        {"moi_knob_kg_m2", "kg m^2", r.moi_knob_kg_m2, ref.moi_knob_kg_m2},
        {"moi_centroid_kg_m2", "kg m^2", r.moi_centroid_kg_m2, ref.moi_centroid_kg_m2},
        {"mass_kg", "kg", r.mass_kg, ref.mass_kg}};
    row.is_auto = inertia == default_model;
    row.termination = "converged";
    report->rows.push_back(row);
    Progress(*report);
  }
}

// ---------------------------------------------------------------------------------- sweet spots

/// max_exit_speed by EvaluateScene with `model`: the closed form (if the model has one) and the
/// NLopt search with each of `algorithms` at each x tolerance. The reference is `reference`
/// (the closed form for rigid_pivot / free_bat, a tight run otherwise).
void SweetSpotRows(const std::string& model, core::CollisionModel exit_model, bool has_closed_form,
                   const core::SceneOptions& base, const core::SceneOptions& reference_options,
                   const std::vector<std::optional<core::NloptAlgorithm>>& algorithms,
                   const std::vector<double>& x_tolerances, const std::vector<double>& ode_tols,
                   const TimingOptions& timing, Report* report) {
  const core::Scene scene = PaperScene();
  const core::SceneResult ref = core::EvaluateScene(scene, reference_options);
  if (!ref.summary.IsSolutionUsable() || !ref.max_exit_speed) {
    Skip(report, model, "reference", ref.summary);
    return;
  }
  const core::ScalarSearchOptions default_search;
  auto run = [&](const core::SceneOptions& options, const std::string& setting, Json parameters,
                 bool is_auto) {
    core::SceneResult r = core::EvaluateScene(scene, options);
    if (!r.summary.IsSolutionUsable() || !r.max_exit_speed) {
      Skip(report, model, setting, r.summary);
      return;
    }
    Row row;
    row.model = model;
    row.setting = setting;
    row.timing = TimePerEvaluation([&] { r = core::EvaluateScene(scene, options); }, timing);
    const core::MaxExitSpeedResult& m = *r.max_exit_speed;
    const core::MaxExitSpeedResult& x = *ref.max_exit_speed;
    row.quantities = {{"position_from_knob_m", "m", m.position_from_knob_m, x.position_from_knob_m},
                      {"exit_speed_mps", "m/s", m.exit_speed_mps, x.exit_speed_mps}};
    parameters["method"] = m.method;
    if (m.summary.evaluations >= 0) parameters["evaluations"] = m.summary.evaluations;
    row.parameters = std::move(parameters);
    row.is_auto = is_auto;
    row.termination = core::TerminationName(m.summary.termination);
    report->rows.push_back(row);
    Progress(*report);
  };
  if (has_closed_form) {
    core::SceneOptions o = base;
    o.model = exit_model;
    o.method = core::SweetSpotMethod::kClosedForm;
    run(o, "closed form", Json{{"method", "closed_form"}}, true);
  }
  for (const double ode_tol : ode_tols) {
    for (const auto& algorithm : algorithms) {
      for (const double xtol : x_tolerances) {
        core::SceneOptions o = base;
        o.model = exit_model;
        o.method = core::SweetSpotMethod::kNlopt;
        o.nlopt.algorithm = algorithm;
        o.nlopt.x_tolerance_m = xtol;
        std::string setting = "nlopt ";
        setting += algorithm ? core::NloptAlgorithmName(*algorithm) : "default algorithm";
        setting += ", x_tolerance_m " + Tol(xtol);
        Json parameters{{"method", "nlopt"},
                        {"nlopt.algorithm",
                         algorithm ? Json(core::NloptAlgorithmName(*algorithm)) : Json("default")},
                        {"nlopt.x_tolerance_m", xtol}};
        if (exit_model == core::CollisionModel::kHertz) {
          o.hertz.solver.relative_tolerance = ode_tol;
          o.hertz.solver.refine_check = false;
          setting += ", hertz tolerance " + Tol(ode_tol) + ", no refine check";
          parameters["hertz.relative_tolerance"] = ode_tol;
          parameters["hertz.refine_check"] = false;
        }
        // Never the default: closed-form models default to the closed form, hertz's default
        // row (its own defaults, refine check included) follows below.
        run(o, setting, parameters, false);
      }
    }
  }
  if (exit_model == core::CollisionModel::kHertz) {
    // The service's default for model = hertz: NLopt's default (derivative-free) algorithm,
    // the default x tolerance and the default contact-model solver (with its refine check).
    core::SceneOptions o = base;
    o.model = exit_model;
    run(o,
        "defaults: nlopt default algorithm, x_tolerance_m " + Tol(default_search.x_tolerance_m) +
            ", hertz tolerance " + Tol(core::HertzSolverOptions{}.relative_tolerance) +
            " with refine check",
        Json{{"nlopt.algorithm", "default"},
             {"nlopt.x_tolerance_m", default_search.x_tolerance_m},
             {"hertz.relative_tolerance", core::HertzSolverOptions{}.relative_tolerance},
             {"hertz.refine_check", core::HertzSolverOptions{}.refine_check}},
        true);
  }
}

void RigidAndFreeSweetSpotRows(const TimingOptions& timing, bool quick, Report* report) {
  const core::ScalarSearchOptions default_search;
  const std::vector<double> xtols = {1e-4, 1e-8, default_search.x_tolerance_m};
  std::vector<std::optional<core::NloptAlgorithm>> all;
  for (const core::NloptAlgorithm a : core::OfferedNloptAlgorithms()) all.push_back(a);
  if (quick) all.resize(2);
  report->models.push_back(
      {"rigid_pivot_sweet_spot", "Sweet spot (max exit speed), rigid_pivot",
       "one core::EvaluateScene with outputs = [max_exit_speed] and model = rigid_pivot (mass "
       "properties + the sweet spot), by the closed form or by the NLopt search over [0, L]",
       "the closed form (core::ClosedFormMaxExitSpeed): the rows' errors are against it",
       "method = closed_form: core::SceneOptions::method = SweetSpotMethod::kClosedForm "
       "(core/scene/scene.hpp), request default \"closed_form\" (api/scene_json.cpp); model = auto "
       "(the default) is free_bat, and rigid_pivot for the paper's bats "
       "(core::ResolveExitModel). With method = nlopt the default algorithm is "
       "LD_SLSQP and x_tolerance_m = " +
           Tol(default_search.x_tolerance_m) +
           " (core::ScalarSearchOptions, core/numerics/nlopt_search.hpp)"});
  core::SceneOptions closed;
  closed.model = core::CollisionModel::kRigidPivot;
  SweetSpotRows("rigid_pivot_sweet_spot", core::CollisionModel::kRigidPivot, true, {}, closed, all,
                xtols, {0.0}, timing, report);

  report->models.push_back(
      {"free_bat_sweet_spot", "Sweet spot (max exit speed), free_bat",
       "one core::EvaluateScene with outputs = [max_exit_speed] and model = free_bat, by the "
       "closed form or by the NLopt search",
       "the free bat's closed form (core::FreeBatProfile + ClosedFormMaxExitSpeed)",
       "method = closed_form (as for rigid_pivot: core::SceneOptions::method)"});
  closed.model = core::CollisionModel::kFreeBat;
  std::vector<std::optional<core::NloptAlgorithm>> some = {core::NloptAlgorithm::kLdSlsqp,
                                                           core::NloptAlgorithm::kLnBobyqa,
                                                           core::NloptAlgorithm::kGnDirectL};
  if (quick) some.resize(1);
  SweetSpotRows("free_bat_sweet_spot", core::CollisionModel::kFreeBat, true, {}, closed, some,
                xtols, {0.0}, timing, report);
}

void HertzSweetSpotRows(const TimingOptions& timing, bool quick, Report* report) {
  const core::ScalarSearchOptions default_search;
  const core::HertzSolverOptions default_solver;
  report->models.push_back(
      {"hertz_sweet_spot", "Sweet spot (max exit speed), hertz",
       "one core::EvaluateScene with outputs = [max_exit_speed] and model = hertz: the NLopt "
       "search (no closed form), each evaluation an ODE solve of the contact",
       "the same search (LN_BOBYQA, x_tolerance_m 1e-12) with the contact solved at relative "
       "tolerance 1e-12 without refine check. The maximum is flat (the speed changes with the "
       "square of the distance to it), so a speed error δ moves the position by ~√(2δ/|v''|), "
       "v'' the curvature of the exit-speed curve: position errors are large next to speed "
       "errors",
       "nlopt default algorithm (LN_BOBYQA without a derivative), x_tolerance_m = " +
           Tol(default_search.x_tolerance_m) +
           " (core::ScalarSearchOptions), hertz relative "
           "tolerance " +
           Tol(default_solver.relative_tolerance) +
           " with refine_check on (core::HertzSolverOptions, core/collision/hertz_contact.hpp)"});
  core::SceneOptions base;
  base.model = core::CollisionModel::kHertz;
  core::SceneOptions reference = base;
  reference.method = core::SweetSpotMethod::kNlopt;
  reference.nlopt.algorithm = core::NloptAlgorithm::kLnBobyqa;
  reference.hertz.solver.relative_tolerance = 1e-12;
  reference.hertz.solver.refine_check = false;
  reference.hertz.solver.max_steps = 200000;
  std::vector<std::optional<core::NloptAlgorithm>> algorithms = {core::NloptAlgorithm::kLnBobyqa,
                                                                 core::NloptAlgorithm::kLnCobyla,
                                                                 core::NloptAlgorithm::kGnDirectL};
  std::vector<double> ode_tols = {1e-4, 1e-6, 1e-8};
  if (quick) {
    algorithms.resize(1);
    ode_tols.resize(1);
  }
  SweetSpotRows("hertz_sweet_spot", core::CollisionModel::kHertz, false, base, reference,
                algorithms, {1e-4, default_search.x_tolerance_m}, ode_tols, timing, report);
}

// ------------------------------------------------------------------------------- hertz impact

void HertzImpactRows(const TimingOptions& timing, bool quick, Report* report) {
  const std::string model = "hertz_impact";
  const core::HertzSolverOptions defaults;
  report->models.push_back(
      {model, "Contact model (hertz): one impact",
       "one core::Collide(scene, " + Fixed(kImpactFromKnobM, 2) +
           " m, hertz): mass properties + the Dopri5 integration of the contact",
       "the same impact at relative tolerance 1e-12, no refine check",
       "relative_tolerance = " + Tol(defaults.relative_tolerance) +
           " with refine_check = true (a second solve at tolerance/16 for the error estimate): "
           "core::HertzSolverOptions (core/collision/hertz_contact.hpp). model = auto picks "
           "hertz only when contact details are asked for (core::CollisionOptions::"
           "want_contact_details), free_bat otherwise (rigid_pivot for the paper's bats)"});
  const core::Scene scene = PaperScene();
  core::CollisionOptions ref_o;
  ref_o.hertz.solver.relative_tolerance = 1e-12;
  ref_o.hertz.solver.refine_check = false;
  ref_o.hertz.solver.max_steps = 200000;
  const core::CollisionResult ref =
      core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kHertz, ref_o);
  if (!ref.summary.IsSolutionUsable() || !ref.hertz) {
    Skip(report, model, "reference", ref.summary);
    return;
  }
  core::CollisionOptions check_o = ref_o;
  check_o.hertz.solver.relative_tolerance = 1e-11;
  const core::CollisionResult check =
      core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kHertz, check_o);
  if (check.summary.IsSolutionUsable()) {
    report->models.back().reference += " (at 1e-11 instead the exit speed differs by " +
                                       Sci(std::abs(check.exit_speed_mps - ref.exit_speed_mps), 1) +
                                       " m/s)";
  }
  auto run = [&](const core::CollisionOptions& o, const std::string& setting, bool is_auto) {
    core::CollisionResult r =
        core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kHertz, o);
    if (!r.summary.IsSolutionUsable() || !r.hertz) {
      Skip(report, model, setting, r.summary);
      return;
    }
    Row row;
    row.model = model;
    row.setting = setting;
    row.timing = TimePerEvaluation(
        [&] { r = core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kHertz, o); },
        timing);
    row.quantities = {{"exit_speed_mps", "m/s", r.exit_speed_mps, ref.exit_speed_mps},
                      {"contact_time_s", "s", r.hertz->contact_time_s, ref.hertz->contact_time_s}};
    row.parameters = {{"hertz.relative_tolerance", o.hertz.solver.relative_tolerance},
                      {"hertz.refine_check", o.hertz.solver.refine_check},
                      {"steps", r.hertz->steps}};
    row.is_auto = is_auto;
    row.termination = core::TerminationName(r.summary.termination);
    report->rows.push_back(row);
    Progress(*report);
  };
  std::vector<double> tols = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  if (quick) tols = {1e-4, 1e-8};
  for (const double tol : tols) {
    core::CollisionOptions o;
    o.hertz.solver.relative_tolerance = tol;
    o.hertz.solver.refine_check = false;
    run(o, "relative_tolerance " + Tol(tol) + ", no refine check", false);
  }
  run(core::CollisionOptions{},
      "defaults: relative_tolerance " + Tol(defaults.relative_tolerance) + " + refine check", true);
}

// ----------------------------------------------------------------------------------- barrel

/// The hollow preset of the barrel rows and its BBCOR impact point (6 in from the tip), m.
constexpr char kHollowPreset[] = "bbcor-33-aluminium";
constexpr double kBbcorImpactFromTipM = 0.1524;

void BarrelHoopRows(const TimingOptions& timing, bool quick, Report* report) {
  const std::string model = "barrel_hoop";
  const core::Bat bat = core::FindPreset(kHollowPreset)->bat;
  const double x = bat.LengthM() - kBbcorImpactFromTipM;
  const core::BarrelWall wall = core::BarrelWallAt(bat, x);
  const core::Material& m = bat.material;
  const int ref_elements = quick ? 128 : 512;
  report->models.push_back(
      {model, "Barrel (trampoline model): the hoop frequency",
       "the n = 2 hoop frequency of " + std::string(kHollowPreset) + "'s wall " +
           Fixed(kBbcorImpactFromTipM, 4) +
           " m from the tip: the thin-ring closed form (core::BarrelWallAt, what the barrel "
           "and bbcor outputs report) or the ring finite-element model "
           "(core::RingFeHoopFrequencyHz, N frame elements, a dense generalised eigenproblem)",
       "the ring FE model with " + std::to_string(ref_elements) +
           " elements (converged in N; it keeps the ring's extensibility, which the "
           "inextensional closed form drops: their gap at this wall's h/R = " +
           Fixed(wall.thickness_m / wall.mid_radius_m, 3) + " is the closed form's error)",
       "the closed form: core::BarrelWallAt (core/collision/barrel.hpp); the FE model is the "
       "check, never run by a request"});
  const double ref =
      core::RingFeHoopFrequencyHz(m.youngs_modulus_pa, m.poissons_ratio, m.density_kg_m3,
                                  wall.mid_radius_m, wall.thickness_m, ref_elements);
  auto push = [&](Row row) {
    report->rows.push_back(std::move(row));
    Progress(*report);
  };
  {
    core::BarrelWall w;
    Row row;
    row.model = model;
    row.setting = "closed form (thin inextensional ring)";
    row.timing = TimePerEvaluation([&] { w = core::BarrelWallAt(bat, x); }, timing);
    row.quantities = {{"hoop_frequency_hz", "Hz", w.hoop_frequency_hz, ref}};
    row.parameters = {{"method", "closed_form"}};
    row.is_auto = true;
    row.termination = "converged";
    push(row);
  }
  std::vector<int> counts = {8, 16, 32, 64, 128, 256};
  if (quick) counts = {16, 64};
  for (const int n : counts) {
    double f = 0.0;
    Row row;
    row.model = model;
    row.setting = "ring FE, " + std::to_string(n) + " elements";
    row.timing = TimePerEvaluation(
        [&] {
          f = core::RingFeHoopFrequencyHz(m.youngs_modulus_pa, m.poissons_ratio, m.density_kg_m3,
                                          wall.mid_radius_m, wall.thickness_m, n);
        },
        timing);
    row.quantities = {{"hoop_frequency_hz", "Hz", f, ref}};
    row.parameters = {{"method", "ring_fe"}, {"elements", n}};
    row.termination = "converged";
    push(row);
  }
}

void BarrelTrampolineRows(const TimingOptions& timing, bool quick, Report* report) {
  const std::string model = "barrel_trampoline";
  const core::BarrelOptions defaults;
  const core::Bat bat = core::FindPreset(kHollowPreset)->bat;
  const core::BbcorProtocol protocol;
  const core::BallPreset ball = *core::FindBallPreset(protocol.ball);
  const double x = bat.LengthM() - protocol.impact_from_tip_m;
  const double z = x - protocol.pivot_from_knob_m;
  const core::MassProperties mp = core::ComputeMassProperties(bat);
  const core::BarrelWall wall = core::BarrelWallAt(bat, x);
  // The BBCOR impact of the preset (core::ComputeBbcor's problem) with the wall's modal mass.
  core::TrampolineProblem p;
  p.ball_mass_kg = ball.mass_kg;
  p.ball_stiffness = ball.stiffness;
  p.ball_exponent = ball.stiffness_exponent;
  p.surface_stiffness =
      core::BatSurfaceHertzStiffness(bat.material.youngs_modulus_pa, bat.material.poissons_ratio,
                                     ball.radius_m, wall.outer_radius_m);
  p.ball_cor = ball.cor_law.CorAt(protocol.ball_speed_mps);
  p.bat_effective_mass_kg = mp.MoiAboutKgM2(protocol.pivot_from_knob_m) / (z * z);
  p.approach_speed_mps = protocol.ball_speed_mps;
  p.barrel_stiffness_n_m = wall.stiffness_n_m;
  p.barrel_modal_mass_kg = wall.modal_mass_kg;
  p.barrel_damping_ratio = wall.damping_ratio;
  p.barrel_loss = wall.barrel_loss;
  report->models.push_back(
      {model, "Barrel (trampoline model): the integrated wall",
       "one core::TrampolineImpact: the BBCOR impact of " + std::string(kHollowPreset) +
           " (the ncaa-nfhs ball at 136 mph, 6 in from the tip, the bat pivoted 6 in from the "
           "knob) with the wall's modal mass on its spring, integrated by Dormand-Prince 5(4). "
           "The dynamic model is core's check of the quasi-static closed form "
           "(core::QuasiStaticTrampoline), which the barrel and bbcor outputs use",
       "the same impact at relative tolerance 1e-12",
       "relative_tolerance = " + Tol(defaults.relative_tolerance) +
           ": core::BarrelOptions (core/collision/barrel.hpp), the dynamic model's default; "
           "no request runs it (the outputs use the quasi-static closed form)"});
  core::BarrelOptions ref_o;
  ref_o.relative_tolerance = 1e-12;
  const core::TrampolineResult ref = core::TrampolineImpact(p, ref_o);
  if (!ref.ok) {
    core::Summary failed;
    failed.message = ref.message;
    Skip(report, model, "reference", failed);
    return;
  }
  {
    // The closed form the outputs use, for scale (not a row: a different model).
    const core::TrampolineResult qs = core::QuasiStaticTrampoline(p);
    report->models.back().reference +=
        "; the quasi-static closed form gives e_eff = " + Fixed(qs.effective_cor, 5) +
        " against the integrated " + Fixed(ref.effective_cor, 5) +
        " (a modelling difference: the wall's phase when the ball leaves, docs/models.md)";
  }
  auto run = [&](const core::BarrelOptions& o, const std::string& setting, bool is_auto) {
    core::TrampolineResult r = core::TrampolineImpact(p, o);
    if (!r.ok) {
      core::Summary failed;
      failed.message = r.message;
      Skip(report, model, setting, failed);
      return;
    }
    Row row;
    row.model = model;
    row.setting = setting;
    row.timing = TimePerEvaluation([&] { r = core::TrampolineImpact(p, o); }, timing);
    row.quantities = {{"effective_cor", "1", r.effective_cor, ref.effective_cor},
                      {"contact_time_s", "s", r.contact_time_s, ref.contact_time_s}};
    row.parameters = {{"barrel.relative_tolerance", o.relative_tolerance}, {"steps", r.steps}};
    row.is_auto = is_auto;
    row.termination = "converged";
    report->rows.push_back(row);
    Progress(*report);
  };
  std::vector<double> tols = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-9, 1e-10};
  if (quick) tols = {1e-4};
  for (const double tol : tols) {
    core::BarrelOptions o;
    o.relative_tolerance = tol;
    run(o, "relative_tolerance " + Tol(tol), false);
  }
  run(defaults, "defaults: relative_tolerance " + Tol(defaults.relative_tolerance), true);
}

// ----------------------------------------------------------------------------- flight

void FlightRows(const TimingOptions& timing, bool quick, Report* report) {
  namespace flight = core::flight;
  const std::string model = "flight";
  const flight::FlightOptions defaults;
  flight::Launch launch;
  launch.exit_speed_mps = 100.0 * flight::kMpsPerMph;
  launch.launch_angle_deg = 28.0;  // spin from the Statcast relation: 2597 rpm back, -849 side
  report->models.push_back(
      {model, "Batted-ball flight (nathan-2016)",
       "one core::flight::Fly: 100 mph at 28 degrees, the Statcast spin relation, 70 F, sea "
       "level, 50 %, 29.92 inHg, calm; Dormand-Prince 5(4), the landing as a dense-output event",
       "the same flight at relative and absolute tolerance 1e-12",
       "relative_tolerance = " + Tol(defaults.relative_tolerance) +
           ", absolute_tolerance_m = " + Tol(defaults.absolute_tolerance_m) +
           ": core::flight::FlightOptions (core/flight/flight.hpp), chosen for 0.1 ft (3 cm) of "
           "distance"});
  flight::FlightOptions ref_o;
  ref_o.relative_tolerance = 1e-12;
  ref_o.absolute_tolerance_m = 1e-12;
  const flight::FlightResult ref = flight::Fly(launch, {}, {}, ref_o);
  auto run = [&](const flight::FlightOptions& o, const std::string& setting, bool is_auto) {
    flight::FlightResult r = flight::Fly(launch, {}, {}, o);
    if (!r.Landed()) {
      core::Summary failed;
      failed.message = flight::FlightTerminationName(r.termination);
      Skip(report, model, setting, failed);
      return;
    }
    Row row;
    row.model = model;
    row.setting = setting;
    row.timing = TimePerEvaluation([&] { r = flight::Fly(launch, {}, {}, o); }, timing);
    row.quantities = {{"distance_m", "m", r.distance_m, ref.distance_m},
                      {"hang_time_s", "s", r.hang_time_s, ref.hang_time_s},
                      {"apex_m", "m", r.apex_m, ref.apex_m}};
    row.parameters = {{"options.relative_tolerance", o.relative_tolerance},
                      {"options.absolute_tolerance_m", o.absolute_tolerance_m},
                      {"steps", r.steps},
                      {"error_estimate_m", r.error_estimate_m}};
    row.is_auto = is_auto;
    row.termination = "converged";
    report->rows.push_back(row);
    Progress(*report);
  };
  std::vector<double> tols = {1e-3, 1e-4, 1e-6, 1e-7, 1e-8, 1e-10};
  if (quick) tols = {1e-4};
  for (const double tol : tols) {
    flight::FlightOptions o;
    o.relative_tolerance = tol;
    o.absolute_tolerance_m = 100.0 * tol;
    run(o, "relative_tolerance " + Tol(tol) + ", absolute_tolerance_m " + Tol(100.0 * tol), false);
  }
  run(defaults,
      "defaults: relative_tolerance " + Tol(defaults.relative_tolerance) +
          ", absolute_tolerance_m " + Tol(defaults.absolute_tolerance_m),
      true);
}

// ----------------------------------------------------------------------------- flexible modes

void FlexibleModesRows(core::BeamTheory theory, const TimingOptions& timing, bool quick,
                       Report* report) {
  const std::string theory_name = core::BeamTheoryName(theory);
  const std::string model = "flexible_modes_" + theory_name;
  const core::FlexibleOptions defaults;
  report->models.push_back(
      {model, "Bending modes and vibration node, " + theory_name,
       "one core::EvaluateScene with outputs = [vibration_node], flexible.theory = " + theory_name +
           ": the first 2 free-free modes by FE with mesh refinement until the estimated "
           "relative frequency error is below flexible.frequency_tolerance, then the nodes "
           "(no modes cache)",
       "the same at frequency_tolerance 1e-9, max_elements 4096",
       "frequency_tolerance = " + Tol(defaults.frequency_tolerance) +
           ", max_elements = " + std::to_string(defaults.max_elements) +
           ": core::FlexibleOptions (core/scene/scene.hpp); the default theory is " +
           core::BeamTheoryName(defaults.theory)});
  core::Scene scene = PaperScene();
  scene.outputs = {core::SceneOutput::kVibrationNode};
  core::SceneOptions ref_o;
  ref_o.flexible.theory = theory;
  ref_o.flexible.frequency_tolerance = 1e-9;
  ref_o.flexible.max_elements = 4096;
  const core::SceneResult ref = core::EvaluateScene(scene, ref_o);
  if (!ref.summary.IsSolutionUsable() || !ref.vibration_node) {
    Skip(report, model, "reference", ref.summary);
    return;
  }
  report->models.back().reference +=
      " (" + std::to_string(ref.vibration_node->elements) +
      " elements; its own estimated error: mode 1 " +
      Sci(ref.vibration_node->error_estimate_hz / ref.vibration_node->frequency_hz, 1) +
      " relative, node " + Sci(ref.vibration_node->error_estimate_m, 1) + " m)";
  std::vector<double> tols = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
  if (quick) tols = {1e-2, 1e-4};
  for (const double tol : tols) {
    core::SceneOptions o;
    o.flexible.theory = theory;
    o.flexible.frequency_tolerance = tol;
    const std::string setting = "frequency_tolerance " + Tol(tol);
    core::SceneResult r = core::EvaluateScene(scene, o);
    if (!r.summary.IsSolutionUsable() || !r.vibration_node) {
      Skip(report, model, setting, r.summary);
      continue;
    }
    Row row;
    row.model = model;
    row.setting = setting;
    row.timing = TimePerEvaluation([&] { r = core::EvaluateScene(scene, o); }, timing);
    const core::VibrationNodeResult& v = *r.vibration_node;
    const core::VibrationNodeResult& x = *ref.vibration_node;
    row.quantities = {
        {"node_from_knob_m", "m", v.position_from_knob_m, x.position_from_knob_m},
        {"mode_1_frequency_hz", "Hz", v.frequency_hz, x.frequency_hz},
        {"mode_2_frequency_hz", "Hz", v.second_mode_frequency_hz, x.second_mode_frequency_hz}};
    row.parameters = {{"flexible.theory", theory_name},
                      {"flexible.frequency_tolerance", tol},
                      {"elements", v.elements},
                      {"refinement_elements", v.refinement_elements}};
    row.setting += " (" + std::to_string(v.elements) + " elements)";
    row.is_auto = tol == defaults.frequency_tolerance;
    row.termination = core::TerminationName(v.summary.termination);
    report->rows.push_back(row);
    Progress(*report);
  }
}

// ---------------------------------------------------------------------------- flexible impact

void FlexibleImpactRows(const TimingOptions& timing, bool quick, Report* report) {
  const std::string model = "flexible_impact";
  const core::FlexibleImpactOptions defaults;
  report->models.push_back(
      {model, "Flexible bat (Timoshenko): one impact",
       "one core::Collide(scene, " + Fixed(kImpactFromKnobM, 2) +
           " m, flexible) without a modes cache: the modes (FE) + the modal impact integration",
       "40 modes to frequency tolerance 1e-5 (max_elements 1024), cutoff_factor 1000, "
       "integration tolerance 1e-12, no refine check",
       "max_modes = " + std::to_string(defaults.max_modes) + " to frequency_tolerance " +
           Tol(defaults.frequency_tolerance) + ", cutoff_factor " +
           Fixed(defaults.cutoff_factor, 0) + ", relative_tolerance " +
           Tol(defaults.relative_tolerance) +
           ", static_correction and refine_check on: core::FlexibleImpactOptions "
           "(core/collision/flexible_impact.hpp). The server keeps a modes cache, so a repeated "
           "request costs the \"modes cached\" row"});
  const core::Scene scene = PaperScene();
  core::CollisionOptions ref_o;
  ref_o.flexible.max_elements = 1024;
  ref_o.flexible.impact.max_modes = 40;
  ref_o.flexible.impact.frequency_tolerance = 1e-5;
  ref_o.flexible.impact.cutoff_factor = 1000.0;
  ref_o.flexible.impact.relative_tolerance = 1e-12;
  ref_o.flexible.impact.refine_check = false;
  const core::CollisionResult ref =
      core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kFlexible, ref_o);
  if (!ref.summary.IsSolutionUsable() || !ref.flexible) {
    Skip(report, model, "reference", ref.summary);
    return;
  }
  // How far the reference itself may be from the converged answer: the same with 30 modes.
  core::CollisionOptions check_o = ref_o;
  check_o.flexible.impact.max_modes = 30;
  const core::CollisionResult check =
      core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kFlexible, check_o);
  if (check.summary.IsSolutionUsable()) {
    report->models.back().reference += " (" + std::to_string(ref.flexible->elements) +
                                       " elements; with 30 modes instead the "
                                       "exit speed differs by " +
                                       Sci(std::abs(check.exit_speed_mps - ref.exit_speed_mps), 1) +
                                       " m/s: errors below that are not resolved)";
  }
  auto run = [&](const core::CollisionOptions& o, const std::string& setting, bool is_auto) {
    core::CollisionResult r =
        core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kFlexible, o);
    if (!r.summary.IsSolutionUsable() || !r.flexible) {
      Skip(report, model, setting, r.summary);
      return;
    }
    Row row;
    row.model = model;
    row.setting = setting;
    row.timing = TimePerEvaluation(
        [&] { r = core::Collide(scene, kImpactFromKnobM, core::CollisionModel::kFlexible, o); },
        timing);
    const core::FlexibleImpactResult& f = *r.flexible;
    row.quantities = {{"exit_speed_mps", "m/s", f.exit_speed_mps, ref.flexible->exit_speed_mps},
                      {"contact_time_s", "s", f.contact_time_s, ref.flexible->contact_time_s}};
    const core::FlexibleImpactOptions& i = o.flexible.impact;
    row.parameters = {{"flexible.max_modes", i.max_modes},
                      {"flexible.mode_frequency_tolerance", i.frequency_tolerance},
                      {"flexible.cutoff_factor", i.cutoff_factor},
                      {"flexible.relative_tolerance", i.relative_tolerance},
                      {"flexible.static_correction", i.static_correction},
                      {"flexible.refine_check", i.refine_check},
                      {"modes_cached", o.flexible.modes_cache != nullptr},
                      {"modes_used", f.modes_used},
                      {"elements", f.elements}};
    row.is_auto = is_auto;
    row.termination = core::TerminationName(r.summary.termination);
    report->rows.push_back(row);
    Progress(*report);
  };
  std::vector<int> counts = {1, 2, 4, 8, 12, 16, 24};
  if (quick) counts = {2, 12};
  for (const int n : counts) {
    core::CollisionOptions o;
    o.flexible.impact.max_modes = n;
    o.flexible.impact.cutoff_factor = 1000.0;
    o.flexible.impact.refine_check = false;
    run(o, std::to_string(n) + (n == 1 ? " mode" : " modes") + ", no refine check", false);
  }
  for (const int n : {4, 12}) {
    if (quick) break;
    core::CollisionOptions o;
    o.flexible.impact.max_modes = n;
    o.flexible.impact.cutoff_factor = 1000.0;
    o.flexible.impact.refine_check = false;
    o.flexible.impact.static_correction = false;
    run(o, std::to_string(n) + " modes, no static correction, no refine check", false);
  }
  for (const double tol : {1e-4, 1e-6}) {
    if (quick) break;
    core::CollisionOptions o;
    o.flexible.impact.relative_tolerance = tol;
    o.flexible.impact.refine_check = false;
    run(o, "12 modes, relative_tolerance " + Tol(tol) + ", no refine check", false);
  }
  const std::string defaults_text = "defaults: " + std::to_string(defaults.max_modes) +
                                    " modes, relative_tolerance " +
                                    Tol(defaults.relative_tolerance) + " + refine check";
  run(core::CollisionOptions{}, defaults_text, true);
  core::ModesCache cache;
  core::CollisionOptions cached;
  cached.flexible.modes_cache = &cache;
  run(cached, defaults_text + ", modes cached (as in the server)", false);
}

// ---------------------------------------------------------------------------------- design

/// The paper-wood bat resampled on `n` evenly spaced knots (same material).
core::Bat KnotPaperWood(int n) {
  const core::Bat base = core::FindPreset(kPreset)->bat;
  core::Bat bat;
  bat.material = base.material;
  const double length = base.LengthM();
  for (int i = 0; i < n; ++i) {
    const double x = length * i / (n - 1);
    bat.knots.push_back({x, base.RadiusAtM(std::min(x, length))});
  }
  return bat;
}

/// Max exit speed over the radii of the inner knots 1..n-2 at the base mass, balance point
/// <= 0.60 m, diameters within the paper bat's (handle 0.025 m, barrel 0.07 m), non-decreasing
/// taper.
core::DesignProblem KnotProblem(int n) {
  core::DesignProblem p;
  p.bat = KnotPaperWood(n);
  for (int i = 1; i <= n - 2; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.0110, 0.0350});
  }
  p.constraints.mass_kg = core::DesignRange::Equal(core::ComputeMassProperties(p.bat).mass_kg);
  p.constraints.balance_point_m = core::DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = 0.070;
  p.constraints.min_handle_diameter_m = 0.025;
  p.constraints.taper = core::TaperRule::kNonDecreasing;
  return p;
}

/// The largest |x - x*| over the variables of two answers to the same problem, m.
double DesignDistanceM(const core::DesignResult& a, const core::DesignResult& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.variables.size() && i < b.variables.size(); ++i) {
    worst = std::max(worst, std::abs(a.variables[i].value - b.variables[i].value));
  }
  return worst;
}

/// The design model's name at `knots` knots.
std::string DesignModelName(int knots) { return "design_" + std::to_string(knots) + "_knots"; }

/// Rows of one design problem (KnotProblem(knots)): the request's default (the optimiser's
/// chosen backend), Ipopt on the lifted formulation (exact sparse Hessian) at three tolerances,
/// Ipopt on the dense formulation with its default limited-memory Hessian, and NLopt SLSQP
/// where it is allowed (at most 32 variables). The reference is a certified Ipopt solve at
/// tolerance 1e-12; error = the objective's difference, and each row states the design's
/// distance to the reference's (the largest |x - x*|, m) and whether its certificate held.
void DesignRowsAt(int knots, const TimingOptions& timing, bool quick, Report* report) {
  const std::string model = DesignModelName(knots);
  const core::DesignOptions defaults;
  core::DesignOptions request_default;  // What /v1/optimize sets without "backend"/"hessian".
  request_default.choose_backend = true;
  report->models.push_back(
      {model, "Design optimisation, " + std::to_string(knots) + " knots",
       "one core::OptimizeDesign: max exit speed over the radii of the " +
           std::to_string(knots - 2) + " inner knots of the paper-wood bat resampled on " +
           std::to_string(knots) +
           " knots, at its mass, balance point <= 0.60 m, diameters within [0.025, 0.07] m, "
           "non-decreasing taper (one start)",
       "Ipopt with the exact Hessian at tolerance 1e-12, certified (its first-order conditions "
       "checked by the service); error = the objective's (max exit speed's) difference, and "
       "distance_to_optimum_m = the largest difference of a variable",
       "the request's default: the optimiser chooses the backend (NLopt SLSQP up to " +
           std::to_string(24) +
           " variables when its answer is certified, else Ipopt on the lifted formulation), "
           "tolerance " +
           Tol(defaults.tolerance) +
           ": core::DesignOptions::choose_backend (core/optimize/backend_choice.hpp), set by "
           "api/handlers/optimize.cpp"});
  const core::DesignProblem problem = KnotProblem(knots);
  core::DesignOptions ref_o;
  ref_o.hessian = core::HessianMode::kExact;
  ref_o.tolerance = 1e-12;
  ref_o.max_iterations = 3000;
  ref_o.max_time_s = 60.0;
  const core::DesignResult ref = core::OptimizeDesign(problem, ref_o);
  if (!ref.summary.IsSolutionUsable()) {
    Skip(report, model, "reference", ref.summary);
    return;
  }
  report->models.back().reference +=
      " (" + std::string(core::TerminationName(ref.summary.termination)) + ", " +
      std::to_string(ref.summary.iterations) + " iterations, objective " +
      Fixed(ref.objective_value, 9) + " m/s, certified " +
      (ref.certificate.certified ? "yes" : "no") + ")";
  auto run = [&](const core::DesignOptions& o, const std::string& setting, bool is_auto) {
    core::DesignResult r = core::OptimizeDesign(problem, o);
    if (!r.summary.IsSolutionUsable()) {
      Skip(report, model, setting, r.summary);
      return;
    }
    Row row;
    row.model = model;
    row.setting = setting;
    row.timing = TimePerEvaluation([&] { r = core::OptimizeDesign(problem, o); }, timing);
    row.quantities = {
        {"objective_mps", "m/s", r.objective_value, ref.objective_value},
        {"sweet_spot_from_knob_m", "m", r.sweet_spot_from_knob_m, ref.sweet_spot_from_knob_m}};
    row.parameters = {
        {"backend", r.summary.backend},
        {"hessian", o.hessian == core::HessianMode::kExact || o.lift ? "exact" : "limited_memory"},
        {"lifted", o.lift},
        {"tolerance", o.tolerance},
        {"iterations", r.summary.iterations},
        {"evaluations", r.summary.evaluations},
        {"distance_to_optimum_m", DesignDistanceM(r, ref)},
        {"certified", r.certificate.certified}};
    row.is_auto = is_auto;
    row.termination = core::TerminationName(r.summary.termination);
    report->rows.push_back(row);
    Progress(*report);
  };
  run(request_default, "default (chosen backend), tolerance " + Tol(defaults.tolerance), true);
  std::vector<double> tols = {1e-3, 1e-6, defaults.tolerance};
  if (quick) tols = {defaults.tolerance};
  for (const double tol : tols) {
    core::DesignOptions o;
    o.tolerance = tol;
    run(o, "ipopt, lifted (exact sparse Hessian), tolerance " + Tol(tol), false);
  }
  if (quick) return;
  core::DesignOptions radii;  // the lifted formulation over the radii, not the taper's steps
  radii.taper_steps = false;
  run(radii, "ipopt, lifted over the knot radii (no taper steps), tolerance " +
                 Tol(radii.tolerance),
      false);
  core::DesignOptions dense;
  dense.lift = false;
  run(dense, "ipopt, dense, limited-memory Hessian, tolerance " + Tol(dense.tolerance), false);
  if (knots - 2 <= 32) {
    core::DesignOptions o;
    o.backend = core::DesignBackend::kNloptSlsqp;
    run(o, "nlopt LD_SLSQP backend, tolerance " + Tol(o.tolerance), false);
  }
}

void DesignRows(const TimingOptions& timing, bool quick, Report* report) {
  DesignRowsAt(16, timing, quick, report);
  if (!quick) DesignRowsAt(64, timing, quick, report);
}

// -------------------------------------------------------------------------------- machine

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        std::string v = line.substr(colon + 1);
        v.erase(0, v.find_first_not_of(' '));
        return v;
      }
    }
  }
  return "unknown";
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double one = 0.0, five = 0.0, fifteen = 0.0;
  if (in >> one >> five >> fifteen) {
    return Fixed(one, 2) + ", " + Fixed(five, 2) + ", " + Fixed(fifteen, 2);
  }
  return "unknown";
}

/// What `nproc` prints: the CPUs this process may run on.
int ProcessorCount() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) return CPU_COUNT(&set);
  return static_cast<int>(std::thread::hardware_concurrency());
}

double D(const Json& j) { return j.get<double>(); }

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buffer;
}

Json Metadata(const std::string& command, const TimingOptions& timing, bool quick,
              double run_time_s, const std::string& load_before) {
  const core::Scene scene = PaperScene();
  const core::MassProperties mp = core::ComputeMassProperties(*scene.bat);
  Json m;
  m["generated"] = UtcNow();
  m["command"] = command;
  m["sweetspot_version"] = core::SweetspotVersion();
  m["libraries"] = {{"eigen", core::EigenVersion()},
                    {"nlopt", core::NloptVersion()},
                    {"ipopt", core::IpoptVersion()}};
  m["compiler"] = __VERSION__;
  m["build_type"] = SWEETSPOT_BUILD_TYPE;
  m["machine"] = {{"cpu_model", CpuModel()},
                  {"nproc", ProcessorCount()},
                  {"load_average_at_start", load_before}};
  m["scene"] = {
      {"preset", kPreset},
      {"length_m", scene.bat->LengthM()},
      {"mass_kg", mp.mass_kg},
      {"balance_point_m", mp.balance_point_m},
      {"cor", scene.bat->material.cor.value_or(std::nan(""))},
      {"ball_mass_kg", scene.ball.mass_kg},
      {"ball_speed_mps", scene.ball.speed_mps},
      {"angular_speed_rad_s", scene.swing.angular_speed_rad_s},
      {"pivot_from_knob_m", scene.swing.pivot_from_knob_m},
      {"hands_from_knob_m", scene.swing.hands_from_knob_m},
      {"impact_from_knob_m", kImpactFromKnobM},
  };
  m["timing_method"] =
      "wall time (std::chrono::steady_clock) of one call of the entry point named per model; "
      "one warm-up call, then batches of n calls (n set so a batch lasts >= " +
      Duration(timing.min_batch_s) + ") until >= " + std::to_string(timing.min_batches) +
      " batches and >= " + Duration(timing.min_total_s) +
      " in total; time_per_eval_s is the median over batches of batch time / n (single thread; "
      "cpu_time_per_eval_s: the same with the thread's CPU time, less sensitive to other load).";
  m["error_method"] =
      "error = |value - reference| of the model's primary quantity (error_unit); relative_error "
      "= the largest |value - reference| / |reference| over the quantities listed in errors. "
      "An error of exactly 0 means bit-identical to the reference.";
  m["quick"] = quick;
  m["run_time_s"] = run_time_s;
  return m;
}

// -------------------------------------------------------------------------------- outputs

Json ToJson(const Report& report, const Json& metadata) {
  Json out;
  out["metadata"] = metadata;
  out["models"] = Json::array();
  for (const ModelInfo& m : report.models) {
    out["models"].push_back({{"name", m.name},
                             {"title", m.title},
                             {"evaluation", m.what},
                             {"reference", m.reference},
                             {"auto_setting", m.auto_setting}});
  }
  out["rows"] = Json::array();
  for (const Row& r : report.rows) {
    Json errors = Json::object();
    for (const Quantity& q : r.quantities) {
      errors[q.name] = {{"value", q.value},
                        {"reference", q.reference},
                        {"error", q.Error()},
                        {"unit", q.unit},
                        {"relative_error", q.Relative()}};
    }
    const ModelInfo* info = nullptr;
    for (const ModelInfo& m : report.models) {
      if (m.name == r.model) info = &m;
    }
    out["rows"].push_back(
        {{"model", r.model},
         {"setting", r.setting},
         {"parameters", r.parameters},
         {"time_per_eval_s", r.timing.per_eval_s},
         {"cpu_time_per_eval_s", r.timing.cpu_per_eval_s},
         {"time_spread_s", {{"min", r.timing.min_per_eval_s}, {"max", r.timing.max_per_eval_s}}},
         {"batches", r.timing.batches},
         {"batch_size", r.timing.batch_size},
         {"error", r.Error()},
         {"error_unit", r.quantities.front().unit},
         {"error_quantity", r.quantities.front().name},
         {"relative_error", r.RelativeError()},
         {"errors", errors},
         {"reference", info != nullptr ? info->reference : ""},
         {"termination", r.termination},
         {"is_auto", r.is_auto}});
  }
  out["skipped"] = report.skipped;
  return out;
}

std::vector<const Row*> RowsOf(const Report& report, const std::string& model) {
  std::vector<const Row*> out;
  for (const Row& r : report.rows) {
    if (r.model == model) out.push_back(&r);
  }
  return out;
}

/// The fastest row within max_relative, among fresh computations (rows with cached modes are
/// not comparable with them); nullptr if none.
const Row* Cheapest(const std::vector<const Row*>& rows, double max_relative) {
  const Row* best = nullptr;
  for (const Row* r : rows) {
    if (r->parameters.value("modes_cached", false)) continue;
    if (r->RelativeError() <= max_relative &&
        (best == nullptr || r->timing.per_eval_s < best->timing.per_eval_s)) {
      best = r;
    }
  }
  return best;
}

std::string ErrorText(double e) { return e == 0.0 ? "0" : Sci(e, 1); }

/// What a row's solve did: evaluations, ODE steps, elements, modes, iterations (when known).
std::string Work(const Row& r) {
  std::string out;
  for (const char* key : {"evaluations", "iterations", "steps", "elements", "modes_used"}) {
    if (r.parameters.contains(key) && r.parameters[key].is_number()) {
      out += (out.empty() ? "" : ", ") + std::string(key) + " " + r.parameters[key].dump();
    }
  }
  return out;
}

/// The row of `model` whose setting starts with `prefix` (nullptr if none).
const Row* FindRow(const Report& report, const std::string& model, const std::string& prefix) {
  for (const Row& r : report.rows) {
    if (r.model == model && r.setting.rfind(prefix, 0) == 0) return &r;
  }
  return nullptr;
}

/// "83.1 ns" for the row's time, "?" when the row is missing (e.g. --quick).
std::string TimeOf(const Row* r) { return r == nullptr ? "?" : Duration(r->timing.per_eval_s); }
/// The row's primary error with its unit, "?" when missing.
std::string ErrorOf(const Row* r) {
  return r == nullptr ? "?" : ErrorText(r->Error()) + " " + r->quantities.front().unit;
}
/// a's time / b's time as "2.3×", "?" when either is missing.
std::string Ratio(const Row* a, const Row* b) {
  return a == nullptr || b == nullptr ? "?"
                                      : Fixed(a->timing.per_eval_s / b->timing.per_eval_s, 1) + "×";
}

/// The how-to-choose bullets, every figure taken from the rows.
std::string HowToChoose(const Report& report) {
  std::ostringstream md;
  const core::ScalarSearchOptions search;
  const std::string slsqp = "nlopt LD_SLSQP, x_tolerance_m " + Tol(search.x_tolerance_m);
  const Row* closed = FindRow(report, "rigid_pivot_sweet_spot", "closed form");
  const Row* nlopt = FindRow(report, "rigid_pivot_sweet_spot", slsqp);
  double global_min = std::numeric_limits<double>::infinity(), global_max = 0.0;
  for (const Row& r : report.rows) {
    if (r.model == "rigid_pivot_sweet_spot" && r.setting.rfind("nlopt GN_", 0) == 0) {
      global_min = std::min(global_min, r.timing.per_eval_s);
      global_max = std::max(global_max, r.timing.per_eval_s);
    }
  }
  md << "* **Rigid models** (`rigid_pivot`, `free_bat`): keep the closed form (auto, "
     << TimeOf(closed) << " for mass properties + sweet spot). The NLopt search is an "
     << "independent check: with its defaults (" << slsqp << ") it takes " << TimeOf(nlopt) << " ("
     << Ratio(nlopt, closed) << ") and lands within " << ErrorOf(nlopt) << " of the closed form";
  if (global_max > 0.0) {
    md << "; the global algorithms (GN_*) take " << Duration(global_min) << "–"
       << Duration(global_max);
  }
  md << ".\n";
  const Row* h_auto = FindRow(report, "hertz_impact", "defaults");
  const Row* h_8 = FindRow(report, "hertz_impact", "relative_tolerance 1e-08");
  const Row* h_6 = FindRow(report, "hertz_impact", "relative_tolerance 1e-06");
  const Row* h_2 = FindRow(report, "hertz_impact", "relative_tolerance 1e-02");
  md << "* **Contact model** (`hertz`): below 1e-4 the exit speed's error follows the "
        "integration tolerance (1e-6: "
     << ErrorOf(h_6) << ", 1e-8: " << ErrorOf(h_8)
     << "); at looser tolerances the step bound, not the tolerance, sets it (1e-2: " << ErrorOf(h_2)
     << "). The default's refine check (a second solve at tolerance/16) costs "
     << Ratio(h_auto, h_8) << " (" << TimeOf(h_auto) << " against " << TimeOf(h_8)
     << ") and buys an error estimate, not accuracy. `model = auto` runs `free_bat` "
        "(`rigid_pivot` for the paper's bats) unless contact details are asked for.\n";
  const Row* hs_auto = FindRow(report, "hertz_sweet_spot", "defaults");
  md << "* **Sweet spot with `hertz`**: NLopt over ODE solves, " << TimeOf(hs_auto)
     << " with the defaults; the exit speed is flat at the maximum, so the position is "
        "resolved far worse than the speed (see its table).\n";
  const Row* m_auto = FindRow(report, "flexible_modes_timoshenko", "frequency_tolerance 1e-04");
  const Row* m_6 = FindRow(report, "flexible_modes_timoshenko", "frequency_tolerance 1e-06");
  const Row* eb_auto =
      FindRow(report, "flexible_modes_euler_bernoulli", "frequency_tolerance 1e-04");
  md << "* **Bending modes** (`vibration_node`: 2 modes; `/v1/bat/modes` computes 4 with the "
        "same default tolerance): the default 1e-4 places the node within "
     << ErrorOf(m_auto) << " of the reference in " << TimeOf(m_auto) << "; 1e-6 gives "
     << ErrorOf(m_6) << " in " << TimeOf(m_6)
     << ". Euler–Bernoulli at the default: " << TimeOf(eb_auto) << " against " << TimeOf(m_auto)
     << " for Timoshenko";
  if (m_auto != nullptr && eb_auto != nullptr) {
    const double f_ti = m_auto->quantities[1].reference, f_eb = eb_auto->quantities[1].reference;
    md << "; but the two theories' converged fundamentals differ by "
       << Sci(std::abs(f_eb - f_ti) / f_ti, 1)
       << " relative, far more than either's discretisation error: the theory is a modelling "
          "choice, not a numeric setting";
  }
  md << ".\n";
  const Row* f4 = FindRow(report, "flexible_impact", "4 modes, no refine");
  const Row* f8 = FindRow(report, "flexible_impact", "8 modes, no refine");
  const Row* f12 = FindRow(report, "flexible_impact", "12 modes, no refine");
  const Row* f24 = FindRow(report, "flexible_impact", "24 modes, no refine");
  const Row* f12u = FindRow(report, "flexible_impact", "12 modes, no static");
  const Row* f_auto = nullptr;
  const Row* f_cached = nullptr;
  for (const Row& r : report.rows) {
    if (r.model != "flexible_impact") continue;
    if (r.is_auto) f_auto = &r;
    if (r.parameters.value("modes_cached", false)) f_cached = &r;
  }
  md << "* **Flexible impact**: the number of modes sets the error: 4 / 8 / 12 / 24 modes give "
     << ErrorOf(f4) << " / " << ErrorOf(f8) << " / " << ErrorOf(f12) << " / " << ErrorOf(f24)
     << " in " << TimeOf(f4) << " / " << TimeOf(f8) << " / " << TimeOf(f12) << " / " << TimeOf(f24)
     << " (the static correction matters: 12 modes without it, " << ErrorOf(f12u)
     << "). Computing the modes is most of a fresh call: the default costs " << TimeOf(f_auto)
     << " fresh and " << TimeOf(f_cached) << " with the modes cached, as the server does "
     << "for a repeated bat.\n";
  for (const int knots : {16, 64}) {
    const std::string name = DesignModelName(knots);
    const std::string tol = Tol(core::DesignOptions{}.tolerance);
    const Row* d_auto = FindRow(report, name, "default (chosen backend)");
    const Row* d_lifted =
        FindRow(report, name, "ipopt, lifted (exact sparse Hessian), tolerance " + tol);
    const Row* d_loose =
        FindRow(report, name, "ipopt, lifted (exact sparse Hessian), tolerance 1e-03");
    const Row* d_radii = FindRow(report, name, "ipopt, lifted over the knot radii");
    const Row* d_dense = FindRow(report, name, "ipopt, dense, limited-memory Hessian");
    if (d_auto == nullptr) continue;  // Not run (--quick runs 16 knots only).
    auto distance = [](const Row* r) -> std::string {
      if (r == nullptr) return "n/a";
      std::ostringstream o;
      o << std::setprecision(2) << std::scientific
        << r->parameters.value("distance_to_optimum_m", 0.0) << " m";
      return o.str();
    };
    md << "* **Design** (" << knots << " knots): the request's default ("
       << (d_auto ? d_auto->parameters.value("backend", std::string("?")) : std::string("?"))
       << ") took " << TimeOf(d_auto) << ", " << ErrorOf(d_auto) << " from the certified "
       << "optimum's objective, its design " << distance(d_auto) << " from it; Ipopt on the "
       << "lifted formulation " << TimeOf(d_lifted) << " (" << ErrorOf(d_lifted) << ", "
       << distance(d_lifted) << "), at tolerance 1e-3 " << TimeOf(d_loose) << " ("
       << ErrorOf(d_loose) << ", " << distance(d_loose) << "); over the knot radii instead of "
       << "the taper's steps " << TimeOf(d_radii) << " (" << ErrorOf(d_radii) << ", "
       << distance(d_radii) << "); the dense formulation with its "
       << "limited-memory Hessian " << TimeOf(d_dense) << " (" << ErrorOf(d_dense) << ", "
       << distance(d_dense) << ").\n";
  }
  const Row* hoop = FindRow(report, "barrel_hoop", "closed form");
  const Row* hoop_fe = FindRow(report, "barrel_hoop", "ring FE, 64 elements");
  const Row* tr_auto = FindRow(report, "barrel_trampoline", "defaults");
  const Row* tr_6 = FindRow(report, "barrel_trampoline", "relative_tolerance 1e-06");
  md << "* **Barrel** (`barrel`, `bbcor` outputs of a hollow bat): the hoop frequency's closed "
        "form takes "
     << TimeOf(hoop) << " and differs from the converged ring FE model by " << ErrorOf(hoop)
     << " (the inextensional ring's modelling error, not a numeric one); the FE model with 64 "
        "elements takes "
     << TimeOf(hoop_fe) << " (" << Ratio(hoop_fe, hoop)
     << "), a check only. The integrated trampoline (core's check of the quasi-static closed "
        "form the outputs use) at its default tolerance takes "
     << TimeOf(tr_auto) << " within " << (tr_auto ? ErrorText(tr_auto->Error()) : "?")
     << " of the reference COR; 1e-6: " << TimeOf(tr_6) << ", "
     << (tr_6 ? ErrorText(tr_6->Error()) : "?") << ".\n";
  const Row* fl_auto = FindRow(report, "flight", "defaults");
  const Row* fl_3 = FindRow(report, "flight", "relative_tolerance 1e-03");
  const Row* fl_8 = FindRow(report, "flight", "relative_tolerance 1e-08");
  md << "* **Flight** (`/v1/flight`, `nathan-2016`): the default tolerance lands within "
     << (fl_auto ? ErrorText(fl_auto->Error()) : "?") << " m of the reference distance in "
     << TimeOf(fl_auto) << " (the target is 0.1 ft, 0.03 m); 1e-3: " << TimeOf(fl_3) << ", "
     << (fl_3 ? ErrorText(fl_3->Error()) : "?") << " m; 1e-8: " << TimeOf(fl_8) << ", "
     << (fl_8 ? ErrorText(fl_8->Error()) : "?")
     << " m. The model's own difference from Nathan's sheet (its 0.01 s steps) is 0.7 ft, "
        "far above any of these (docs/validation.md).\n";
  return md.str();
}

std::string Markdown(const Report& report, const Json& metadata) {
  std::ostringstream md;
  const Json& scene = metadata["scene"];
  md << "# Speed against error\n\n"
     << "Generated by `" << metadata["command"].get<std::string>() << "` ("
     << "`bench/speed_vs_error.cpp`) on " << metadata["generated"].get<std::string>()
     << ": do not edit by hand. The same data: [speed-vs-error.json](speed-vs-error.json) and "
        "`GET /v1/speed-vs-error`; the plot: [speed-vs-error.svg](speed-vs-error.svg).\n\n"
     << "For every model and numeric setting the service offers: the time of one evaluation "
        "against its error relative to a reference (the closed form where one exists, otherwise "
        "the same model at much tighter settings), so you can pick the cheapest setting for the "
        "accuracy you need. **auto** marks the setting the service uses when a request leaves "
        "it at its default.\n\n"
     << "* **Scene**: preset `" << kPreset << "` (L = " << Fixed(D(scene["length_m"]), 3)
     << " m, M = " << Fixed(D(scene["mass_kg"]), 4) << " kg, balance point "
     << Fixed(D(scene["balance_point_m"]), 4) << " m, COR " << Fixed(D(scene["cor"]), 2)
     << " from the material), the defaults of `core::Ball` and `core::Swing` (the paper's "
        "Table 3): ball "
     << Fixed(D(scene["ball_mass_kg"]), 3) << " kg at " << Fixed(D(scene["ball_speed_mps"]), 1)
     << " m/s, bat " << Fixed(D(scene["angular_speed_rad_s"]), 3) << " rad/s about a pivot "
     << Fixed(D(scene["pivot_from_knob_m"]), 3) << " m from the knob, hands at "
     << Fixed(D(scene["hands_from_knob_m"]), 4) << " m; impacts at "
     << Fixed(D(scene["impact_from_knob_m"]), 2) << " m from the knob.\n"
     << "* **Machine**: " << metadata["machine"]["cpu_model"].get<std::string>()
     << ", `nproc` = " << metadata["machine"]["nproc"].get<int>() << ", load average at start "
     << metadata["machine"]["load_average_at_start"].get<std::string>() << " (a shared machine: "
     << "times are indicative, ratios more reliable); sweetspot "
     << metadata["sweetspot_version"].get<std::string>() << ", GCC "
     << metadata["compiler"].get<std::string>() << ", " << metadata["build_type"].get<std::string>()
     << " build; whole run " << Fixed(D(metadata["run_time_s"]), 0) << " s.\n"
     << "* **Timing**: " << metadata["timing_method"].get<std::string>() << "\n"
     << "* **Error**: " << metadata["error_method"].get<std::string>() << "\n";
  if (metadata["quick"].get<bool>()) {
    md << "* **Quick run** (`--quick`): fewer settings and shorter timing; not for decisions.\n";
  }
  md << "\n![time per evaluation against relative error](speed-vs-error.svg)\n\n";

  md << "## How to choose\n\n"
     << "Per model: the default (**auto**) setting, and the cheapest setting measured that "
        "meets a relative error of 1e-6 and of 1e-3 (fresh computations: a row with cached "
        "modes is not a candidate).\n\n"
     << "| model | auto: time, relative error | cheapest ≤ 1e-6 | cheapest ≤ 1e-3 |\n"
     << "|---|---|---|---|\n";
  auto pick = [](const Row* r) {
    return r == nullptr ? std::string("none measured")
                        : r->setting + ": " + Duration(r->timing.per_eval_s) + ", " +
                              ErrorText(r->RelativeError());
  };
  for (const ModelInfo& m : report.models) {
    const auto rows = RowsOf(report, m.name);
    const Row* a = nullptr;
    for (const Row* r : rows) {
      if (r->is_auto) a = r;
    }
    md << "| `" << m.name << "` | "
       << (a == nullptr ? std::string("—")
                        : Duration(a->timing.per_eval_s) + ", " + ErrorText(a->RelativeError()))
       << " | " << pick(Cheapest(rows, kTightRelative)) << " | "
       << pick(Cheapest(rows, kLooseRelative)) << " |\n";
  }
  md << "\n" << HowToChoose(report) << "\n";

  for (const ModelInfo& m : report.models) {
    md << "## `" << m.name << "`: " << m.title << "\n\n"
       << "* One evaluation: " << m.what << ".\n"
       << "* Reference: " << m.reference << ".\n"
       << "* **auto** (service default): " << m.auto_setting << ".\n\n";
    const auto rows = RowsOf(report, m.name);
    if (rows.empty()) {
      md << "No usable rows (see `skipped` in the JSON).\n\n";
      continue;
    }
    md << "| setting | time / evaluation | CPU time | error ("
       << rows.front()->quantities.front().name
       << ") | unit | relative error | other errors | work | auto |\n"
       << "|---|---:|---:|---:|---|---:|---|---|:-:|\n";
    for (const Row* r : rows) {
      std::string others;
      for (std::size_t i = 1; i < r->quantities.size(); ++i) {
        const Quantity& q = r->quantities[i];
        others += (others.empty() ? "" : "; ") + q.name + " " + ErrorText(q.Error()) + " " + q.unit;
      }
      md << "| " << r->setting << (r->termination == "converged" ? "" : " (" + r->termination + ")")
         << " | " << Duration(r->timing.per_eval_s) << " | " << Duration(r->timing.cpu_per_eval_s)
         << " | " << ErrorText(r->Error()) << " | " << r->quantities.front().unit << " | "
         << ErrorText(r->RelativeError()) << " | " << others << " | " << Work(*r) << " | "
         << (r->is_auto ? "**auto**" : "") << " |\n";
    }
    md << "\n";
  }
  if (!report.skipped.empty()) {
    md << "## Skipped\n\nThese settings gave no usable result:\n\n";
    for (const Json& s : report.skipped) {
      md << "* `" << s["model"].get<std::string>() << "`, " << s["setting"].get<std::string>()
         << ": " << s["termination"].get<std::string>() << ", " << s["message"].get<std::string>()
         << "\n";
    }
    md << "\n";
  }
  return md.str();
}

std::string XmlEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// "1 ns", "10 µs", "1 s" for a decade of seconds.
std::string DecadeDuration(int decade) {
  static const char* units[] = {"ns", "µs", "ms", "s"};
  const int shifted = decade + 9;
  const int group = std::clamp(shifted >= 0 ? shifted / 3 : -1, 0, 3);
  const int power = decade - (group * 3 - 9);
  std::string mantissa = "1";
  if (power > 0) mantissa += std::string(static_cast<std::size_t>(power), '0');
  if (power < 0) return "1e" + std::to_string(decade) + " s";
  return mantissa + " " + units[group];
}

std::string Svg(const Report& report) {
  const double width = 1000, height = 600;
  const double x0 = 80, y0 = 40, w = 600, h = 470;
  double t_min = std::numeric_limits<double>::infinity(), t_max = 0.0;
  double e_min = std::numeric_limits<double>::infinity(), e_max = 0.0;
  for (const Row& r : report.rows) {
    t_min = std::min(t_min, r.timing.per_eval_s);
    t_max = std::max(t_max, r.timing.per_eval_s);
    const double e = r.RelativeError();
    if (e > 0.0) {
      e_min = std::min(e_min, e);
      e_max = std::max(e_max, e);
    }
  }
  if (report.rows.empty()) t_min = t_max = 1e-6;
  if (!(e_max > 0.0)) e_min = e_max = 1e-12;
  const int x_lo = static_cast<int>(std::floor(std::log10(t_min)));
  const int x_hi = std::max(x_lo + 1, static_cast<int>(std::ceil(std::log10(t_max))));
  const int y_lo = std::max(-17, static_cast<int>(std::floor(std::log10(e_min))));
  const int y_hi = std::max(0, static_cast<int>(std::ceil(std::log10(e_max))));
  const int y_floor = y_lo - 1;  // where errors of exactly 0 are drawn
  auto X = [&](double t) { return x0 + (std::log10(t) - x_lo) / (x_hi - x_lo) * w; };
  auto Y = [&](double e) {
    const double l = e > 0.0 ? std::max(std::log10(e), static_cast<double>(y_lo)) : y_floor;
    return y0 + h - (l - y_floor) / (y_hi - y_floor) * h;
  };
  static const char* colors[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                                 "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#17becf"};
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" viewBox=\"0 0 " << width << " " << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<title>sweetspot: time per evaluation against relative error</title>\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  // Grid, ticks, labels.
  for (int d = x_lo; d <= x_hi; ++d) {
    const double x = X(std::pow(10.0, d));
    s << "<line x1=\"" << x << "\" y1=\"" << y0 << "\" x2=\"" << x << "\" y2=\"" << y0 + h
      << "\" stroke=\"#ddd\"/>\n"
      << "<text x=\"" << x << "\" y=\"" << y0 + h + 18 << "\" text-anchor=\"middle\">"
      << DecadeDuration(d) << "</text>\n";
  }
  for (int d = y_floor; d <= y_hi; ++d) {
    const double y = d == y_floor ? Y(0.0) : Y(std::pow(10.0, d));
    s << "<line x1=\"" << x0 << "\" y1=\"" << y << "\" x2=\"" << x0 + w << "\" y2=\"" << y
      << "\" stroke=\"" << (d == y_floor ? "#999\" stroke-dasharray=\"4 3" : "#ddd") << "\"/>\n";
    if (d == y_floor) {
      s << "<text x=\"" << x0 - 6 << "\" y=\"" << y + 4
        << "\" text-anchor=\"end\">0 (exact)</text>\n";
    } else if ((d - y_lo) % 2 == 0 || y_hi - y_lo <= 8) {
      s << "<text x=\"" << x0 - 6 << "\" y=\"" << y + 4
        << "\" text-anchor=\"end\">10<tspan dy=\"-6\" "
        << "font-size=\"9\">" << d << "</tspan></text>\n";
    }
  }
  s << "<rect x=\"" << x0 << "\" y=\"" << y0 << "\" width=\"" << w << "\" height=\"" << h
    << "\" fill=\"none\" stroke=\"#333\"/>\n"
    << "<text x=\"" << x0 + w / 2 << "\" y=\"" << y0 + h + 40
    << "\" text-anchor=\"middle\" font-size=\"13\">time per evaluation (wall, log scale)</text>\n"
    << "<text transform=\"translate(20," << y0 + h / 2 << ") rotate(-90)\" text-anchor=\"middle\" "
    << "font-size=\"13\">relative error against the reference (log scale)</text>\n"
    << "<text x=\"" << x0 << "\" y=\"" << y0 - 16
    << "\" font-size=\"14\" font-weight=\"bold\">Speed against error, paper-wood scene "
       "(lower left is better)</text>\n";
  // Series: every point, and the line through the model's cheapest settings per accuracy.
  for (std::size_t k = 0; k < report.models.size(); ++k) {
    const std::string color = colors[k % 10];
    auto rows = RowsOf(report, report.models[k].name);
    std::sort(rows.begin(), rows.end(), [](const Row* a, const Row* b) {
      if (a->timing.per_eval_s != b->timing.per_eval_s) {
        return a->timing.per_eval_s < b->timing.per_eval_s;
      }
      return a->RelativeError() < b->RelativeError();
    });
    std::string front;
    double best = std::numeric_limits<double>::infinity();
    for (const Row* r : rows) {
      const double e = r->RelativeError();
      if (e < best) {
        best = e;
        if (!front.empty()) front += ' ';
        front += Fixed(X(r->timing.per_eval_s), 1);
        front += ',';
        front += Fixed(Y(e), 1);
      }
    }
    s << "<g>\n<polyline points=\"" << front << "\" fill=\"none\" stroke=\"" << color
      << "\" stroke-width=\"1.5\" opacity=\"0.8\"/>\n";
    for (const Row* r : rows) {
      const double cx = X(r->timing.per_eval_s), cy = Y(r->RelativeError());
      s << "<circle cx=\"" << Fixed(cx, 1) << "\" cy=\"" << Fixed(cy, 1) << "\" r=\"3.5\" fill=\""
        << color << "\"><title>" << XmlEscape(r->model + ": " + r->setting) << " — "
        << Duration(r->timing.per_eval_s) << ", relative error " << ErrorText(r->RelativeError())
        << (r->is_auto ? " (auto)" : "") << "</title></circle>\n";
      if (r->is_auto) {
        s << "<circle cx=\"" << Fixed(cx, 1) << "\" cy=\"" << Fixed(cy, 1)
          << "\" r=\"8\" fill=\"none\" stroke=\"black\" stroke-width=\"2\"/>\n";
      }
    }
    s << "</g>\n";
  }
  // Legend.
  const double lx = x0 + w + 20;
  double ly = y0 + 10;
  for (std::size_t k = 0; k < report.models.size(); ++k) {
    s << "<circle cx=\"" << lx + 6 << "\" cy=\"" << ly - 4 << "\" r=\"5\" fill=\"" << colors[k % 10]
      << "\"/>\n<text x=\"" << lx + 18 << "\" y=\"" << ly << "\">"
      << XmlEscape(report.models[k].name) << "</text>\n";
    ly += 20;
  }
  ly += 6;
  s << "<circle cx=\"" << lx + 6 << "\" cy=\"" << ly - 4
    << "\" r=\"8\" fill=\"none\" stroke=\"black\" stroke-width=\"2\"/>\n<text x=\"" << lx + 18
    << "\" y=\"" << ly << "\">auto (service default)</text>\n";
  ly += 26;
  for (const char* line :
       {"Lines join each model's", "cheapest setting for each", "accuracy (its Pareto front).", "",
        "Errors of exactly 0 (the", "reference itself, or bit-", "identical to it) are drawn",
        "on the dashed floor \"0\".", "", "Hover a point for its setting."}) {
    s << "<text x=\"" << lx << "\" y=\"" << ly << "\" font-size=\"11\" fill=\"#444\">" << line
      << "</text>\n";
    ly += 15;
  }
  s << "</svg>\n";
  return s.str();
}

bool WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  return static_cast<bool>(out);
}

int Main(int argc, char** argv) {
  std::string out_dir = "docs";
  std::string command;
  bool quick = false;
  bool strict = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out-dir" && i + 1 < argc) {
      out_dir = argv[++i];
    } else if (a == "--command" && i + 1 < argc) {
      command = argv[++i];
    } else if (a == "--quick") {
      quick = true;
    } else if (a == "--strict") {
      strict = true;
    } else {
      std::cerr << "usage: sweetspot-speed-vs-error [--out-dir DIR] [--command TEXT] [--quick] "
                   "[--strict]\n"
                   "Writes DIR/speed-vs-error.{json,md,svg} (default DIR: docs). --quick: fewer "
                   "settings, short timing (a smoke run). --strict: exit 3 when a setting gave no "
                   "usable result.\n";
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  if (command.empty()) {
    for (int i = 0; i < argc; ++i) command += (i > 0 ? " " : "") + std::string(argv[i]);
  }
  TimingOptions timing;
  if (quick) {
    timing.min_batch_s = 0.001;
    timing.min_total_s = 0.003;
    timing.min_batches = 3;
  }
  const std::string load_before = LoadAverage();
  const auto t0 = Clock::now();
  Report report;
  std::cerr << "speed vs error (" << (quick ? "quick" : "full") << " run)\n";
  MassPropertiesRows(timing, &report);
  RigidAndFreeSweetSpotRows(timing, quick, &report);
  HertzSweetSpotRows(timing, quick, &report);
  HertzImpactRows(timing, quick, &report);
  FlexibleModesRows(core::BeamTheory::kTimoshenko, timing, quick, &report);
  FlexibleModesRows(core::BeamTheory::kEulerBernoulli, timing, quick, &report);
  FlexibleImpactRows(timing, quick, &report);
  DesignRows(timing, quick, &report);
  BarrelHoopRows(timing, quick, &report);
  BarrelTrampolineRows(timing, quick, &report);
  FlightRows(timing, quick, &report);
  const Json metadata = Metadata(command, timing, quick, SecondsSince(t0), load_before);
  const Json json = ToJson(report, metadata);
  const std::string base = out_dir + "/speed-vs-error";
  if (!WriteFile(base + ".json", json.dump(1) + "\n") ||
      !WriteFile(base + ".md", Markdown(report, metadata)) ||
      !WriteFile(base + ".svg", Svg(report))) {
    std::cerr << "cannot write " << base << ".{json,md,svg}\n";
    return 1;
  }
  std::cerr << "wrote " << base << ".{json,md,svg}: " << report.rows.size() << " rows, "
            << report.skipped.size() << " skipped, " << Fixed(SecondsSince(t0), 1) << " s\n";
  return strict && !report.skipped.empty() ? 3 : 0;
}

}  // namespace
}  // namespace sweetspot::bench

int main(int argc, char** argv) { return sweetspot::bench::Main(argc, argv); }
