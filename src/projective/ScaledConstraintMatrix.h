#pragma once
// The constraint matrix C_s of the global steps (projective-maps paper, Eq. 4): each
// entry is a fixed coefficient (a homogeneous coordinate of a base vertex or handle point)
// divided by a scale that every local step changes (that corner's reciprocal scale
// factor shat). C's pattern depends on the topology and the constrained vertices only, so
// it is built once and each step fills its values in place: 3.7 ms of host time on 64k
// faces and 46 ms on 1M, where assembling C from triplets every step took 46 ms and 2.3 s
// (BM_GlobalStepConstraints).
#include <Eigen/Core>
#include <span>
#include <vector>

#include "compute/Admm.h"
#include "compute/Backend.h"

namespace plano::projective {

class ScaledConstraintMatrix {
 public:
  /// The entries of one row on one face's map: C(row, 4 face + k) = coefficients[k] /
  /// scales[scale] for k = 0..3 (all four stored, zero coefficients included, so that the
  /// pattern never depends on values).
  struct Term {
    Index row;
    Index face;
    Eigen::RowVector4d coefficients;
    Index scale;  ///< Index into the scales given to fill().
  };

  ScaledConstraintMatrix() = default;
  /// C is rows x 4 faces; fill() takes `scales` scales. Throws Error(Usage) for a term
  /// outside C, a scale index outside 0 .. scales - 1, or two terms on the same entry.
  ScaledConstraintMatrix(Index rows, Index faces, Index scales, const std::vector<Term>& terms);

  /// C's values for these scales (exactly as many as given to the constructor, else
  /// Error(Usage)). The matrix stays valid until the next fill.
  const compute::SparseMatrix& fill(std::span<const double> scales);

  /// C as last filled (zero values before the first fill).
  const compute::SparseMatrix& matrix() const { return C_; }
  /// The coefficient and scale index of every stored entry of C (compressed order), for a
  /// solver that forms C's values itself (compute::AdmmSolver::setConstraintScaling).
  const compute::ConstraintScaling& scaling() const { return scaling_; }

 private:
  compute::SparseMatrix C_;
  compute::ConstraintScaling scaling_;
};

}  // namespace plano::projective
