// Scenes: validation, "model only what is needed", NLopt backend mapping and algorithms,
// auto model choice, refusals, determinism across threads.
#include "core/scene/closed_form_designs.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include "core/bat/presets.hpp"
#include "core/numerics/nlopt_search.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace scene_test {
namespace {

Scene PaperWood(std::vector<SceneOutput> outputs = {SceneOutput::kMaxExitSpeed}) {
  Scene s;
  s.bat = FindPreset("paper-wood")->bat;
  s.paper_bat = true;  // as the api marks the paper's preset: model auto is the paper's rigid_pivot
  s.outputs = std::move(outputs);
  return s;
}

TEST(SceneDefaults, AreValidAndMatchTheContract) {
  std::string why;
  EXPECT_TRUE(Validates(Ball{}, &why)) << why;
  EXPECT_TRUE(Validates(Swing{}, &why)) << why;
  EXPECT_TRUE(Validates(SceneOptions{}, &why)) << why;
  EXPECT_TRUE(Validates(CollisionOptions{}, &why)) << why;
  EXPECT_TRUE(Validates(ScalarSearchOptions{}, &why)) << why;
  EXPECT_TRUE(Validates(PaperWood(), &why)) << why;
  EXPECT_EQ(Ball{}.mass_kg, 0.145);
  EXPECT_EQ(Ball{}.radius_m, 0.0366);
  EXPECT_EQ(Ball{}.speed_mps, 27.7);
  EXPECT_EQ(Swing{}.angular_speed_rad_s, 17.288);
  EXPECT_EQ(Swing{}.pivot_from_knob_m, 0.0);
  EXPECT_EQ(Swing{}.hands_from_knob_m, 0.1524);
}

TEST(SceneValidation, ExactMessages) {
  std::string why;
  Scene s;
  EXPECT_FALSE(Validates(s, &why));
  EXPECT_EQ(why, "bat: missing (give a bat or precomputed mass_properties)");
  s = PaperWood();
  s.ball.speed_mps = -3;
  EXPECT_FALSE(Validates(s, &why));
  EXPECT_EQ(why, "ball.speed_mps = -3: must be in [0, 1000]");
  s = PaperWood();
  s.cor = 1.5;
  EXPECT_FALSE(Validates(s, &why));
  EXPECT_EQ(why, "cor = 1.5: must be in [0, 1]");
  s = PaperWood();
  s.outputs.clear();
  EXPECT_FALSE(Validates(s, &why));
  EXPECT_EQ(why, "outputs: empty: name at least one output");
  s = PaperWood();
  s.ball.stiffness_exponent = 4;
  EXPECT_FALSE(Validates(s, &why));
  EXPECT_EQ(why, "ball.stiffness_exponent = 4: must be in [1, 3]");
  SceneOptions o;
  o.curve_samples = 1;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "curve_samples = 1: must be in [2, 10000]");
  o = SceneOptions{};
  o.sweet_zone_tolerance = -1;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "sweet_zone_tolerance_mps = -1: must be in [0, 1000]");
  o.sweet_zone_unit = ToleranceUnit::kPercent;  // named by its unit, as in a request
  o.sweet_zone_tolerance = 100.5;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "sweet_zone_tolerance_percent = 100.5: must be in [0, 100]");
  o = SceneOptions{};
  o.nlopt.x_tolerance_m = 0;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "nlopt.x_tolerance_m = 0: must be finite and > 0");
  o = SceneOptions{};
  o.hertz.hands_stiffness_n_m = -1;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "hertz.hands_stiffness_n_m = -1: must be finite and >= 0");
  // An invalid scene still returns a summary.
  s = PaperWood();
  s.swing.hands_from_knob_m = 2.0;
  const SceneResult r = EvaluateScene(s, SceneOptions{});
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.summary.message,
            "swing.hands_from_knob_m = 2: must be within the bat [0, 0.85499999999999998]");
}

TEST(SceneCor, FromTheMaterialOrTheScene) {
  SceneResult r = EvaluateScene(PaperWood(), {});
  EXPECT_EQ(r.cor, 0.5);
  EXPECT_EQ(r.cor_source, "material:paper-wood");
  Scene s = PaperWood();
  s.cor = 0.45;
  r = EvaluateScene(s, {});
  EXPECT_EQ(r.cor, 0.45);
  EXPECT_EQ(r.cor_source, "scene");
  s = PaperWood();
  s.bat->material.cor.reset();
  r = EvaluateScene(s, {});
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.summary.message, "cor: not given, and material 'paper-wood' has no default COR");
}

TEST(SceneCor, OnlyOutputsThatRunAnImpactNeedOne) {
  // paper-wood's bat with the same material numbers but no default COR (a custom material).
  Scene custom = PaperWood({SceneOutput::kCenterOfPercussion, SceneOutput::kVibrationNode});
  custom.bat->material.name = "custom";
  custom.bat->material.cor.reset();
  const SceneResult r = EvaluateScene(custom, {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  // No COR was needed, so none is reported (and none was invented).
  EXPECT_FALSE(r.cor.has_value());
  EXPECT_EQ(r.cor_source, "");
  // The same outputs of the paper-wood bat (COR 0.5): neither depends on the COR, and the bat's
  // geometry and material numbers are identical, so the same arithmetic gives the same bits.
  const SceneResult wood =
      EvaluateScene(PaperWood({SceneOutput::kCenterOfPercussion, SceneOutput::kVibrationNode}), {});
  ASSERT_EQ(wood.summary.termination, Termination::kConverged) << wood.summary.message;
  ASSERT_TRUE(r.center_of_percussion.has_value());
  ASSERT_TRUE(r.vibration_node.has_value());
  EXPECT_EQ(r.center_of_percussion->position_from_knob_m,
            wood.center_of_percussion->position_from_knob_m);
  EXPECT_EQ(r.vibration_node->position_from_knob_m, wood.vibration_node->position_from_knob_m);
  EXPECT_EQ(r.vibration_node->frequency_hz, wood.vibration_node->frequency_hz);
  EXPECT_EQ(r.mass_properties.mass_kg, wood.mass_properties.mass_kg);
  // Outputs that run an impact still need one, with the same refusal as before.
  for (SceneOutput o : {SceneOutput::kMaxExitSpeed, SceneOutput::kSweetZone,
                        SceneOutput::kExitSpeedCurve, SceneOutput::kLeastStingZone}) {
    custom.outputs = {SceneOutput::kCenterOfPercussion, o};
    const SceneResult refused = EvaluateScene(custom, {});
    EXPECT_EQ(refused.summary.termination, Termination::kInvalidInput) << SceneOutputName(o);
    EXPECT_EQ(refused.summary.message, "cor: not given, and material 'custom' has no default COR")
        << SceneOutputName(o);
  }
  // Collide always runs an impact.
  const CollisionResult hit = Collide(custom, 0.7, CollisionModel::kRigidPivot);
  EXPECT_EQ(hit.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(hit.summary.message, "cor: not given, and material 'custom' has no default COR");
}

TEST(SceneModels, EachOutputRunsOnlyWhatItNeeds) {
  EXPECT_EQ(ModelsFor(SceneOutput::kCenterOfPercussion, CollisionModel::kHertz),
            std::vector<std::string>{"mass_properties"});
  // auto: the free bat (the paper's bats aside: rigid_pivot, also closed form).
  EXPECT_EQ(ModelsFor(SceneOutput::kMaxExitSpeed, CollisionModel::kAuto),
            (std::vector<std::string>{"mass_properties", "free_bat"}));
  EXPECT_EQ(ModelsFor(SceneOutput::kVibrationNode, CollisionModel::kRigidPivot),
            std::vector<std::string>{"flexible_beam"});
  SceneResult r = EvaluateScene(PaperWood({SceneOutput::kCenterOfPercussion}), {});
  EXPECT_EQ(r.summary.models_used, std::vector<std::string>{"mass_properties"});
  EXPECT_TRUE(r.exit_speed_model.empty());
  r = EvaluateScene(PaperWood({SceneOutput::kMaxExitSpeed, SceneOutput::kSweetZone,
                               SceneOutput::kExitSpeedCurve, SceneOutput::kCenterOfPercussion}),
                    {});
  EXPECT_EQ(r.summary.models_used, (std::vector<std::string>{"mass_properties", "rigid_pivot"}));
  // Mass properties are computed once per request, shared by every output.
  ASSERT_EQ(r.timings.size(), 2u);
  EXPECT_EQ(r.timings[0].model, "mass_properties");
  EXPECT_EQ(r.timings[0].calls, 1);
  EXPECT_GE(r.timings[0].time_s, 0.0);
  EXPECT_GT(r.timings[1].calls, 1);
  EXPECT_GE(r.summary.solve_time_s, 0.0);
  // Precomputed properties: nothing is recomputed.
  Scene given = PaperWood({SceneOutput::kMaxExitSpeed});
  given.mass_properties = r.mass_properties;
  const SceneResult g = EvaluateScene(given, {});
  EXPECT_EQ(g.summary.models_used, std::vector<std::string>{"rigid_pivot"});
  EXPECT_EQ(g.max_exit_speed->position_from_knob_m, r.max_exit_speed->position_from_knob_m);
}

TEST(SceneModels, PerOutputErrorEstimates) {
  SceneOptions o;
  const SceneResult r =
      EvaluateScene(PaperWood({SceneOutput::kMaxExitSpeed, SceneOutput::kSweetZone,
                               SceneOutput::kExitSpeedCurve, SceneOutput::kCenterOfPercussion}),
                    o);
  // Closed forms: rounding only (a few ulps of ~0.7 m and ~23 m/s).
  EXPECT_GT(r.max_exit_speed->error_estimate_m, 0.0);
  EXPECT_LT(r.max_exit_speed->error_estimate_m, 1e-14);
  EXPECT_LT(r.max_exit_speed->error_estimate_mps, 1e-12);  // 8 eps (u + peak) ~ 1.4e-13
  EXPECT_LT(r.sweet_zone->error_estimate_m, 1e-12);
  EXPECT_LT(r.exit_speed_curve->error_estimate_mps, 1e-13);
  EXPECT_LT(r.center_of_percussion->error_estimate_m, 1e-14);
  // NLopt: its tolerance.
  o.method = SweetSpotMethod::kNlopt;
  const SceneResult n = EvaluateScene(PaperWood(), o);
  EXPECT_EQ(n.max_exit_speed->method, "nlopt:LD_SLSQP");
  EXPECT_GE(n.max_exit_speed->error_estimate_m, o.nlopt.x_tolerance_m);
  EXPECT_LT(n.max_exit_speed->error_estimate_m, 1e-9);
}

TEST(SceneModels, HertzSweetSpotByDerivativeFreeSearch) {
  Scene s = PaperWood({SceneOutput::kMaxExitSpeed});
  SceneOptions o;
  o.model = CollisionModel::kHertz;
  o.hertz.hands_stiffness_n_m = 0.0;  // the free-bat limit has a closed form to compare with
  o.hertz.solver.relative_tolerance = 1e-9;
  const SceneResult h = EvaluateScene(s, o);
  ASSERT_EQ(h.summary.termination, Termination::kConverged) << h.summary.message;
  EXPECT_EQ(h.max_exit_speed->method, "nlopt:LN_BOBYQA");
  EXPECT_EQ(h.summary.models_used, (std::vector<std::string>{"mass_properties", "hertz"}));
  o.model = CollisionModel::kFreeBat;
  const SceneResult f = EvaluateScene(s, o);
  // Derivative-free on an ODE whose values carry ~1e-9 relative noise: the flat maximum is
  // resolvable to ~sqrt(2 x 3e-8 / |f''|) ~ 1e-4 m; the speed to 1e-7 relative.
  EXPECT_NEAR(h.max_exit_speed->position_from_knob_m, f.max_exit_speed->position_from_knob_m, 2e-4);
  EXPECT_NEAR(h.max_exit_speed->exit_speed_mps, f.max_exit_speed->exit_speed_mps,
              1e-7 * f.max_exit_speed->exit_speed_mps);
  // A gradient algorithm on a model without derivatives is refused, naming both.
  o.model = CollisionModel::kHertz;
  o.nlopt.algorithm = NloptAlgorithm::kLdSlsqp;
  const SceneResult bad = EvaluateScene(s, o);
  EXPECT_EQ(bad.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(bad.summary.message,
            "max_exit_speed: nlopt.algorithm = LD_SLSQP: needs the objective's derivative, which "
            "this model does not provide; use an LN_ or GN_ algorithm");
}

TEST(SceneModels, FlexibleCollisionRunsTheBeamModel) {
  // Since the flexible beam landed, model flexible runs it (no refusal); its
  // own accuracy is tested in flexible_*_test.cpp.
  const CollisionResult c = Collide(PaperWood(), 0.7, CollisionModel::kFlexible);
  ASSERT_TRUE(c.summary.IsSolutionUsable()) << c.summary.message;
  EXPECT_EQ(c.model, CollisionModel::kFlexible);
  EXPECT_TRUE(c.missing_model.empty());
  // Vibrations take energy: the flexible exit speed is below the rigid free bat's
  // (paper-wood at 0.7 m: 22.79 against 23.1 m/s for the contact model).
  const CollisionResult rigid = Collide(PaperWood(), 0.7, CollisionModel::kHertz);
  EXPECT_GT(c.exit_speed_mps, 0.0);
  EXPECT_LT(c.exit_speed_mps, rigid.exit_speed_mps);
}

TEST(Collide, AutoPicksTheFreeBatOrThePapersModelAndSaysWhy) {
  // The paper's bat: the paper's pinned bat.
  CollisionResult c = Collide(PaperWood(), 0.7, CollisionModel::kAuto);
  EXPECT_EQ(c.model, CollisionModel::kRigidPivot);
  EXPECT_NE(c.model_reason.find("the paper's model"), std::string::npos);
  EXPECT_TRUE(c.rigid_pivot.has_value());
  EXPECT_EQ(c.summary.models_used, (std::vector<std::string>{"mass_properties", "rigid_pivot"}));
  // Any other bat: the free bat in the swing's velocity field.
  Scene other = PaperWood();
  other.paper_bat = false;
  c = Collide(other, 0.7, CollisionModel::kAuto);
  EXPECT_EQ(c.model, CollisionModel::kFreeBat);
  EXPECT_NE(c.model_reason.find("auto: free_bat"), std::string::npos);
  EXPECT_TRUE(c.free_bat.has_value());
  EXPECT_EQ(c.summary.models_used, (std::vector<std::string>{"mass_properties", "free_bat"}));
  CollisionOptions o;
  o.want_contact_details = true;
  c = Collide(PaperWood(), 0.7, CollisionModel::kAuto, o);
  EXPECT_EQ(c.model, CollisionModel::kHertz);
  EXPECT_TRUE(c.hertz.has_value());
  EXPECT_NE(c.model_reason.find("contact time"), std::string::npos);
  for (CollisionModel m :
       {CollisionModel::kAuto, CollisionModel::kRigidPivot, CollisionModel::kFreeBat,
        CollisionModel::kHertz, CollisionModel::kFlexible}) {
    EXPECT_EQ(ParseCollisionModel(CollisionModelName(m)), m);
  }
}

TEST(Collide, WithoutBatGeometryTheSurfaceIsRigidAndSaysSo) {
  Scene s = PaperWood();
  const SceneResult r = EvaluateScene(s, {});
  Scene props;
  props.mass_properties = r.mass_properties;
  props.length_m = 0.855;
  props.cor = 0.5;
  const CollisionResult c = Collide(props, 0.7, CollisionModel::kHertz);
  ASSERT_EQ(c.summary.termination, Termination::kConverged);
  EXPECT_EQ(c.hertz->problem.surface_stiffness, 0.0);
  ASSERT_FALSE(c.summary.warnings.empty());
  EXPECT_EQ(c.summary.warnings[0],
            "no bat geometry in the scene: the bat surface is taken as rigid");
}

TEST(NloptBackend, NewuoaIsNotOfferedIn1D) {
  std::string why;
  EXPECT_FALSE(ParseNloptAlgorithm("LN_NEWUOA", &why).has_value());
  EXPECT_EQ(why,
            "nlopt.algorithm = LN_NEWUOA: not offered for 1-D searches (NLopt refuses "
            "NEWUOA in one dimension)");
  EXPECT_FALSE(ParseNloptAlgorithm("LD_FOO", &why).has_value());
  EXPECT_EQ(why.rfind("nlopt.algorithm = LD_FOO: must be one of LD_SLSQP, ", 0), 0u);
  for (NloptAlgorithm a : OfferedNloptAlgorithms()) {
    EXPECT_EQ(ParseNloptAlgorithm(NloptAlgorithmName(a), nullptr), a);
  }
}

TEST(NloptBackend, EveryOfferedAlgorithmFindsThePaperSweetSpot) {
  const SceneResult ref = EvaluateScene(PaperWood(), {});
  const double x0 = ref.max_exit_speed->position_from_knob_m;
  for (NloptAlgorithm a : OfferedNloptAlgorithms()) {
    SCOPED_TRACE(NloptAlgorithmName(a));
    SceneOptions o;
    o.method = SweetSpotMethod::kNlopt;
    o.nlopt.algorithm = a;
    const SceneResult r = EvaluateScene(PaperWood(), o);
    ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.message;
    // With the exact derivative the first-order selection resolves ~eps |x| (1e-9 m is the
    // issue's bar); derivative-free methods are limited by the flat maximum to
    // ~sqrt(eps |f| / |f''|) ~ 1e-8 m; 1e-6 m leaves room for their stopping rules.
    const double tol = a == NloptAlgorithm::kLdSlsqp                                 ? 1e-9 * x0
                       : NloptAlgorithmNeedsGradient(a) || NloptAlgorithmIsGlobal(a) ? 1e-8
                                                                                     : 1e-6;
    EXPECT_NEAR(r.max_exit_speed->position_from_knob_m, x0, tol);
    EXPECT_NEAR(r.max_exit_speed->exit_speed_mps, ref.max_exit_speed->exit_speed_mps, 1e-10);
    EXPECT_EQ(r.max_exit_speed->method, std::string("nlopt:") + NloptAlgorithmName(a));
  }
}

TEST(NloptBackend, ObjectiveFailuresAreReportedNotThrown) {
  ScalarSearchOptions o;
  auto throws = [](double x, double*) -> double {
    if (x > 0.5) throw std::runtime_error("boom");
    return -x * x;
  };
  ScalarSearchResult r = MaximizeScalar(throws, false, 0.0, 1.0, o);
  EXPECT_EQ(r.summary.termination, Termination::kFailure);
  EXPECT_EQ(r.summary.message, "the objective threw: boom");
  auto nan = [](double, double*) { return std::nan(""); };
  r = MaximizeScalar(nan, false, 0.0, 1.0, o);
  EXPECT_EQ(r.summary.termination, Termination::kFailure);
  EXPECT_EQ(r.summary.message, "the objective returned a non-finite value at x = 0");
  r = MaximizeScalar(nan, false, 1.0, 0.0, o);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  // A tiny budget stops with the best point kept and says so.
  o.max_evaluations = 10;
  o.start_samples = 9;
  auto f = [](double x, double* g) {
    if (g) *g = -2 * (x - 0.3);
    return -(x - 0.3) * (x - 0.3);
  };
  r = MaximizeScalar(f, true, 0.0, 1.0, o);
  EXPECT_TRUE(r.summary.IsSolutionUsable());
  EXPECT_EQ(r.summary.raw_status, 5);  // MAXEVAL_REACHED
  EXPECT_EQ(r.summary.termination, Termination::kNoConvergence);
}

TEST(NloptBackend, StochasticAlgorithmsAreReproducibleWithTheirSeed) {
  SceneOptions o;
  o.method = SweetSpotMethod::kNlopt;
  o.nlopt.algorithm = NloptAlgorithm::kGnCrs2Lm;
  o.nlopt.polish = false;
  o.nlopt.seed = 7;
  const SceneResult a = EvaluateScene(PaperWood(), o);
  const SceneResult b = EvaluateScene(PaperWood(), o);
  EXPECT_EQ(a.max_exit_speed->position_from_knob_m, b.max_exit_speed->position_from_knob_m);
}

TEST(SceneThreads, ManySolvesOnManyThreadsGiveIdenticalResults) {
  SceneOptions o;
  o.method = SweetSpotMethod::kNlopt;
  o.nlopt.algorithm = NloptAlgorithm::kGnCrs2Lm;
  o.nlopt.seed = 3;
  const Scene s = PaperWood({SceneOutput::kMaxExitSpeed, SceneOutput::kSweetZone});
  const SceneResult ref = EvaluateScene(s, o);
  std::vector<std::thread> threads;
  std::vector<int> mismatches(8, 0);
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 20; ++i) {
        const SceneResult r = EvaluateScene(s, o);
        if (r.max_exit_speed->position_from_knob_m != ref.max_exit_speed->position_from_knob_m ||
            r.sweet_zone->to_knob_m != ref.sweet_zone->to_knob_m) {
          ++mismatches[t];
        }
      }
    });
  }
  for (auto& th : threads) th.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
}

// What a result says, field by field (its numbers to the bit): a reused result must say exactly
// what a fresh one does.
std::string Describe(const SceneResult& r) {
  std::ostringstream o;
  o.precision(17);
  const Summary& s = r.summary;
  o << TerminationName(s.termination) << '|' << s.message << '|' << s.backend << '|' << s.raw_status
    << '|' << s.iterations << '|' << s.evaluations << '|' << s.objective << '|'
    << s.constraint_violation << '|' << s.error_estimate << '|' << s.refusal.has_value() << '|';
  for (const auto& m : s.models_used) o << m << ',';
  for (const auto& w : s.warnings) o << w << ',';
  o << '|' << r.missing_model << '|' << r.refused_field << '|' << r.cor.value_or(-1) << '|'
    << r.cor_source << '|' << r.mass_properties.mass_kg << '|' << r.mass_properties.balance_point_m
    << '|' << r.length_m << '|' << r.exit_speed_model << '|' << r.model_reason << '|';
  if (r.max_exit_speed) {
    o << "max " << r.max_exit_speed->position_from_knob_m << ' ' << r.max_exit_speed->exit_speed_mps
      << ' ' << r.max_exit_speed->model << ' ' << r.max_exit_speed->method << ' '
      << r.max_exit_speed->summary.message;
  }
  if (r.center_of_percussion) o << "|cop " << r.center_of_percussion->position_from_knob_m;
  if (r.sweet_zone) o << "|zone " << r.sweet_zone->to_knob_m;
  if (r.exit_speed_curve) o << "|curve " << r.exit_speed_curve->points.size();
  if (r.vibration_node) o << "|node";
  if (r.least_sting_zone) o << "|sting";
  for (const auto& t : r.timings) o << '|' << t.model << ' ' << t.calls;
  return o.str();
}

TEST(SceneEvaluatorReuse, EachResultEqualsAFreshEvaluation) {
  // One evaluator, one result written over again and again, through scenes that fill
  // different fields (every output, a refusal, a missing bat, an exit speed only): each
  // must equal EvaluateScene's fresh result, so nothing of a previous design survives.
  SceneOptions o;
  o.time_models = false;  // timings are 0 s and comparable
  SceneEvaluator evaluator(o);
  SceneResult reused;
  Scene all = PaperWood({SceneOutput::kMaxExitSpeed, SceneOutput::kSweetZone,
                         SceneOutput::kCenterOfPercussion, SceneOutput::kExitSpeedCurve});
  Scene refused = PaperWood();
  refused.ball.speed_mps = -3;
  Scene no_bat = PaperWood({SceneOutput::kCenterOfPercussion});
  no_bat.mass_properties = ComputeMassProperties(*no_bat.bat);
  no_bat.bat.reset();
  Scene cop_beyond = PaperWood({SceneOutput::kCenterOfPercussion});
  cop_beyond.swing.hands_from_knob_m = 0.5;  // a warning, and cop beyond the tip
  Scene given_cor = PaperWood();
  given_cor.cor = 0.45;
  int compared = 0;
  for (const Scene* scene :
       {&all, &refused, &all, &no_bat, &cop_beyond, &given_cor, &all, &refused, &given_cor}) {
    evaluator.Evaluate(*scene, &reused);
    EXPECT_EQ(Describe(reused), Describe(EvaluateScene(*scene, o))) << "scene " << compared;
    ++compared;
  }
  EXPECT_EQ(compared, 9);
  // The scenes did differ: a refusal, a result with every output.
  EXPECT_EQ(EvaluateScene(refused, o).summary.termination, Termination::kInvalidInput);
  EXPECT_TRUE(EvaluateScene(all, o).sweet_zone.has_value());
}

TEST(SceneEvaluatorReuse, InvalidOptionsRefuseEveryScene) {
  SceneOptions o;
  o.curve_samples = 0;  // out of range
  SceneEvaluator evaluator(o);
  SceneResult r;
  for (int i = 0; i < 2; ++i) {
    evaluator.Evaluate(PaperWood(), &r);
    EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
    EXPECT_EQ(r.summary.message, EvaluateScene(PaperWood(), o).summary.message);
    EXPECT_FALSE(r.max_exit_speed.has_value());
  }
}

// One design of a lean sweep: true when ClosedFormDesigns vouches for it, and then its numbers
// must be EvaluateScene's, field by field and bit for bit; *placement gets the maximum's.
bool VouchedAndEqual(ClosedFormDesigns* lean, const Scene& design, const SceneOptions& o, int k,
                     Placement* placement) {
  ClosedFormDesign d;
  if (!lean->Evaluate(design, &d)) return false;
  const SceneResult full = EvaluateScene(design, o);
  EXPECT_TRUE(full.summary.IsSolutionUsable()) << "design " << k << ": " << full.summary.message;
  if (!full.max_exit_speed.has_value()) {
    ADD_FAILURE() << "design " << k << ": vouched for, but EvaluateScene has no max_exit_speed";
    return true;
  }
  const MaxExitSpeedResult& m = *full.max_exit_speed;
  EXPECT_EQ(d.max_exit_speed.exit_speed_mps, m.exit_speed_mps) << k;
  EXPECT_EQ(d.max_exit_speed.position_from_knob_m, m.position_from_knob_m) << k;
  EXPECT_EQ(d.max_exit_speed.unconstrained_position_from_knob_m,
            m.unconstrained_position_from_knob_m)
      << k;
  EXPECT_EQ(d.max_exit_speed.placement, m.placement) << k;
  EXPECT_EQ(d.max_exit_speed.error_estimate_m, m.error_estimate_m) << k;
  EXPECT_EQ(d.max_exit_speed.error_estimate_mps, m.error_estimate_mps) << k;
  EXPECT_EQ(CollisionModelName(lean->model()), m.model) << k;
  EXPECT_EQ(d.length_m, full.length_m) << k;
  EXPECT_EQ(d.mass_properties.mass_kg, full.mass_properties.mass_kg) << k;
  EXPECT_EQ(d.mass_properties.balance_point_m, full.mass_properties.balance_point_m) << k;
  EXPECT_EQ(d.mass_properties.moi_knob_kg_m2, full.mass_properties.moi_knob_kg_m2) << k;
  EXPECT_EQ(d.mass_properties.moi_centroid_kg_m2, full.mass_properties.moi_centroid_kg_m2) << k;
  EXPECT_EQ(d.mass_properties.volume_m3, full.mass_properties.volume_m3) << k;
  *placement = m.placement;
  return true;
}

// The lean path of a sweep (ClosedFormDesigns): whenever it vouches for a design, its numbers
// are EvaluateScene's, bit for bit; a design EvaluateScene refuses it never vouches for. The
// designs change the geometry, the ball, the swing and the COR, some of them out of range.
TEST(ClosedFormDesigns, VouchesOnlyForEvaluateScenesNumbers) {
  for (const CollisionModel model : {CollisionModel::kRigidPivot, CollisionModel::kFreeBat}) {
    SceneOptions o;
    o.time_models = false;
    o.model = model;
    Scene scene;
    ThreeSegmentShape shape{0.8636, 0.0125, 0.033, 0.30, 0.55};
    scene.bat = MakeThreeSegmentBat(shape, FindMaterial("ash").value());
    scene.cor = 0.5;
    scene.outputs = {SceneOutput::kMaxExitSpeed};
    ASSERT_TRUE(ClosedFormDesigns::Applies(o, scene));
    SceneChanges changes;
    changes.bat_geometry = changes.ball = changes.swing = changes.cor = true;
    ClosedFormDesigns lean(o, scene, changes);
    EXPECT_EQ(lean.model(), model);
    int vouched = 0, refused = 0, off_bat = 0;
    for (int k = 0; k < 240; ++k) {
      Scene design = scene;
      shape.taper_end_m = 0.45 + 0.01 * (k % 30);  // from 0.45 to 0.74
      design.bat->knots = shape.Knots();
      design.bat->wall_thickness_m = k % 7 == 3 ? 0.02 : 0.0;       // the wall above r1 in some
      design.ball.mass_kg = k % 11 == 5 ? 0.0 : 0.145;              // out of range in some
      design.swing.hands_from_knob_m = k % 13 == 7 ? 0.9 : 0.1524;  // past the tip in some
      design.swing.pivot_from_knob_m = -1.0 + 0.02 * (k % 100);
      // The maximum off the bat in some: no swing (rigid_pivot), or no ball speed (free_bat).
      design.swing.angular_speed_rad_s = k % 5 == 2 ? 0.0 : 17.288;
      design.ball.speed_mps = k % 3 == 1 ? 0.0 : 27.7;
      design.cor = k % 17 == 9 ? 1.5 : 0.5;  // out of range in some
      Placement at = Placement::kOnBat;
      if (!VouchedAndEqual(&lean, design, o, k, &at)) {
        ++refused;
        continue;
      }
      ++vouched;
      off_bat += at != Placement::kOnBat;
    }
    // Both kinds of design, and a placement off the bat among the vouched ones.
    EXPECT_GT(vouched, 100);
    EXPECT_GT(refused, 40);
    EXPECT_GT(off_bat, 0) << CollisionModelName(model);
  }
  // A sweep of a shape's fields alone (knots_of_valid_shape): the knots' own checks are left
  // out, the wall's and the fill's are not. Shapes that put the handle inside the wall, the
  // barrel around a bore too wide, a step, all handle or all barrel, and a step on a bat too
  // short for its two knots to differ: each vouched for only when EvaluateScene gives it.
  for (const bool hollow : {true, false}) {
    SceneOptions o;
    o.time_models = false;
    Scene scene;
    ThreeSegmentShape shape{0.8636, 0.0125, 0.033, 0.30, 0.55};
    scene.bat = MakeThreeSegmentBat(shape, FindMaterial("ash").value());
    if (hollow) {
      scene.bat->wall_thickness_m = 0.008;
    } else {
      scene.bat->fill = Fill{FindMaterial("cork").value(), 0.04, 0.3};
    }
    scene.cor = 0.5;
    scene.outputs = {SceneOutput::kMaxExitSpeed};
    ASSERT_TRUE(scene.Validate(nullptr));
    SceneChanges changes;
    changes.bat_geometry = changes.knots_of_valid_shape = true;
    ClosedFormDesigns lean(o, scene, changes);
    ClosedFormDesign first;
    ASSERT_TRUE(lean.Evaluate(scene, &first));  // the template, validated in full
    int vouched = 0, refused = 0;
    for (int k = 0; k < 200; ++k) {
      Scene design = scene;
      ThreeSegmentShape s = shape;
      s.handle_radius_m = 0.006 + 0.002 * (k % 7);                   // below the wall in some
      s.barrel_radius_m = 0.015 + 0.005 * (k % 5);                   // around the bore or not
      s.taper_start_m = k % 4 == 0 ? 0.0 : 0.35;                     // no handle in some
      s.taper_end_m = k % 6 == 1 ? 0.35 : 0.6;                       // a step in some
      if (k % 9 == 4) s.taper_start_m = s.taper_end_m = s.length_m;  // all handle
      if (k == 199) {  // a step of width L * kStepWidth that rounds to 0
        s = {4e-312, 0.0125, 0.033, 2e-312, 2e-312};
        design.swing.hands_from_knob_m = 0.0;
        design.swing.pivot_from_knob_m = 0.0;
      }
      ASSERT_TRUE(s.Validate(nullptr)) << k;
      s.KnotsInto(&design.bat->knots);
      if (k == 199) {
        EXPECT_FALSE(design.bat->ValidateGeometry(nullptr));
        EXPECT_FALSE(design.bat->ValidateGeometryOfShapeKnots(nullptr));
      }
      EXPECT_EQ(design.bat->ValidateGeometryOfShapeKnots(nullptr),
                design.bat->ValidateGeometry(nullptr))
          << k;
      Placement at = Placement::kOnBat;
      if (!VouchedAndEqual(&lean, design, o, k, &at)) {
        ++refused;
        continue;
      }
      ++vouched;
    }
    EXPECT_GT(vouched, 40) << hollow;
    EXPECT_GT(refused, 40) << hollow;
  }

  // Not for what it does not take: another output, a bat speed, flexible, NLopt.
  SceneOptions o;
  Scene scene = PaperWood({SceneOutput::kMaxExitSpeed, SceneOutput::kCenterOfPercussion});
  EXPECT_FALSE(ClosedFormDesigns::Applies(o, scene));
  scene.outputs = {SceneOutput::kMaxExitSpeed};
  EXPECT_TRUE(ClosedFormDesigns::Applies(o, scene));
  scene.swing.bat_speed_mps = 30.0;
  EXPECT_FALSE(ClosedFormDesigns::Applies(o, scene));
  scene.swing.bat_speed_mps.reset();
  o.model = CollisionModel::kFlexible;
  EXPECT_FALSE(ClosedFormDesigns::Applies(o, scene));
  o.model = CollisionModel::kAuto;
  o.method = SweetSpotMethod::kNlopt;
  EXPECT_FALSE(ClosedFormDesigns::Applies(o, scene));
}

}  // namespace
}  // namespace scene_test
}  // namespace sweetspot::core
