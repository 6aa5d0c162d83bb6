// static_flexibility: the free-free bat's static flexibility under inertia relief, from the
// FE model of core/flexible/beam_model.hpp on the mesh of its modes. The flexible impact
// (core/collision/flexible_impact.cpp) puts the part of it its modes leave out in series with
// the contact (the residual flexibility, docs/models.md "Flexible bat").
#pragma once

#include "core/bat/bat.hpp"
#include "core/flexible/modes.hpp"

namespace sweetspot::core {

/// The static flexibility of the free-free beam at x under inertia relief, m/N: the sum over
/// every flexible FE mode of phi_k(x)^2 / omega_k^2 (one sparse static solve with a
/// self-equilibrated load and the rigid-body motion removed, on the modes' mesh with a node
/// put at x: the point load's kink in the shear deflection needs one). NaN when the solve fails.
double InertiaReliefFlexibility(const Bat& bat, const BatModes& modes, double x_m);

}  // namespace sweetspot::core
