// modes: implementation; the accuracy control is described at the top of modes.hpp.
#include "core/flexible/modes.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <boost/math/tools/roots.hpp>

#include "core/flexible/eigensolvers.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

// The dense solver is only a fallback when the subspace iteration fails, up to this size.
constexpr int kDenseMaxDofs = 400;

// One mesh's solution: the mesh, the wanted modes and the Ritz basis for the next mesh.
struct Level {
  BeamMesh mesh;
  std::vector<double> frequencies_hz;
  std::vector<Eigen::VectorXd> vectors;  // flexible modes, mass-normalised
  Eigen::MatrixXd basis;                 // lowest p eigenvectors (rigid ones included)
  Eigen::VectorXd basis_values;          // their eigenvalues
  double mass_kg = 0.0, balance_point_m = 0.0, moi_centroid_kg_m2 = 0.0;
  // The largest eigenvalue (dense fallback) or max K_ii / M_ii over the w_b DOFs, its order of
  // magnitude: sets the round-off floor of the frequencies.
  double lambda_max = 0.0;
  int iterations = 0;  // Lanczos steps or subspace iterations (0 = dense)
};

// The p seed columns of the subspace iteration on `mesh` (ndof DOFs): the coarser mesh's Ritz
// basis prolonged exactly (`previous`, may be null), then rigid translation and rotation and
// cosines cos(j pi x / L) as w_b.
Eigen::MatrixXd SeedBasis(const BeamModesOptions& o, const BeamMesh& mesh, const Level* previous,
                          int p, int ndof) {
  Eigen::MatrixXd seed = Eigen::MatrixXd::Zero(ndof, p);
  // Columns seeded from the coarser mesh (its Ritz basis prolonged exactly); the others start
  // as the first mesh's do.
  const Eigen::Index prolonged =
      previous == nullptr ? 0 : std::min<Eigen::Index>(p, previous->basis.cols());
  for (Eigen::Index j = 0; j < prolonged; ++j) {
    seed.col(j) =
        ProlongField(o.theory, previous->mesh.nodes_m, previous->basis.col(j), mesh.nodes_m);
  }
  // Rigid translation and rotation, then cosines cos(j pi x / L) as w_b.
  const double length = mesh.nodes_m.back();
  for (int e = 0; e < mesh.Elements(); ++e) {
    int idx[kElementDofs];
    ElementDofIndices(o.theory, e, idx);
    for (int side = 0; side < 2; ++side) {
      const double x = mesh.nodes_m[static_cast<std::size_t>(e + side)];
      const int iw = idx[side == 0 ? 0 : 4], it = idx[side == 0 ? 1 : 5];
      if (prolonged <= 0) seed(iw, 0) = 1.0;
      if (prolonged <= 1) {
        seed(iw, 1) = x - 0.5 * length;
        seed(it, 1) = 1.0;
      }
      for (Eigen::Index j = std::max<Eigen::Index>(prolonged, 2); j < p; ++j) {
        const double kj = static_cast<double>(j - 1) * kPi / length;
        seed(iw, j) = std::cos(kj * x);
        seed(it, j) = -kj * std::sin(kj * x);
      }
    }
  }
  return seed;
}

// The shift of the iteration on `mesh`: near the coarser mesh's first bending mode, or a uniform
// beam's first free-free mode with the bat's mean section on the first mesh.
double ShiftFor(const Bat& bat, const BeamMesh& mesh, const Level* previous) {
  if (previous != nullptr) {
    // Shift near the first bending mode: K + sigma M is positive definite and the wanted modes
    // converge at the rate (lambda_i + sigma) / (lambda_p + sigma).
    return previous->basis_values[2];
  }
  // The shift: a uniform beam's first free-free mode with the bat's mean section.
  double ei = 0.0, rho_a = 0.0;
  constexpr int kProbes = 64;
  for (int i = 0; i < kProbes; ++i) {
    const BeamSection sec = SectionAt(bat, mesh.nodes_m.back() * (i + 0.5) / kProbes);
    ei += sec.bending_stiffness_n_m2 / kProbes;
    rho_a += sec.mass_per_length_kg_m / kProbes;
  }
  const double beta = 4.730040745 / mesh.nodes_m.back();
  return beta * beta * beta * beta * ei / rho_a;
}

// The rigid modes, M-orthonormal: translation (w_b = 1) and rotation about the centroid
// (w_b = x - C, theta = 1), both in K's null space.
Eigen::MatrixXd RigidModes(const BeamModesOptions& o, const BeamMesh& mesh,
                           const BeamMatrices& mats, int ndof) {
  Eigen::MatrixXd rigid = Eigen::MatrixXd::Zero(ndof, 2);
  for (int e = 0; e < mesh.Elements(); ++e) {
    int idx[kElementDofs];
    ElementDofIndices(o.theory, e, idx);
    rigid(idx[0], 0) = rigid(idx[4], 0) = 1.0;
    rigid(idx[0], 1) = mesh.nodes_m[static_cast<std::size_t>(e)];
    rigid(idx[4], 1) = mesh.nodes_m[static_cast<std::size_t>(e) + 1];
    rigid(idx[1], 1) = rigid(idx[5], 1) = 1.0;
  }
  const Eigen::VectorXd mt = mats.mass * rigid.col(0);
  const double mass = rigid.col(0).dot(mt);
  rigid.col(1) -= (rigid.col(1).dot(mt) / mass) * rigid.col(0);
  rigid.col(0) /= std::sqrt(mass);
  rigid.col(1) /= std::sqrt(rigid.col(1).dot(mats.mass * rigid.col(1)));
  return rigid;
}

// The wanted modes of `lambda`/`vectors` (the two rigid ones first) into *out: frequencies and
// vectors with a deterministic sign, and the basis for the next mesh. False with *why when the
// rigid modes or a flexible one are not what they must be.
bool TakeModes(const BeamModesOptions& o, const BeamMesh& mesh, Eigen::VectorXd lambda,
               Eigen::MatrixXd vectors, Level* out, std::string* why) {
  const double lambda2 = lambda[2];
  if (!(std::isfinite(lambda2) && lambda2 > 0.0) ||
      std::max(std::abs(lambda[0]), std::abs(lambda[1])) > 1e-3 * lambda2) {
    *why = "expected two rigid-body modes (eigenvalues ~0) below the first bending mode, got " +
           FormatNumber17(lambda[0]) + ", " + FormatNumber17(lambda[1]) + " and " +
           FormatNumber17(lambda2) + " rad^2/s^2";
    return false;
  }
  out->frequencies_hz.clear();
  out->vectors.clear();
  BatModes probe;  // to evaluate the tip displacement
  probe.theory = o.theory;
  probe.nodes_m = mesh.nodes_m;
  for (int k = 0; k < o.num_modes; ++k) {
    const double l = lambda[k + 2];
    if (!(std::isfinite(l) && l > 0.0)) {
      *why =
          "mode " + std::to_string(k + 1) + " has a non-positive eigenvalue " + FormatNumber17(l);
      return false;
    }
    out->frequencies_hz.push_back(std::sqrt(l) / (2.0 * kPi));
    Eigen::VectorXd v = vectors.col(k + 2);
    // Deterministic sign: the tip moves positive (a tip node: the largest |w| sample instead).
    double ref = probe.Displacement(v, mesh.nodes_m.back());
    if (std::abs(ref) < 1e-9 * v.cwiseAbs().maxCoeff()) {
      double best = 0.0;
      for (double x : mesh.nodes_m) {
        const double w = probe.Displacement(v, x);
        if (std::abs(w) > std::abs(best)) best = w;
      }
      ref = best;
    }
    if (ref < 0.0) v = -v;
    out->vectors.push_back(std::move(v));
  }
  out->basis = std::move(vectors);
  out->basis_values = std::move(lambda);
  return true;
}

// Rigid-body properties of M into *out: translation t (w_b = 1), rotation about the knob
// (w_b = x, theta = 1).
void RigidBodyOfMass(const BeamModesOptions& o, const BeamMesh& mesh, const BeamMatrices& mats,
                     Level* out) {
  const int ndof = static_cast<int>(mats.mass.rows());
  Eigen::VectorXd t = Eigen::VectorXd::Zero(ndof), r0 = Eigen::VectorXd::Zero(ndof);
  const int ne = mesh.Elements();
  for (int e = 0; e < ne; ++e) {
    int idx[kElementDofs];
    ElementDofIndices(o.theory, e, idx);
    t[idx[0]] = t[idx[4]] = 1.0;
    r0[idx[0]] = mesh.nodes_m[static_cast<std::size_t>(e)];
    r0[idx[4]] = mesh.nodes_m[static_cast<std::size_t>(e) + 1];
    r0[idx[1]] = r0[idx[5]] = 1.0;
  }
  const Eigen::VectorXd mt = mats.mass * t;
  out->mass_kg = t.dot(mt);
  out->balance_point_m = r0.dot(mt) / out->mass_kg;
  const Eigen::VectorXd r = r0 - out->balance_point_m * t;
  out->moi_centroid_kg_m2 = r.dot(mats.mass * r);
}

// Solves one mesh; false with *why on failure. `previous` (may be null) seeds the iteration.
bool SolveLevel(const Bat& bat, const BeamModesOptions& o, BeamMesh mesh, const Level* previous,
                Level* out, std::string* why) {
  const BeamMatrices mats = AssembleBeam(bat, mesh, o.theory, o.rotary_inertia);
  const int ndof = static_cast<int>(mats.mass.rows());
  const int wanted = o.num_modes + 2;  // the two rigid-body modes come first
  if (ndof < wanted) {
    *why = "the mesh has too few degrees of freedom for " + std::to_string(o.num_modes) + " modes";
    return false;
  }
  // Ritz basis: twice the wanted modes, never more than half the DOFs (the projected problem
  // must hold only well-resolved low modes for its dense solve to be accurate).
  const int p = std::max(wanted + 2, std::min(ndof / 2, std::max(2 * wanted, wanted + 8)));
  const Eigen::MatrixXd seed = SeedBasis(o, mesh, previous, p, ndof);
  const double sigma = ShiftFor(bat, mesh, previous);
  for (int e = 0; e < mesh.Elements(); ++e) {
    int idx[kElementDofs];
    ElementDofIndices(o.theory, e, idx);
    for (int i : {idx[0], idx[4]}) {
      const double mii = mats.mass.coeff(i, i);
      if (mii > 0.0) out->lambda_max = std::max(out->lambda_max, mats.stiffness.coeff(i, i) / mii);
    }
  }
  const Eigen::MatrixXd rigid = RigidModes(o, mesh, mats, ndof);
  Eigen::VectorXd lambda;
  Eigen::MatrixXd vectors;
  std::string iteration_error;
  const bool shifted = std::isfinite(sigma) && sigma > 0.0;
  // The fast path: shift-invert Lanczos from the sum of the seed's flexible columns.
  const bool solved =
      shifted && ConfirmedLanczos(mats.stiffness, mats.mass, rigid, o.num_modes, p - wanted, sigma,
                                  seed.rightCols(p - 2).rowwise().sum(), &lambda, &vectors,
                                  &out->iterations);
  if (!solved && (!shifted || !SubspaceIteration(mats.stiffness, mats.mass, wanted, sigma, seed,
                                                 &lambda, &vectors, &out->iterations,
                                                 &iteration_error))) {
    if (ndof > kDenseMaxDofs) {
      *why =
          iteration_error.empty() ? "no usable shift for the subspace iteration" : iteration_error;
      return false;
    }
    // Small meshes: the dense generalized solver as a fallback (norm-wise accurate only).
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(
        Eigen::MatrixXd(mats.stiffness), Eigen::MatrixXd(mats.mass),
        Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    if (es.info() != Eigen::Success) {
      *why = "the generalized eigensolver failed (the mass matrix is not positive definite?)";
      return false;
    }
    lambda = es.eigenvalues().head(p);
    vectors = es.eigenvectors().leftCols(p);
    out->lambda_max = std::max(out->lambda_max, es.eigenvalues()[ndof - 1]);
    out->iterations = 0;
  }
  if (!TakeModes(o, mesh, std::move(lambda), std::move(vectors), out, why)) return false;
  RigidBodyOfMass(o, mesh, mats, out);
  out->mesh = std::move(mesh);
  return true;
}

}  // namespace

bool BeamModesOptions::Validate(Refusal* why) const {
  if (num_modes < 1 || num_modes > 50)
    return Refuse(why, IntegerRefusal("num_modes", num_modes, "must be in [1, 50]"));
  if (!(std::isfinite(relative_tolerance) && relative_tolerance >= 1e-9 &&
        relative_tolerance <= 0.1))
    return Refuse(
        why, Number17Refusal("relative_tolerance", relative_tolerance, "must be in [1e-9, 0.1]"));
  if (initial_elements < 1 || initial_elements > 4096)
    return Refuse(why,
                  IntegerRefusal("initial_elements", initial_elements, "must be in [1, 4096]"));
  if (max_elements < 2 || max_elements > 4096)
    return Refuse(why, IntegerRefusal("max_elements", max_elements, "must be in [2, 4096]"));
  return true;
}

double BatModes::Displacement(const Eigen::VectorXd& v, double x_m) const {
  const BeamField f = EvaluateField(theory, nodes_m, v, x_m);
  return f.bending_m + f.shear_m;
}

double BatModes::Rotation(const Eigen::VectorXd& v, double x_m) const {
  return EvaluateField(theory, nodes_m, v, x_m).rotation;
}

Eigen::VectorXd BatModes::TranslationMode() const {
  const int ne = Elements();
  Eigen::VectorXd v = Eigen::VectorXd::Zero(BeamDofCount(theory, ne));
  for (int e = 0; e < ne; ++e) {
    int idx[kElementDofs];
    ElementDofIndices(theory, e, idx);
    v[idx[0]] = v[idx[4]] = 1.0 / std::sqrt(mass_kg);
  }
  return v;
}

Eigen::VectorXd BatModes::RotationMode() const {
  const int ne = Elements();
  Eigen::VectorXd v = Eigen::VectorXd::Zero(BeamDofCount(theory, ne));
  const double s = 1.0 / std::sqrt(moi_centroid_kg_m2);
  for (int e = 0; e < ne; ++e) {
    int idx[kElementDofs];
    ElementDofIndices(theory, e, idx);
    v[idx[0]] = (nodes_m[static_cast<std::size_t>(e)] - balance_point_m) * s;
    v[idx[4]] = (nodes_m[static_cast<std::size_t>(e) + 1] - balance_point_m) * s;
    v[idx[1]] = v[idx[5]] = s;
  }
  return v;
}

std::vector<double> DisplacementZeros(const BatModes& modes, const Eigen::VectorXd& v) {
  std::vector<double> out;
  constexpr int kSamples = 8;
  const std::vector<double>& nodes = modes.nodes_m;
  auto w = [&](double x) { return modes.Displacement(v, x); };
  double x_prev = nodes.front();
  double w_prev = w(x_prev);
  if (w_prev == 0.0) out.push_back(x_prev);
  for (std::size_t e = 0; e + 1 < nodes.size(); ++e) {
    for (int j = 1; j <= kSamples; ++j) {
      const double x =
          j == kSamples ? nodes[e + 1] : nodes[e] + (nodes[e + 1] - nodes[e]) * j / kSamples;
      const double wx = w(x);
      if (wx == 0.0) {
        if (out.empty() || out.back() != x) out.push_back(x);
      } else if (w_prev != 0.0 && (wx > 0.0) != (w_prev > 0.0)) {
        boost::uintmax_t iters = 100;
        try {
          const auto r = boost::math::tools::toms748_solve(
              w, x_prev, x, w_prev, wx, boost::math::tools::eps_tolerance<double>(52), iters);
          out.push_back(0.5 * (r.first + r.second));
        } catch (const std::exception&) {
          out.push_back(0.5 * (x_prev + x));  // bracketed to one sample interval
        }
      }
      x_prev = x;
      w_prev = wx;
    }
  }
  // Keep the list strictly increasing (a zero exactly on a sample is found once).
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace modes_steps {
namespace {

// The bat and options the modes can be computed for; otherwise the refusal in out->summary.
bool CheckModesInputs(const Bat& bat, const BeamModesOptions& options, BatModes* out) {
  Summary& s = out->summary;
  if (Refusal refusal; !options.Validate(&refusal)) {
    s.SetRefusal(std::move(refusal));
    return false;
  }
  if (Refusal refusal; !bat.Validate(&refusal)) {
    s.SetRefusal(Prefixed("bat.", std::move(refusal)));
    return false;
  }
  out->length_m = bat.LengthM();
  double r_max = 0.0;
  for (const ProfileKnot& k : bat.knots) r_max = std::max(r_max, k.radius_m);
  if (!(out->length_m >= 4.0 * r_max)) {
    s.SetRefusal(Number17Refusal(
        "bat.length_m", out->length_m,
        "the beam model needs a slender bat (length at least 4 x the largest radius " +
            FormatNumber17(r_max) + " m)"));
    return false;
  }
  return true;
}

// The meshes solved, finest last, with each level's (from the second on) error estimate and
// observed order per mode.
struct Refinement {
  std::vector<Level> levels;
  std::vector<std::vector<double>> errs = std::vector<std::vector<double>>(1);
  std::vector<std::vector<double>> orders = std::vector<std::vector<double>>(1);
  bool converged = false;
  bool round_off_limited = false;
};

// The error estimate and observed order of each mode at level j >= 1 of `levels` into *err and
// *order; true when every mode is within the tolerance. *worst_now: the worst relative error
// now; *worst_next: what the next mesh could reach.
bool LevelErrors(const std::vector<Level>& levels, std::size_t j, const BeamModesOptions& options,
                 std::vector<double>* err, std::vector<double>* order, double* worst_now,
                 double* worst_next) {
  bool converged = true;
  *worst_now = 0.0;
  *worst_next = 0.0;
  for (std::size_t k = 0; k < err->size(); ++k) {
    const double f2 = levels[j].frequencies_hz[k];
    const double d2 = std::abs(f2 - levels[j - 1].frequencies_hz[k]);
    double p = 2.0;  // two meshes only: assume less than the theoretical 4
    if (j >= 2) {
      const double d1 = std::abs(levels[j - 1].frequencies_hz[k] - levels[j - 2].frequencies_hz[k]);
      if (d1 > 0.0 && d2 > 0.0) {
        (*order)[k] = std::log2(d1 / d2);
        p = std::clamp((*order)[k], 1.0, 4.0);
      } else if (d2 == 0.0) {
        p = 4.0;
      }
    }
    // Round-off floor: the Rayleigh quotient x'Kx of a smooth mode cancels terms of size
    // ~lambda_max x'Mx, so omega^2 carries ~eps lambda_max / lambda_k relative rounding and
    // f half of it (measured: ~30 times below this bound on a uniform beam).
    const double lambda_k = 4.0 * kPi * kPi * f2 * f2;
    const double floor = std::max(
        0.5 * std::numeric_limits<double>::epsilon() * levels[j].lambda_max / lambda_k, 1e-13);
    const double discretisation = d2 / (std::pow(2.0, p) - 1.0);
    (*err)[k] = discretisation + floor * f2;
    *worst_now = std::max(*worst_now, (*err)[k] / f2);
    // The next mesh: discretisation / 2^p, floor x 16 (h^-4 in lambda_max).
    *worst_next = std::max(*worst_next, discretisation / std::pow(2.0, p) / f2 + 16.0 * floor);
    if ((*err)[k] > options.relative_tolerance * f2) converged = false;
  }
  return converged;
}

// Solves finer meshes until the modes converge, round-off takes over or max_elements is reached,
// into *r. False with out->summary's refusal or failure set when no mesh could be solved.
bool Refine(const Bat& bat, const BeamModesOptions& options, Refinement* r, BatModes* out) {
  Summary& s = out->summary;
  const int n0 = std::max(options.initial_elements, 2 * options.num_modes + 4);
  const std::size_t nm = static_cast<std::size_t>(options.num_modes);
  std::vector<Level>& levels = r->levels;
  std::string why;
  for (int level = 0; level < 20; ++level) {
    BeamMesh mesh = MakeBeamMesh(bat, n0, level);
    if (mesh.Elements() > options.max_elements) {
      if (levels.empty()) {
        s.SetRefusal(IntegerRefusal("max_elements", options.max_elements,
                                    "the bat needs at least " + std::to_string(mesh.Elements()) +
                                        " elements (one per profile segment, and " +
                                        std::to_string(n0) + " for the modes asked for)"));
        return false;
      }
      break;
    }
    Level lv;
    if (!SolveLevel(bat, options, std::move(mesh), levels.empty() ? nullptr : &levels.back(), &lv,
                    &why)) {
      s.termination = Termination::kFailure;
      s.message = why;
      return false;
    }
    out->refinement_elements.push_back(lv.mesh.Elements());
    levels.push_back(std::move(lv));
    const std::size_t j = levels.size() - 1;
    if (j == 0) continue;
    std::vector<double> err(nm, 0.0), order(nm, 0.0);
    double worst_now = 0.0, worst_next = 0.0;
    r->converged = LevelErrors(levels, j, options, &err, &order, &worst_now, &worst_next);
    r->errs.push_back(std::move(err));
    r->orders.push_back(std::move(order));
    if (r->converged) break;
    // The floor grows ~16x per halving of h: once the next mesh cannot do better, stop.
    if (worst_next >= worst_now) {
      r->round_off_limited = true;
      break;
    }
  }
  return true;
}

// The level with the smallest worst relative error (the last one unless round-off took over).
std::size_t BestLevel(const Refinement& r, std::size_t nm) {
  const std::vector<Level>& levels = r.levels;
  std::size_t best = levels.size() - 1;
  if (!r.converged && levels.size() >= 2) {
    double best_err = std::numeric_limits<double>::infinity();
    for (std::size_t j = 1; j < levels.size(); ++j) {
      double worst = 0.0;
      for (std::size_t k = 0; k < nm; ++k) {
        worst = std::max(worst, r.errs[j][k] / levels[j].frequencies_hz[k]);
      }
      if (worst < best_err) {
        best_err = worst;
        best = j;
      }
    }
  }
  return best;
}

// The modes of the finest level of `levels` (cut at the best one) into *out, with their error
// estimates (err, order) and nodes.
void FillModes(const Bat& bat, const BeamModesOptions& options, const std::vector<Level>& levels,
               const std::vector<double>& err, const std::vector<double>& order, BatModes* out) {
  const Level& fin = levels.back();
  out->nodes_m = fin.mesh.nodes_m;
  out->breakpoints_m = fin.mesh.breakpoints_m;
  out->mass_kg = fin.mass_kg;
  out->balance_point_m = fin.balance_point_m;
  out->moi_centroid_kg_m2 = fin.moi_centroid_kg_m2;
  out->element_parts = BeamElementPartsOf(bat, fin.mesh, out->theory, out->rotary_inertia);
  // The previous level's modes, for the node error estimates.
  BatModes prev;
  if (levels.size() >= 2) {
    const Level& pl = levels[levels.size() - 2];
    prev.theory = options.theory;
    prev.nodes_m = pl.mesh.nodes_m;
  }
  for (std::size_t k = 0; k < err.size(); ++k) {
    BeamMode mode;
    mode.frequency_hz = fin.frequencies_hz[k];
    mode.error_estimate_hz = levels.size() >= 2 ? err[k] : mode.frequency_hz;
    mode.observed_order = order[k];
    mode.vector = fin.vectors[k];
    mode.nodes_from_knob_m = DisplacementZeros(*out, mode.vector);
    if (levels.size() >= 2) {
      const auto pn = DisplacementZeros(prev, levels[levels.size() - 2].vectors[k]);
      if (pn.size() == mode.nodes_from_knob_m.size()) {
        double d = 0.0;
        for (std::size_t i = 0; i < pn.size(); ++i)
          d = std::max(d, std::abs(pn[i] - mode.nodes_from_knob_m[i]));
        // Positions converge like the frequencies; divide by 2^2 - 1 only (conservative).
        mode.nodes_error_estimate_m = d / 3.0;
      } else {
        double h = 0.0;
        for (std::size_t i = 0; i + 1 < out->nodes_m.size(); ++i)
          h = std::max(h, out->nodes_m[i + 1] - out->nodes_m[i]);
        mode.nodes_error_estimate_m = h;
      }
    } else {
      mode.nodes_error_estimate_m = out->length_m;
    }
    out->max_relative_error =
        std::max(out->max_relative_error, mode.error_estimate_hz / mode.frequency_hz);
    out->modes.push_back(std::move(mode));
  }
}

// The summary of modes computed from `levels`: counts, error, termination and message.
void ConcludeModes(const BeamModesOptions& options, const Refinement& r, BatModes* out) {
  Summary& s = out->summary;
  s.iterations = static_cast<int>(r.levels.size());
  // evaluations: the shift-invert steps of every mesh (Lanczos steps or subspace iterations; a
  // dense solve counts 1).
  s.evaluations = 0;
  for (const Level& l : r.levels) s.evaluations += std::max(l.iterations, 1);
  s.error_estimate = out->max_relative_error;
  s.objective = out->modes.front().frequency_hz;
  if (r.converged) {
    s.termination = Termination::kConverged;
    s.message = std::to_string(options.num_modes) + " modes to a relative frequency error of " +
                FormatNumber17(out->max_relative_error) + " with " +
                std::to_string(out->Elements()) + " elements";
    return;
  }
  s.termination = Termination::kNoConvergence;
  s.message = r.round_off_limited
                  ? "round-off limits the relative frequency error to about " +
                        FormatNumber17(out->max_relative_error) + " (" +
                        std::to_string(out->Elements()) +
                        " elements; a finer mesh would be worse), above the tolerance " +
                        FormatNumber17(options.relative_tolerance)
                  : "max_elements = " + std::to_string(options.max_elements) +
                        " reached before the relative tolerance " +
                        FormatNumber17(options.relative_tolerance) + " (estimated error " +
                        FormatNumber17(out->max_relative_error) + " with " +
                        std::to_string(out->Elements()) + " elements)";
  s.warnings.push_back(s.message);
}

}  // namespace
}  // namespace modes_steps

BatModes ComputeBatModes(const Bat& bat, const BeamModesOptions& options) {
  using namespace modes_steps;
  return TimedSolve<BatModes>([&](BatModes& out) {
    Summary& s = out.summary;
    s.backend = "eigen:generalized_self_adjoint";
    s.models_used = {"flexible_beam"};
    out.theory = options.theory;
    out.rotary_inertia = options.rotary_inertia && options.theory == BeamTheory::kTimoshenko;
    out.tolerance = options.relative_tolerance;
    if (!CheckModesInputs(bat, options, &out)) return;
    Refinement r;
    if (!Refine(bat, options, &r, &out)) return;
    const std::size_t nm = static_cast<std::size_t>(options.num_modes);
    const std::size_t best = BestLevel(r, nm);
    r.levels.resize(best + 1);
    const std::vector<double> err =
        r.levels.size() >= 2 ? r.errs[best] : std::vector<double>(nm, 0.0);
    const std::vector<double> order =
        r.levels.size() >= 2 ? r.orders[best] : std::vector<double>(nm, 0.0);
    FillModes(bat, options, r.levels, err, order, &out);
    ConcludeModes(options, r, &out);
  });
}

}  // namespace sweetspot::core
