#include "subspace/SparseShapes.h"

#include <Eigen/Dense>
#include <set>
#include <string>

#include "core/Error.h"

namespace plano::subspace {

Positions sparseShape(const ConstraintMatrix& constraints, Index vertex, const Eigen::Vector3d& direction,
                      const SparseShapeSettings& settings, SparseShapeInfo* info) {
  const Index nv = constraints.vertexCount;
  if (vertex < 0 || vertex >= nv) throwBadInput("sparse shape: vertex " + std::to_string(vertex) + " out of range");
  if (!(direction.norm() > 0.0)) throwUsage("sparse shape: the direction must be non-zero");
  const Eigen::SparseMatrix<double> B = constraints.fullMatrix();  // Column-major: columns are atoms.
  const Eigen::Index n = B.cols();
  Eigen::VectorXd seed = Eigen::VectorXd::Zero(n);
  seed.segment<3>(3 * vertex) = direction.normalized();
  const Eigen::VectorXd b = B * seed;
  Eigen::VectorXd columnNorms(n);
  for (Eigen::Index j = 0; j < n; ++j) columnNorms[j] = B.col(j).norm();

  SparseShapeInfo local;
  local.initialResidual = b.norm();
  Eigen::VectorXd x = seed;
  Eigen::VectorXd r = b;
  std::vector<Index> support;
  std::set<Index> movingVertices{vertex};
  std::vector<bool> used(static_cast<std::size_t>(n), false);
  for (int c = 0; c < 3; ++c) used[3 * vertex + c] = true;  // The seed moves exactly along `direction`.
  std::vector<Index> rowSlot(static_cast<std::size_t>(B.rows()), -1);
  std::vector<Index> activeRows;
  for (Eigen::Index i = 0; i < b.size(); ++i) {
    if (b[i] != 0.0) {
      rowSlot[i] = static_cast<Index>(activeRows.size());
      activeRows.push_back(static_cast<Index>(i));
    }
  }
  const double target = settings.exactTolerance;
  while (r.norm() > target * x.norm()) {
    // Most correlated unused atom.
    const Eigen::VectorXd correlation = B.transpose() * r;
    Eigen::Index best = -1;
    double bestValue = 0.0;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (used[j] || columnNorms[j] == 0.0) continue;
      const double value = std::abs(correlation[j]) / columnNorms[j];
      if (value > bestValue) {
        bestValue = value;
        best = j;
      }
    }
    if (best < 0) break;
    const Index bestVertex = static_cast<Index>(best / 3);
    if (!movingVertices.count(bestVertex) && static_cast<Index>(movingVertices.size()) >= settings.maxSupportVertices) {
      break;
    }
    used[best] = true;
    movingVertices.insert(bestVertex);
    support.push_back(static_cast<Index>(best));
    // Least squares min ||B_S y + b|| on the rows that the support and the seed touch
    // (all other rows are zero on both sides).
    for (Eigen::SparseMatrix<double>::InnerIterator it(B, best); it; ++it) {
      if (rowSlot[it.row()] < 0) {
        rowSlot[it.row()] = static_cast<Index>(activeRows.size());
        activeRows.push_back(static_cast<Index>(it.row()));
      }
    }
    const Eigen::Index s = static_cast<Eigen::Index>(support.size());
    const Eigen::Index m = static_cast<Eigen::Index>(activeRows.size());
    Eigen::MatrixXd Bs = Eigen::MatrixXd::Zero(m, s);
    Eigen::VectorXd rhs(m);
    for (Eigen::Index i = 0; i < m; ++i) rhs[i] = -b[activeRows[i]];
    for (Eigen::Index j = 0; j < s; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(B, support[j]); it; ++it) Bs(rowSlot[it.row()], j) = it.value();
    const Eigen::VectorXd y = Bs.colPivHouseholderQr().solve(rhs);
    x = seed;
    for (Eigen::Index j = 0; j < s; ++j) x[support[j]] = y[j];
    r = B * x;
    local.iterations += 1;
  }
  local.residual = r.norm() / x.norm();
  local.status = local.residual <= target ? SparseShapeStatus::Exact : SparseShapeStatus::Approximate;
  local.supportVertices = 0;
  for (Index v = 0; v < nv; ++v) local.supportVertices += x.segment<3>(3 * v).norm() > 0.0 ? 1 : 0;
  local.initialResidual /= seed.norm();
  if (info) *info = local;
  Positions X(nv, 3);
  Eigen::Map<Eigen::VectorXd>(X.data(), X.size()) = x;
  return X;
}

}  // namespace plano::subspace
