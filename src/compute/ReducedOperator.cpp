#include "compute/ReducedOperator.h"

#include <string>

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

Eigen::MatrixXd reducedOperatorReference(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) {
  checkReducedOperatorInputs(S, N, coordinates);
  if (coordinates == 1) return N.transpose() * (S * N);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Index vertices = S.rows(), d = N.cols();
  Eigen::MatrixXd SN(N.rows(), d);
  for (Eigen::Index j = 0; j < d; ++j) {
    const Eigen::Map<const RowMajor> Xj(N.col(j).data(), vertices, coordinates);
    Eigen::Map<RowMajor>(SN.col(j).data(), vertices, coordinates) = S * Xj;
  }
  return N.transpose() * SN;
}

Eigen::MatrixXd Backend::reducedOperator(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) {
  return reducedOperatorReference(S, N, coordinates);
}

}  // namespace plano::compute
