#include "subspace/SparseShapes.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::subspace {

namespace {

/// Sorted set of the columns with a non-zero in one of `rows` (of row-major `Br`): the only
/// atoms whose correlation with a residual supported on those rows can be non-zero.
std::vector<Index> columnsTouching(const compute::SparseMatrix& Br, const std::vector<Index>& rows,
                                   std::vector<char>& mark) {
  std::vector<Index> columns;
  for (Index i : rows) {
    for (compute::SparseMatrix::InnerIterator it(Br, i); it; ++it) {
      if (!mark[it.col()]) {
        mark[it.col()] = 1;
        columns.push_back(it.col());
      }
    }
  }
  for (Index j : columns) mark[j] = 0;
  std::sort(columns.begin(), columns.end());
  return columns;
}

}  // namespace

Positions sparseShape(const ConstraintMatrix& constraints, Index vertex, const Eigen::Vector3d& direction,
                      const SparseShapeSettings& settings, SparseShapeInfo* info) {
  const Index nv = constraints.vertexCount;
  if (vertex < 0 || vertex >= nv) throwBadInput("sparse shape: vertex " + std::to_string(vertex) + " out of range");
  if (!(direction.norm() > 0.0)) throwUsage("sparse shape: the direction must be non-zero");
  // Every vector of the iteration lives on few rows and columns: x on the seed and the
  // support, the residual B x on the rows those columns touch, and so the correlation
  // B^T r on the columns touching the rows where r is non-zero (the active rows). Each
  // step therefore works on those alone, in the order a whole product would sum them (the
  // same atoms are chosen): its cost is the support's neighbourhood, not the mesh
  // (BM_SparseShape).
  const compute::SparseMatrix Br = constraints.fullMatrix();  // row access: a row's atoms
  const Eigen::SparseMatrix<double> B = Br;                   // column access: an atom's rows
  const Eigen::Index n = B.cols();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  x.segment<3>(3 * vertex) = direction.normalized();
  std::vector<Index> nonZeroColumns{3 * vertex, 3 * vertex + 1, 3 * vertex + 2};  // x's, sorted

  Eigen::VectorXd r = Eigen::VectorXd::Zero(B.rows());
  auto productWithX = [&]() {  // r = B x
    for (Index j : nonZeroColumns) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(B, j); it; ++it) r[it.row()] = 0.0;
    }
    for (Index j : nonZeroColumns) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(B, j); it; ++it) r[it.row()] += x[j] * it.value();
    }
  };
  productWithX();
  const Eigen::VectorXd b = r;  // B seed
  // The least squares' rows: those of b's non-zeros, then those each new atom touches.
  std::vector<Index> activeRows;
  std::vector<Index> rowSlot(static_cast<std::size_t>(B.rows()), -1);
  auto activateRow = [&](Index row) {
    if (rowSlot[row] < 0) {
      rowSlot[row] = static_cast<Index>(activeRows.size());
      activeRows.push_back(row);
    }
  };
  for (Index j : nonZeroColumns) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(B, j); it; ++it) {
      if (b[it.row()] != 0.0) activateRow(static_cast<Index>(it.row()));
    }
  }
  std::sort(activeRows.begin(), activeRows.end());
  for (std::size_t slot = 0; slot < activeRows.size(); ++slot) rowSlot[activeRows[slot]] = static_cast<Index>(slot);
  auto activate = [&](Index column) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(B, column); it; ++it) activateRow(static_cast<Index>(it.row()));
  };
  auto residualOnActiveRows = [&]() {  // ||r||: r is zero off the active rows
    productWithX();
    double squared = 0.0;
    for (Index i : activeRows) squared += r[i] * r[i];
    return std::sqrt(squared);
  };
  auto normOfX = [&]() {
    double squared = 0.0;
    for (Index j : nonZeroColumns) squared += x[j] * x[j];
    return std::sqrt(squared);
  };
  double residual = residualOnActiveRows();

  SparseShapeInfo local;
  double xNorm = normOfX();
  local.initialResidual = residual / xNorm;
  std::vector<Index> support;
  std::set<Index> movingVertices{vertex};
  std::vector<bool> used(static_cast<std::size_t>(n), false);
  for (int c = 0; c < 3; ++c) used[3 * vertex + c] = true;  // The seed moves exactly along `direction`.
  std::vector<char> mark(static_cast<std::size_t>(n), 0);
  const double target = settings.exactTolerance;
  while (residual > target * xNorm) {
    // An iteration on a large support takes a second or more; a run may take thousands.
    throwIfCancelled("the sparse shape (orthogonal matching pursuit)");
    // Most correlated unused atom (the lowest index among equals, as a scan of B^T r).
    Eigen::Index best = -1;
    double bestValue = 0.0;
    for (Index j : columnsTouching(Br, activeRows, mark)) {
      if (used[j]) continue;
      const double norm = B.col(j).norm();
      if (norm == 0.0) continue;
      const double value = std::abs(B.col(j).dot(r)) / norm;
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
    nonZeroColumns.insert(std::lower_bound(nonZeroColumns.begin(), nonZeroColumns.end(), best), best);
    // Least squares min ||B_S y + b|| on the rows that the support and the seed touch
    // (all other rows are zero on both sides).
    activate(static_cast<Index>(best));
    const Eigen::Index s = static_cast<Eigen::Index>(support.size());
    const Eigen::Index m = static_cast<Eigen::Index>(activeRows.size());
    Eigen::MatrixXd Bs = Eigen::MatrixXd::Zero(m, s);
    Eigen::VectorXd rhs(m);
    for (Eigen::Index i = 0; i < m; ++i) rhs[i] = -b[activeRows[i]];
    for (Eigen::Index j = 0; j < s; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(B, support[j]); it; ++it) Bs(rowSlot[it.row()], j) = it.value();
    const Eigen::VectorXd y = Bs.colPivHouseholderQr().solve(rhs);
    for (Eigen::Index j = 0; j < s; ++j) x[support[j]] = y[j];
    residual = residualOnActiveRows();
    xNorm = normOfX();
    local.iterations += 1;
  }
  local.residual = residual / xNorm;
  local.status = local.residual <= target ? SparseShapeStatus::Exact : SparseShapeStatus::Approximate;
  local.supportVertices = 0;
  for (Index v = 0; v < nv; ++v) local.supportVertices += x.segment<3>(3 * v).norm() > 0.0 ? 1 : 0;
  if (info) *info = local;
  Positions X(nv, 3);
  Eigen::Map<Eigen::VectorXd>(X.data(), X.size()) = x;
  return X;
}

}  // namespace plano::subspace
