// static_flexibility: implementation (see static_flexibility.hpp).
#include "core/flexible/static_flexibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/SparseCholesky>

#include "core/flexible/beam_model.hpp"

namespace sweetspot::core {

double InertiaReliefFlexibility(const Bat& bat, const BatModes& modes, double x_m) {
  // The static solve's mesh: the modes' mesh with a node at x (the point load puts a kink in the
  // shear deflection that only a node resolves): a node within a quarter element moves to x,
  // otherwise x is inserted.
  BeamMesh mesh;
  mesh.nodes_m = modes.nodes_m;
  mesh.breakpoints_m = modes.breakpoints_m;
  std::vector<double>& nodes = mesh.nodes_m;
  const double x = std::clamp(x_m, nodes.front(), nodes.back());
  {
    const auto it = std::upper_bound(nodes.begin(), nodes.end(), x);
    const std::size_t e = std::min<std::size_t>(
        it == nodes.begin() ? 0 : static_cast<std::size_t>(it - nodes.begin()) - 1,
        nodes.size() - 2);
    const double h = nodes[e + 1] - nodes[e];
    const double dl = x - nodes[e], dr = nodes[e + 1] - x;
    if (dl > 1e-9 * h && dr > 1e-9 * h) {
      const std::size_t near = dl < dr ? e : e + 1;
      if (std::min(dl, dr) < 0.25 * h && near != 0 && near != nodes.size() - 1) {
        nodes[near] = x;
      } else {
        nodes.insert(nodes.begin() + static_cast<std::ptrdiff_t>(e) + 1, x);
      }
    }
  }
  BatModes on_mesh;  // the rigid-body modes on this mesh (same mass properties)
  on_mesh.theory = modes.theory;
  on_mesh.nodes_m = nodes;
  on_mesh.mass_kg = modes.mass_kg;
  on_mesh.balance_point_m = modes.balance_point_m;
  on_mesh.moi_centroid_kg_m2 = modes.moi_centroid_kg_m2;
  // K and the products of M with the rigid modes (M itself is not needed).
  // The elements the node at x leaves as they were: taken from the modes' (the same numbers).
  const BeamStiffnessAndInertia mats =
      modes.element_parts.empty()
          ? AssembleBeamStiffnessAndInertia(bat, mesh, modes.theory, modes.rotary_inertia)
          : AssembleBeamStiffnessAndInertia(bat, mesh, modes.theory, modes.rotary_inertia,
                                            modes.element_parts);
  const int ne = mesh.Elements();
  const Eigen::Index n = mats.stiffness.rows();
  // The load: a unit force at x, as consistent nodal loads (the displacement shape functions).
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  {
    const auto it = std::upper_bound(nodes.begin(), nodes.end(), x);
    int e = it == nodes.begin() ? 0 : static_cast<int>(it - nodes.begin()) - 1;
    e = std::min(e, ne - 1);
    const double a = nodes[static_cast<std::size_t>(e)];
    const double h = nodes[static_cast<std::size_t>(e) + 1] - a;
    const ElementShape sh = EvaluateElementShape(h, std::clamp((x - a) / h, 0.0, 1.0));
    int idx[kElementDofs];
    ElementDofIndices(modes.theory, e, idx);
    for (int i = 0; i < kElementDofs; ++i) {
      if (idx[i] >= 0) f[idx[i]] += sh.w[i];
    }
  }
  const Eigen::VectorXd t = on_mesh.TranslationMode();
  const Eigen::VectorXd r = on_mesh.RotationMode();
  // M t and M r: t = t0 / sqrt(mass), r = (r0 - C t0) / sqrt(I_cm).
  const Eigen::VectorXd mt = mats.mass_times_translation / std::sqrt(modes.mass_kg);
  const Eigen::VectorXd mr =
      (mats.mass_times_rotation - modes.balance_point_m * mats.mass_times_translation) /
      std::sqrt(modes.moi_centroid_kg_m2);
  // Inertia relief: the rigid body's inertia forces balance the load.
  const Eigen::VectorXd f_bal = f - mt * t.dot(f) - mr * r.dot(f);
  // Hold w_b at both ends (the balanced load has no reactions there), then remove the
  // rigid-body part of the deflection.
  const Eigen::Index first = 0;
  int last_idx[kElementDofs];
  ElementDofIndices(modes.theory, ne - 1, last_idx);
  const Eigen::Index last = last_idx[4];
  Eigen::SparseMatrix<double> k = mats.stiffness;
  const double diag = k.coeff(first, first) > 0.0 ? k.coeff(first, first) : 1.0;
  k.prune([&](Eigen::Index row, Eigen::Index col, double) {
    return row != first && row != last && col != first && col != last;
  });
  k.coeffRef(first, first) = diag;
  k.coeffRef(last, last) = diag;
  Eigen::VectorXd rhs = f_bal;
  rhs[first] = 0.0;
  rhs[last] = 0.0;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>>
      ldlt(k);
  if (ldlt.info() != Eigen::Success) return std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd u = ldlt.solve(rhs);
  u -= t * mt.dot(u) + r * mr.dot(u);
  return f.dot(u);
}

}  // namespace sweetspot::core
