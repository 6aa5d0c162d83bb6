#include "core/flexible/eigensolvers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include "core/geometry_format.hpp"

namespace sweetspot::core {
namespace {
using SparseMatrix = Eigen::SparseMatrix<double>;
}  // namespace

// a <- (a + a') / 2 without a temporary.
void SymmetrizeInPlace(Eigen::MatrixXd* a) {
  for (Eigen::Index j = 0; j < a->cols(); ++j) {
    for (Eigen::Index i = j + 1; i < a->rows(); ++i) {
      const double v = 0.5 * ((*a)(i, j) + (*a)(j, i));
      (*a)(i, j) = v;
      (*a)(j, i) = v;
    }
  }
}

// Lowest eigenpairs of (K, M) by shift-invert subspace iteration from the basis X (n x p).
bool SubspaceIteration(const SparseMatrix& k, const SparseMatrix& m, int wanted, double sigma,
                       Eigen::MatrixXd x, Eigen::VectorXd* values, Eigen::MatrixXd* vectors,
                       int* iterations, std::string* why) {
  const SparseMatrix shifted = k + sigma * m;
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(shifted);
  if (ldlt.info() != Eigen::Success) {
    *why = "the factorisation of K + sigma M failed (sigma = " + FormatNumber17(sigma) + ")";
    return false;
  }
  // Every buffer is allocated once, before the loop: the products below assign into them
  // (noalias), so an iteration allocates nothing. (Allocating them per iteration cost ~20 times
  // the arithmetic: buffers of ~60 kB each, freed together at the heap's top, made glibc hand
  // the pages back to the kernel every iteration and fault them in again.)
  const Eigen::Index n = x.rows(), p = x.cols();
  Eigen::MatrixXd mx(n, p), y(n, p), ky(n, p), my(n, p), kr(p, p), mr(p, p);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(p);
  Eigen::VectorXd lambda;
  double best = std::numeric_limits<double>::infinity();
  int stalled = 0;
  mx.noalias() = m * x;
  for (int it = 1; it <= kMaxSubspaceIterations; ++it) {
    y = ldlt.solve(mx);  // evaluated into y (copy, then the triangular solves in place)
    // Residual of the (well-conditioned) shift-invert operator for the current Ritz pairs:
    // |(lambda_i + sigma) (K + sigma M)^-1 M x_i - x_i| / |x_i|.
    double worst = lambda.size() == 0 ? std::numeric_limits<double>::infinity() : 0.0;
    for (int i = 2; i < wanted && lambda.size() > 0; ++i) {
      const double r = ((lambda[i] + sigma) * y.col(i) - x.col(i)).norm() / x.col(i).norm();
      worst = std::max(worst, std::isfinite(r) ? r : std::numeric_limits<double>::infinity());
    }
    // Converged, or stalled at round-off (no halving for 3 iterations once below 1e-6; fine
    // meshes of ~1000 DOFs stall near 2e-8: K + sigma M has a condition number ~lambda_max /
    // sigma). The Ritz values are then accurate to ~residual^2, the vectors to ~residual.
    if (worst < 0.5 * best) {
      best = worst;
      stalled = 0;
    } else {
      ++stalled;
    }
    const bool done = worst <= kResidualTolerance || (best <= 1e-6 && stalled >= 3);
    ky.noalias() = k * y;
    my.noalias() = m * y;
    kr.noalias() = y.transpose() * ky;
    mr.noalias() = y.transpose() * my;
    SymmetrizeInPlace(&kr);
    SymmetrizeInPlace(&mr);
    es.compute(kr, mr, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    if (es.info() != Eigen::Success) {
      *why = "the Rayleigh-Ritz step failed (the basis lost independence)";
      return false;
    }
    x.noalias() = y * es.eigenvectors();
    lambda = es.eigenvalues();
    if (done) {
      *values = lambda;
      *vectors = std::move(x);
      *iterations = it;
      return true;
    }
    // M x for the next iteration from M y: x = y V, so M x = (M y) V (no sparse product).
    mx.noalias() = my * es.eigenvectors();
  }
  *why = "the subspace iteration did not converge in " + std::to_string(kMaxSubspaceIterations) +
         " iterations";
  return false;
}

// The number of eigenvalues of (K, M) below mu (Sylvester's law of inertia: the negative
// pivots of the LDL' factorisation of K - mu M, the Sturm sequence check of structural
// codes); -1 when the factorisation meets a zero pivot.
int ModesBelowCount(const SparseMatrix& k, const SparseMatrix& m, double mu) {
  const SparseMatrix shifted = k - mu * m;
  const Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(
      shifted);
  if (ldlt.info() != Eigen::Success) return -1;
  const Eigen::VectorXd d = ldlt.vectorD();
  int below = 0;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (!std::isfinite(d[i])) return -1;
    if (d[i] < 0.0) ++below;
  }
  return below;
}

// The lowest `flexible` flexible eigenpairs of (K, M) by shift-invert Lanczos: the Krylov
// space of A = (K + sigma M)^-1 M from `start`, kept M-orthogonal to the rigid modes (`rigid`,
// M-orthonormal, K rigid = 0: A's largest eigenvalue 1/sigma, double, which one Krylov vector
// could not resolve) and fully reorthogonalised (classical Gram-Schmidt twice in the M inner
// product). Every few steps the tridiagonal T = Q' M A Q gives Ritz values theta = 1/(lambda +
// sigma); once the Lanczos estimates say the wanted ones converged, their residuals are
// checked explicitly with the subspace iteration's criterion and tolerance. Returns the
// flexible Ritz values (ascending lambda; the wanted ones first, then up to `extra` more, not
// converged: seeds for the next mesh) and A applied to their Ritz vectors x (the explicit
// check's products: smoother than x, whose rounding K amplifies by lambda_max; the caller's
// Rayleigh-Ritz step takes them as the subspace iteration took its last iterate). False when
// it did not converge
// within its step budget or broke down: the caller falls back to the subspace iteration.
// Cost: one sparse solve and O(n j) for the reorthogonalisation per step j, instead of p
// solves and O(n p^2) dense work per subspace iteration.
bool ShiftInvertLanczos(const SparseMatrix& k, const SparseMatrix& m, const Eigen::MatrixXd& rigid,
                        int flexible, int extra, double sigma, const Eigen::VectorXd& start,
                        Eigen::VectorXd* values, Eigen::MatrixXd* vectors, int* steps) {
  const Eigen::Index n = k.rows();
  const Eigen::Index max_steps = std::min<Eigen::Index>(n - rigid.cols(), 4 * flexible + 40);
  if (max_steps < flexible + 1) return false;
  const SparseMatrix shifted = k + sigma * m;
  const Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(
      shifted);
  if (ldlt.info() != Eigen::Success) return false;
  const Eigen::MatrixXd m_rigid = m * rigid;
  Eigen::MatrixXd q(n, max_steps + 1), mq(n, max_steps + 1);
  Eigen::VectorXd alpha(max_steps), beta(max_steps), w(n), mw(n), h(max_steps);
  w = start - rigid * (m_rigid.transpose() * start);
  mw.noalias() = m * w;
  const double norm = std::sqrt(std::max(w.dot(mw), 0.0));
  if (!(norm > 0.0 && std::isfinite(norm))) return false;
  q.col(0) = w / norm;
  mq.col(0) = mw / norm;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> tri;
  Eigen::MatrixXd x, mx, y;
  double previous_worst = std::numeric_limits<double>::infinity();
  for (Eigen::Index j = 0; j < max_steps; ++j) {
    w = ldlt.solve(mq.col(j));
    w -= rigid * (m_rigid.transpose() * w);
    const Eigen::Index cols = j + 1;
    for (int pass = 0; pass < 2; ++pass) {
      h.head(cols).noalias() = mq.leftCols(cols).transpose() * w;
      if (pass == 0) alpha[j] = h[j];
      w.noalias() -= q.leftCols(cols) * h.head(cols);
    }
    w -= rigid * (m_rigid.transpose() * w);
    mw.noalias() = m * w;
    beta[j] = std::sqrt(std::max(w.dot(mw), 0.0));
    if (!std::isfinite(beta[j]) || !std::isfinite(alpha[j])) return false;
    // An invariant subspace: its Ritz pairs are exact (beta = 0 in the estimates below).
    const bool breakdown = beta[j] <= 1e-14 * std::abs(alpha[0]);
    const bool check = cols >= flexible + 2 && (cols % 4 == 0 || breakdown || j + 1 == max_steps);
    if (check) {
      tri.computeFromTridiagonal(alpha.head(cols), beta.head(cols - 1), Eigen::ComputeEigenvectors);
      if (tri.info() != Eigen::Success) return false;
      // Ascending theta: the wanted (lowest lambda) are the last `flexible` ones.
      bool estimated = true;
      for (int i = 0; i < flexible; ++i) {
        const Eigen::Index c = cols - 1 - i;
        const double theta = tri.eigenvalues()[c];
        if (!(theta > 0.0)) return false;
        const double r = std::abs(beta[j] * tri.eigenvectors()(cols - 1, c)) / theta;
        if (!breakdown && !(r <= 0.1 * kResidualTolerance)) estimated = false;
      }
      if (estimated || breakdown) {
        const Eigen::Index keep = std::min<Eigen::Index>(cols, flexible + extra);
        const Eigen::MatrixXd s = tri.eigenvectors().rightCols(keep).rowwise().reverse();
        x.noalias() = q.leftCols(cols) * s;
        mx.noalias() = m * x;
        y = ldlt.solve(mx);
        Eigen::VectorXd lambda(keep);
        for (Eigen::Index i = 0; i < keep; ++i) {
          lambda[i] = 1.0 / tri.eigenvalues()[cols - 1 - i] - sigma;
        }
        double worst = 0.0;
        for (int i = 0; i < flexible; ++i) {
          const double r = ((lambda[i] + sigma) * y.col(i) - x.col(i)).norm() / x.col(i).norm();
          worst = std::max(worst, std::isfinite(r) ? r : std::numeric_limits<double>::infinity());
        }
        // Converged, or at round-off: the Lanczos estimates are below the tolerance but the
        // explicit residual, which carries the rounding of the solve (K + sigma M has a
        // condition number ~lambda_max / sigma), no longer halves (the subspace iteration's
        // rule: fine meshes stall near 1e-8, accepted below 1e-6).
        const bool converged =
            worst <= kResidualTolerance || (worst <= 1e-6 && worst > 0.5 * previous_worst);
        previous_worst = worst;
        if (converged) {
          *values = std::move(lambda);
          *vectors = std::move(y);
          *steps = static_cast<int>(cols);
          return true;
        }
      }
    }
    if (breakdown) return false;
    q.col(j + 1) = w / beta[j];
    mq.col(j + 1) = mw / beta[j];
  }
  return false;
}

bool ConfirmedLanczos(const SparseMatrix& k, const SparseMatrix& m, const Eigen::MatrixXd& rigid,
                      int num_modes, int extra, double sigma, const Eigen::VectorXd& start,
                      Eigen::VectorXd* lambda, Eigen::MatrixXd* vectors, int* iterations) {
  const int ndof = static_cast<int>(m.rows());
  const int wanted = num_modes + 2;
  Eigen::VectorXd flex_values;
  Eigen::MatrixXd flex_vectors;
  int steps = 0;
  if (!ShiftInvertLanczos(k, m, rigid, num_modes, extra, sigma, start, &flex_values, &flex_vectors,
                          &steps)) {
    return false;
  }
  const double last = flex_values[num_modes - 1];
  // Between the last wanted eigenvalue and the next Ritz value (an upper bound of the next
  // eigenvalue), at most 5 % above the last: a missed mode below it changes the count.
  const double next = flex_values.size() > num_modes ? flex_values[num_modes] : 2.0 * last;
  const double mu = last + 0.5 * std::min(next - last, 0.1 * last);
  if (!(next > last && ModesBelowCount(k, m, mu) == wanted)) return false;
  // The eigenpairs as the subspace iteration gave them: a Rayleigh-Ritz step of (K, M) on
  // A x for the Ritz vectors x (1/theta - sigma carries the rounding of the solves, up to
  // ~2e-8 relative on meshes of ~1700 DOFs; the Rayleigh quotients of A x do not).
  const Eigen::MatrixXd kx = k * flex_vectors;
  const Eigen::MatrixXd mx = m * flex_vectors;
  Eigen::MatrixXd kr = flex_vectors.transpose() * kx;
  Eigen::MatrixXd mr = flex_vectors.transpose() * mx;
  SymmetrizeInPlace(&kr);
  SymmetrizeInPlace(&mr);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> rr(
      kr, mr, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (rr.info() != Eigen::Success) return false;  // the subspace iteration then
  flex_values = rr.eigenvalues();
  flex_vectors = flex_vectors * rr.eigenvectors();
  lambda->resize(flex_values.size() + 2);
  *lambda << 0.0, 0.0, flex_values;
  vectors->resize(ndof, lambda->size());
  *vectors << rigid, flex_vectors;
  *iterations = steps;
  return true;
}

}  // namespace sweetspot::core
