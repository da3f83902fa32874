#pragma once
// Fundamental shapes (linear-spaces paper, §3): for a chosen vertex i,
//   min_X ||X - delta_i||^2 + lambda ||L X||^2  s.t.  B X = 0,
// delta_i moving vertex i by a unit direction. With X = N W (N orthonormal) the
// constraint disappears: (I + lambda N^T L^T L N) W = N^T delta_i, a d x d SPD system.
#include "compute/Backend.h"
#include "subspace/SubspaceBasis.h"

namespace plano::subspace {

struct FundamentalShapeSettings {
  double smoothness = 1.0;  ///< lambda.
};

/// The fundamental shape of `vertex` along `direction` (#V x 3). Throws Error(BadInput)
/// for a vertex out of range, Error(Usage) for a zero direction or negative smoothness.
/// N^T L^T L N is formed on `backend` (Backend::reducedOperator), the d x d solve on the host.
Positions fundamentalShape(compute::Backend& backend, const SubspaceBasis& N, const compute::SparseMatrix& L,
                           Index vertex, const Eigen::Vector3d& direction, const FundamentalShapeSettings& settings = {});
/// The same on the CPU reference.
Positions fundamentalShape(const SubspaceBasis& N, const compute::SparseMatrix& L, Index vertex,
                           const Eigen::Vector3d& direction, const FundamentalShapeSettings& settings = {});

}  // namespace plano::subspace
