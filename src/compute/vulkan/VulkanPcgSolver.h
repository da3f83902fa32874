#pragma once
// SPD solves on the device: Jacobi-preconditioned conjugate gradients for several
// right-hand sides at once (the x, y, z columns of a global step).
//
// Why Jacobi: it is one multiply per entry, row-parallel, needs no set-up beyond the
// diagonal and no triangular solves (incomplete Cholesky's are sequential and slow on
// GPUs); the global-step matrices (Laplacian-like plus positional weights) are
// symmetric with positive, fairly uniform diagonals that Jacobi equilibrates. The
// coordinates decouple, so a block (3x3) Jacobi would have nothing to couple.
//
// The iteration runs in recorded blocks of kCheckInterval iterations: the step lengths
// (r.z / p.q) stay on the device, and only the m residual norms are read back after each
// block, so the iteration count reported is a multiple of kCheckInterval.
#include <memory>

#include "compute/vulkan/VulkanLinearAlgebra.h"

namespace plano::vk {

class PcgSolver final : public compute::SpdSolver {
 public:
  static constexpr int kCheckInterval = 8;  ///< Iterations per recorded block (even).

  /// Upload A (SPD, compressed) and its inverse diagonal. Throws Error(Numerical) when
  /// A is not square or a diagonal entry is not positive (naming the row).
  PcgSolver(Context& context, const compute::SparseMatrix& A, const compute::LinearSolverSettings& settings);
  ~PcgSolver() override;

  /// Solve A X = B column by column, warm-started from X. Stops when every column has
  /// ||b - A x|| <= relativeTolerance * ||b|| (recursive residual, checked every
  /// kCheckInterval iterations) or at maxIterations; relativeResidual in the info is
  /// the largest true relative residual, recomputed at the end.
  compute::LinearSolveInfo solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) override;
  Eigen::Index size() const override { return n_; }

 private:
  struct Workspace;  // vectors and recorded sequences for one column count m
  void prepare(std::uint32_t m);

  Context& context_;
  compute::LinearSolverSettings settings_;
  std::uint32_t n_;
  LinearAlgebra algebra_;
  DeviceCsrMatrix matrix_;
  Array<double> inverseDiagonal_;
  Pipeline spmvDot_;
  Pipeline step_;
  Pipeline direction_;
  std::unique_ptr<Workspace> workspace_;
};

}  // namespace plano::vk
