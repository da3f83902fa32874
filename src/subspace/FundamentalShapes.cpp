#include "subspace/FundamentalShapes.h"

#include <Eigen/Dense>
#include <string>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"

namespace plano::subspace {

Positions fundamentalShape(compute::Backend& backend, const SubspaceBasis& N, const compute::SparseMatrix& L,
                           Index vertex, const Eigen::Vector3d& direction, const FundamentalShapeSettings& settings) {
  const Index nv = N.vertexCount();
  if (vertex < 0 || vertex >= nv) throwBadInput("fundamental shape: vertex " + std::to_string(vertex) + " out of range");
  if (!(direction.norm() > 0.0)) throwUsage("fundamental shape: the direction must be non-zero");
  if (!(settings.smoothness >= 0.0)) throwUsage("fundamental shape: smoothness must be >= 0");
  Positions delta = Positions::Zero(nv, 3);
  delta.row(vertex) = direction.normalized().transpose();
  const compute::SparseMatrix LtL = compute::SparseMatrix(L.transpose()) * L;
  Eigen::MatrixXd H = settings.smoothness * N.reducedOperator(backend, LtL);
  H.diagonal().array() += 1.0;
  const Eigen::VectorXd W = H.ldlt().solve(N.coefficients(delta));
  return N.shape(W);
}

Positions fundamentalShape(const SubspaceBasis& N, const compute::SparseMatrix& L, Index vertex,
                           const Eigen::Vector3d& direction, const FundamentalShapeSettings& settings) {
  compute::CpuBackend cpu;
  return fundamentalShape(cpu, N, L, vertex, direction, settings);
}

}  // namespace plano::subspace
