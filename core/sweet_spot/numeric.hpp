// The numeric sweet-spot definitions, for exit-speed models without a closed form (hertz,
// flexible) or when the independent path is asked for: the maximum exit speed by the NLopt
// scalar search and the sweet zone by bracketed root finding (TOMS 748).
#pragma once

#include <string>

#include "core/optimize/nlopt_search.hpp"
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
};

/// The maximum exit speed over the bat [0, length_m] by the NLopt scalar search; the summary
/// says whether it converged (and why the model failed, if it did).
MaxExitSpeedResult SearchMaxExitSpeed(ExitSpeedFunction* model, double length_m,
                                      const ScalarSearchOptions& options);

/// The sweet zone around `max` (tolerance_mps below its exit speed) by root finding on each
/// side, clipped to [0, length_m]. On failure *error is set (the result is then not usable).
SweetZoneResult RootFindSweetZone(ExitSpeedFunction* model, double length_m,
                                  const MaxExitSpeedResult& max, double tolerance_mps,
                                  std::string* error);

}  // namespace sweetspot::core
