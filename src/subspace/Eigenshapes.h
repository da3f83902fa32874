#pragma once
// Eigenshapes (linear-spaces paper, §3 Eq. 4 and §4 "Implementation details"): the
// eigenvectors of the Laplacian constrained to a linear space, computed as X = N W with W
// the eigenvectors of the small matrix N^T L N (N orthonormal, so W^T W = X^T X and no
// pseudo-inverse is needed), ordered by frequency (Rayleigh quotient), lowest first.
#include "compute/Backend.h"
#include "subspace/SubspaceBasis.h"

namespace plano::subspace {

struct EigenshapeSettings {
  Index count = 10;          ///< Number of eigenshapes (clamped to the dimension).
  Index denseLimit = 1500;   ///< Reduced size up to which a dense eigensolver is used; Spectra above.
  Index maxIterations = 1000;
  double tolerance = 1e-10;  ///< Spectra convergence tolerance.
};

enum class EigenshapeStatus { Converged, NotConverged };

struct EigenshapeInfo {
  EigenshapeStatus status = EigenshapeStatus::Converged;
  bool dense = true;          ///< Dense solver (true) or Spectra shift-invert Lanczos (false).
  Index iterations = 0;       ///< Spectra restarts (0 for dense).
  Index reducedSize = 0;      ///< Size of the eigenproblem solved (d1 for a separable basis).
};

struct Eigenshapes {
  Eigen::MatrixXd coefficients;  ///< d x K: eigenshape k is N * coefficients.col(k); orthonormal columns.
  Eigen::VectorXd frequencies;   ///< K Rayleigh quotients X^T L X / X^T X, ascending.
  Index count() const { return static_cast<Index>(frequencies.size()); }
};

/// Lowest-frequency eigenshapes of the scalar Laplacian L (#V x #V, applied per
/// coordinate) in the space with basis N. For a separable basis every scalar eigenvector
/// yields three eigenshapes (x, y, z) of equal frequency. L must be positive semidefinite
/// (a Laplacian): above `denseLimit` the eigenpairs come from a shift-invert Lanczos
/// iteration on a Cholesky factor of N^T L N shifted just below 0. Throws
/// Error(Numerical) when Spectra does not converge or no such factor exists.
/// The reduced operator N^T L N, the d x d matrix whose eigenproblem this is, is formed on
/// `backend` (Backend::reducedOperator); the small eigenproblem runs on the host.
Eigenshapes computeEigenshapes(compute::Backend& backend, const SubspaceBasis& N, const compute::SparseMatrix& L,
                               const EigenshapeSettings& settings = {}, EigenshapeInfo* info = nullptr);
/// The same on the CPU reference.
Eigenshapes computeEigenshapes(const SubspaceBasis& N, const compute::SparseMatrix& L,
                               const EigenshapeSettings& settings = {}, EigenshapeInfo* info = nullptr);

/// Band-pass exploration (§3): base + amplitude * diag * sum_{lo <= k < hi} X_k / max_v |X_k(v)|,
/// diag the bounding-box diagonal of `base`. Throws Error(Usage) for an empty or
/// out-of-range band.
Positions bandPass(const SubspaceBasis& N, const Eigenshapes& shapes, const Positions& base, Index lo, Index hi,
                   double amplitude);

}  // namespace plano::subspace
