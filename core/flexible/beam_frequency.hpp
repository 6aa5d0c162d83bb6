// The first free-free bending mode of a bat as a smooth function of its design parameters, with
// its exact gradient: the design code's stiffness constraint (constraints.min_frequency_hz).
//
// The beam is the one of beam_model.hpp (same sections, same element matrices, same theory)
// on a mesh that is held fixed during one optimisation: its nodes are fixed fractions of the
// length (the nodes of the modes code's final mesh for the start design, divided by its
// length), so the mesh moves smoothly with L and never changes its number of elements. Knots
// and the fill's bottom that move off the nodes are integration breakpoints inside elements
// (the element matrices stay exact for the piecewise-linear profile); K and M are then C1
// functions of the knots' positions and radii, the wall, the densities and L.
//
// Derivative: for a simple eigenvalue lambda with phi mass-normalised (phi' M phi = 1),
// d lambda / dp = phi' (dK/dp - lambda dM/dp) phi. The element matrices' derivatives come from
// forward-mode AD (jet.hpp) of the same quadrature: per piece of the profile (a knot segment
// cut at the nodes and the fill's bottom) the integrand phi_e' (k_e - lambda m_e) phi_e is
// differentiated with respect to 10 local parameters (the segment's two knot positions and
// radii, L, the wall, the density, the fill's diameter, depth and density), which also moves
// the Gauss points, the nodes (through L) and the shape functions. The frequency is
// f = sqrt(lambda) / (2 pi).
//
// Eigenpair: shift-invert subspace iteration on the sparse banded K + sigma M from a start basis
// (the rigid modes and the start design's first flexible modes), Rayleigh-Ritz in the
// shift-invert form (Y' M X, Y' M Y: no product with K's large shear entries), to a residual of
// 1e-11. Internal to core (the design model and its tests).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/bat/bat.hpp"
#include "core/flexible/beam_model.hpp"

namespace sweetspot::core {

/// A bat's beam on a fixed mesh, parametrised by DesignParameterLayout{num_knots} (knot radii,
/// knot positions, density, wall, fill diameter, depth and density).
struct FixedMeshBeam {
  BeamTheory theory = BeamTheory::kTimoshenko;  ///< The beam theory.
  bool rotary_inertia = true;                   ///< Timoshenko: rho I in M.
  std::vector<double> node_fractions;           ///< Nodes / L, strictly increasing from 0 to 1.
  int num_knots = 0;                            ///< Knots of the profile (coincident ones allowed).
  bool hollow = false;                          ///< The shell of wall t[WallThickness()] applies.
  bool has_fill = false;                        ///< The fill entries apply.
  double youngs_modulus_pa = 0.0;               ///< The bat material's E, Pa (fixed).
  double shear_modulus_pa = 0.0;                ///< Its effective G, Pa (fixed).
  double poissons_ratio = 0.0;                  ///< Its nu (fixed).
  double fill_youngs_modulus_pa = 0.0;          ///< The fill's E, Pa (fixed).
  double fill_shear_modulus_pa = 0.0;           ///< The fill's effective G, Pa (fixed).
  double fill_poissons_ratio = 0.0;             ///< The fill's nu (fixed).
  /// Start basis of the subspace iteration (DOFs x p, p >= 3): the rigid translation and
  /// rotation, then flexible modes of a nearby design.
  Eigen::MatrixXd start_basis;
  double shift = 0.0;  ///< sigma > 0 of K + sigma M: about the first bending eigenvalue, rad²/s².

  /// Number of elements.
  int Elements() const { return static_cast<int>(node_fractions.size()) - 1; }
};

/// The fixed-mesh beam of `bat` (its materials, shell and fill) on the nodes `nodes_m` (from the
/// knob, 0 to the bat's length), for parameters with `num_knots` knots; `hollow` and `has_fill`
/// as the parameters will be used. The start basis and shift are left empty.
FixedMeshBeam MakeFixedMeshBeam(const Bat& bat, const std::vector<double>& nodes_m, int num_knots,
                                bool hollow, bool has_fill, BeamTheory theory, bool rotary_inertia);

/// The first bending mode at one design.
struct FirstBendingMode {
  bool ok = false;            ///< False when the eigenpair could not be computed (see message).
  std::string message;        ///< Why not.
  double lambda = 0.0;        ///< omega^2 of the first bending mode, rad²/s².
  double frequency_hz = 0.0;  ///< sqrt(lambda) / (2 pi), Hz.
  Eigen::VectorXd vector;     ///< Mass-normalised mode (the fixed mesh's DOFs).
  /// d lambda / d t over DesignParameterLayout{num_knots} (when requested), rad²/s² per unit.
  Eigen::VectorXd lambda_gradient;
  int iterations = 0;  ///< Subspace iterations.
};

/// The first bending mode of the design with parameters `t` (DesignParameterLayout order), and
/// when `gradient` d lambda / d t. Never throws.
FirstBendingMode ComputeFirstBendingMode(const FixedMeshBeam& beam, const std::vector<double>& t,
                                         bool gradient);

/// K and M of the design `t` on the fixed mesh (for tests: the same quadrature as above).
BeamMatrices AssembleFixedMeshBeam(const FixedMeshBeam& beam, const std::vector<double>& t);

}  // namespace sweetspot::core
