#pragma once
// Sparse shapes (linear-spaces paper, §3): members of null(B) that move few vertices,
// found by Orthogonal Matching Pursuit (Tropp and Gilbert) as in Habbecke and Kobbelt.
// The seed vertex moves by a unit `direction`; OMP greedily adds the coordinates (columns
// of B) most correlated with the residual B X and re-solves the least-squares problem on
// the support, until B X vanishes (an exact sparse shape) or the support cap is reached
// (an approximate one, with its residual reported: the paper's ||BX|| ~ 1e-4 case).
#include "subspace/ConstraintMatrix.h"

namespace plano::subspace {

struct SparseShapeSettings {
  Index maxSupportVertices = 64;  ///< Cap on the vertices that may move (seed included).
  double exactTolerance = 1e-9;   ///< ||B X|| / ||X|| below this: exact.
};

enum class SparseShapeStatus { Exact, Approximate };

struct SparseShapeInfo {
  SparseShapeStatus status = SparseShapeStatus::Approximate;
  Index iterations = 0;       ///< OMP steps (coordinates added).
  Index supportVertices = 0;  ///< Vertices that move (seed included).
  double residual = 0.0;      ///< ||B X|| / ||X||.
  double initialResidual = 0.0;  ///< The same for the seed alone.
};

/// Sparse shape seeded at `vertex` moving along `direction` (#V x 3 displacement field).
/// Throws Error(BadInput) for a vertex out of range, Error(Usage) for a zero direction.
Positions sparseShape(const ConstraintMatrix& B, Index vertex, const Eigen::Vector3d& direction,
                      const SparseShapeSettings& settings = {}, SparseShapeInfo* info = nullptr);

}  // namespace plano::subspace
