#include "compute/vulkan/VulkanPcgSolver.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <string>
#include <vector>

#include "compute/vulkan/PcgPushConstants.h"
#include "core/Error.h"

namespace plano::vk {
namespace {


// Scalar slots (one value per column each).
enum Slot : std::uint32_t { kRzEven = 0, kRzOdd, kPq, kRr, kBb, kSlots };

std::uint32_t squareSize(const compute::SparseMatrix& A) {
  if (A.rows() != A.cols()) {
    throwNumerical("SPD solver: matrix is " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                   ", not square");
  }
  return static_cast<std::uint32_t>(A.rows());
}

std::uint32_t blockSizeFor(const compute::LinearSolverSettings& settings, std::uint32_t n) {
  const int b = settings.preconditionerBlock;
  if (b < 1 || b > 4 || n % static_cast<std::uint32_t>(b) != 0) {
    throwUsage("SPD solver: preconditioner blocks of " + std::to_string(b) + " rows for " + std::to_string(n) +
               " rows (need 1 to 4 rows dividing them)");
  }
  return static_cast<std::uint32_t>(b);
}

/// The inverses of A's b x b diagonal blocks, row-major, block after block (b = 1: the
/// inverse diagonal). Throws Error(Numerical) naming a block that is not positive definite.
std::vector<double> inverseDiagonalBlocksOf(const compute::SparseMatrix& A, std::uint32_t b) {
  std::vector<double> inverse(static_cast<std::size_t>(A.rows()) * b);
  for (Eigen::Index first = 0; first < A.rows(); first += b) {
    if (b == 1) {
      const double d = A.coeff(first, first);
      if (!(d > 0.0)) {
        throwNumerical("SPD solver: diagonal entry of row " + std::to_string(first) + " is " + std::to_string(d) +
                       " (a symmetric positive definite matrix has a positive diagonal)");
      }
      inverse[static_cast<std::size_t>(first)] = 1.0 / d;
      continue;
    }
    Eigen::MatrixXd block(b, b);
    for (std::uint32_t i = 0; i < b; ++i) {
      for (std::uint32_t j = 0; j < b; ++j) block(i, j) = A.coeff(first + i, first + j);
    }
    const Eigen::LLT<Eigen::MatrixXd> llt(block);
    if (llt.info() != Eigen::Success || !block.allFinite()) {
      throwNumerical("SPD solver: the diagonal block of rows " + std::to_string(first) + " to " +
                     std::to_string(first + b - 1) + " is not positive definite");
    }
    const Eigen::MatrixXd blockInverse = llt.solve(Eigen::MatrixXd::Identity(b, b));
    double* out = inverse.data() + static_cast<std::size_t>(first) * b;
    for (std::uint32_t i = 0; i < b; ++i) {
      for (std::uint32_t j = 0; j < b; ++j) out[i * b + j] = blockInverse(i, j);
    }
  }
  return inverse;
}

}  // namespace

struct PcgSolver::Workspace {
  Workspace(Context& context, std::uint32_t n, std::uint32_t m)
      : m(m),
        b(context, n, m, "PCG right-hand sides"),
        x(context, n, m, "PCG solution"),
        r(context, n, m, "PCG residual"),
        z(context, n, m, "PCG preconditioned residual"),
        p(context, n, m, "PCG direction"),
        q(context, n, m, "PCG A times direction"),
        scalars(context, kSlots, m, n),
        start(context),
        block(context),
        finish(context) {}
  std::uint32_t m;
  DeviceVectors b, x, r, z, p, q;
  DeviceScalars scalars;
  Sequence start;   ///< r = b - A x, z = M^-1 r, p = z, rz, bb, rr
  Sequence block;   ///< kCheckInterval iterations, then rr
  Sequence finish;  ///< true residual r = b - A x and rr
};

PcgSolver::PcgSolver(Context& context, const compute::SparseMatrix& A, const compute::LinearSolverSettings& settings)
    : context_(context),
      settings_(settings),
      n_(squareSize(A)),
      algebra_(context),
      matrix_(context, A),
      block_(blockSizeFor(settings, n_)),
      inverseBlocks_(context, static_cast<std::size_t>(n_) * block_, MemoryClass::Device, "inverse diagonal blocks"),
      spmvDot_(context, "pcg_spmv_dot", 6, sizeof(PcgSpmvDotPush)),
      step_(context, "pcg_step", 8, sizeof(PcgStepPush)),
      direction_(context, "pcg_direction", 3, sizeof(PcgDirectionPush)) {
  inverseBlocks_.upload(inverseDiagonalBlocksOf(A, block_));
}

PcgSolver::~PcgSolver() = default;

void PcgSolver::prepare(std::uint32_t m) {
  if (workspace_ && workspace_->m == m) return;
  workspace_ = std::make_unique<Workspace>(context_, n_, m);
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  const std::uint32_t count = n_ * m;

  auto residual = [&](Sequence& s) {  // r = b - A x, rr = r.r
    la.spmv(s, matrix_, w.x, w.q);
    la.copy(s, w.b, w.r);
    la.axpby(s, -1.0, w.q, 1.0, w.r);
    la.dot(s, w.r, w.r, w.scalars, kRr);
  };

  w.start.begin();
  residual(w.start);
  la.applyBlockDiagonal(w.start, inverseBlocks_, block_, w.r, w.z);
  la.copy(w.start, w.z, w.p);
  la.dot(w.start, w.r, w.z, w.scalars, kRzEven);
  la.dot(w.start, w.b, w.b, w.scalars, kBb);
  w.start.end();

  w.block.begin();
  for (int iteration = 0; iteration < kCheckInterval; ++iteration) {
    // r.z of the current iterate alternates between two slots, so that the direction
    // update can read both the old and the new value without a copy.
    const std::uint32_t current = iteration % 2 == 0 ? kRzEven : kRzOdd;
    const std::uint32_t next = iteration % 2 == 0 ? kRzOdd : kRzEven;
    // Five dispatches an iteration: q = A p with the partial sums of p.q, their reduction,
    // the x/r/z update with the partial sums of the new r.z, their reduction, and p.
    w.block.dispatch(spmvDot_,
                     {matrix_.rowOffsets(), matrix_.columns(), matrix_.values(), w.p.data(), w.q.data(),
                      w.scalars.partial()},
                     PcgSpmvDotPush{n_, m}, w.scalars.groups());
    w.block.barrier();
    la.reduce(w.block, w.scalars, kPq);
    w.block.dispatch(step_,
                     {w.p.data(), w.q.data(), w.x.data(), w.r.data(), w.z.data(), inverseBlocks_,
                      w.scalars.values(), w.scalars.partial()},
                     PcgStepPush{n_, m, current, kPq, block_}, w.scalars.groups(), m);
    w.block.barrier();
    la.reduce(w.block, w.scalars, next);
    w.block.dispatch(direction_, {w.z.data(), w.p.data(), w.scalars.values()},
                     PcgDirectionPush{n_, m, next, current}, sweepGroupsFor(context_, count));
    w.block.barrier();
  }
  la.dot(w.block, w.r, w.r, w.scalars, kRr);
  w.block.end();

  w.finish.begin();
  residual(w.finish);
  w.finish.end();
}

compute::LinearSolveInfo PcgSolver::solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) {
  if (B.rows() != n_) {
    throwUsage("PCG solve: right-hand side has " + std::to_string(B.rows()) + " rows for a " + std::to_string(n_) +
               " x " + std::to_string(n_) + " matrix");
  }
  const auto m = static_cast<std::uint32_t>(B.cols());
  compute::LinearSolveInfo info;
  info.iterations = 0;
  if (m == 0) return info;
  if (X.rows() != B.rows() || X.cols() != B.cols()) X = Eigen::MatrixXd::Zero(B.rows(), B.cols());
  prepare(m);
  Workspace& w = *workspace_;
  w.b.upload(B);
  w.x.upload(X);

  const double tolerance2 = settings_.relativeTolerance * settings_.relativeTolerance;
  auto converged = [&](const std::vector<double>& s) {
    for (std::uint32_t c = 0; c < m; ++c) {
      const double rr = w.scalars.at(s, kRr, c);
      if (!std::isfinite(rr)) throwNumerical("PCG solve: the residual of column " + std::to_string(c) + " is NaN");
      if (rr > tolerance2 * w.scalars.at(s, kBb, c)) return false;
    }
    return true;
  };

  w.start.run();
  const std::vector<double> first = w.scalars.read();
  std::vector<double> bb(m);
  for (std::uint32_t c = 0; c < m; ++c) bb[c] = w.scalars.at(first, kBb, c);
  bool done = converged(first);
  while (!done && info.iterations < settings_.maxIterations) {
    w.block.run();
    info.iterations += kCheckInterval;
    done = converged(w.scalars.read());
  }

  w.finish.run();
  const std::vector<double> last = w.scalars.read();
  w.x.download(X);
  info.relativeResidual = 0.0;
  for (std::uint32_t c = 0; c < m; ++c) {
    const double rr = w.scalars.at(last, kRr, c);
    const double relative = bb[c] > 0.0 ? std::sqrt(rr / bb[c]) : std::sqrt(rr);
    info.relativeResidual = std::max(info.relativeResidual, relative);
  }
  info.converged = done && std::isfinite(info.relativeResidual);
  return info;
}

}  // namespace plano::vk
