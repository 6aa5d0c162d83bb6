// Gauss-Legendre quadrature rules on [-1, 1], shared by the beam's element integrals.
#pragma once

#include <array>

namespace sweetspot::core {

/// 5-point Gauss-Legendre nodes on [-1, 1] (dimensionless): exact for polynomials of degree <= 9.
inline constexpr std::array<double, 5> kGauss5X = {
    -0.9061798459386639927976269, -0.5384693101056830910363144, 0.0, 0.5384693101056830910363144,
    0.9061798459386639927976269};
/// The weights of kGauss5X (they sum to 2).
inline constexpr std::array<double, 5> kGauss5W = {
    0.2369268850561890875142640, 0.4786286704993664680412915, 0.5688888888888888888888889,
    0.4786286704993664680412915, 0.2369268850561890875142640};

}  // namespace sweetspot::core
