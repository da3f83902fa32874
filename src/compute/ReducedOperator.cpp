#include "compute/ReducedOperator.h"

#include <string>

#include "compute/cpu/SymmetricProduct.h"
#include "core/Error.h"

namespace plano::compute {

void checkReducedOperatorInputs(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) {
  if (S.rows() != S.cols()) {
    throwUsage("reducedOperator: S is " + std::to_string(S.rows()) + " x " + std::to_string(S.cols()) +
               ", not square");
  }
  if (coordinates < 1) throwUsage("reducedOperator: " + std::to_string(coordinates) + " coordinates per vertex");
  if (N.rows() != static_cast<Eigen::Index>(coordinates) * S.rows()) {
    throwUsage("reducedOperator: the basis has " + std::to_string(N.rows()) + " rows for " +
               std::to_string(S.rows()) + " vertices of " + std::to_string(coordinates) + " coordinates");
  }
}

namespace {

/// Whether S equals its transpose to rounding: its operators (Laplacians, L^T L) are
/// symmetric by construction, up to the order of a sparse product's sums.
bool isSymmetric(const SparseMatrix& S) {
  if (S.nonZeros() == 0) return true;
  const SparseMatrix difference = S - SparseMatrix(S.transpose());
  const double scale = Eigen::Map<const Eigen::VectorXd>(S.valuePtr(), S.nonZeros()).cwiseAbs().maxCoeff();
  if (difference.nonZeros() == 0) return true;
  const double asymmetry =
      Eigen::Map<const Eigen::VectorXd>(difference.valuePtr(), difference.nonZeros()).cwiseAbs().maxCoeff();
  return asymmetry <= 1e-14 * scale;
}

}  // namespace

Eigen::MatrixXd reducedOperatorReference(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) {
  checkReducedOperatorInputs(S, N, coordinates);
  Eigen::MatrixXd SN;
  if (coordinates == 1) {
    SN.noalias() = S * N;  // No temporary: N's size again at a million vertices.
  } else {
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const Eigen::Index vertices = S.rows(), d = N.cols();
    SN.resize(N.rows(), d);
    for (Eigen::Index j = 0; j < d; ++j) {
      const Eigen::Map<const RowMajor> Xj(N.col(j).data(), vertices, coordinates);
      Eigen::Map<RowMajor>(SN.col(j).data(), vertices, coordinates) = S * Xj;
    }
  }
  // N^T (S N) is symmetric when S is: half the product, the cost of every space's eigenshapes.
  return isSymmetric(S) ? symmetricTransposeProduct(N, SN) : Eigen::MatrixXd(N.transpose() * SN);
}

Eigen::MatrixXd Backend::reducedOperator(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) {
  return reducedOperatorReference(S, N, coordinates);
}

}  // namespace plano::compute
