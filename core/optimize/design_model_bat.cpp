// The design model's designs as bats (DesignModel::ShapeAt, BatAt), their sting (EvaluateSting,
// StingOf) and the model restricted to some constraints (WithConstraints). Split from
// design_model.cpp (issue 33, item 6).
#include "core/optimize/design_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <set>

#include "core/bat/geometry_integrals.hpp"
#include "core/collision/exit_speed_algebra.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/flexible/beam_frequency.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/jet.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_bbcor.hpp"
#include "core/optimize/design_integrals.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"
#include "core/units.hpp"

namespace sweetspot::core {

std::optional<ThreeSegmentShape> DesignModel::ShapeAt(const double* x) const {
  if (!base_shape_.has_value()) return std::nullopt;
  return design_detail::ThreeSegmentShapeAt(ParametersAt(x), *base_shape_);
}

Bat DesignModel::BatAt(const double* x) const {
  const std::vector<double> t = ParametersAt(x);
  const DesignParameterLayout lay{num_knots_};
  Bat bat = base_bat_;
  if (base_shape_.has_value()) {
    bat.knots = ShapeAt(x)->Knots();
  } else {
    for (int i = 0; i < num_knots_; ++i) {
      bat.knots[static_cast<std::size_t>(i)].radius_m =
          t[static_cast<std::size_t>(lay.KnotRadius(i))];
      bat.knots[static_cast<std::size_t>(i)].x_m = t[static_cast<std::size_t>(lay.KnotPosition(i))];
    }
  }
  bat.material.density_kg_m3 = t[static_cast<std::size_t>(lay.Density())];
  bat.wall_thickness_m = t[static_cast<std::size_t>(lay.WallThickness())];
  if (bat.fill.has_value()) {
    bat.fill->diameter_m = t[static_cast<std::size_t>(lay.FillDiameter())];
    bat.fill->depth_m = t[static_cast<std::size_t>(lay.FillDepth())];
    bat.fill->material.density_kg_m3 = t[static_cast<std::size_t>(lay.FillDensity())];
  }
  return bat;
}

StingEvaluation EvaluateSting(const Bat& bat, const StingScene& scene, bool refine_check,
                              ModesCache* cache) {
  StingEvaluation out;
  try {
    // A swing given by its bat speed: omega for this bat's length (the design's own).
    Swing swing;
    Refusal refusal;
    if (!ResolveSwing(scene.swing, bat.LengthM(), &swing, &refusal)) {
      out.termination = Termination::kInvalidInput;
      out.message = refusal.Message();
      out.sting_j = kNaN;
      return out;
    }
    const MassProperties p = ComputeMassProperties(bat, scene.inertia_model);
    const MaxExitSpeedResult max = ClosedFormMaxExitSpeed(
        ClosedFormProfileFor(scene.model, p, scene.ball, swing, scene.cor), bat.LengthM());
    out.sweet_spot_from_knob_m = max.position_from_knob_m;
    Scene s;
    s.bat = bat;
    s.mass_properties = p;
    s.inertia_model = scene.inertia_model;
    s.ball = scene.ball;
    s.swing = swing;
    s.cor = scene.cor;
    CollisionOptions options;
    options.flexible = scene.flexible;
    options.flexible.modes_cache = cache;
    options.flexible.impact.refine_check = refine_check && scene.flexible.impact.refine_check;
    const CollisionResult r =
        Collide(s, max.position_from_knob_m, CollisionModel::kFlexible, options);
    out.termination = r.summary.termination;
    out.message = r.summary.message;
    if (!r.summary.IsSolutionUsable() || !r.flexible.has_value()) return out;
    out.impact = *r.flexible;
    for (const std::string& w : r.summary.warnings) {
      if (std::find(out.impact.summary.warnings.begin(), out.impact.summary.warnings.end(), w) ==
          out.impact.summary.warnings.end()) {
        out.impact.summary.warnings.push_back(w);
      }
    }
    out.sting_j = r.flexible->hands_vibration_energy_j;
    out.ok = std::isfinite(out.sting_j);
    if (!out.ok) out.message = "the hands' vibration energy is not finite";
  } catch (...) {
    // Whatever is thrown (a std::exception or not): no exception leaves the evaluation.
    out.ok = false;
    out.termination = Termination::kFailure;
    out.message = InternalErrorMessage();
  }
  if (!out.ok) out.sting_j = kNaN;
  return out;
}

StingEvaluation DesignModel::StingOf(const Bat& bat, bool refine_check) const {
  return EvaluateSting(bat, sting_scene_, refine_check, sting_modes_.get());
}

DistanceEvaluation DesignModel::DistanceOf(const Bat& bat) const {
  if (distance_scene_ == nullptr) {
    DistanceEvaluation none;
    none.message = "the objective is not max_distance";
    return none;
  }
  return EvaluateDistance(bat, *distance_scene_);
}

DesignModel DesignModel::WithObjective(const DesignFunctionSpec& f, bool maximize, double scale,
                                       const std::string& unit) const {
  DesignModel copy = *this;
  copy.objective_ = f;
  copy.maximize_ = maximize;
  copy.objective_scale_ = scale > 0.0 && std::isfinite(scale) ? scale : 1.0;
  copy.objective_unit_ = unit;
  return copy;
}

DesignModel DesignModel::WithConstraints(const std::vector<int>& keep) const {
  DesignModel copy = *this;
  copy.constraints_.clear();
  for (int k : keep) copy.constraints_.push_back(constraints_[static_cast<std::size_t>(k)]);
  return copy;
}

}  // namespace sweetspot::core
