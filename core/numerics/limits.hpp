// The IEEE double constants core's sources share. One definition for the whole library:
// core compiles as a unity build (cmake/BuildSpeed.cmake), where each file's private copy
// of the same name would collide with its neighbours'.
#pragma once

#include <limits>

namespace sweetspot::core {

/// Quiet NaN: the value of a field that was not computed.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Positive infinity: an absent upper bound.
inline constexpr double kInf = std::numeric_limits<double>::infinity();
/// Machine epsilon of double (2.22e-16), the unit of relative round-off.
inline constexpr double kEps = std::numeric_limits<double>::epsilon();

}  // namespace sweetspot::core
