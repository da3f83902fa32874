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
  /// C is rows x 4 faces. Throws Error(Usage) for a term outside C, a negative scale
  /// index, or two terms on the same entry.
  ScaledConstraintMatrix(Index rows, Index faces, const std::vector<Term>& terms);

  /// C's values for these scales (one per scale index; the terms' indices must be below
  /// scales.size(), else Error(Usage)). The matrix stays valid until the next fill.
  const compute::SparseMatrix& fill(std::span<const double> scales);

 private:
  compute::SparseMatrix C_;
  std::vector<double> coefficients_;  ///< Per stored entry of C, in its compressed order.
  std::vector<Index> scaleOf_;        ///< Per stored entry of C.
  Index scaleCount_ = 0;              ///< Largest scale index + 1.
};

}  // namespace plano::projective
