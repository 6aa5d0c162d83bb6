// The eigensolvers of the beam's modes (core/flexible/modes.cpp): the lowest eigenpairs of
// the generalised problem K x = lambda M x by shift-invert Lanczos or subspace iteration, and
// the Sturm count that checks none was missed.
#pragma once

#include <string>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

namespace sweetspot::core {

/// The most subspace iterations one solve may take.
inline constexpr int kMaxSubspaceIterations = 200;
/// Convergence of the subspace iteration and of Lanczos' explicit check: the shift-invert
/// residual (see SubspaceIteration), dimensionless.
inline constexpr double kResidualTolerance = 1e-9;

/// a <- (a + a') / 2 without a temporary.
void SymmetrizeInPlace(Eigen::MatrixXd* a);

/// Lowest `wanted` eigenpairs of (K, M) by shift-invert subspace iteration (shift -sigma) from
/// the basis X (n x p): ascending values and M-normalised vectors; false with *why otherwise.
bool SubspaceIteration(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m,
                       int wanted, double sigma, Eigen::MatrixXd x, Eigen::VectorXd* values,
                       Eigen::MatrixXd* vectors, int* iterations, std::string* why);

/// The number of eigenvalues of (K, M) below mu (Sylvester's law of inertia: the negative
/// pivots of the LDL' factorisation of K - mu M, the Sturm sequence check of structural
/// codes); -1 when the factorisation meets a zero pivot.
int ModesBelowCount(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m,
                    double mu);

/// The lowest `flexible` flexible eigenpairs of (K, M) by shift-invert Lanczos: the Krylov
/// space of A = (K + sigma M)^-1 M from `start`, kept M-orthogonal to the rigid modes (`rigid`,
/// M-orthonormal, K rigid = 0: A's largest eigenvalue 1/sigma, double, which one Krylov vector
/// could not resolve) and fully reorthogonalised (classical Gram-Schmidt twice in the M inner
/// product). Every few steps the tridiagonal T = Q' M A Q gives Ritz values theta = 1/(lambda +
/// sigma); once the Lanczos estimates say the wanted ones converged, their residuals are
/// checked explicitly with the subspace iteration's criterion and tolerance. Returns the
/// flexible Ritz values (ascending lambda; the wanted ones first, then up to `extra` more, not
/// converged: seeds for the next mesh) and A applied to their Ritz vectors x (the explicit
/// check's products: smoother than x, whose rounding K amplifies by lambda_max; the caller's
/// Rayleigh-Ritz step takes them as the subspace iteration took its last iterate). False when
/// it did not converge within its step budget or broke down: the caller falls back to the subspace
/// iteration. Cost: one sparse solve and O(n j) for the reorthogonalisation per step j, instead of
/// p solves and O(n p^2) dense work per subspace iteration.
bool ShiftInvertLanczos(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m,
                        const Eigen::MatrixXd& rigid, int flexible, int extra, double sigma,
                        const Eigen::VectorXd& start, Eigen::VectorXd* values,
                        Eigen::MatrixXd* vectors, int* steps);

/// The lowest `num_modes` flexible eigenpairs of (K, M) by ShiftInvertLanczos (shift sigma,
/// `extra` more Ritz vectors, `rigid` deflated, from `start`), accepted only when the Sturm
/// count (ModesBelowCount) confirms that no mode below the last wanted one was missed, and
/// polished by a Rayleigh-Ritz step of (K, M): true with the eigenpairs, the two rigid modes
/// first (eigenvalue 0), in *lambda and *vectors and the Lanczos steps in *iterations;
/// otherwise false, the outputs untouched.
bool ConfirmedLanczos(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m,
                      const Eigen::MatrixXd& rigid, int num_modes, int extra, double sigma,
                      const Eigen::VectorXd& start, Eigen::VectorXd* lambda,
                      Eigen::MatrixXd* vectors, int* iterations);

}  // namespace sweetspot::core
