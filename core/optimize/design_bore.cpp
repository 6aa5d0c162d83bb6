// The bore's exact validity rules on a three-segment design (the shape fit's, issue 33 item 3):
// the bore inside the material at its bottom, L - d, wherever that lies on the profile, and at
// the tip. The knots' rules of design_model_constraints.cpp are conservative (every knot that can
// reach the bore); these are the fit's, used with the least-squares objective. The bottom's
// clearance is a closed form of the parameters, differentiated with the design code's AD type.
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/numerics/jet.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_model_builder.hpp"

namespace sweetspot::core {
namespace {

// The local inputs of the clearance: x1, x2, L, r1, r2, wall, diameter, depth.
constexpr int kInputs = 8;

// Their parameters in DesignParameterLayout{4} (r1 read at knot 1, r2 at knot 2: a radius
// variable sets both knots of its segment, the chain rule goes through one).
std::array<int, kInputs> BoreParameters() {
  const DesignParameterLayout lay{4};
  return {lay.KnotPosition(1), lay.KnotPosition(2), lay.KnotPosition(3), lay.KnotRadius(1),
          lay.KnotRadius(2),   lay.WallThickness(), lay.FillDiameter(),  lay.FillDepth()};
}

// keep (R(L - d) - wall) - diameter / 2 with the family's outer radius R: r1 up to x1, r2 from
// x2, linear between (a kink at each end, as the rule itself).
template <typename T>
T Clearance(const std::array<T, kInputs>& v, bool hollow) {
  const T& x1 = v[0];
  const T& x2 = v[1];
  const T y = v[2] - v[7];
  T radius = v[3];
  if (jet::Value(y) >= jet::Value(x2)) {
    radius = v[4];
  } else if (jet::Value(y) > jet::Value(x1)) {
    radius = v[3] + (v[4] - v[3]) * ((y - x1) / (x2 - x1));
  }
  const double keep = 1.0 - design_detail::kStrictMargin;
  return keep * (hollow ? radius - v[5] : radius) - 0.5 * v[6];
}

}  // namespace

bool DesignModel::BoreBottomOf(const std::vector<double>& t, double* value, double* gradient_row,
                               int stride) const {
  const std::array<int, kInputs> parameter = BoreParameters();
  using J = jet::Jet<kInputs, false>;
  std::array<J, kInputs> v;
  for (int i = 0; i < kInputs; ++i) {
    const auto q = static_cast<std::size_t>(parameter[static_cast<std::size_t>(i)]);
    v[static_cast<std::size_t>(i)] = J::Variable(t[q], i);
  }
  const J c = Clearance(v, hollow_);
  *value = c.v;
  if (gradient_row != nullptr) {
    for (int i = 0; i < kInputs; ++i) {
      const auto q = static_cast<std::size_t>(parameter[static_cast<std::size_t>(i)]);
      const int j = parameter_variable_[q];
      if (j >= 0)
        gradient_row[j * stride] += c.g[static_cast<std::size_t>(i)] * parameter_scale_[q];
    }
  }
  return std::isfinite(c.v);
}

void DesignModel::AddBoreBottomHessian(const std::vector<double>& t, double weight,
                                       Eigen::MatrixXd* h) const {
  const std::array<int, kInputs> parameter = BoreParameters();
  using J = jet::Jet<kInputs, true>;
  std::array<J, kInputs> v;
  for (int i = 0; i < kInputs; ++i) {
    const auto q = static_cast<std::size_t>(parameter[static_cast<std::size_t>(i)]);
    v[static_cast<std::size_t>(i)] = J::Variable(t[q], i);
  }
  const J c = Clearance(v, hollow_);
  // The inputs are linear in x (a parameter is its coefficient times its variable).
  for (int a = 0; a < kInputs; ++a) {
    const auto qa = static_cast<std::size_t>(parameter[static_cast<std::size_t>(a)]);
    const int ja = parameter_variable_[qa];
    if (ja < 0) continue;
    for (int b = 0; b < kInputs; ++b) {
      const auto qb = static_cast<std::size_t>(parameter[static_cast<std::size_t>(b)]);
      const int jb = parameter_variable_[qb];
      if (jb < 0) continue;
      (*h)(ja, jb) += weight * c.h[static_cast<std::size_t>(a * kInputs + b)] *
                      parameter_scale_[qa] * parameter_scale_[qb];
    }
  }
}

namespace design_detail {

bool ModelBuilder::BoreConstraints(double keep) {
  if (!problem.three_segment.has_value() || problem.objective != DesignObjective::kLeastSquares) {
    return false;
  }
  // At the tip: the bore inside r2 (less the wall).
  std::vector<std::pair<int, double>> tip = {{lay.KnotRadius(2), keep}, {lay.FillDiameter(), -0.5}};
  if (model.hollow_) tip.push_back({lay.WallThickness(), -keep});
  AddLinear("validity.fill.diameter_m.tip", "validity.fill.diameter_m.tip",
            "validity.fill.diameter_m.tip", "m", std::move(tip), 0.0, 0.0, kInf, false, true);
  // At the bottom, where a variable can move it.
  std::vector<std::pair<int, double>> inputs;
  for (int p : BoreParameters()) inputs.push_back({p, 1.0});
  if (Depends(inputs)) {
    AddNonlinear("validity.fill.diameter_m.bottom", "m", DesignFunction::kBoreBottom, 0.0, kInf);
    DesignConstraintSpec& c = model.constraints_.back();
    c.min_name = c.max_name = c.name;
    c.property = false;  // validity, not a mass property
  }
  return true;
}

}  // namespace design_detail
}  // namespace sweetspot::core
