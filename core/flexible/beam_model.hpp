// The bat as a finite-element beam: cross-sections from the profile, shell and fill, a mesh
// with nodes at every section breakpoint, and the element matrices of two theories.
//
// Assumptions (docs/models.md, "Flexible bat"):
// - Small transverse vibration in one plane; the axis is straight; free-free ends (the hands
//   barely restrain a ~1 ms impact: a grip of ~5e4 N/m against a ~1 kg bat has a period of
//   ~25 ms, see hertz_contact.hpp).
// - Section at x: the bat material's annulus between the inner radius (the shell's cavity,
//   or the bore where a solid bat is filled) and the outer radius, plus the fill's disc.
//   Mass per length rho A and rotary inertia rho I add over both; the bending stiffness
//   E I and the shear stiffness kappa G A also add (a perfectly bonded coaxial fill; a cork or
//   rubber fill contributes ~1e-3 of the wood's E I, an empty bore nothing).
// - Within an element the outer radius is linear between profile knots, so A(x) and I(x) are
//   polynomials (degree <= 2 and <= 4); the element matrices are integrated piecewise between
//   breakpoints with 5-point Gauss-Legendre (exact to degree 9), hence exactly for the
//   piecewise-linear profile. The shear coefficient kappa(x) (Cowper) is rational in x: the
//   Timoshenko shear term is the one quadrature that is not exact (error far below 1e-10).
// - Euler-Bernoulli: Hermite cubic elements (DOFs w, theta = w' per node), no rotary inertia.
// - Timoshenko: the deflection is split into a bending part and a shear part, w = w_b + w_s,
//   with theta = w_b' and the shear strain gamma = w' - theta = w_s'. Energies:
//   U = 1/2 int EI (w_b'')^2 + kappa G A (w_s')^2,  T = 1/2 int rho A (w_b + w_s)^2 + rho I
//   (w_b')^2. w_b: Hermite cubics (C1); w_s: C0 quadratics (nodal values + one bubble per element),
//   so gamma may jump where the section jumps (the fill's bottom). Neither part locks (the shear
//   energy never constrains w_b), the frequencies converge as h^4 like the Hermite element's,
//   and kappa G A -> infinity gives back Euler-Bernoulli (plus rotary inertia) exactly. The
//   constant w_s (a translation that is also one of w_b) is removed by fixing w_s = 0 at the
//   knob, which loses nothing.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "core/bat/bat.hpp"

namespace sweetspot::core {

/// The beam theory of the flexible model.
enum class BeamTheory {
  kEulerBernoulli,  ///< Bending only, no shear deformation, no rotary inertia.
  kTimoshenko,      ///< Bending + shear deformation + rotary inertia.
};

/// Stable name: "euler_bernoulli", "timoshenko".
const char* BeamTheoryName(BeamTheory theory);
/// The theory called `name`, or nullopt.
std::optional<BeamTheory> ParseBeamTheory(std::string_view name);

/// Cowper's shear coefficient of a circular annulus with radius ratio m = inner / outer in
/// [0, 1) and Poisson's ratio nu (G. R. Cowper, "The shear coefficient in Timoshenko's beam
/// theory", J. Appl. Mech. 33 (1966) 335-340, Table 1):
/// kappa = 6 (1 + nu) (1 + m^2)^2 / ((7 + 6 nu) (1 + m^2)^2 + (20 + 12 nu) m^2)
/// (solid: 6 (1 + nu) / (7 + 6 nu); thin tube: 2 (1 + nu) / (4 + 3 nu)). Dimensionless.
double CowperShearCoefficient(double poissons_ratio, double inner_over_outer);

/// The beam's section properties at one position (per unit length), SI.
struct BeamSection {
  double mass_per_length_kg_m = 0.0;    ///< rho A (bat material + fill), kg/m.
  double rotary_inertia_kg_m = 0.0;     ///< rho I about a diameter (bat + fill), kg m.
  double bending_stiffness_n_m2 = 0.0;  ///< E I (bat + bonded fill), N m^2.
  double shear_stiffness_n = 0.0;       ///< kappa G A (bat + fill, Cowper kappa of each), N.
};

/// The section of `bat` at `x_m` metres from the knob (precondition: bat.Validate(nullptr) and
/// 0 <= x_m <= L). At a fill's bottom the fill is included (x >= L - depth).
BeamSection SectionAt(const Bat& bat, double x_m);

/// Node positions of a beam mesh and the section breakpoints inside its elements.
struct BeamMesh {
  std::vector<double> nodes_m;  ///< Node positions from the knob, m, strictly increasing, 0 to L.
  std::vector<double> breakpoints_m;  ///< Every knot and the fill's bottom (sorted), m.

  /// Number of elements (nodes - 1; 0 for an empty mesh).
  int Elements() const { return nodes_m.empty() ? 0 : static_cast<int>(nodes_m.size()) - 1; }
};

/// Breakpoints closer than this fraction of L to a kept one are not made nodes (they stay
/// integration breakpoints): a 1e-12 m step would otherwise make an element whose stiffness
/// (~1/h^3) ruins the conditioning.
inline constexpr double kMinNodeSpacingFraction = 1e-3;

/// The intervals between the section breakpoints kept as nodes (knots and the fill's bottom,
/// merged when closer than kMinNodeSpacingFraction L), as node positions.
std::vector<double> BeamBaseNodes(const Bat& bat);

/// A mesh of `bat`: each base interval of length l gets max(1, ceil(target_elements l / L))
/// equal elements, times 2^refinement_level. Nested: level j + 1 splits every element of
/// level j in two.
BeamMesh MakeBeamMesh(const Bat& bat, int target_elements, int refinement_level);

/// The local DOFs of one element, in this order: w_b1, theta1, w_s1, bubble, w_b2, theta2, w_s2
/// (Euler-Bernoulli uses only w_b and theta).
inline constexpr int kElementDofs = 7;

/// Global indices of element `e`'s local DOFs (-1 = not a DOF of this theory; the knob's w_s is
/// fixed at 0). Euler-Bernoulli: node i holds (w, theta) at 2i, 2i+1. Timoshenko: node 0 holds
/// (w_b, theta) at 0, 1; element e's bubble and then node e+1's (w_b, theta, w_s) follow.
void ElementDofIndices(BeamTheory theory, int e, int out[kElementDofs]);

/// Size of the global DOF vector of a mesh with `elements` elements.
int BeamDofCount(BeamTheory theory, int elements);

/// The assembled free-free matrices (sparse, symmetric, banded).
struct BeamMatrices {
  Eigen::SparseMatrix<double> stiffness;  ///< K (N/m, N, N m blocks by DOF kind).
  Eigen::SparseMatrix<double> mass;       ///< M (kg, kg m, kg m^2 blocks by DOF kind).
};

/// K and M of `bat` on `mesh`. `rotary_inertia` applies to Timoshenko only.
BeamMatrices AssembleBeam(const Bat& bat, const BeamMesh& mesh, BeamTheory theory,
                          bool rotary_inertia);

/// K and, instead of M, its products with the two rigid motions: what a static solve under
/// inertia relief needs of M (core/flexible/static_flexibility.hpp), without assembling it.
struct BeamStiffnessAndInertia {
  Eigen::SparseMatrix<double> stiffness;   ///< K, as AssembleBeam's.
  Eigen::VectorXd mass_times_translation;  ///< M t, t the translation w = 1 (kg per DOF unit).
  /// M r0, r0 the rotation about the knob w = x, theta = 1 (kg m per DOF unit).
  Eigen::VectorXd mass_times_rotation;
};

/// K of `bat` on `mesh` with M t and M r0 (see BeamStiffnessAndInertia), integrated directly.
BeamStiffnessAndInertia AssembleBeamStiffnessAndInertia(const Bat& bat, const BeamMesh& mesh,
                                                        BeamTheory theory, bool rotary_inertia);

/// One element's share of K, M t and M r0 (AssembleBeamStiffnessAndInertia's), in the element's
/// local DOF order (ElementDofIndices).
struct BeamElementParts {
  double a_m = 0.0;  ///< The element's knob-side node, m from the knob.
  double b_m = 0.0;  ///< Its tip-side node, m from the knob.
  /// K_e, row-major (N/m, N, N m entries by DOF kind).
  std::array<double, kElementDofs * kElementDofs> stiffness{};
  std::array<double, kElementDofs> mass_t{};   ///< (M t)_e, kg per DOF unit.
  std::array<double, kElementDofs> mass_r0{};  ///< (M r0)_e, kg m per DOF unit.
};

/// The parts of every element of `mesh`, in order (what AssembleBeamStiffnessAndInertia sums).
std::vector<BeamElementParts> BeamElementPartsOf(const Bat& bat, const BeamMesh& mesh,
                                                 BeamTheory theory, bool rotary_inertia);

/// AssembleBeamStiffnessAndInertia, bit for bit, taking the parts of every element whose two
/// nodes equal those of an element of `known` (BeamElementPartsOf of another mesh of the same
/// bat, with the same breakpoints, theory and rotary_inertia; in order) from there instead of
/// integrating them again.
BeamStiffnessAndInertia AssembleBeamStiffnessAndInertia(const Bat& bat, const BeamMesh& mesh,
                                                        BeamTheory theory, bool rotary_inertia,
                                                        const std::vector<BeamElementParts>& known);

/// Shape functions of one element of length h at xi in [0, 1], per local DOF.
struct ElementShape {
  double w[kElementDofs];          ///< Total displacement w = w_b + w_s.
  double theta[kElementDofs];      ///< Rotation theta = w_b', rad per DOF unit.
  double curvature[kElementDofs];  ///< theta' = w_b'', 1/m per DOF unit.
  double shear[kElementDofs];      ///< Shear strain w_s' (zero weights for Euler-Bernoulli use).
};

/// The shape functions at xi (Hermite cubics for w_b, C0 quadratic for w_s).
ElementShape EvaluateElementShape(double h_m, double xi);

/// Bending and shear parts of a DOF vector at one position.
struct BeamField {
  double bending_m = 0.0;  ///< w_b per DOF unit.
  double rotation = 0.0;   ///< theta = w_b'.
  double shear_m = 0.0;    ///< w_s (0 for Euler-Bernoulli).
};

/// The field of DOF vector `v` at x (m from the knob, clamped to the mesh).
BeamField EvaluateField(BeamTheory theory, const std::vector<double>& nodes_m,
                        const Eigen::VectorXd& v, double x_m);

/// EvaluateField of every vector of `vs` at x into out[0..vs.size()) (the same values; the
/// element is located and its shape functions evaluated once for all of them).
void EvaluateFields(BeamTheory theory, const std::vector<double>& nodes_m,
                    const std::vector<Eigen::VectorXd>& vs, double x_m, BeamField* out);

/// The DOF vector on the nested fine mesh `fine_nodes_m` that represents exactly the field of
/// `coarse` on `coarse_nodes_m` (every coarse element is a union of fine ones).
Eigen::VectorXd ProlongField(BeamTheory theory, const std::vector<double>& coarse_nodes_m,
                             const Eigen::VectorXd& coarse,
                             const std::vector<double>& fine_nodes_m);

}  // namespace sweetspot::core
