#pragma once
// The matrices of a real global step, for tests of its linear algebra: P and C of the
// first ADMM solver a CPU global step creates on a side x side translational grid (first
// column of vertices fixed, every other face's target rotated), and its ADMM matrix.
#include "compute/Backend.h"

namespace plano::test {

struct GlobalStepMatrices {
  compute::SparseMatrix P, C;
  double sigma = 0.0;
  /// K = P + sigma I + rho C^T C: every row an equality row of penalty rho (the exact,
  /// ε = 0, attempt with rho = rho_ADMM * equalityRhoScale).
  compute::SparseMatrix K(double rho) const;
};

GlobalStepMatrices globalStepMatrices(Index side);

}  // namespace plano::test
