// The numeric sweet-spot definitions, for exit-speed models without a closed form (hertz,
// flexible) or when the independent path is asked for: the maximum exit speed by the NLopt
// scalar search or by a bracketing search (evenly spaced samples, then Brent's method between
// the best sample's neighbours: the flexible model's default), and the sweet zone by bracketed
// root finding (TOMS 748).
#pragma once

#include <string>

#include "core/numerics/nlopt_search.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {

/// The exit speed along the bat under one model, as the numeric definitions evaluate it.
class ExitSpeedFunction {
 public:
  virtual ~ExitSpeedFunction() = default;
  /// The model's stable name (e.g. "hertz"), reported in the results.
  virtual const char* name() const = 0;
  /// True when Eval fills the derivative.
  virtual bool has_gradient() const = 0;
  /// The exit speed *v (m/s) of an impact s m from the knob, its derivative *grad (1/s; may be
  /// null) and error estimate *err (m/s; may be null). False with the reason in *why (may be
  /// null) when the model could not evaluate it.
  virtual bool Eval(double s, double* v, double* grad, double* err, std::string* why) = 0;
  /// A cheaper evaluation for a search's samples and steps: the exit speed *v (m/s) and its
  /// noise *noise (m/s, may be null: how far nearby values may scatter, e.g. the integration
  /// tolerance's share), without the model's own error checks. The same value as Eval where the
  /// model computes both. Defaults to Eval (its error estimate as the noise).
  virtual bool EvalFast(double s, double* v, double* noise, std::string* why) {
    return Eval(s, v, nullptr, noise, why);
  }
};

/// Options of the bracketing search of the maximum exit speed (BracketMaxExitSpeed).
struct BracketSearchOptions {
  /// Evenly spaced fast evaluations from the knob to the tip (both included) that bracket the
  /// maximum, in [3, 1001].
  int samples = 9;
  /// Brent's position tolerance, m, in [1e-9, 0.01]. 10 um: below what the exit speed's
  /// integration noise resolves on a flexible bat (see the error estimate, ~1e-4 m).
  double x_tolerance_m = 1e-5;
  /// Brent's evaluation budget (then the result is kept, not converged), in [5, 1000].
  int max_iterations = 100;

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// The maximum exit speed over the bat [0, length_m] by the NLopt scalar search; the summary
/// says whether it converged (and why the model failed, if it did).
MaxExitSpeedResult SearchMaxExitSpeed(ExitSpeedFunction* model, double length_m,
                                      const ScalarSearchOptions& options);

/// The maximum exit speed over the bat [0, length_m] by a bracketing search: `options.samples`
/// fast evaluations (EvalFast) from the knob to the tip, Brent's method between the best
/// sample's neighbours to options.x_tolerance_m, then one full evaluation (Eval, with the
/// model's error checks) at the answer. An end of the bat that beats the interior maximum is
/// reported exactly (placement kBeyondTip / kBeforeKnob). error_estimate_m bounds the distance
/// to the converged maximiser of the same model: the tolerance plus how far the evaluations'
/// noise can move a maximum of the sampled curvature, sqrt(4 noise / |f''|). The summary's
/// backend is "bracket_brent"; evaluations counts every model evaluation.
MaxExitSpeedResult BracketMaxExitSpeed(ExitSpeedFunction* model, double length_m,
                                       const BracketSearchOptions& options);

/// The sweet zone around `max` (tolerance_mps below its exit speed) by root finding on each
/// side, clipped to [0, length_m]. On failure *error is set (the result is then not usable).
SweetZoneResult RootFindSweetZone(ExitSpeedFunction* model, double length_m,
                                  const MaxExitSpeedResult& max, double tolerance_mps,
                                  std::string* error);

}  // namespace sweetspot::core
