// The certificate's cost beside the solve it certifies (core/optimize/certificate.*): the merge
// of duplicated constraints (once per request, before the solve) and the certificate with its
// uniqueness check (at the answer), on the n-knot problem of bench/scipy_peers.py's design16
// (Ipopt, exact Hessian). Arg: knots.
// Run: build/bench/sweetspot_bench_core --benchmark_filter='Certif|MergeDuplicate'
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/certificate.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the bench programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_certificate {
namespace {

DesignProblem CertificateKnotProblem(int n) {
  DesignProblem p;
  const double length = 0.86;
  for (int i = 0; i < n; ++i) {
    const double x = length * i / (n - 1);
    p.bat.knots.push_back({x, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (x / length - 0.55)))});
  }
  p.bat.material = *FindMaterial("ash");
  for (int i = 1; i <= n - 2; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.011, 0.0332});
  }
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  p.constraints.balance_point_m = DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = InchesToMetres(2.61);
  p.constraints.min_handle_diameter_m = InchesToMetres(0.9);
  p.constraints.taper = TaperRule::kNonDecreasing;
  p.model = CollisionModel::kRigidPivot;
  return p;
}

DesignOptions ExactHessian() {
  DesignOptions o;
  o.hessian = HessianMode::kExact;
  return o;
}

// The whole solve (the merge and every certificate included).
void BM_CertifiedSolve(benchmark::State& state) {
  const DesignProblem p = CertificateKnotProblem(static_cast<int>(state.range(0)));
  DesignResult r;
  for (auto _ : state) {
    r = OptimizeDesign(p, ExactHessian());
    benchmark::DoNotOptimize(r);
  }
  state.counters["certified"] = r.certificate.certified ? 1 : 0;
}
BENCHMARK(BM_CertifiedSolve)->Arg(16)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

void BM_MergeDuplicateConstraints(benchmark::State& state) {
  const DesignProblem p = CertificateKnotProblem(static_cast<int>(state.range(0)));
  DesignModel model;
  DesignModel::Build(p, ExactHessian(), &model, nullptr);
  for (auto _ : state) {
    DesignModel copy = model;
    benchmark::DoNotOptimize(design_detail::MergeDuplicateConstraints(&copy));
  }
}
BENCHMARK(BM_MergeDuplicateConstraints)->Arg(16)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

// The answer's certificate with the uniqueness check, at the optimum.
void BM_CertifyAnswer(benchmark::State& state) {
  const DesignProblem p = CertificateKnotProblem(static_cast<int>(state.range(0)));
  const DesignResult r = OptimizeDesign(p, ExactHessian());
  DesignModel model;
  DesignModel::Build(p, ExactHessian(), &model, nullptr);
  std::vector<double> x;
  for (const DesignValue& v : r.variables) x.push_back(v.value);
  for (auto _ : state) {
    benchmark::DoNotOptimize(design_detail::Certify(model, x, {}, true));
  }
}
BENCHMARK(BM_CertifyAnswer)->Arg(16)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench_core_certificate
}  // namespace sweetspot::core
