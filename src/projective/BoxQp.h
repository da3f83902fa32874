#pragma once
// OSQP-style ADMM for the convex quadratic programs of the global step (projective-maps
// paper, Eq. 4 with the ε relaxation of §4.2):
//
//   minimize  sum_c 1/2 x_c^T P x_c + q_c^T x_c   subject to  l_c <= C x_c <= u_c,
//
// for k independent columns x_c that share P (n x n, symmetric positive definite) and C
// (m x n) and differ in q, l and u. The iteration follows OSQP (Stellato et al. 2020):
// the only linear system is K = P + sigma I + C^T diag(rho) C, one solve for all k
// columns; rows with l = u get a 1e3 times stiffer rho, as in OSQP. rho adapts to the
// ratio of the residuals (K changes only when rho moves by more than
// `adaptiveRhoFactor`). The iteration itself is the backend's (Backend::createAdmmSolver,
// compute/Admm.h): on the CPU the Eigen loop with a prefactored Cholesky, on Vulkan the
// whole loop on the device. A converged (or solved-inaccurate) solution is then polished
// here, on the host, by re-solving with the active bounds as equalities, which removes the
// ADMM's residual tolerance from the answer.
#include <Eigen/Core>
#include <memory>
#include <span>

#include "compute/Admm.h"
#include "compute/Backend.h"
#include "projective/ScaledConstraintMatrix.h"

namespace plano::projective {

/// The ADMM's settings (compute::AdmmSettings) and those of the final polish.
struct BoxQpSettings : compute::AdmmSettings {
  bool polish = true;
  int polishIterations = 30;         ///< Max method-of-multipliers refinements of the polish.
  double polishRho = 1e9;            ///< Penalty of the polish's equality system.
};

enum class BoxQpStatus {
  Solved,               ///< Primal and dual residuals below their tolerances.
  PrimalInfeasible,     ///< An infeasibility certificate was found (no x satisfies the bounds).
  MaxIterationsReached, ///< Neither converged nor proven infeasible.
  NonFinite,            ///< NaN or Inf appeared in the iteration.
  Stalled,              ///< Neither converging nor certifying (compute::AdmmStatus::Stalled).
  SolvedInaccurate,     ///< Feasible, optimal only to a looser tolerance (compute::AdmmStatus::SolvedInaccurate).
};

const char* toString(BoxQpStatus status);

/// Solved or SolvedInaccurate: the solution is usable.
inline bool isSolved(BoxQpStatus status) {
  return status == BoxQpStatus::Solved || status == BoxQpStatus::SolvedInaccurate;
}

struct BoxQpInfo {
  BoxQpStatus status = BoxQpStatus::MaxIterationsReached;
  int iterations = 0;            ///< ADMM iterations.
  int factorizations = 0;        ///< Factorizations of K (1 + rho updates).
  long linearIterations = 0;     ///< Of the ADMM's solves with K (1 per direct solve, PCG iterations on the device).
  double primalResidual = 0.0;   ///< ||C x - z||_inf (max over columns), after polishing.
  double dualResidual = 0.0;     ///< ||P x + q + C^T y||_inf before polishing.
  double maxBoundViolation = 0.0;  ///< max(l - Cx, Cx - u, 0) over all rows and columns.
  double rho = 0.0;              ///< Final rho.
  bool polished = false;         ///< The polished solution was accepted.
  /// Method-of-multipliers refinements of the polish, one solve each (columns that share
  /// an active set share them).
  int polishRefinements = 0;
};

class BoxQpSolver {
 public:
  /// Precompute: keeps P (n x n) and C (m x n) and creates the backend's ADMM solver; K
  /// is formed on the first solve.
  BoxQpSolver(compute::Backend& backend, compute::SparseMatrix P, compute::SparseMatrix C,
              const BoxQpSettings& settings = {});

  /// Solve for k columns at once.
  ///   q     in: n x k linear terms.
  ///   lower, upper  in: m x k bounds (lower <= upper; equal for equality rows).
  ///   x     in/out: n x k, warm start on entry (zero if empty), solution on exit.
  ///   y     in/out: m x k dual variables, warm start on entry (zero if empty).
  /// Rows whose bounds are equal in every column are equality rows. K changes when the
  /// equality pattern or rho changed since the last solve.
  BoxQpInfo solve(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                  Eigen::MatrixXd& x, Eigen::MatrixXd& y);

  /// C's values as a scaling of its entries from now on (compute::AdmmSolver::
  /// setConstraintScaling), then new values by their scales: the ADMM forms them where it
  /// runs, and C (its values for those scales) serves the polish here.
  void setConstraintScaling(const compute::ConstraintScaling& scaling);
  void setScaledConstraintValues(const compute::SparseMatrix& C, std::span<const double> scales);
  /// The rho the next solve starts at (compute::AdmmSolver::rho, setRho).
  double rho() const { return admm_->rho(); }
  void setRho(double rho) { admm_->setRho(rho); }

  const BoxQpSettings& settings() const { return settings_; }

 private:
  bool polish(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
              const Eigen::MatrixXd& z, Eigen::MatrixXd& x, Eigen::MatrixXd& y, int& refinements);

  compute::Backend& backend_;
  BoxQpSettings settings_;
  compute::SparseMatrix P_;
  compute::SparseMatrix C_;
  std::unique_ptr<compute::AdmmSolver> admm_;
};

/// The solver of a sequence of QPs whose C keeps one sparsity pattern (a loop's global
/// steps: C's values follow each local step's scale factors, its pattern the topology):
/// created by the first call, given C's new scales by later ones (C, filled for `scales`,
/// must be their values), so that everything it built for the pattern is kept (on the
/// device: buffers, pipelines, K's pattern, the multigrid's aggregates) and rho carries
/// over from one problem to the next (they are alike). `settings` is used on creation only.
BoxQpSolver& keptSolver(std::unique_ptr<BoxQpSolver>& kept, compute::Backend& backend, const compute::SparseMatrix& P,
                        const ScaledConstraintMatrix& C, std::span<const double> scales, const BoxQpSettings& settings);

}  // namespace plano::projective
