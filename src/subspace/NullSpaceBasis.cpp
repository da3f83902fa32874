#include "subspace/NullSpaceBasis.h"

#include <Eigen/Dense>
#include <algorithm>
#include <Eigen/SPQRSupport>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/Memory.h"

namespace plano::subspace {
namespace {

Eigen::MatrixXd denseNullSpace(const compute::SparseMatrix& B, double tolerance, Index& rank) {
  const Eigen::Index n = B.cols();
  if (B.rows() == 0) {
    rank = 0;
    return Eigen::MatrixXd::Identity(n, n);
  }
  // A wide B is padded with zero rows (same singular values and V). One-sided Jacobi
  // (after a QR preconditioner) gives null vectors accurate to rounding; the
  // divide-and-conquer SVD was measured to lose digits on these clustered zero singular
  // values and to return wrong vectors for the full V of a wide matrix.
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(std::max(B.rows(), n), n);
  dense.topRows(B.rows()) = Eigen::MatrixXd(B);
  // The SVD itself cannot be interrupted: checked before and after it.
  throwIfCancelled("the null-space basis (before the SVD)");
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(dense, Eigen::ComputeFullV);
  throwIfCancelled("the null-space basis (after the SVD)");
  const Eigen::VectorXd& s = svd.singularValues();
  const double cut = tolerance * std::max(s.size() ? s[0] : 0.0, 1e-300);
  Eigen::Index r = 0;
  while (r < s.size() && s[r] > cut) ++r;
  rank = static_cast<Index>(r);
  return svd.matrixV().rightCols(n - r);
}

Eigen::MatrixXd sparseNullSpace(const compute::SparseMatrix& B, double tolerance, std::uint64_t memoryLimit,
                                Index& rank) {
  using SpqrMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, SuiteSparse_long>;
  const Eigen::Index n = B.cols();
  if (B.rows() == 0) {
    rank = 0;
    return Eigen::MatrixXd::Identity(n, n);
  }
  // B^T P = Q R: the first rank(B) columns of Q span range(B^T), the others null(B).
  const SpqrMatrix At = SpqrMatrix(B.transpose());
  Eigen::SPQR<SpqrMatrix> qr;
  double maxColumn = 0.0;
  for (Eigen::Index j = 0; j < At.outerSize(); ++j) maxColumn = std::max(maxColumn, At.col(j).norm());
  qr.setPivotThreshold(tolerance * std::max(maxColumn, 1e-300));
  qr.cholmodCommon()->print = 0;  // A failure is the Error below, not CHOLMOD's own lines.
  // SPQR's factorization cannot be interrupted: checked before and after it.
  throwIfCancelled("the null-space basis (before the sparse QR)");
  qr.compute(At);
  throwIfCancelled("the null-space basis (after the sparse QR)");
  if (qr.info() != Eigen::Success) throwNumerical("sparse QR of the constraint matrix failed");
  rank = static_cast<Index>(qr.rank());
  requireBasisMemory(n, n - rank, /*atLeast=*/false, memoryLimit);
  // The last n - rank columns of Q, formed a block of columns at a time: on a large mesh
  // applying Q takes as long as the factorization, and a Ctrl-C is looked at between blocks.
  constexpr Eigen::Index kBlock = 256;
  const Eigen::Index dimension = n - rank;
  Eigen::MatrixXd N(n, dimension);
  for (Eigen::Index first = 0; first < dimension; first += kBlock) {
    throwIfCancelled("the null-space basis (forming Q)");
    const Eigen::Index width = std::min(kBlock, dimension - first);
    Eigen::MatrixXd selector = Eigen::MatrixXd::Zero(n, width);
    selector.block(rank + first, 0, width, width).setIdentity();
    N.middleCols(first, width) = qr.matrixQ() * selector;
  }
  return N;
}

}  // namespace

void requireBasisMemory(Index unknowns, Index dimension, bool atLeast, std::uint64_t limit) {
  if (dimension <= 0) return;
  // The selector and N, both unknowns x dimension, live at once.
  const double basisBytes = static_cast<double>(unknowns) * static_cast<double>(dimension) * sizeof(double);
  requireMemory(2.0 * basisBytes,
                "the null-space basis (" + std::to_string(unknowns) + " unknowns x " + (atLeast ? "at least " : "") +
                    std::to_string(dimension) + " dimensions" + (atLeast ? ", the topological lower bound" : "") +
                    ", formed from a selector of its size)",
                limit);
}

SubspaceBasis computeNullSpaceBasis(const ConstraintMatrix& B, const BasisSettings& settings, BasisInfo* info) {
  const Index unknowns = static_cast<Index>(B.matrix.cols());
  BasisMethod method = settings.method;
  if (method == BasisMethod::Auto) method = unknowns <= settings.denseLimit ? BasisMethod::DenseSvd : BasisMethod::SparseQr;
  Index rank = 0;
  const double tolerance = std::max(settings.rankTolerance, settings.noiseFactor * B.maxNonPlanarity);
  Eigen::MatrixXd N = method == BasisMethod::DenseSvd
                          ? denseNullSpace(B.matrix, tolerance, rank)
                          : sparseNullSpace(B.matrix, tolerance, settings.memoryLimitBytes, rank);
  if (!N.allFinite()) throwNumerical("null-space basis of the constraint matrix is not finite");
  SubspaceBasis basis(std::move(N), B.separable);
  if (info) {
    info->method = method;
    info->unknowns = unknowns;
    info->rank = rank;
    info->rankTolerance = tolerance;
    info->dimension = basis.dimension();
    const Eigen::MatrixXd& C = basis.columns();
    info->residual = C.cols() && B.matrix.rows() ? (B.matrix * C).cwiseAbs().maxCoeff() : 0.0;
  }
  return basis;
}

}  // namespace plano::subspace
