#include "compute/cpu/SymmetricProduct.h"

#include <cblas.h>

#include <algorithm>
#include <climits>
#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::compute {
namespace {

/// Columns of R per BLAS call: wide enough for the kernels' full speed, narrow enough that
/// the blocks above the diagonal (skipped) are most of the upper triangle's work and that a
/// cancellation is noticed within seconds.
constexpr Eigen::Index kBlockColumns = 128;

}  // namespace

Eigen::MatrixXd symmetricTransposeProduct(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  if (A.rows() != B.rows() || A.cols() != B.cols()) {
    throwUsage("symmetric product: A is " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) + ", B " +
               std::to_string(B.rows()) + " x " + std::to_string(B.cols()));
  }
  const Eigen::Index n = A.rows(), d = A.cols();
  Eigen::MatrixXd R(d, d);
  if (d == 0) return R;
  if (n == 0) return Eigen::MatrixXd::Zero(d, d);
  if (n > INT_MAX || d > INT_MAX) throwUsage("symmetric product: sizes beyond BLAS's 32-bit indices");
  for (Eigen::Index first = 0; first < d; first += kBlockColumns) {
    throwIfCancelled("a reduced operator");
    const Eigen::Index width = std::min(kBlockColumns, d - first);
    // R(first:, first:first+width) = A(:, first:)^T B(:, first:first+width).
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, static_cast<int>(d - first), static_cast<int>(width),
                static_cast<int>(n), 1.0, A.data() + first * n, static_cast<int>(n), B.data() + first * n,
                static_cast<int>(n), 0.0, R.data() + first * d + first, static_cast<int>(d));
  }
  R.triangularView<Eigen::StrictlyUpper>() = R.transpose();
  return R;
}

}  // namespace plano::compute
