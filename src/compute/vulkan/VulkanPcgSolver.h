#pragma once
// SPD solves on the device: Jacobi- or block-Jacobi-preconditioned conjugate gradients
// for several right-hand sides at once (the x, y, z columns of a global step).
//
// Why Jacobi: it is one multiply per entry, row-parallel, needs no set-up beyond the
// diagonal and no triangular solves (incomplete Cholesky's are sequential and slow on
// GPUs); the vertex-based matrices (Laplacian-like plus positional weights) are
// symmetric with positive, fairly uniform diagonals that Jacobi equilibrates, and their
// coordinates decouple, so a (3x3) block would have nothing to couple. The projective
// global step's polish systems couple the four entries of each face's map strongly
// (through the homogeneous corner coordinates): LinearSolverSettings::preconditionerBlock
// = 4 inverts those 4x4 blocks (as the device ADMM's inner solve does).
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

  /// Upload A (SPD, compressed) and the inverses of its diagonal blocks
  /// (settings.preconditionerBlock rows each). Throws Error(Numerical) when A is not square
  /// or a diagonal entry (block) is not positive (definite), naming its rows, and
  /// Error(Usage) for a block size that is not 1 to 4 or does not divide A's size.
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
  std::uint32_t block_;           ///< Preconditioner block size (1: Jacobi).
  Array<double> inverseBlocks_;  ///< n / block_ inverse diagonal blocks, row-major.
  Pipeline spmvDot_;
  Pipeline step_;
  Pipeline direction_;
  std::unique_ptr<Workspace> workspace_;
};

}  // namespace plano::vk
