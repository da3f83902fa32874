#include "planarize/ShapeUpStep.h"

#include <Eigen/SparseCore>

namespace plano::planarize::detail {

ShapeUpStep::ShapeUpStep(const Problem& problem, double closeness, compute::Backend& backend)
    : problem_(&problem), closeness_(closeness) {
  const FaceList& faces = *problem.faces;
  const Index n = problem.freeCount;
  fixedRhs_ = Eigen::MatrixXd::Zero(n, 3);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(n) + 16 * problem.constrainedFaces.size());
  for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
    const Index row = problem.freeIndex[v];
    if (row < 0) continue;
    triplets.emplace_back(row, row, closeness);
    fixedRhs_.row(row) = closeness * problem.input.row(v);
  }
  for (std::size_t c = 0; c < problem.constrainedFaces.size(); ++c) {
    const auto face = faces[problem.constrainedFaces[c]];
    const double k = static_cast<double>(face.size());
    const double w = 1.0 / (problem.faceSize[c] * problem.faceSize[c]);
    Eigen::RowVector3d fixedSum = Eigen::RowVector3d::Zero();
    for (Index j : face) {
      if (problem.freeIndex[j] < 0) fixedSum += problem.input.row(j);
    }
    for (Index i : face) {
      const Index row = problem.freeIndex[i];
      if (row < 0) continue;
      // Fixed corners move to the right-hand side: -A_ij y_j = +w/k y_j for j != i.
      fixedRhs_.row(row) += (w / k) * fixedSum;
      for (Index j : face) {
        const Index col = problem.freeIndex[j];
        if (col < 0) continue;
        triplets.emplace_back(row, col, (i == j ? w : 0.0) - w / k);
      }
    }
  }
  compute::SparseMatrix A(n, n);
  A.setFromTriplets(triplets.begin(), triplets.end());
  solver_ = backend.createSpdSolver(A, compute::LinearSolverSettings{});
  rhs_ = fixedRhs_;
  solution_ = Eigen::MatrixXd::Zero(n, 3);
}

double ShapeUpStep::project(const Positions& Y) {
  const Problem& problem = *problem_;
  const FaceList& faces = *problem.faces;
  rhs_ = fixedRhs_;
  double energy = 0.0;
  for (std::size_t c = 0; c < problem.constrainedFaces.size(); ++c) {
    const auto face = faces[problem.constrainedFaces[c]];
    const FacePlane plane = bestFitPlane(Y, face);
    const double w = 1.0 / (problem.faceSize[c] * problem.faceSize[c]);
    for (Index i : face) {
      // The projection p_i - c_f: the plane passes through the centroid, so the
      // projected corners keep it and C_f P = P - c_f.
      const Eigen::Vector3d local = Y.row(i).transpose() - plane.centroid;
      const double distance = plane.normal.dot(local);
      energy += w * distance * distance;
      const Index row = problem.freeIndex[i];
      if (row >= 0) rhs_.row(row) += w * (local - distance * plane.normal).transpose();
    }
  }
  for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
    if (problem.freeIndex[v] >= 0) energy += closeness_ * (Y.row(v) - problem.input.row(v)).squaredNorm();
  }
  return energy;
}

void ShapeUpStep::globalStep(Positions& Y) {
  const Problem& problem = *problem_;
  const compute::LinearSolveInfo info = solver_->solve(rhs_, solution_);
  linearResidual_ = info.relativeResidual;
  for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
    const Index row = problem.freeIndex[v];
    if (row >= 0) Y.row(v) = solution_.row(row);
  }
}

}  // namespace plano::planarize::detail
