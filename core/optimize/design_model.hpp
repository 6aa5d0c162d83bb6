// Internal to core/optimize (public only so that tests can check it): the design problem as a
// smooth nonlinear program. No solver headers here.
//
// Parameters: the knot list of the profile (a three-segment design is the 4 knots (0, r1),
// (x1, r1), (x2, r2), (L, r2), coincident knots allowed: the integrals never divide by a
// segment's length, so the map from (L, r1, r2, x1, x2) to the mass properties is smooth
// everywhere, including x1 = 0, x2 = L and x1 = x2 where ThreeSegmentShape::Knots() merges
// knots), then density, wall, fill diameter, depth and density (DesignParameterLayout order).
// Each variable sets one or more of these parameters, each parameter = its coefficient times
// the variable (1; a scale variable's field: the field's base value), so every derivative
// chained from parameters to variables carries the coefficient (a Hessian term: both).
//
// Mass integrals: P = (M, S1, S2, L) with S1, S2 the first and second moments about a fixed
// reference point c0 (the base design's balance point; S2 includes the cross-sections' own
// moments for the rigid-body model). Every property is a closed form in P: C = c0 + S1 / M,
// I(p) = S2 + 2 (c0 - p) S1 + (c0 - p)^2 M. Gradients come from forward-mode AD per segment
// (6 local parameters) and per fill (5), Hessians from second-order forward-mode AD of the
// same code (jet.hpp): H = (dP/dx)^T W (dP/dx) + sum_c w_c d2P_c/dx2.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/bat/bat.hpp"
#include "core/flexible/modes_cache.hpp"
#include "core/optimize/design_distance.hpp"
#include "core/optimize/design_problem.hpp"

namespace sweetspot::core {

struct FixedMeshBeam;  // core/flexible/beam_frequency.hpp
class LiftedDesignNlp;  // core/optimize/lifted_nlp.hpp

namespace design_detail {
struct ModelBuilder;        // DesignModel::Build's steps (design_model_build.cpp)
struct BbcorConstants;      // design_bbcor.hpp
struct BarrelCorConstants;  // design_bbcor.hpp
struct IntegralContext;     // design_integrals.hpp
struct Integrals;           // design_integrals.hpp
template <typename J>
struct WallInputs;  // design_model.cpp
}  // namespace design_detail

/// A smooth function of the design (internal).
enum class DesignFunction {
  kLinear,        ///< sum coefficient * parameter + constant.
  kMass,          ///< M, kg.
  kBalancePoint,  ///< C, m from the knob.
  kMoiSixInch,    ///< I about 0.1524 m, kg·m².
  kDrop,          ///< length_in - weight_oz (dimensionless).
  /// The first free-free bending frequency on the fixed mesh, Hz (core/flexible/beam_frequency).
  kFirstFrequency,
  /// The BBCOR by the NCAA protocol (ComputeBbcor's quasi-static trampoline, design_bbcor.hpp):
  /// the `bbcor` rule's constraint on a hollow design (dimensionless).
  kBbcor,
  /// The bore's clearance at its bottom on a three-segment design, m: keep (R(L - d) - wall) -
  /// diameter / 2, R the outer radius, keep = 1 - kStrictMargin (>= 0: the bore inside the
  /// material there; the shape fit's exact rule, design_bore.cpp).
  kBoreBottom,
  kObjective,  ///< The problem's objective, in its unit.
};

/// A function of the design: what constraints and objectives are made of (internal).
struct DesignFunctionSpec {
  DesignFunction function = DesignFunction::kLinear;  ///< Which function.
  std::vector<std::pair<int, double>> terms;          ///< kLinear: (parameter index, coefficient).
  double constant = 0.0;                              ///< kLinear: constant term.
};

/// A constraint lower <= f(x) <= upper (internal).
struct DesignConstraintSpec {
  std::string name;      ///< Equality name / base name, e.g. "mass_kg".
  std::string min_name;  ///< Name when the lower limit is active, e.g. "balance_point_m.min".
  std::string max_name;  ///< Name when the upper limit is active.
  std::string unit;      ///< "kg", "m", "kg_m2", "" (dimensionless).
  DesignFunctionSpec f;  ///< The constrained function.
  double lower = -std::numeric_limits<double>::infinity();  ///< Lower limit (unit).
  double upper = std::numeric_limits<double>::infinity();   ///< Upper limit (unit).
  double scale = 1.0;     ///< Typical magnitude (unit): the NLP sees f / scale.
  bool property = false;  ///< A mass-property or length constraint (analysed for conflicts).
};

/// A design variable (internal).
struct DesignVariableSpec {
  std::string path;             ///< Its path.
  DesignVariableRef ref;        ///< Parsed path.
  double lower = 0.0;           ///< Bound, field unit.
  double upper = 0.0;           ///< Bound, field unit.
  double base = 0.0;            ///< The base design's value (not clamped); 1 for a scale.
  std::vector<int> parameters;  ///< Parameter indices it sets (its own and the linked fields').
  std::vector<std::string> linked_paths;  ///< The fields set to the same value.
  /// A scale variable (path is its name, ref unused): the fields it scales, and their base
  /// design's values (each field = its base value times the variable).
  bool scale = false;
  std::vector<std::string> scale_paths;  ///< The scaled fields (scale only).
  std::vector<double> scale_bases;       ///< Their base values, field unit (scale only).
};

/// One constraint's gradient by its nonzero entries: (variable index, d g / d x_j in the
/// constraint's unit per the variable's unit), by increasing index (internal).
using DesignGradientRow = std::vector<std::pair<int, double>>;

/// Values (and gradients) of the objective and constraints at a point, in user units.
struct DesignPoint {
  double objective = 0.0;              ///< F, objective unit.
  std::vector<double> constraints;     ///< g_k, unit of each.
  Eigen::VectorXd objective_gradient;  ///< dF/dx (when requested).
  Eigen::MatrixXd jacobian;            ///< dg/dx, m x n (when requested; not by EvaluateRows).
  /// dg/dx by rows, their nonzero entries only (EvaluateRows; empty otherwise): each entry has
  /// the same bits as the dense jacobian's.
  std::vector<DesignGradientRow> jacobian_rows;
  double mass_kg = 0.0;                ///< M.
  double balance_point_m = 0.0;        ///< C.
  double moi_six_inch_kg_m2 = 0.0;     ///< I6.
  double length_m = 0.0;               ///< L.
};

/// The scene of a sting evaluation (min_sting), taken from the DesignProblem.
struct StingScene {
  Ball ball;                                              ///< The ball.
  Swing swing;                                            ///< Pivot, omega and the hands.
  double cor = 0.5;                                       ///< The COR used.
  InertiaModel inertia_model = InertiaModel::kRigidBody;  ///< For the mass properties.
  FlexibleOptions flexible;                               ///< The flexible beam's settings.
  CollisionModel model = CollisionModel::kRigidPivot;     ///< The sweet spot's closed form.
};

/// One sting evaluation (internal).
struct StingEvaluation {
  bool ok = false;      ///< False when the sting could not be computed.
  std::string message;  ///< Why not (the flexible model's or the scene's message).
  Termination termination = Termination::kFailure;  ///< The collision's termination.
  double sweet_spot_from_knob_m = std::numeric_limits<double>::quiet_NaN();  ///< Impact, m.
  double sting_j = std::numeric_limits<double>::quiet_NaN();  ///< Hands' vibration energy, J.
  FlexibleImpactResult impact;                                ///< The impact (when computed).
};

/// The sting of `bat`: its mass properties (ComputeMassProperties), the rigid-pivot max-exit-
/// speed point in closed form (RigidPivotProfile, ClosedFormMaxExitSpeed, at the scene's
/// omega), then Collide(kFlexible) there; the sting is the impact's hands_vibration_energy_j
/// (the measure of least_sting_zone). refine_check as in the scene's flexible options when
/// true, off (one integration, 1/3 of the cost, same value) when false. `cache` (may be null)
/// holds modes across calls. Never throws.
StingEvaluation EvaluateSting(const Bat& bat, const StingScene& scene, bool refine_check,
                              ModesCache* cache);

/// A constraint that no design variable changes and that fails at the base design.
struct FixedViolation {
  std::string constraint;  ///< Its name ("taper.knots[2]", "length_m", "length_m.min").
  std::string message;     ///< One sentence, starting with the name and its value.
};

/// The design problem as an NLP over the variables x (user units). Immutable after Build;
/// const methods are thread-safe.
class DesignModel {
 public:
  /// Builds the model; false, with the refusal in *why (if non-null: field in core's names,
  /// value, rule), for invalid input. A constraint that no variable can change is checked
  /// here: if it fails, the model is still built and fixed_violations() names it.
  static bool Build(const DesignProblem& problem, const DesignOptions& options, DesignModel* out,
                    Refusal* why);

  int n() const { return static_cast<int>(variables_.size()); }                    ///< Variables.
  int m() const { return static_cast<int>(constraints_.size()); }                  ///< Constraints.
  const std::vector<DesignVariableSpec>& variables() const { return variables_; }  ///< Variables.
  const std::vector<DesignConstraintSpec>& constraints() const { return constraints_; }  ///< All.
  /// Constraints that no variable changes and that fail at the base design.
  const std::vector<FixedViolation>& fixed_violations() const { return fixed_violations_; }
  const DesignFunctionSpec& objective() const { return objective_; }  ///< The objective.
  bool maximize() const { return maximize_; }                         ///< Objective sense.
  double objective_scale() const { return objective_scale_; }         ///< Typical |F|.
  std::string objective_unit() const { return objective_unit_; }      ///< Unit of F.
  /// The COR used: the fixed one, or with cor_from_barrel() the start's (BaseX) barrel COR.
  double cor() const { return cor_; }
  /// True when the objective's COR is the design's barrel's (DesignProblem::cor_from_barrel).
  bool cor_from_barrel() const { return barrel_cor_ != nullptr; }
  /// The COR the objective uses at x: cor(), or with cor_from_barrel() the barrel's at x (NaN
  /// when it cannot be computed); equals EffectiveCorAt on BatAt(x) to rounding.
  double CorAt(const double* x) const;
  /// With cor_from_barrel(): where the barrel COR is taken, m from the tip (NaN otherwise).
  double cor_impact_from_tip_m() const;
  double reference_moi_six_inch_kg_m2() const { return i6_ref_; }  ///< I6_ref.
  /// omega of the swing for a design with MOI `i6` about the 6-in point and length `length_m`,
  /// rad/s (the length matters for a swing given by its bat speed, omega0 = v / (L - d - p)).
  double AngularSpeedFor(double i6_kg_m2, double length_m) const;
  /// The start: the base design clamped into the bounds.
  std::vector<double> BaseX() const;

  /// f(x) for a function (user units); NaN when not finite.
  double Value(const DesignFunctionSpec& f, const double* x) const;
  /// The parameters at x (DesignParameterLayout order), for LinearValueAt.
  std::vector<double> Parameters(const double* x) const { return ParametersAt(x); }
  /// A kLinear function's value at the parameters t = Parameters(x): Value(f, x)'s bits, without
  /// computing the parameters once per function (O(terms), not O(n)).
  static double LinearValueAt(const DesignFunctionSpec& f, const std::vector<double>& t);
  /// Objective and constraints at x; false when a value is not finite (or M <= 0). With
  /// gradients, false for the sting objective (it has none): use values only.
  bool Evaluate(const double* x, bool with_gradients, DesignPoint* out) const;
  /// Evaluate with gradients, the constraints' gradients as sparse rows (out->jacobian_rows;
  /// out->jacobian left empty): a linear row (a knot's limit, the taper) in O(its terms), so
  /// that work over every constraint is O(m + n) rather than O(m n). The same values, the same
  /// bits, and the same verdict as Evaluate(x, true, ...).
  bool EvaluateRows(const double* x, DesignPoint* out) const;
  /// Hessian of objective_weight * F + sum_k constraint_weights[k] g_k at x (n x n, user
  /// units); false when not finite (and for the sting objective with a nonzero weight).
  bool Hessian(const double* x, double objective_weight, const double* constraint_weights,
               Eigen::MatrixXd* out) const;
  /// True when `f` is a function of P = (M, S1, S2, L) alone (kMass, kBalancePoint,
  /// kMoiSixInch, kDrop, and kObjective unless it is the sting or uses the barrel's COR).
  bool IsFunctionOfP(DesignFunction f) const;
  /// Such a function at P = (M kg, S1 kg·m, S2 kg·m², L m), in its unit, with (when non-null)
  /// its gradient over P (4) and its Hessian (4 x 4, row-major); NaN otherwise. The lifted
  /// formulation's (lifted_nlp.hpp) objective and property constraints.
  double FunctionOfP(DesignFunction f, const double* p, double* gradient, double* hessian) const;

  /// kLeastSquares: the scaled residuals r = ((M - M*) / s_M, (C - C*) / s_C) of the targets
  /// given (phi = |r|^2) and, if `jacobian`, dr/dx (one row per residual, n columns); false
  /// without the objective or when not finite (least_squares_objective.cpp).
  bool LeastSquaresResiduals(const double* x, Eigen::VectorXd* r, Eigen::MatrixXd* jacobian) const;
  /// True with the least-squares objective (DesignObjective::kLeastSquares).
  bool least_squares() const { return least_squares_.has_value(); }
  /// kLeastSquares: the targets' tolerance (LeastSquaresTargets::tolerance; 1e-9 without).
  double least_squares_tolerance() const {
    return least_squares_.has_value() ? least_squares_->tolerance : 1e-9;
  }

  /// The bat at x (a three-segment design goes through ThreeSegmentShape::Knots()).
  Bat BatAt(const double* x) const;
  /// The three-segment shape at x (nullopt for a profile design).
  std::optional<ThreeSegmentShape> ShapeAt(const double* x) const;

  /// True when the objective has values only, no derivatives: the sting (min_sting) or the
  /// distance sweet spot's carry (max_distance).
  bool derivative_free() const {
    return (objective_kind_ == DesignObjective::kMinSting ||
            objective_kind_ == DesignObjective::kMaxDistance) &&
           objective_.function == DesignFunction::kObjective;
  }
  /// The objective's name for the messages of a derivative-free objective ("min_sting",
  /// "max_distance").
  const char* objective_name() const { return DesignObjectiveName(objective_kind_); }
  /// The first bending frequency at x on the model's fixed mesh, Hz (NaN without the
  /// min_frequency_hz constraint or when it cannot be computed).
  double FirstFrequencyAt(const double* x) const;
  /// Elements of the fixed mesh of the frequency constraint (0 without it).
  int frequency_elements() const;
  /// The BBCOR at x by the model's closed form (NaN without the bbcor constraint or outside
  /// its domain); equals ComputeBbcor(BatAt(x)).value to rounding.
  double BbcorAt(const double* x) const;
  /// The sting of `bat` in this problem's scene (EvaluateSting with the model's modes cache).
  StingEvaluation StingOf(const Bat& bat, bool refine_check) const;
  /// The distance sweet spot of `bat` in this problem's scene (max_distance; EvaluateDistance).
  DistanceEvaluation DistanceOf(const Bat& bat) const;

  /// A copy that minimises or maximises `f` instead of the objective (same constraints).
  DesignModel WithObjective(const DesignFunctionSpec& f, bool maximize, double scale,
                            const std::string& unit) const;
  /// A copy with only the constraints whose indices are in `keep` (in that order).
  DesignModel WithConstraints(const std::vector<int>& keep) const;
  /// A copy with constraint `index`'s limits (its unit) set to [lower, upper] and its scale
  /// recomputed as Build computes it: the model Build makes for the problem with that
  /// property constraint's range changed (the frontier's swept constraint, frontier.cpp).
  /// `index` must be a constraint's index.
  DesignModel WithConstraintLimits(int index, double lower, double upper) const;

 private:
  friend struct design_detail::ModelBuilder;
  friend class LiftedDesignNlp;  // lifted_nlp.hpp: the integrals' context and parameters

  // The objective of P = (M, S1, S2, L) with the COR `e` (a double: fixed; a jet: the barrel's).
  template <typename Scalar, typename Cor>
  Scalar ObjectiveOf(const Scalar* p, const Cor& e) const;
  // omega of the swing for the design P (the swing weight's and the length's), rad/s.
  template <typename Scalar>
  Scalar AngularSpeedOf(const Scalar* p) const;
  // omega0 of the swing for a bat of length L, rad/s: the scene's angular speed, or the bat
  // speed over the arm, v / (L - from_tip - pivot), when the length varies with the design.
  template <typename Scalar>
  Scalar SwingAngularSpeedAt(const Scalar& length_m) const;
  template <typename Scalar>
  Scalar FunctionOf(DesignFunction f, const Scalar* p) const;
  std::vector<double> ParametersAt(const double* x) const;
  // Evaluate and EvaluateRows: with `rows`, the gradients as out->jacobian_rows.
  bool EvaluateImpl(const double* x, bool with_gradients, bool rows, DesignPoint* out) const;
  // One function (the objective or a constraint) at the parameters t with the integrals `in`:
  // its value and, when gradient_row is non-null, its gradient added at gradient_row[j * stride].
  bool EvaluateFunction(const DesignFunctionSpec& f, const std::vector<double>& t,
                        const design_detail::Integrals& in, double* value, double* gradient_row,
                        int stride) const;
  // EvaluateRows's constraints: values and gradients by sparse rows (out->jacobian_rows).
  bool EvaluateConstraintRows(const std::vector<double>& t, const design_detail::Integrals& in,
                              DesignPoint* out) const;
  // The frequency at parameters t, Hz, and (when gradient_row) df/dx added into
  // gradient_row[j * stride]; false when it cannot be computed.
  bool FrequencyOf(const std::vector<double>& t, double* value, double* gradient_row,
                   int stride) const;
  // Functions of the wall at an impact point (f = kBbcor, or kObjective with cor_from_barrel()):
  // the value at parameters t and (when gradient_row) its gradient added into
  // gradient_row[j * stride]; false when it cannot be computed.
  bool WallFunctionOf(DesignFunction f, const std::vector<double>& t, double* value,
                      double* gradient_row, int stride) const;
  // Adds weight times such a function's Hessian at parameters t into *h; false when not finite.
  bool AddWallFunctionHessian(DesignFunction f, const std::vector<double>& t, double weight,
                              Eigen::MatrixXd* h) const;
  // The integrals' context at parameters t (kept by reference) for a function `f` of the wall:
  // the rigid body's inertia for kBbcor (ComputeBbcor's I_pivot), the objective's model's
  // otherwise.
  design_detail::IntegralContext WallIntegralContext(DesignFunction f,
                                                     const std::vector<double>& t) const;
  // ComputeIntegrals in that context (with their derivatives when `derivatives`); false when the
  // mass is not positive.
  bool WallIntegrals(DesignFunction f, const std::vector<double>& t, bool derivatives,
                     design_detail::Integrals* in) const;
  // kBoreBottom (design_bore.cpp): its value at parameters t and (when gradient_row) its
  // gradient added into gradient_row[j * stride]; false when not finite.
  bool BoreBottomOf(const std::vector<double>& t, double* value, double* gradient_row,
                    int stride) const;
  // Adds weight times kBoreBottom's Hessian at parameters t into *h.
  void AddBoreBottomHessian(const std::vector<double>& t, double weight, Eigen::MatrixXd* h) const;
  // True when `f` is a function of the wall (WallFunctionOf), not of P alone.
  bool IsWallFunction(DesignFunction f) const {
    return f == DesignFunction::kBbcor || (f == DesignFunction::kObjective && barrel_cor_);
  }
  // Such a function as a jet over its 9 local inputs (M, S1, S2 of the integrals (the rigid
  // body's for the BBCOR, the objective's inertia model's for the objective), L, h, the impact
  // segment's x_a, x_b, r_a, r_b) and the parameters each one is (-1 for M, S1, S2).
  template <typename J>
  J WallJet(DesignFunction f, const std::vector<double>& t, const std::array<double, 3>& integrals,
            std::array<int, 9>* parameter_of) const;
  // The 9 local inputs at the point from_tip_m from the tip of the design at t (WallJet's).
  template <typename J>
  design_detail::WallInputs<J> WallInputsAt(const std::vector<double>& t,
                                            const std::array<double, 3>& integrals,
                                            double from_tip_m,
                                            std::array<int, 9>* parameter_of) const;
  // The barrel COR (EffectiveCorAt's e_eff) from the local inputs.
  template <typename J>
  J BarrelCorOf(const design_detail::WallInputs<J>& w) const;

  std::vector<DesignVariableSpec> variables_;
  std::vector<DesignConstraintSpec> constraints_;
  std::vector<FixedViolation> fixed_violations_;
  DesignFunctionSpec objective_;
  bool maximize_ = true;
  double objective_scale_ = 1.0;
  std::string objective_unit_;
  DesignObjective objective_kind_ = DesignObjective::kMaxExitSpeed;
  // kLeastSquares: the targets and scales (least_squares_objective.hpp).
  std::optional<LeastSquaresTargets> least_squares_;

  Bat base_bat_;                                 // material, wall, fill, profile knots
  std::optional<ThreeSegmentShape> base_shape_;  // three-segment designs
  std::vector<double> base_parameters_;          // DesignParameterLayout order
  std::vector<int> parameter_variable_;          // parameter -> variable index or -1
  // parameter -> d parameter / d its variable: 1, or a scaled field's base value (the
  // parameter is parameter_scale_[idx] * x[parameter_variable_[idx]]).
  std::vector<double> parameter_scale_;
  int num_knots_ = 0;
  bool hollow_ = false;
  bool has_fill_ = false;
  bool rigid_ = true;
  double c0_ = 0.0;  // reference point of S1, S2, m from the knob

  // Scene.
  double ball_mass_kg_ = 0.145;
  double ball_speed_mps_ = 27.7;
  double omega0_rad_s_ = 17.288;  // a bat speed with a fixed length: resolved once
  // swing.bat_speed_mps with a length that varies: omega0 = bat_speed_mps_ / (L -
  // bat_speed_from_tip_m_ - pivot_from_knob_m_).
  bool omega_from_length_ = false;
  double bat_speed_mps_ = 0.0;
  double bat_speed_from_tip_m_ = 0.0;
  double pivot_from_knob_m_ = 0.0;
  double cor_ = 0.5;
  bool free_bat_ = false;  // the exit-speed model: free_bat (else rigid_pivot)
  double swing_weight_exponent_ = kSwingWeightExponent;
  double zone_tolerance_mps_ = 1.0;
  double i6_ref_ = 1.0;
  // min_sting: the scene of the flexible impact and a per-solve cache of modes (shared by the
  // model's copies; thread-safe), so repeated points do not recompute them.
  StingScene sting_scene_;
  std::shared_ptr<ModesCache> sting_modes_;
  // max_distance: the scene of the distance sweet spot (immutable, shared by the copies).
  std::shared_ptr<const DistanceScene> distance_scene_;
  // min_frequency_hz: the beam on its fixed mesh (immutable, shared by the model's copies).
  std::shared_ptr<const FixedMeshBeam> frequency_beam_;
  // rules bbcor on a hollow design: the protocol's constants (immutable, shared by the copies).
  std::shared_ptr<const design_detail::BbcorConstants> bbcor_;
  // cor_from_barrel on a hollow design: the scene ball's trampoline (immutable, shared).
  std::shared_ptr<const design_detail::BarrelCorConstants> barrel_cor_;
};

/// The model as the solvers see it: variables scaled to s in [0, 1] (x = lower + (upper -
/// lower) s), objective sense * F / objective_scale (always minimised), constraints g / scale.
/// Caches the last point's values and gradients. One per solve (not thread-safe).
class ScaledDesignNlp {
 public:
  explicit ScaledDesignNlp(const DesignModel& model);

  int n() const { return model_.n(); }                 ///< Variables.
  int m() const { return model_.m(); }                 ///< Constraints.
  const DesignModel& model() const { return model_; }  ///< The model.
  /// Scaled constraint bounds (+-inf for open sides).
  void ConstraintBounds(std::vector<double>* lower, std::vector<double>* upper) const;
  /// For each constraint, the variables its gradient may involve (the Jacobian's structure).
  const std::vector<std::vector<int>>& structure() const { return structure_; }
  /// x (user units) -> s.
  std::vector<double> ToScaled(const std::vector<double>& x) const;
  /// s -> x (user units).
  std::vector<double> ToUser(const double* s) const;

  /// Evaluates at s (cached); false when not finite.
  bool Evaluate(const double* s, bool with_gradients);
  double f() const { return f_; }  ///< Scaled objective.
  /// The objective at the last evaluated point, in its unit (unscaled, either sense).
  double objective() const { return point_.objective; }
  const std::vector<double>& g() const { return g_; }            ///< Scaled constraints.
  const Eigen::VectorXd& grad_f() const { return grad_f_; }      ///< d f / d s.
  const Eigen::MatrixXd& jacobian() const { return jacobian_; }  ///< d g / d s (m x n).
  /// Evaluates at s with the gradients, d g / d s by sparse rows (jacobian_rows(); jacobian()
  /// is not updated): O(m + n) beyond the mass integrals, where Evaluate(s, true) is O(m n).
  /// The same g, grad_f and entries (the same bits) as Evaluate(s, true); false when not finite.
  bool EvaluateRows(const double* s);
  /// d g / d s by rows, their nonzero entries (after EvaluateRows; unscaled entries' order).
  const std::vector<DesignGradientRow>& jacobian_rows() const { return rows_; }
  /// Hessian of sigma f + sum lambda_k g_k in s (n x n); false when not finite.
  bool Hessian(const double* s, double sigma, const double* lambda, Eigen::MatrixXd* out) const;
  int evaluations() const { return evaluations_; }  ///< Model evaluations so far.

  /// Largest violation of the scaled constraints at the last evaluated point (>= 0).
  double Violation() const;

 private:
  const DesignModel& model_;
  std::vector<double> width_;
  std::vector<std::vector<int>> structure_;
  std::vector<double> last_s_;
  bool have_values_ = false;
  bool have_gradients_ = false;
  double f_ = 0.0;
  std::vector<double> g_;
  Eigen::VectorXd grad_f_;
  Eigen::MatrixXd jacobian_;
  std::vector<DesignGradientRow> rows_;
  DesignPoint point_;
  int evaluations_ = 0;
};

}  // namespace sweetspot::core
