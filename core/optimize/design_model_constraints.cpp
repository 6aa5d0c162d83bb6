// DesignModel::Build's constraints, by concern: length, mass properties and drop, diameters,
// taper, the cup of a wooden bat, and the validity of the bat and its fill (the frequency, the
// barrel COR and the bbcor rule: design_model_physics.cpp).
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/ball/ball_catalogue.hpp"
#include "core/collision/barrel.hpp"
#include "core/flexible/beam_frequency.hpp"
#include "core/flexible/modes.hpp"
#include "core/optimize/design_bbcor.hpp"
#include "core/optimize/design_model_builder.hpp"
#include "core/units.hpp"

namespace sweetspot::core::design_detail {

// True when a variable changes the linear function `terms`.
bool ModelBuilder::Depends(const std::vector<std::pair<int, double>>& terms) const {
  for (const auto& [idx, k] : terms) {
    if (k != 0.0 && model.parameter_variable_[static_cast<std::size_t>(idx)] >= 0) return true;
  }
  return false;
}

// The least and the largest value parameter `idx` can take within the variables' bounds (its
// coefficient times the bounds of its variable: a scaled field's base value is not 0, and the
// bounds' order is kept or swapped by its sign); the base value twice for a fixed parameter.
std::pair<double, double> ModelBuilder::ParamRange(int idx) const {
  const auto i = static_cast<std::size_t>(idx);
  const int j = model.parameter_variable_[i];
  if (j < 0) return {Param(idx), Param(idx)};
  const DesignVariableSpec& v = model.variables_[static_cast<std::size_t>(j)];
  const double k = model.parameter_scale_[i];
  const double a = k * v.lower;
  const double b = k * v.upper;
  return {std::min(a, b), std::max(a, b)};
}

double ModelBuilder::ParamLower(int idx) const { return ParamRange(idx).first; }

double ModelBuilder::ParamUpper(int idx) const { return ParamRange(idx).second; }

// The linear function's value at the base design.
double ModelBuilder::LinearValue(const std::vector<std::pair<int, double>>& terms,
                                 double constant) const {
  double v = constant;
  for (const auto& [idx, k] : terms) v += k * Param(idx);
  return v;
}

// Adds a linear constraint, or checks it now when no variable changes it.
void ModelBuilder::AddLinear(const std::string& name, const std::string& min_name,
                             const std::string& max_name, const std::string& unit,
                             std::vector<std::pair<int, double>> terms, double constant,
                             double lower, double upper, bool property, bool skip_if_fixed) {
  DesignConstraintSpec c;
  c.name = name;
  c.min_name = min_name;
  c.max_name = max_name;
  c.unit = unit;
  c.f.function = DesignFunction::kLinear;
  c.f.terms = std::move(terms);
  c.f.constant = constant;
  c.lower = lower;
  c.upper = upper;
  c.property = property;
  if (!Depends(c.f.terms)) {
    if (skip_if_fixed) return;
    const double v = LinearValue(c.f.terms, c.f.constant);
    const double slack = 1e-12 * std::max({1.0, std::abs(lower) < kInf ? std::abs(lower) : 0.0,
                                           std::abs(upper) < kInf ? std::abs(upper) : 0.0});
    if (v < lower - slack || v > upper + slack) {
      const std::string& n = lower == upper ? name : (v < lower ? min_name : max_name);
      model.fixed_violations_.push_back({n, n + " = " + Num(v) + (unit.empty() ? "" : " " + unit) +
                                                " must be " + RangeText(lower, upper) +
                                                ", and no design variable changes it"});
    }
    return;
  }
  model.constraints_.push_back(std::move(c));
}

// Adds a nonlinear (mass property) constraint.
void ModelBuilder::AddNonlinear(const std::string& name, const std::string& unit, DesignFunction f,
                                double lower, double upper) {
  DesignConstraintSpec c;
  c.name = name;
  c.min_name = lower == upper ? name : name + ".min";
  c.max_name = lower == upper ? name : name + ".max";
  c.unit = unit;
  c.f.function = f;
  c.lower = lower;
  c.upper = upper;
  c.property = true;
  model.constraints_.push_back(std::move(c));
}

// A range from the request, checked.
bool ModelBuilder::RangeOf(const char* field, const DesignRange& r, double cap, double* lower,
                           double* upper) {
  *lower = r.min.value_or(-kInf);
  *upper = r.max.value_or(kInf);
  if (!r.min.has_value() && !r.max.has_value()) {
    return Refuse(why, TextRefusal(std::string("constraints.") + field, "give min, max or both"));
  }
  if (r.min.has_value() && !std::isfinite(*r.min)) {
    return Refuse(why, std::string("constraints.") + field + ".min", *r.min, "must be finite");
  }
  if (r.max.has_value() && !std::isfinite(*r.max)) {
    return Refuse(why, std::string("constraints.") + field + ".max", *r.max, "must be finite");
  }
  // Each limit in (0, cap]; an equality (a number in the request) is named without .min.
  const std::string name = std::string("constraints.") + field;
  if (r.min.has_value() && !CheckInRange(why, r.IsEquality() ? name : name + ".min", *r.min, 0.0,
                                         cap, /*lo_open=*/true)) {
    return false;
  }
  if (r.max.has_value() && !CheckInRange(why, name + ".max", *r.max, 0.0, cap, true)) return false;
  if (*lower > *upper) {
    return Refuse(
        why, std::string("constraints.") + field + ".max", *upper,
        "must not be less than constraints." + std::string(field) + ".min = " + Num(*lower));
  }
  return true;
}

// Length: the request's range and the rules' maximum.
bool ModelBuilder::LengthConstraint() {
  double lower = -kInf, upper = kInf;
  std::string max_name = "length_m.max";
  bool equality = false;
  if (cons.length_m.has_value()) {
    if (!RangeOf("length_m", *cons.length_m, kMaxBatLengthM, &lower, &upper)) return false;
    equality = cons.length_m->IsEquality();
  }
  for (RuleSet rule : cons.rules) {
    const RuleSetLimits limits = LimitsOf(rule);
    if (!limits.max_length_m.has_value() || !(*limits.max_length_m < upper)) continue;
    const std::string rule_name = std::string("rules.") + RuleSetName(rule) + ".length";
    if (equality) {
      if (lower > *limits.max_length_m) {
        model.fixed_violations_.push_back({"length_m", "length_m = " + Num(lower) + " m exceeds " +
                                                           rule_name + ": at most " +
                                                           Num(*limits.max_length_m) + " m"});
      }
      continue;
    }
    upper = *limits.max_length_m;
    max_name = rule_name;
  }
  if (lower > upper) {
    model.fixed_violations_.push_back(
        {"length_m.min",
         "length_m.min = " + Num(lower) + " m exceeds " + max_name + " = " + Num(upper) + " m"});
  } else if (std::isfinite(lower) || std::isfinite(upper)) {
    const std::string name = equality || cons.length_m.has_value() ? "length_m" : max_name;
    AddLinear(name, equality ? name : "length_m.min", equality ? name : max_name, "m",
              {{lay.KnotPosition(model.num_knots_ - 1), 1.0}}, 0.0, lower, upper, true, false);
  }
  return true;
}

// Mass properties and the rules' drop.
bool ModelBuilder::PropertyConstraints() {
  struct PropertyField {
    const char* name;
    const char* unit;
    const std::optional<DesignRange>* range;
    DesignFunction f;
    double cap;  // the largest limit, unit of the quantity
  };
  const PropertyField properties[] = {
      {"mass_kg", "kg", &cons.mass_kg, DesignFunction::kMass, kMaxDesignMassKg},
      {"balance_point_m", "m", &cons.balance_point_m, DesignFunction::kBalancePoint,
       kMaxBatLengthM},
      {"moi_six_inch_kg_m2", "kg_m2", &cons.moi_six_inch_kg_m2, DesignFunction::kMoiSixInch,
       kMaxDesignMoiKgM2},
  };
  for (const PropertyField& pf : properties) {
    if (!pf.range->has_value()) continue;
    double lower = 0.0, upper = 0.0;
    if (!RangeOf(pf.name, **pf.range, pf.cap, &lower, &upper)) return false;
    AddNonlinear(pf.name, pf.unit, pf.f, lower, upper);
  }
  for (RuleSet rule : cons.rules) {
    const RuleSetLimits limits = LimitsOf(rule);
    if (limits.max_drop.has_value()) {
      DesignConstraintSpec c;
      c.name = c.min_name = c.max_name = std::string("rules.") + RuleSetName(rule) + ".drop";
      c.unit = "";
      c.f.function = DesignFunction::kDrop;
      c.upper = *limits.max_drop;
      c.property = true;
      model.constraints_.push_back(std::move(c));
    }
  }

  return true;
}

// The knots whose radii the diameter and wall constraints bound.
void ModelBuilder::RadiusKnots() {
  if (problem.three_segment.has_value()) {
    radius_knots = {0, 2};
    knot_suffix = {".three_segment.handle_radius_m", ".three_segment.barrel_radius_m"};
  } else {
    for (int i = 0; i < model.num_knots_; ++i) {
      radius_knots.push_back(i);
      knot_suffix.push_back(".knots[" + std::to_string(i) + "]");
    }
  }
}

// Diameters: the tightest of the request and the rules.
bool ModelBuilder::DiameterConstraints() {
  double max_d = kInf;
  std::string max_name;
  if (cons.max_barrel_diameter_m.has_value()) {
    if (!CheckInRange(why, "constraints.max_barrel_diameter_m", *cons.max_barrel_diameter_m, 0.0,
                      kMaxDesignDiameterM, /*lo_open=*/true)) {
      return false;
    }
    max_d = *cons.max_barrel_diameter_m;
    max_name = "max_barrel_diameter_m";
  }
  for (RuleSet rule : cons.rules) {
    const double d = LimitsOf(rule).max_diameter_m;
    if (d < max_d) {
      max_d = d;
      max_name = std::string("rules.") + RuleSetName(rule) + ".diameter";
    }
  }
  if (std::isfinite(max_d)) {
    for (std::size_t q = 0; q < radius_knots.size(); ++q) {
      const std::string n = max_name + knot_suffix[q];
      AddLinear(n, n, n, "m", {{lay.KnotRadius(radius_knots[q]), 2.0}}, 0.0, -kInf, max_d, false,
                false);
    }
  }
  if (cons.min_handle_diameter_m.has_value()) {
    if (!CheckInRange(why, "constraints.min_handle_diameter_m", *cons.min_handle_diameter_m, 0.0,
                      kMaxDesignDiameterM, /*lo_open=*/true)) {
      return false;
    }
    std::vector<std::size_t> knots;
    if (!HandleRegionKnots(&knots)) return false;
    for (std::size_t q : knots) {
      const std::string n = "min_handle_diameter_m" + knot_suffix[q];
      AddLinear(n, n, n, "m", {{lay.KnotRadius(radius_knots[q]), 2.0}}, 0.0,
                *cons.min_handle_diameter_m, kInf, false, false);
    }
  } else if (cons.handle_region_from_knob_m.has_value()) {
    return Refuse(why, TextRefusal("constraints.handle_region_from_knob_m",
                                   "needs constraints.min_handle_diameter_m"));
  }
  return true;
}

// The knots (indices into radius_knots) the minimum diameter bounds.
bool ModelBuilder::HandleRegionKnots(std::vector<std::size_t>* out) {
  out->clear();
  if (!cons.handle_region_from_knob_m.has_value()) {
    for (std::size_t q = 0; q < radius_knots.size(); ++q) out->push_back(q);
    return true;
  }
  const auto [from, to] = *cons.handle_region_from_knob_m;
  if (!CheckInRange(why, "constraints.handle_region_from_knob_m[0]", from, 0.0, kMaxBatLengthM)) {
    return false;
  }
  if (!CheckInRange(why, "constraints.handle_region_from_knob_m[1]", to, 0.0, kMaxBatLengthM,
                    /*lo_open=*/true)) {
    return false;
  }
  if (!(to > from)) {
    return Refuse(why, "constraints.handle_region_from_knob_m[1]", to,
                  "must be greater than constraints.handle_region_from_knob_m[0] = " + Num(from));
  }
  // The least and largest position a knot can take within the variables' bounds.
  auto lower_of = [&](int k) { return ParamLower(lay.KnotPosition(k)); };
  auto upper_of = [&](int k) { return ParamUpper(lay.KnotPosition(k)); };
  const int last = model.num_knots_ - 1;
  if (problem.three_segment.has_value()) {
    // r1 sets the radius on [0, x2) (the handle and the taper), r2 on (x1, L].
    if (from < upper_of(2)) out->push_back(0);
    if (to > lower_of(1)) out->push_back(1);
    return true;
  }
  // Knot k sets the radius on (x(k-1), x(k+1)) (from the knob for k = 0, to the tip for the
  // last): constrained when that interval can meet [from, to].
  for (std::size_t q = 0; q < radius_knots.size(); ++q) {
    const int k = radius_knots[q];
    const bool starts_before_end = k == 0 || lower_of(k - 1) < to;
    const bool ends_after_start = k == last || upper_of(k + 1) > from;
    if (starts_before_end && ends_after_start) out->push_back(q);
  }
  return true;
}

// Taper: the knot pairs it bounds (refused when the request's knots are not in the profile).
bool ModelBuilder::TaperPairs(std::vector<std::pair<int, int>>* pairs_out,
                              std::vector<std::string>* suffix_out) {
  if (cons.taper == TaperRule::kMaxSlope &&
      !CheckInRange(why, "constraints.max_taper_slope", cons.max_taper_slope, 0.0, kMaxTaperSlope,
                    /*lo_open=*/true)) {
    return false;
  }

  std::vector<std::pair<int, int>> pairs;  // knot a, knot b (a before b)
  std::vector<std::string> suffix;
  if (problem.three_segment.has_value()) {
    // The shape's own pair; the knot indices must still be indices (or -1 for the last).
    if (cons.taper_first_knot < 0) {
      return Refuse(why, IntegerRefusal("constraints.taper_first_knot", cons.taper_first_knot,
                                        "must be a knot index (>= 0)"));
    }
    if (cons.taper_last_knot < -1) {
      return Refuse(why, IntegerRefusal("constraints.taper_last_knot", cons.taper_last_knot,
                                        "must be -1 (the last knot) or a knot index"));
    }
    pairs = {{1, 2}};
    suffix = {".three_segment"};
  } else {
    const int first = cons.taper_first_knot;
    const int last = cons.taper_last_knot < 0 ? model.num_knots_ - 1 : cons.taper_last_knot;
    if (first < 0 || first >= model.num_knots_) {
      return Refuse(why, "constraints.taper_first_knot", first,
                    "must be a knot index in [0, " + std::to_string(model.num_knots_ - 1) + "]");
    }
    if (last <= first || last >= model.num_knots_) {
      return Refuse(why, "constraints.taper_last_knot", cons.taper_last_knot,
                    "must be -1 (the last knot) or a knot index in (" + std::to_string(first) +
                        ", " + std::to_string(model.num_knots_ - 1) + "]");
    }
    for (int i = first; i < last; ++i) {
      pairs.push_back({i, i + 1});
      suffix.push_back(".knots[" + std::to_string(i) + "]");
    }
  }
  *pairs_out = std::move(pairs);
  *suffix_out = std::move(suffix);
  return true;
}

// Taper.
bool ModelBuilder::TaperConstraints() {
  if (cons.taper == TaperRule::kNone) return true;
  std::vector<std::pair<int, int>> pairs;  // knot a, knot b (a before b)
  std::vector<std::string> suffix;
  if (!TaperPairs(&pairs, &suffix)) return false;
  for (std::size_t q = 0; q < pairs.size(); ++q) {
    const auto [a, b] = pairs[q];
    if (cons.taper == TaperRule::kNonDecreasing) {
      const std::string n = "taper" + suffix[q];
      AddLinear(n, n, n, "m", {{lay.KnotRadius(b), 1.0}, {lay.KnotRadius(a), -1.0}}, 0.0, 0.0, kInf,
                false, false);
    } else {
      const double s = cons.max_taper_slope;
      const std::string rise = "max_slope" + suffix[q] + ".rise";
      const std::string fall = "max_slope" + suffix[q] + ".fall";
      AddLinear(rise, rise, rise, "m",
                {{lay.KnotRadius(b), 1.0},
                 {lay.KnotRadius(a), -1.0},
                 {lay.KnotPosition(b), -s},
                 {lay.KnotPosition(a), s}},
                0.0, -kInf, 0.0, false, false);
      AddLinear(fall, fall, fall, "m",
                {{lay.KnotRadius(b), -1.0},
                 {lay.KnotRadius(a), 1.0},
                 {lay.KnotPosition(b), -s},
                 {lay.KnotPosition(a), s}},
                0.0, -kInf, 0.0, false, false);
    }
  }
  return true;
}

// Rules: the cup of a solid wooden bat.
void ModelBuilder::CupConstraints() {
  for (RuleSet rule : cons.rules) {
    const RuleSetLimits limits = LimitsOf(rule);
    if (!limits.solid_wood_only || !base.fill.has_value()) continue;
    const std::string prefix = std::string("rules.") + RuleSetName(rule);
    if (limits.max_cup_depth_m.has_value()) {
      const std::string n = prefix + ".cup_depth";
      AddLinear(n, n, n, "m", {{lay.FillDepth(), 1.0}}, 0.0, -kInf, *limits.max_cup_depth_m, false,
                false);
    }
    if (limits.min_cup_diameter_m.has_value() && limits.max_cup_diameter_m.has_value()) {
      const std::string n = prefix + ".cup_diameter";
      AddLinear(n, n + ".min", n + ".max", "m", {{lay.FillDiameter(), 1.0}}, 0.0,
                *limits.min_cup_diameter_m, *limits.max_cup_diameter_m, false, false);
    }
  }
}

// Validity of the bat (only where a variable can break it; the base bat is valid).
void ModelBuilder::ValidityConstraints() {
  const double keep = 1.0 - kStrictMargin;
  if (problem.three_segment.has_value()) {
    AddLinear("validity.three_segment.taper_order", "validity.three_segment.taper_order",
              "validity.three_segment.taper_order", "m",
              {{lay.KnotPosition(2), 1.0}, {lay.KnotPosition(1), -1.0}}, 0.0, 0.0, kInf, false,
              true);
    AddLinear("validity.three_segment.taper_end", "validity.three_segment.taper_end",
              "validity.three_segment.taper_end", "m",
              {{lay.KnotPosition(3), 1.0}, {lay.KnotPosition(2), -1.0}}, 0.0, 0.0, kInf, false,
              true);
  } else {
    for (int i = 1; i < model.num_knots_; ++i) {
      const double base_gap = Param(lay.KnotPosition(i)) - Param(lay.KnotPosition(i - 1));
      const std::string n = "validity.knots[" + std::to_string(i) + "].x_m.gap";
      AddLinear(n, n, n, "m", {{lay.KnotPosition(i), 1.0}, {lay.KnotPosition(i - 1), -1.0}}, 0.0,
                std::min(options.min_knot_gap_m, base_gap), kInf, false, true);
    }
  }
  if (model.hollow_) {
    for (std::size_t q = 0; q < radius_knots.size(); ++q) {
      const std::string n = "validity.wall_thickness_m" + knot_suffix[q];
      AddLinear(n, n, n, "m",
                {{lay.KnotRadius(radius_knots[q]), keep}, {lay.WallThickness(), -1.0}}, 0.0, 0.0,
                kInf, false, true);
    }
  }
  if (model.has_fill_) FillValidityConstraints(keep);
}

// Validity of the fill: its depth and its bore inside the material.
void ModelBuilder::FillValidityConstraints(double keep) {
  const int last = lay.KnotPosition(model.num_knots_ - 1);
  AddLinear("validity.fill.depth_m", "validity.fill.depth_m", "validity.fill.depth_m", "m",
            {{last, 1.0}, {lay.FillDepth(), -1.0}}, 0.0, 0.0, kInf, false, true);
  if (BoreConstraints(keep)) return;  // the shape fit's exact rules (design_bore.cpp)
  // The bore must stay inside the material over its depth. The profile is piecewise linear,
  // so its least radius over [L - d, L] is at a knot inside or at the bore's bottom, which
  // lies on the segment of the last knot at or before it: constrain every knot that can be
  // at or after the knot before the bottom (conservative when positions or depth vary).
  auto upper_of = [&](int idx) { return ParamUpper(idx); };
  auto lower_of = [&](int idx) { return ParamLower(idx); };
  const double bottom_min = lower_of(last) - upper_of(lay.FillDepth());
  int first = model.num_knots_ - 1;
  while (first > 0 && upper_of(lay.KnotPosition(first)) >= bottom_min) --first;
  // `first` is now the last knot that is surely before the bottom (or knot 0).
  std::set<int> radius_params;
  for (int i = first; i < model.num_knots_; ++i) radius_params.insert(lay.KnotRadius(i));
  for (std::size_t q = 0; q < radius_knots.size(); ++q) {
    // For a three-segment design knots 0-1 share r1 and 2-3 share r2.
    const int k = radius_knots[q];
    const bool used =
        radius_params.count(lay.KnotRadius(k)) > 0 ||
        (problem.three_segment.has_value() && radius_params.count(lay.KnotRadius(k + 1)) > 0);
    if (!used) continue;
    const std::string n = "validity.fill.diameter_m" + knot_suffix[q];
    std::vector<std::pair<int, double>> terms = {{lay.KnotRadius(k), keep},
                                                 {lay.FillDiameter(), -0.5}};
    if (model.hollow_) terms.push_back({lay.WallThickness(), -keep});
    AddLinear(n, n, n, "m", std::move(terms), 0.0, 0.0, kInf, false, true);
  }
}

}  // namespace sweetspot::core::design_detail
