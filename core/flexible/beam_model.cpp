// beam_model: implementation; the assumptions are stated at the top of beam_model.hpp.
#include "core/flexible/beam_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/numerics/gauss_legendre.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

// The pieces of [a, b] between the breakpoints strictly inside it.
std::vector<double> PiecesOf(double a, double b, const std::vector<double>& breakpoints) {
  std::vector<double> out = {a};
  for (double x : breakpoints) {
    if (x > a && x < b) out.push_back(x);
  }
  out.push_back(b);
  return out;
}

// Calls f(x, weight) at the Gauss points of every piece of [a, b].
template <typename F>
void IntegratePiecewise(double a, double b, const std::vector<double>& breakpoints, F&& f) {
  const std::vector<double> pieces = PiecesOf(a, b, breakpoints);
  for (std::size_t i = 0; i + 1 < pieces.size(); ++i) {
    const double lo = pieces[i];
    const double hi = pieces[i + 1];
    const double half = 0.5 * (hi - lo);
    const double mid = 0.5 * (hi + lo);
    if (!(half > 0.0)) continue;
    for (std::size_t g = 0; g < kGauss5X.size(); ++g) {
      f(mid + half * kGauss5X[g], half * kGauss5W[g]);
    }
  }
}

}  // namespace

const char* BeamTheoryName(BeamTheory theory) {
  switch (theory) {
    case BeamTheory::kEulerBernoulli:
      return "euler_bernoulli";
    case BeamTheory::kTimoshenko:
      return "timoshenko";
  }
  return "timoshenko";
}

std::optional<BeamTheory> ParseBeamTheory(std::string_view name) {
  for (BeamTheory t : {BeamTheory::kEulerBernoulli, BeamTheory::kTimoshenko}) {
    if (name == BeamTheoryName(t)) return t;
  }
  return std::nullopt;
}

double CowperShearCoefficient(double poissons_ratio, double inner_over_outer) {
  const double nu = poissons_ratio;
  const double m2 = inner_over_outer * inner_over_outer;
  const double a = (1.0 + m2) * (1.0 + m2);
  return 6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2);
}

BeamSection SectionAt(const Bat& bat, double x_m) {
  BeamSection s;
  const double r = bat.RadiusAtM(x_m);
  const double length = bat.LengthM();
  const bool in_fill = bat.fill.has_value() && bat.fill->depth_m > 0.0 &&
                       bat.fill->RadiusM() > 0.0 && x_m >= length - bat.fill->depth_m;
  // A two-piece bat's handle side (x < joint): the handle's material and wall.
  const bool in_handle = bat.handle.has_value() && x_m < bat.handle->joint_from_knob_m;
  const double wall = in_handle ? bat.handle->WallM(bat.WallAtM(x_m)) : bat.WallAtM(x_m);
  double r_in = wall > 0.0 ? std::max(r - wall, 0.0) : 0.0;
  const double r_fill = in_fill ? bat.fill->RadiusM() : 0.0;
  if (in_fill && !bat.IsHollow()) r_in = r_fill;  // the bore replaces the solid's core
  // r^2 - ri^2 and r^4 - ri^4 as products: no cancellation for a thin wall.
  const double a_b = kPi * (r - r_in) * (r + r_in);
  const double i_b = 0.25 * kPi * (r - r_in) * (r + r_in) * (r * r + r_in * r_in);
  const Material& mb = in_handle ? bat.handle->material : bat.material;
  s.mass_per_length_kg_m = mb.density_kg_m3 * a_b;
  s.rotary_inertia_kg_m = mb.density_kg_m3 * i_b;
  s.bending_stiffness_n_m2 = mb.youngs_modulus_pa * i_b;
  const double ratio = r > 0.0 ? r_in / r : 0.0;
  s.shear_stiffness_n =
      CowperShearCoefficient(mb.poissons_ratio, ratio) * mb.EffectiveShearModulusPa() * a_b;
  if (in_fill && !bat.fill->IsEmpty()) {
    const Material& mf = bat.fill->material;
    const double a_f = kPi * r_fill * r_fill;
    const double i_f = 0.25 * kPi * r_fill * r_fill * r_fill * r_fill;
    s.mass_per_length_kg_m += mf.density_kg_m3 * a_f;
    s.rotary_inertia_kg_m += mf.density_kg_m3 * i_f;
    s.bending_stiffness_n_m2 += mf.youngs_modulus_pa * i_f;
    s.shear_stiffness_n +=
        CowperShearCoefficient(mf.poissons_ratio, 0.0) * mf.EffectiveShearModulusPa() * a_f;
  }
  // An end cap or knob (bat.hpp): its mass and rotary inertia per length over its range, no
  // stiffness (a cap or knob plug is a lumped part, not a bonded section).
  const auto add_part = [&](const std::optional<BatPart>& part, bool at_tip) {
    if (!part.has_value() || !(part->length_m > 0.0)) return;
    const bool inside = at_tip ? x_m >= length - part->length_m : x_m <= part->length_m;
    if (!inside) return;
    const double per_length = part->mass_kg / part->length_m;
    const double rp = bat.PartRadiusM(at_tip);
    s.mass_per_length_kg_m += per_length;
    s.rotary_inertia_kg_m += per_length * 0.25 * rp * rp;
  };
  add_part(bat.end_cap, true);
  add_part(bat.knob, false);
  return s;
}

namespace {

std::vector<double> Breakpoints(const Bat& bat) {
  std::vector<double> out;
  out.reserve(bat.knots.size() + 3);
  for (const ProfileKnot& k : bat.knots) out.push_back(k.x_m);
  const double length = bat.LengthM();
  if (bat.fill.has_value() && bat.fill->depth_m > 0.0 && bat.fill->depth_m < length) {
    out.push_back(length - bat.fill->depth_m);
  }
  // Where an end cap or knob ends inside the bat: the sections jump there.
  if (bat.end_cap.has_value() && bat.end_cap->length_m < length) {
    out.push_back(length - bat.end_cap->length_m);
  }
  if (bat.knob.has_value() && bat.knob->length_m < length) out.push_back(bat.knob->length_m);
  if (bat.handle.has_value()) out.push_back(bat.handle->joint_from_knob_m);  // the joint
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

std::vector<double> BeamBaseNodes(const Bat& bat) {
  const std::vector<double> bp = Breakpoints(bat);
  const double length = bat.LengthM();
  const double gap = kMinNodeSpacingFraction * length;
  std::vector<double> out = {0.0};
  for (double x : bp) {
    if (x <= 0.0 || x >= length) continue;
    if (x - out.back() >= gap && length - x >= gap) out.push_back(x);
  }
  out.push_back(length);
  return out;
}

BeamMesh MakeBeamMesh(const Bat& bat, int target_elements, int refinement_level) {
  BeamMesh mesh;
  mesh.breakpoints_m = Breakpoints(bat);
  const std::vector<double> base = BeamBaseNodes(bat);
  const double length = bat.LengthM();
  const int factor = 1 << std::clamp(refinement_level, 0, 20);
  mesh.nodes_m.push_back(0.0);
  for (std::size_t i = 0; i + 1 < base.size(); ++i) {
    const double a = base[i];
    const double b = base[i + 1];
    const double share = static_cast<double>(target_elements) * (b - a) / length;
    const int n = std::max(1, static_cast<int>(std::ceil(share - 1e-9))) * factor;
    for (int j = 1; j < n; ++j) mesh.nodes_m.push_back(a + (b - a) * j / n);
    mesh.nodes_m.push_back(b);
  }
  return mesh;
}

ElementShape EvaluateElementShape(double h_m, double xi) {
  const double h = h_m;
  const double x2 = xi * xi;
  const double x3 = x2 * xi;
  ElementShape s{};
  // Local order: w_b1, theta1, w_s1, bubble, w_b2, theta2, w_s2.
  const double hw[4] = {1.0 - 3.0 * x2 + 2.0 * x3, h * (xi - 2.0 * x2 + x3), 3.0 * x2 - 2.0 * x3,
                        h * (x3 - x2)};
  const double hd[4] = {6.0 * (x2 - xi) / h, 1.0 - 4.0 * xi + 3.0 * x2, 6.0 * (xi - x2) / h,
                        3.0 * x2 - 2.0 * xi};
  const double hdd[4] = {(12.0 * xi - 6.0) / (h * h), (6.0 * xi - 4.0) / h,
                         (6.0 - 12.0 * xi) / (h * h), (6.0 * xi - 2.0) / h};
  constexpr int kBending[4] = {0, 1, 4, 5};
  for (int i = 0; i < 4; ++i) {
    s.w[kBending[i]] = hw[i];
    s.theta[kBending[i]] = hd[i];
    s.curvature[kBending[i]] = hdd[i];
  }
  s.w[2] = 1.0 - xi;
  s.w[3] = 4.0 * xi * (1.0 - xi);
  s.w[6] = xi;
  s.shear[2] = -1.0 / h;
  s.shear[3] = 4.0 * (1.0 - 2.0 * xi) / h;
  s.shear[6] = 1.0 / h;
  return s;
}

void ElementDofIndices(BeamTheory theory, int e, int out[kElementDofs]) {
  if (theory == BeamTheory::kEulerBernoulli) {
    const int a = 2 * e;
    const int idx[kElementDofs] = {a, a + 1, -1, -1, a + 2, a + 3, -1};
    for (int i = 0; i < kElementDofs; ++i) out[i] = idx[i];
    return;
  }
  if (e == 0) {
    const int idx[kElementDofs] = {0, 1, -1, 2, 3, 4, 5};
    for (int i = 0; i < kElementDofs; ++i) out[i] = idx[i];
    return;
  }
  const int a = 4 * e - 1;
  for (int i = 0; i < kElementDofs; ++i) out[i] = a + i;
}

int BeamDofCount(BeamTheory theory, int elements) {
  return theory == BeamTheory::kEulerBernoulli ? 2 * elements + 2 : 4 * elements + 2;
}

namespace {

using BeamElementMatrix = Eigen::Matrix<double, kElementDofs, kElementDofs>;
using BeamElementVector = Eigen::Matrix<double, kElementDofs, 1>;

// Element [a, b]'s K_e and, with `me` non-null, its M_e; otherwise its (M t)_e in *te and its
// (M r0)_e in *re (AssembleBeamParts's integrals, one element).
void IntegrateBeamElement(const Bat& bat, const std::vector<double>& breakpoints, double a,
                          double b, bool timoshenko, bool rotary, BeamElementMatrix* ke,
                          BeamElementMatrix* me, BeamElementVector* te, BeamElementVector* re) {
  const double h = b - a;
  ke->setZero();
  if (me != nullptr) me->setZero();
  te->setZero();
  re->setZero();
  IntegratePiecewise(a, b, breakpoints, [&](double x, double wgt) {
    const BeamSection s = SectionAt(bat, x);
    ElementShape n = EvaluateElementShape(h, (x - a) / h);
    if (!timoshenko) {
      for (int i : {2, 3, 6}) n.w[i] = 0.0;
    }
    const Eigen::Map<const BeamElementVector> nw(n.w), nt(n.theta), cv(n.curvature), sh(n.shear);
    ke->noalias() += (wgt * s.bending_stiffness_n_m2) * (cv * cv.transpose());
    if (timoshenko) ke->noalias() += (wgt * s.shear_stiffness_n) * (sh * sh.transpose());
    if (me != nullptr) {
      me->noalias() += (wgt * s.mass_per_length_kg_m) * (nw * nw.transpose());
      if (rotary) me->noalias() += (wgt * s.rotary_inertia_kg_m) * (nt * nt.transpose());
    } else {
      te->noalias() += (wgt * s.mass_per_length_kg_m) * nw;
      re->noalias() += (wgt * s.mass_per_length_kg_m * x) * nw;
      if (rotary) re->noalias() += (wgt * s.rotary_inertia_kg_m) * nt;
    }
  });
}

// The element of `known` (in order) with nodes a and b, or null.
const BeamElementParts* KnownElement(const std::vector<BeamElementParts>& known, double a,
                                     double b) {
  const auto it = std::lower_bound(known.begin(), known.end(), a,
                                   [](const BeamElementParts& p, double x) { return p.a_m < x; });
  return it != known.end() && it->a_m == a && it->b_m == b ? &*it : nullptr;
}

// AssembleBeam's loop. With `mass` null, M is not assembled; instead *mass_t and *mass_r0 (if
// non-null) get M t and M r0 for the rigid translation t (w = 1) and rotation about the knob
// r0 (w = x, theta = 1): the consistent loads of the mass distribution, integrated directly.
// With `known` (and `mass` null), an element found there is taken from it.
void AssembleBeamParts(const Bat& bat, const BeamMesh& mesh, BeamTheory theory, bool rotary_inertia,
                       Eigen::SparseMatrix<double>* stiffness, Eigen::SparseMatrix<double>* mass,
                       Eigen::VectorXd* mass_t, Eigen::VectorXd* mass_r0,
                       const std::vector<BeamElementParts>* known = nullptr) {
  const int ne = mesh.Elements();
  const int ndof = BeamDofCount(theory, ne);
  const bool timoshenko = theory == BeamTheory::kTimoshenko;
  const bool rotary = timoshenko && rotary_inertia;
  std::vector<Eigen::Triplet<double>> kt, mt;
  kt.reserve(static_cast<std::size_t>(ne) * 49);
  if (mass != nullptr) mt.reserve(static_cast<std::size_t>(ne) * 49);
  if (mass_t != nullptr) *mass_t = Eigen::VectorXd::Zero(ndof);
  if (mass_r0 != nullptr) *mass_r0 = Eigen::VectorXd::Zero(ndof);
  for (int e = 0; e < ne; ++e) {
    const double a = mesh.nodes_m[static_cast<std::size_t>(e)];
    const double b = mesh.nodes_m[static_cast<std::size_t>(e) + 1];
    BeamElementMatrix ke, me;
    BeamElementVector te, re;
    const BeamElementParts* part =
        known != nullptr && mass == nullptr ? KnownElement(*known, a, b) : nullptr;
    if (part != nullptr) {
      ke = Eigen::Map<const Eigen::Matrix<double, kElementDofs, kElementDofs, Eigen::RowMajor>>(
          part->stiffness.data());
      te = Eigen::Map<const BeamElementVector>(part->mass_t.data());
      re = Eigen::Map<const BeamElementVector>(part->mass_r0.data());
    } else {
      IntegrateBeamElement(bat, mesh.breakpoints_m, a, b, timoshenko, rotary, &ke,
                           mass != nullptr ? &me : nullptr, &te, &re);
    }
    int idx[kElementDofs];
    ElementDofIndices(theory, e, idx);
    for (int i = 0; i < kElementDofs; ++i) {
      if (idx[i] < 0) continue;
      if (mass_t != nullptr) (*mass_t)[idx[i]] += te[i];
      if (mass_r0 != nullptr) (*mass_r0)[idx[i]] += re[i];
      for (int j = 0; j < kElementDofs; ++j) {
        if (idx[j] < 0) continue;
        if (ke(i, j) != 0.0) kt.emplace_back(idx[i], idx[j], ke(i, j));
        if (mass != nullptr && me(i, j) != 0.0) mt.emplace_back(idx[i], idx[j], me(i, j));
      }
    }
  }
  stiffness->resize(ndof, ndof);
  stiffness->setFromTriplets(kt.begin(), kt.end());
  if (mass != nullptr) {
    mass->resize(ndof, ndof);
    mass->setFromTriplets(mt.begin(), mt.end());
  }
}

}  // namespace

BeamMatrices AssembleBeam(const Bat& bat, const BeamMesh& mesh, BeamTheory theory,
                          bool rotary_inertia) {
  BeamMatrices out;
  AssembleBeamParts(bat, mesh, theory, rotary_inertia, &out.stiffness, &out.mass, nullptr, nullptr);
  return out;
}

BeamStiffnessAndInertia AssembleBeamStiffnessAndInertia(const Bat& bat, const BeamMesh& mesh,
                                                        BeamTheory theory, bool rotary_inertia) {
  BeamStiffnessAndInertia out;
  AssembleBeamParts(bat, mesh, theory, rotary_inertia, &out.stiffness, nullptr,
                    &out.mass_times_translation, &out.mass_times_rotation);
  return out;
}

BeamStiffnessAndInertia AssembleBeamStiffnessAndInertia(
    const Bat& bat, const BeamMesh& mesh, BeamTheory theory, bool rotary_inertia,
    const std::vector<BeamElementParts>& known) {
  BeamStiffnessAndInertia out;
  AssembleBeamParts(bat, mesh, theory, rotary_inertia, &out.stiffness, nullptr,
                    &out.mass_times_translation, &out.mass_times_rotation, &known);
  return out;
}

std::vector<BeamElementParts> BeamElementPartsOf(const Bat& bat, const BeamMesh& mesh,
                                                 BeamTheory theory, bool rotary_inertia) {
  const bool timoshenko = theory == BeamTheory::kTimoshenko;
  const bool rotary = timoshenko && rotary_inertia;
  std::vector<BeamElementParts> out(static_cast<std::size_t>(mesh.Elements()));
  for (std::size_t e = 0; e < out.size(); ++e) {
    BeamElementParts& p = out[e];
    p.a_m = mesh.nodes_m[e];
    p.b_m = mesh.nodes_m[e + 1];
    BeamElementMatrix ke;
    BeamElementVector te, re;
    IntegrateBeamElement(bat, mesh.breakpoints_m, p.a_m, p.b_m, timoshenko, rotary, &ke, nullptr,
                         &te, &re);
    Eigen::Map<Eigen::Matrix<double, kElementDofs, kElementDofs, Eigen::RowMajor>>(
        p.stiffness.data()) = ke;
    Eigen::Map<BeamElementVector>(p.mass_t.data()) = te;
    Eigen::Map<BeamElementVector>(p.mass_r0.data()) = re;
  }
  return out;
}

namespace {

// The element holding x and its local coordinate.
void LocateInMesh(const std::vector<double>& nodes, double x, int* element, double* xi) {
  const int ne = static_cast<int>(nodes.size()) - 1;
  x = std::clamp(x, nodes.front(), nodes.back());
  const auto it = std::upper_bound(nodes.begin(), nodes.end(), x);
  int e = it == nodes.begin() ? 0 : static_cast<int>(it - nodes.begin()) - 1;
  if (e >= ne) e = ne - 1;
  const double h = nodes[static_cast<std::size_t>(e) + 1] - nodes[static_cast<std::size_t>(e)];
  *element = e;
  *xi = std::clamp((x - nodes[static_cast<std::size_t>(e)]) / h, 0.0, 1.0);
}

}  // namespace

namespace {
// The field of nodal vector `v` at a point of element `idx` with shape values `s`.
BeamField FieldAt(const ElementShape& s, const int (&idx)[kElementDofs], const Eigen::VectorXd& v) {
  BeamField f;
  for (int i : {0, 1, 4, 5}) {
    const double d = v[idx[i]];
    f.bending_m += s.w[i] * d;
    f.rotation += s.theta[i] * d;
  }
  for (int i : {2, 3, 6}) {
    if (idx[i] >= 0) f.shear_m += s.w[i] * v[idx[i]];
  }
  return f;
}
}  // namespace

BeamField EvaluateField(BeamTheory theory, const std::vector<double>& nodes_m,
                        const Eigen::VectorXd& v, double x_m) {
  int e = 0;
  double xi = 0.0;
  LocateInMesh(nodes_m, x_m, &e, &xi);
  const double h = nodes_m[static_cast<std::size_t>(e) + 1] - nodes_m[static_cast<std::size_t>(e)];
  const ElementShape s = EvaluateElementShape(h, xi);
  int idx[kElementDofs];
  ElementDofIndices(theory, e, idx);
  return FieldAt(s, idx, v);
}

void EvaluateFields(BeamTheory theory, const std::vector<double>& nodes_m,
                    const std::vector<Eigen::VectorXd>& vs, double x_m, BeamField* out) {
  int e = 0;
  double xi = 0.0;
  LocateInMesh(nodes_m, x_m, &e, &xi);
  const double h = nodes_m[static_cast<std::size_t>(e) + 1] - nodes_m[static_cast<std::size_t>(e)];
  const ElementShape s = EvaluateElementShape(h, xi);
  int idx[kElementDofs];
  ElementDofIndices(theory, e, idx);
  for (std::size_t k = 0; k < vs.size(); ++k) out[k] = FieldAt(s, idx, vs[k]);
}

Eigen::VectorXd ProlongField(BeamTheory theory, const std::vector<double>& coarse_nodes_m,
                             const Eigen::VectorXd& coarse,
                             const std::vector<double>& fine_nodes_m) {
  const int ne = static_cast<int>(fine_nodes_m.size()) - 1;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(BeamDofCount(theory, ne));
  for (int e = 0; e < ne; ++e) {
    int idx[kElementDofs];
    ElementDofIndices(theory, e, idx);
    const double a = fine_nodes_m[static_cast<std::size_t>(e)];
    const double b = fine_nodes_m[static_cast<std::size_t>(e) + 1];
    // The coarse field is continuous (w_b C1, w_s C0): its values at the fine nodes and at the
    // fine midpoints (for the bubble) reproduce it exactly on the nested mesh.
    const BeamField fa = EvaluateField(theory, coarse_nodes_m, coarse, a);
    const BeamField fb = EvaluateField(theory, coarse_nodes_m, coarse, b);
    out[idx[0]] = fa.bending_m;
    out[idx[1]] = fa.rotation;
    out[idx[4]] = fb.bending_m;
    out[idx[5]] = fb.rotation;
    if (theory == BeamTheory::kTimoshenko) {
      if (idx[2] >= 0) out[idx[2]] = fa.shear_m;
      out[idx[6]] = fb.shear_m;
      const BeamField fm = EvaluateField(theory, coarse_nodes_m, coarse, 0.5 * (a + b));
      // w_s(mid) = (w_s1 + w_s2) / 2 + bubble (the bubble is 1 at the midpoint).
      out[idx[3]] = fm.shear_m - 0.5 * (fa.shear_m + fb.shear_m);
    }
  }
  return out;
}

}  // namespace sweetspot::core
