// beam_frequency: implementation; the model and its derivative are described at the top of
// beam_frequency.hpp.
#include "core/flexible/beam_frequency.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <limits>
#include <type_traits>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "core/bat/mass_properties.hpp"
#include "core/numerics/gauss_legendre.hpp"
#include "core/numerics/jet.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace beam_frequency_detail {
namespace {

// The local parameters of one knot segment: its two knot positions and radii, L, the wall, the
// density, the fill's diameter, depth and density.
constexpr int kLocal = 10;
using LocalJet = jet::Jet<kLocal, false>;
using SparseMatrix = Eigen::SparseMatrix<double>;
using Matrix7 = Eigen::Matrix<double, kElementDofs, kElementDofs>;

// Subspace iteration: the residual |(lambda + sigma) (K + sigma M)^-1 M x - x| / |x| of the first
// bending mode at which it stops, the round-off level below which a stall also stops it, and
// the most iterations.
constexpr double kResidualTolerance = 1e-11;
constexpr double kStallResidual = 1e-8;
constexpr int kMaxIterations = 100;

template <typename T>
T LocalValue(double v, int i) {
  if constexpr (std::is_same_v<T, double>) {
    (void)i;
    return v;
  } else {
    return T::Variable(v, i);
  }
}

template <typename T>
struct Params {
  T xa, xb, ra, rb, length, wall, rho, fill_d, depth, fill_rho;
};

template <typename T>
struct Section {
  T rho_a, rho_i, ei, kga;
};

template <typename T>
struct Shape {
  std::array<T, kElementDofs> w, theta, curvature, shear;
};

// Cowper's coefficient (beam_model.hpp) for a ratio of the scalar type.
template <typename T>
T Cowper(double nu, const T& m) {
  const T m2 = m * m;
  const T a = (1.0 + m2) * (1.0 + m2);
  return (6.0 * (1.0 + nu)) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2);
}

// The section of SectionAt (beam_model.cpp) at outer radius r, in the scalar type.
template <typename T>
Section<T> SectionOf(const FixedMeshBeam& b, const T& r, bool in_fill, const Params<T>& p,
                     double fill_density_value) {
  T r_in(0.0);
  if (b.hollow) {
    r_in = r - p.wall;
    if (jet::Value(r_in) < 0.0) r_in = T(0.0);
  }
  const T r_fill = 0.5 * p.fill_d;
  if (in_fill && !b.hollow) r_in = r_fill;  // the bore replaces the solid's core
  const T dr = r - r_in;
  const T sr = r + r_in;
  const T a_b = kPi * (dr * sr);
  const T i_b = (0.25 * kPi) * (dr * sr) * (r * r + r_in * r_in);
  Section<T> s;
  s.rho_a = p.rho * a_b;
  s.rho_i = p.rho * i_b;
  s.ei = b.youngs_modulus_pa * i_b;
  const T ratio = jet::Value(r) > 0.0 ? r_in / r : T(0.0);
  s.kga = (Cowper(b.poissons_ratio, ratio) * b.shear_modulus_pa) * a_b;
  if (in_fill && fill_density_value != 0.0) {
    const T rf2 = r_fill * r_fill;
    const T a_f = kPi * rf2;
    const T i_f = (0.25 * kPi) * (rf2 * rf2);
    s.rho_a = s.rho_a + p.fill_rho * a_f;
    s.rho_i = s.rho_i + p.fill_rho * i_f;
    s.ei = s.ei + b.fill_youngs_modulus_pa * i_f;
    s.kga = s.kga +
            (CowperShearCoefficient(b.fill_poissons_ratio, 0.0) * b.fill_shear_modulus_pa) * a_f;
  }
  return s;
}

// EvaluateElementShape (beam_model.cpp) in the scalar type.
template <typename T>
Shape<T> ShapeOf(const T& h, const T& xi) {
  const T x2 = xi * xi;
  const T x3 = x2 * xi;
  Shape<T> s;
  for (int i = 0; i < kElementDofs; ++i) {
    s.w[static_cast<std::size_t>(i)] = T(0.0);
    s.theta[static_cast<std::size_t>(i)] = T(0.0);
    s.curvature[static_cast<std::size_t>(i)] = T(0.0);
    s.shear[static_cast<std::size_t>(i)] = T(0.0);
  }
  const T hh = h * h;
  s.w[0] = 1.0 - 3.0 * x2 + 2.0 * x3;
  s.w[1] = h * (xi - 2.0 * x2 + x3);
  s.w[4] = 3.0 * x2 - 2.0 * x3;
  s.w[5] = h * (x3 - x2);
  s.theta[0] = 6.0 * (x2 - xi) / h;
  s.theta[1] = 1.0 - 4.0 * xi + 3.0 * x2;
  s.theta[4] = 6.0 * (xi - x2) / h;
  s.theta[5] = 3.0 * x2 - 2.0 * xi;
  s.curvature[0] = (12.0 * xi - 6.0) / hh;
  s.curvature[1] = (6.0 * xi - 4.0) / h;
  s.curvature[4] = (6.0 - 12.0 * xi) / hh;
  s.curvature[5] = (6.0 * xi - 2.0) / h;
  s.w[2] = 1.0 - xi;
  s.w[3] = 4.0 * xi * (1.0 - xi);
  s.w[6] = xi;
  s.shear[2] = -1.0 / h;
  s.shear[3] = 4.0 * (1.0 - 2.0 * xi) / h;
  s.shear[6] = 1.0 / h;
  return s;
}

// Calls visit(segment, element, shape, section, weight) at every Gauss point of every piece of
// the profile: each knot segment (coincident knots included: a segment of zero length is one
// piece of zero length, whose derivative is that of the segment it opens) cut at the nodes and
// the fill's bottom strictly inside it. Pieces partition [0, L]; each lies in one element.
template <typename T, typename Visit>
void VisitQuadrature(const FixedMeshBeam& b, const std::vector<double>& t, Visit&& visit) {
  const DesignParameterLayout lay{b.num_knots};
  auto at = [&](int idx) { return t[static_cast<std::size_t>(idx)]; };
  const int nk = b.num_knots;
  const int ne = b.Elements();
  const double length_v = at(lay.KnotPosition(nk - 1));
  const double bottom_v =
      b.has_fill ? length_v - at(lay.FillDepth()) : std::numeric_limits<double>::infinity();
  const double fill_density_v = b.has_fill ? at(lay.FillDensity()) : 0.0;
  std::vector<double> node_v(static_cast<std::size_t>(ne) + 1);
  for (int k = 0; k <= ne; ++k) {
    node_v[static_cast<std::size_t>(k)] = b.node_fractions[static_cast<std::size_t>(k)] * length_v;
  }
  struct Cut {
    double v;
    T x;
    T s;  // position within the segment, 0 at its first knot, 1 at its second
  };
  std::vector<Cut> cuts;
  for (int i = 0; i + 1 < nk; ++i) {
    Params<T> p;
    p.xa = LocalValue<T>(at(lay.KnotPosition(i)), 0);
    p.xb = LocalValue<T>(at(lay.KnotPosition(i + 1)), 1);
    p.ra = LocalValue<T>(at(lay.KnotRadius(i)), 2);
    p.rb = LocalValue<T>(at(lay.KnotRadius(i + 1)), 3);
    p.length = LocalValue<T>(length_v, 4);
    p.wall = LocalValue<T>(at(lay.WallThickness()), 5);
    p.rho = LocalValue<T>(at(lay.Density()), 6);
    p.fill_d = LocalValue<T>(b.has_fill ? at(lay.FillDiameter()) : 0.0, 7);
    p.depth = LocalValue<T>(b.has_fill ? at(lay.FillDepth()) : 0.0, 8);
    p.fill_rho = LocalValue<T>(fill_density_v, 9);
    const double xa = jet::Value(p.xa);
    const double xb = jet::Value(p.xb);
    cuts.clear();
    cuts.push_back({xa, p.xa, T(0.0)});
    if (xb > xa) {
      const T width = p.xb - p.xa;
      for (int k = 1; k < ne; ++k) {
        const double v = node_v[static_cast<std::size_t>(k)];
        if (v > xa && v < xb) {
          const T x = b.node_fractions[static_cast<std::size_t>(k)] * p.length;
          cuts.push_back({v, x, (x - p.xa) / width});
        }
      }
      if (bottom_v > xa && bottom_v < xb) {
        const T x = p.length - p.depth;
        cuts.push_back({bottom_v, x, (x - p.xa) / width});
      }
      std::stable_sort(cuts.begin() + 1, cuts.end(),
                       [](const Cut& l, const Cut& r) { return l.v < r.v; });
    }
    cuts.push_back({xb, p.xb, T(1.0)});
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
      const Cut& lo = cuts[c];
      const Cut& hi = cuts[c + 1];
      const double mid = 0.5 * (lo.v + hi.v);
      int e =
          static_cast<int>(std::upper_bound(node_v.begin(), node_v.end(), mid) - node_v.begin()) -
          1;
      e = std::clamp(e, 0, ne - 1);
      const bool in_fill = b.has_fill && mid >= bottom_v;
      const T a_e = b.node_fractions[static_cast<std::size_t>(e)] * p.length;
      const T h_e = (b.node_fractions[static_cast<std::size_t>(e) + 1] -
                     b.node_fractions[static_cast<std::size_t>(e)]) *
                    p.length;
      const T half = 0.5 * (hi.x - lo.x);
      const T ds = hi.s - lo.s;
      for (std::size_t g = 0; g < kGauss5X.size(); ++g) {
        const double u = 0.5 * (1.0 + kGauss5X[g]);
        const T x = lo.x + (2.0 * u) * half;
        const T s = lo.s + u * ds;
        const T r = p.ra + (p.rb - p.ra) * s;
        const Section<T> sec = SectionOf(b, r, in_fill, p, fill_density_v);
        const Shape<T> shape = ShapeOf(h_e, (x - a_e) / h_e);
        visit(i, e, shape, sec, half * kGauss5W[g]);
      }
    }
  }
}

// The assembled matrices (double).
BeamMatrices Assemble(const FixedMeshBeam& b, const std::vector<double>& t) {
  const int ne = b.Elements();
  const bool timoshenko = b.theory == BeamTheory::kTimoshenko;
  const bool rotary = timoshenko && b.rotary_inertia;
  std::vector<Matrix7> ke(static_cast<std::size_t>(ne), Matrix7::Zero());
  std::vector<Matrix7> me(static_cast<std::size_t>(ne), Matrix7::Zero());
  using Vector7 = Eigen::Matrix<double, kElementDofs, 1>;
  VisitQuadrature<double>(b, t,
                          [&](int, int e, Shape<double> n, const Section<double>& s, double wgt) {
                            if (!timoshenko) {
                              for (int i : {2, 3, 6}) n.w[static_cast<std::size_t>(i)] = 0.0;
                            }
                            const Eigen::Map<const Vector7> nw(n.w.data()), nt(n.theta.data()),
                                cv(n.curvature.data()), sh(n.shear.data());
                            Matrix7& k = ke[static_cast<std::size_t>(e)];
                            Matrix7& m = me[static_cast<std::size_t>(e)];
                            k.noalias() += (wgt * s.ei) * (cv * cv.transpose());
                            if (timoshenko) k.noalias() += (wgt * s.kga) * (sh * sh.transpose());
                            m.noalias() += (wgt * s.rho_a) * (nw * nw.transpose());
                            if (rotary) m.noalias() += (wgt * s.rho_i) * (nt * nt.transpose());
                          });
  const int ndof = BeamDofCount(b.theory, ne);
  std::vector<Eigen::Triplet<double>> kt, mt;
  kt.reserve(static_cast<std::size_t>(ne) * 49);
  mt.reserve(static_cast<std::size_t>(ne) * 49);
  for (int e = 0; e < ne; ++e) {
    int idx[kElementDofs];
    ElementDofIndices(b.theory, e, idx);
    for (int i = 0; i < kElementDofs; ++i) {
      if (idx[i] < 0) continue;
      for (int j = 0; j < kElementDofs; ++j) {
        if (idx[j] < 0) continue;
        const double kv = ke[static_cast<std::size_t>(e)](i, j);
        const double mv = me[static_cast<std::size_t>(e)](i, j);
        if (kv != 0.0) kt.emplace_back(idx[i], idx[j], kv);
        if (mv != 0.0) mt.emplace_back(idx[i], idx[j], mv);
      }
    }
  }
  BeamMatrices out;
  out.stiffness.resize(ndof, ndof);
  out.mass.resize(ndof, ndof);
  out.stiffness.setFromTriplets(kt.begin(), kt.end());
  out.mass.setFromTriplets(mt.begin(), mt.end());
  return out;
}

// The first bending eigenpair by shift-invert subspace iteration from the beam's start basis.
bool SolveFirst(const FixedMeshBeam& b, const BeamMatrices& mats, FirstBendingMode* out) {
  const Eigen::Index ndof = mats.mass.rows();
  if (b.start_basis.rows() != ndof || b.start_basis.cols() < 3 ||
      !(std::isfinite(b.shift) && b.shift > 0.0)) {
    out->message = "the fixed-mesh beam has no usable start basis or shift";
    return false;
  }
  const double sigma = b.shift;
  const SparseMatrix shifted = mats.stiffness + sigma * mats.mass;
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(shifted);
  if (ldlt.info() != Eigen::Success) {
    out->message = "the factorisation of K + sigma M failed";
    return false;
  }
  Eigen::MatrixXd x = b.start_basis;
  Eigen::VectorXd mu;  // Ritz values of (K + sigma M)^-1 M: lambda + sigma
  double best = std::numeric_limits<double>::infinity();
  int stalled = 0;
  for (int it = 1; it <= kMaxIterations; ++it) {
    const Eigen::MatrixXd mx = mats.mass * x;
    const Eigen::MatrixXd y = ldlt.solve(mx);
    double residual = std::numeric_limits<double>::infinity();
    if (mu.size() > 2) {
      residual = (mu[2] * y.col(2) - x.col(2)).norm() / x.col(2).norm();
      if (!std::isfinite(residual)) residual = std::numeric_limits<double>::infinity();
    }
    if (residual < 0.5 * best) {
      best = residual;
      stalled = 0;
    } else {
      ++stalled;
    }
    const bool done = residual <= kResidualTolerance || (best <= kStallResidual && stalled >= 3);
    // Rayleigh-Ritz in the shift-invert form: Y' (K + sigma M) Y = Y' M X, no product with K.
    Eigen::MatrixXd kr = y.transpose() * mx;
    Eigen::MatrixXd mr = y.transpose() * (mats.mass * y);
    kr = 0.5 * (kr + kr.transpose()).eval();
    mr = 0.5 * (mr + mr.transpose()).eval();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(
        kr, mr, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    if (es.info() != Eigen::Success) {
      out->message = "the Rayleigh-Ritz step failed";
      return false;
    }
    x = y * es.eigenvectors();
    mu = es.eigenvalues();
    if (done) {
      out->iterations = it;
      break;
    }
    if (it == kMaxIterations) {
      out->message = "the subspace iteration did not converge";
      return false;
    }
  }
  const double lambda = mu[2] - sigma;
  if (!(std::isfinite(lambda) && lambda > 0.0) ||
      std::max(std::abs(mu[0] - sigma), std::abs(mu[1] - sigma)) > 1e-3 * lambda) {
    out->message = "expected two rigid-body modes below the first bending mode";
    return false;
  }
  out->lambda = lambda;
  out->frequency_hz = std::sqrt(lambda) / (2.0 * kPi);
  out->vector = x.col(2);  // M-normalised by the Ritz step (V' (Y' M Y) V = I)
  return true;
}

// d lambda / d t = phi' (dK/dt - lambda dM/dt) phi, by AD of the quadrature per segment.
Eigen::VectorXd LambdaGradient(const FixedMeshBeam& b, const std::vector<double>& t,
                               const Eigen::VectorXd& phi, double lambda) {
  const DesignParameterLayout lay{b.num_knots};
  Eigen::VectorXd grad = Eigen::VectorXd::Zero(lay.Size());
  const bool timoshenko = b.theory == BeamTheory::kTimoshenko;
  const bool rotary = timoshenko && b.rotary_inertia;
  std::vector<LocalJet> per_segment(static_cast<std::size_t>(std::max(b.num_knots - 1, 0)),
                                    LocalJet(0.0));
  VisitQuadrature<LocalJet>(b, t,
                            [&](int segment, int e, const Shape<LocalJet>& n,
                                const Section<LocalJet>& s, const LocalJet& wgt) {
                              int idx[kElementDofs];
                              ElementDofIndices(b.theory, e, idx);
                              LocalJet w(0.0), theta(0.0), curvature(0.0), shear(0.0);
                              for (int i = 0; i < kElementDofs; ++i) {
                                if (idx[i] < 0) continue;
                                const double d = phi[idx[i]];
                                const auto si = static_cast<std::size_t>(i);
                                const bool shear_dof = i == 2 || i == 3 || i == 6;
                                if (!shear_dof || timoshenko) w = w + n.w[si] * d;
                                theta = theta + n.theta[si] * d;
                                curvature = curvature + n.curvature[si] * d;
                                if (timoshenko) shear = shear + n.shear[si] * d;
                              }
                              LocalJet q =
                                  s.ei * (curvature * curvature) - lambda * (s.rho_a * (w * w));
                              if (timoshenko) q = q + s.kga * (shear * shear);
                              if (rotary) q = q - lambda * (s.rho_i * (theta * theta));
                              LocalJet& acc = per_segment[static_cast<std::size_t>(segment)];
                              acc = acc + wgt * q;
                            });
  for (int i = 0; i + 1 < b.num_knots; ++i) {
    const LocalJet& q = per_segment[static_cast<std::size_t>(i)];
    const int map[kLocal] = {lay.KnotPosition(i),
                             lay.KnotPosition(i + 1),
                             lay.KnotRadius(i),
                             lay.KnotRadius(i + 1),
                             lay.KnotPosition(b.num_knots - 1),
                             lay.WallThickness(),
                             lay.Density(),
                             lay.FillDiameter(),
                             lay.FillDepth(),
                             lay.FillDensity()};
    for (int a = 0; a < kLocal; ++a) grad[map[a]] += q.g[static_cast<std::size_t>(a)];
  }
  return grad;
}

}  // namespace
}  // namespace beam_frequency_detail

FixedMeshBeam MakeFixedMeshBeam(const Bat& bat, const std::vector<double>& nodes_m, int num_knots,
                                bool hollow, bool has_fill, BeamTheory theory,
                                bool rotary_inertia) {
  FixedMeshBeam b;
  b.theory = theory;
  b.rotary_inertia = rotary_inertia;
  b.num_knots = num_knots;
  b.hollow = hollow;
  b.has_fill = has_fill && bat.fill.has_value();
  const double length = nodes_m.empty() ? 0.0 : nodes_m.back();
  for (double x : nodes_m) b.node_fractions.push_back(length > 0.0 ? x / length : 0.0);
  if (!b.node_fractions.empty()) {
    b.node_fractions.front() = 0.0;
    b.node_fractions.back() = 1.0;
  }
  b.youngs_modulus_pa = bat.material.youngs_modulus_pa;
  b.shear_modulus_pa = bat.material.EffectiveShearModulusPa();
  b.poissons_ratio = bat.material.poissons_ratio;
  if (b.has_fill) {
    b.fill_youngs_modulus_pa = bat.fill->material.youngs_modulus_pa;
    b.fill_shear_modulus_pa = bat.fill->material.EffectiveShearModulusPa();
    b.fill_poissons_ratio = bat.fill->material.poissons_ratio;
  }
  return b;
}

BeamMatrices AssembleFixedMeshBeam(const FixedMeshBeam& beam, const std::vector<double>& t) {
  return beam_frequency_detail::Assemble(beam, t);
}

FirstBendingMode ComputeFirstBendingMode(const FixedMeshBeam& beam, const std::vector<double>& t,
                                         bool gradient) {
  FirstBendingMode out;
  try {
    const DesignParameterLayout lay{beam.num_knots};
    if (beam.num_knots < 2 || static_cast<int>(t.size()) != lay.Size() || beam.Elements() < 1) {
      out.message = "the parameters do not fit the fixed-mesh beam";
      return out;
    }
    for (double v : t) {
      if (!std::isfinite(v)) {
        out.message = "a design parameter is not finite";
        return out;
      }
    }
    const BeamMatrices mats = beam_frequency_detail::Assemble(beam, t);
    if (!beam_frequency_detail::SolveFirst(beam, mats, &out)) return out;
    if (gradient) {
      out.lambda_gradient = beam_frequency_detail::LambdaGradient(beam, t, out.vector, out.lambda);
      if (!out.lambda_gradient.allFinite()) {
        out.message = "the frequency's gradient is not finite";
        return out;
      }
    }
    out.ok = true;
  } catch (const std::exception& e) {
    out.ok = false;
    out.message = std::string("failure: ") + e.what();
  } catch (...) {
    out.ok = false;
    out.message = "failure";
  }
  return out;
}

}  // namespace sweetspot::core
