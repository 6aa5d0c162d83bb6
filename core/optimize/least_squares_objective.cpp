// The least-squares objective's checks and value. See least_squares_objective.hpp.
#include "core/optimize/least_squares_objective.hpp"

#include <cmath>
#include <string>

#include "core/optimize/design_model_builder.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {

bool LeastSquaresTargets::Validate(Refusal* why) const {
  if (!mass_kg.has_value() && !balance_point_m.has_value()) {
    return Refuse(why, TextRefusal("least_squares", "must give mass_kg, balance_point_m or both"));
  }
  const auto positive = [why](const char* field, double v) {
    return std::isfinite(v) && v > 0.0 ? true
                                       : Refuse(why, field, v, "must be finite and positive");
  };
  if (mass_kg.has_value() && (!positive("least_squares.mass_kg", *mass_kg) ||
                              !positive("least_squares.mass_scale_kg", mass_scale_kg))) {
    return false;
  }
  if (balance_point_m.has_value() &&
      (!positive("least_squares.balance_point_m", *balance_point_m) ||
       !positive("least_squares.balance_point_scale_m", balance_point_scale_m))) {
    return false;
  }
  if (!(tolerance > 0.0 && tolerance <= 0.1)) {
    return Refuse(why, "least_squares.tolerance", tolerance, "must be in (0, 0.1]");
  }
  return true;
}

double LeastSquaresTargets::Value(double mass, double balance_point) const {
  double phi = 0.0;
  if (mass_kg.has_value()) {
    const double r = (mass - *mass_kg) / mass_scale_kg;
    phi += r * r;
  }
  if (balance_point_m.has_value()) {
    const double r = (balance_point - *balance_point_m) / balance_point_scale_m;
    phi += r * r;
  }
  return phi;
}

namespace design_detail {

bool ModelBuilder::LeastSquaresObjective() {
  const bool least_squares = problem.objective == DesignObjective::kLeastSquares;
  if (!least_squares) {
    if (!problem.least_squares.has_value()) return true;
    return Refuse(why, TextRefusal("least_squares",
                                   "applies only to the objective least_squares (objective is " +
                                       std::string(DesignObjectiveName(problem.objective)) + ")"));
  }
  if (!problem.least_squares.has_value()) {
    return Refuse(why,
                  TextRefusal("least_squares", "must be given with the objective least_squares"));
  }
  if (!problem.least_squares->Validate(why)) return false;
  model.least_squares_ = problem.least_squares;
  return true;
}

}  // namespace design_detail
}  // namespace sweetspot::core
