// The design answer's certificate (core/optimize/certificate.*): the non-negative least squares
// against enumeration, the certificate at an optimum and away from it, the merge of a rule that
// repeats a target (and not of one that does not), the tolerances' validation.
#include "core/optimize/certificate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/bat/material.hpp"
#include "core/optimize/certificate_runs.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/optimize/design_runs.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_certificate_test {
namespace {

using design_detail::CertificateTolerances;
using design_detail::Certify;
using design_detail::MergeDuplicateConstraints;
using design_detail::NonNegativeLeastSquares;

// The least residual over c >= 0 (c_i free where free[i]) by enumerating every passive set:
// the least-squares solution on each subset, kept when its signs hold.
double BruteForceResidual(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                          const std::vector<bool>& free) {
  const int k = static_cast<int>(a.cols());
  double best = b.norm();  // c = 0 is always feasible when nothing is free
  for (int mask = 0; mask < (1 << k); ++mask) {
    bool has_free = true;
    for (int i = 0; i < k; ++i) has_free = has_free && (!free[i] || (mask >> i & 1));
    if (!has_free) continue;
    std::vector<int> idx;
    for (int i = 0; i < k; ++i)
      if (mask >> i & 1) idx.push_back(i);
    Eigen::MatrixXd ap(a.rows(), static_cast<Eigen::Index>(idx.size()));
    for (std::size_t q = 0; q < idx.size(); ++q)
      ap.col(static_cast<Eigen::Index>(q)) = a.col(idx[q]);
    const Eigen::VectorXd z = idx.empty()
                                  ? Eigen::VectorXd()
                                  : Eigen::VectorXd(ap.completeOrthogonalDecomposition().solve(b));
    bool ok = true;
    for (std::size_t q = 0; q < idx.size(); ++q) ok = ok && (free[idx[q]] || z(q) >= 0.0);
    if (!ok) continue;
    best = std::min(best, idx.empty() ? b.norm() : (ap * z - b).norm());
  }
  return best;
}

TEST(CertificateNnls, SmallCasesByHand) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(2, 2);
  Eigen::VectorXd b(2);
  b << 1.0, -1.0;
  // The second coefficient would be -1: clamped to 0.
  const Eigen::VectorXd c = NonNegativeLeastSquares(a, b, {false, false});
  EXPECT_DOUBLE_EQ(c(0), 1.0);
  EXPECT_DOUBLE_EQ(c(1), 0.0);
  // Free: -1 is allowed.
  const Eigen::VectorXd f = NonNegativeLeastSquares(a, b, {false, true});
  EXPECT_DOUBLE_EQ(f(1), -1.0);
}

// Deterministic pseudo-random 6 x 5 systems, some with a repeated (dependent) column and free
// coefficients: the residual must be the enumeration's, to rounding (1e-12 of |b| ~ 1).
TEST(CertificateNnls, MatchesEnumeration) {
  double seed = 0.123;
  auto next = [&seed] {
    seed = std::fmod(seed * 9301.0 + 49297.0, 233280.0);
    return seed / 233280.0 * 2.0 - 1.0;
  };
  for (int trial = 0; trial < 40; ++trial) {
    Eigen::MatrixXd a(6, 5);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 5; ++j) a(i, j) = next();
    if (trial % 3 == 0) a.col(4) = -2.0 * a.col(1);  // dependent, opposite sign
    Eigen::VectorXd b(6);
    for (int i = 0; i < 6; ++i) b(i) = next();
    std::vector<bool> free(5, false);
    if (trial % 4 == 1) free[2] = true;
    const Eigen::VectorXd c = NonNegativeLeastSquares(a, b, free);
    for (int j = 0; j < 5; ++j) {
      if (!free[j]) {
        EXPECT_GE(c(j), 0.0) << "trial " << trial;
      }
    }
    EXPECT_NEAR((a * c - b).norm(), BruteForceResidual(a, b, free), 1e-12) << "trial " << trial;
  }
}

// A three-segment ash bat, max exit speed over the taper start and the barrel radius at a
// fixed mass (the contract's example family).
DesignProblem Family() {
  DesignProblem p;
  p.bat.material = *FindMaterial("ash");
  p.three_segment = ThreeSegmentShape{0.8636, 0.0125, 0.033, 0.30, 0.55};
  p.variables = {{"three_segment.taper_start_m", 0.1, 0.5},
                 {"three_segment.barrel_radius_m", 0.028, 0.0331}};
  p.constraints.mass_kg = DesignRange::Equal(0.88);
  p.cor = 0.5;
  return p;
}

TEST(Certificate, HoldsAtTheOptimumAndNotAtTheStart) {
  const DesignProblem p = Family();
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  EXPECT_TRUE(r.certificate.checked);
  EXPECT_TRUE(r.certificate.certified);
  // Ipopt converged to tol 1e-9 on the scaled problem: the certificate's own residuals are
  // far below the default tolerances (1e-6).
  EXPECT_LE(r.certificate.stationarity, 1e-8);
  EXPECT_LE(r.certificate.feasibility, 1e-8);
  EXPECT_LE(r.certificate.complementarity, 1e-8);
  EXPECT_EQ(r.summary.error_estimate, r.certificate.stationarity);
  EXPECT_TRUE(r.certificate.multipliers_unique);
  EXPECT_DOUBLE_EQ(r.certificate.stationarity_tolerance, kDefaultStationarityTolerance);

  DesignModel model;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, nullptr));
  // The start (taper start 0.30 m, barrel 0.033 m) is not the optimum: not certified.
  const DesignCertificate start = Certify(model, model.BaseX(), CertificateTolerances{}, true);
  EXPECT_TRUE(start.checked);
  EXPECT_FALSE(start.certified);
  EXPECT_FALSE(start.failed.empty());
  // At the answer, the certificate is the answer's.
  std::vector<double> x;
  for (const DesignValue& v : r.variables) x.push_back(v.value);
  const DesignCertificate at = Certify(model, x, CertificateTolerances{}, true);
  EXPECT_TRUE(at.certified) << at.failed;
  // A stationarity tolerance below the answer's residual fails it, naming stationarity.
  CertificateTolerances strict;
  strict.stationarity = at.stationarity > 0.0 ? 0.5 * at.stationarity : 1e-300;
  if (at.stationarity > 0.0) {
    const DesignCertificate tight = Certify(model, x, strict, false);
    EXPECT_FALSE(tight.certified);
    EXPECT_NE(tight.failed.find("stationarity"), std::string::npos) << tight.failed;
  }
}

// The answer's certificate reuses the run's multipliers (Certify's `known`, certificate_runs.cpp):
// the same certificate, bit for bit, as fitting them again, at the optimum and at the start
// (not certified there); the uniqueness is still decided.
TEST(Certificate, KnownMultipliersGiveTheSameCertificateBitForBit) {
  const DesignProblem p = Family();
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  DesignModel model;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, nullptr));
  std::vector<double> answer;
  for (const DesignValue& v : r.variables) answer.push_back(v.value);
  for (const std::vector<double>& x : {answer, model.BaseX()}) {
    const DesignCertificate fitted = Certify(model, x, CertificateTolerances{}, true);
    const DesignCertificate run = Certify(model, x, CertificateTolerances{}, false);
    const DesignCertificate reused = Certify(model, x, CertificateTolerances{}, true, &run);
    ASSERT_TRUE(fitted.checked);
    EXPECT_EQ(reused.checked, fitted.checked);
    EXPECT_EQ(reused.certified, fitted.certified);
    EXPECT_EQ(reused.multipliers_unique, fitted.multipliers_unique);
    EXPECT_EQ(reused.active, fitted.active);
    EXPECT_EQ(reused.failed, fitted.failed);
    // Exact equality: the same operations on the same numbers.
    EXPECT_EQ(reused.stationarity, fitted.stationarity);
    EXPECT_EQ(reused.feasibility, fitted.feasibility);
    EXPECT_EQ(reused.complementarity, fitted.complementarity);
    EXPECT_EQ(reused.lambda, fitted.lambda);
    EXPECT_EQ(reused.z_lower, fitted.z_lower);
    EXPECT_EQ(reused.z_upper, fitted.z_upper);
  }
}

// The multi-start's choice: a start that reported convergence where the certificate fails is
// no_convergence after CertifyRuns, so a certified start is chosen over it even with a worse
// objective (here the uncertified start's objective is set above every design's).
TEST(Certificate, MultiStartPrefersACertifiedStart) {
  const DesignProblem p = Family();
  const DesignResult answer = OptimizeDesign(p);
  ASSERT_TRUE(answer.certificate.certified);
  DesignModel model;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, nullptr));
  std::vector<double> optimum;
  for (const DesignValue& v : answer.variables) optimum.push_back(v.value);
  // Start 0: 1 mm off the optimum in the taper start, claimed converged, feasible and with an
  // objective above every design's; start 1: the optimum, converged.
  std::vector<design_detail::Run> runs(2);
  runs[0].x = optimum;
  runs[0].x[0] -= 1e-3;  // off the mass, not stationary (inward: the optimum may sit at 0.5)
  ASSERT_GE(runs[0].x[0], 0.1);  // still inside the taper start's bounds (else clamped back)
  runs[0].outcome.termination = Termination::kConverged;
  runs[0].feasible = true;  // as claimed: the choice is under test, not Finish
  runs[0].violation = 0.0;
  runs[0].objective = 1e3;  // better than any design
  runs[1].x = optimum;
  runs[1].outcome.termination = Termination::kConverged;
  runs[1].feasible = true;
  runs[1].violation = 0.0;
  runs[1].objective = answer.objective_value;
  design_detail::CertifyRuns(model, DesignOptions{}, &runs);
  EXPECT_TRUE(runs[0].uncertified);
  EXPECT_EQ(runs[0].outcome.termination, Termination::kNoConvergence);
  EXPECT_NE(runs[0].outcome.message.find("first-order conditions do not hold"), std::string::npos);
  EXPECT_FALSE(runs[1].uncertified);
  EXPECT_EQ(runs[1].outcome.termination, Termination::kConverged);
  EXPECT_EQ(design_detail::ChooseRun(model, runs), 1);
}

// A 16-knot solid bat at 33 in: the bbcor drop (length_in - weight_oz <= 3) is the weight's
// floor, 30 oz, when the length is fixed.
DesignProblem Knots(double length_m) {
  DesignProblem p;
  for (int i = 0; i < 16; ++i) {
    const double x = length_m * i / 15.0;
    p.bat.knots.push_back({x, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (x / length_m - 0.55)))});
  }
  p.bat.material = *FindMaterial("ash");
  for (int i = 1; i <= 14; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.011, 0.0332});
  }
  p.constraints.rules = {RuleSet::kBbcor};
  return p;
}

TEST(CertificateMerge, DropRepeatingTheWeightIsMerged) {
  DesignProblem p = Knots(InchesToMetres(33.0));
  p.constraints.mass_kg = DesignRange::Equal(OuncesToKilograms(30.0));
  DesignModel model;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, nullptr));
  const int m = model.m();
  const std::vector<MergedConstraint> merged = MergeDuplicateConstraints(&model);
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_EQ(merged[0].name, "rules.bbcor.drop");
  EXPECT_EQ(merged[0].into, "mass_kg");
  EXPECT_EQ(model.m(), m - 1);
  for (const DesignConstraintSpec& c : model.constraints()) EXPECT_NE(c.name, "rules.bbcor.drop");
}

TEST(CertificateMerge, DropInsideTheWeightRangeOrWithAVariableLengthStays) {
  // 31 oz: the drop (weight >= 30 oz) never binds: nothing to merge.
  DesignProblem p = Knots(InchesToMetres(33.0));
  p.constraints.mass_kg = DesignRange::Equal(OuncesToKilograms(31.0));
  DesignModel model;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, nullptr));
  EXPECT_TRUE(MergeDuplicateConstraints(&model).empty());
  // The length a variable: the drop depends on it, so it is another quantity than the weight.
  DesignProblem q = Knots(InchesToMetres(33.0));
  q.constraints.mass_kg = DesignRange::Equal(OuncesToKilograms(30.0));
  q.variables.push_back({"profile.knots[15].x_m", InchesToMetres(32.0), InchesToMetres(34.0)});
  DesignModel variable;
  ASSERT_TRUE(DesignModel::Build(q, DesignOptions{}, &variable, nullptr));
  const int m = variable.m();
  EXPECT_TRUE(MergeDuplicateConstraints(&variable).empty());
  EXPECT_EQ(variable.m(), m);
}

// A barrel limit of exactly twice every radius's upper bound repeats the bounds: each knot's
// limit is merged into its variable's bounds (both would be active together); a limit 1e-6 m
// inside them is a constraint of its own and stays.
TEST(CertificateMerge, DiameterLimitRepeatingTheBoundsIsMergedIntoThem) {
  DesignProblem p = Knots(0.86);
  p.constraints.rules.clear();
  p.constraints.max_barrel_diameter_m = 2.0 * 0.0332;
  DesignModel model;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, nullptr));
  const std::vector<MergedConstraint> merged = MergeDuplicateConstraints(&model);
  ASSERT_EQ(merged.size(), 14u);  // knots 1..14 (0 and 15 are fixed: no variable moves them)
  EXPECT_EQ(merged[0].name, "max_barrel_diameter_m.knots[1]");
  EXPECT_EQ(merged[0].into, "profile.knots[1].radius_m");
  p.constraints.max_barrel_diameter_m = 2.0 * 0.0332 - 1e-6;
  DesignModel inside;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &inside, nullptr));
  EXPECT_TRUE(MergeDuplicateConstraints(&inside).empty());
}

TEST(CertificateOptions, TolerancesAreValidated) {
  for (const char* field :
       {"stationarity_tolerance", "feasibility_tolerance", "complementarity_tolerance"}) {
    for (double bad : {0.0, 1.0, -1e-6, std::nan("")}) {
      DesignOptions o;
      if (std::string(field) == "stationarity_tolerance") o.stationarity_tolerance = bad;
      if (std::string(field) == "feasibility_tolerance") o.feasibility_tolerance = bad;
      if (std::string(field) == "complementarity_tolerance") o.complementarity_tolerance = bad;
      Refusal why;
      EXPECT_FALSE(o.Validate(&why)) << field << " = " << bad;
      EXPECT_EQ(why.field, field);
    }
  }
}

}  // namespace
}  // namespace optimize_certificate_test
}  // namespace sweetspot::core
