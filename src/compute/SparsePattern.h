#pragma once
// Lookups in the fixed sparsity pattern of a compressed matrix: the places that assemble a
// matrix once and refill its values every iteration (planarizers, device kernels) keep the
// position of each value among the stored entries instead of searching again.
#include <cstdint>
#include <vector>

#include "compute/Backend.h"

namespace plano::compute {

/// Position of entry (row, column) among the stored entries of the compressed A, or -1 when
/// that entry is not stored.
std::int32_t storedEntryIndex(const SparseMatrix& A, Index row, Index column);

/// For each stored entry (r, c) of the compressed A, in storage order, the position among the
/// compressed B's stored entries of entry (rowOf(r), columnOf(c)), or -1 where B does not
/// store it: the gather that adds A's values into B's (a multigrid's coarsening, on a device).
template <class RowOf, class ColumnOf>
std::vector<std::int32_t> entryTargets(const SparseMatrix& A, const SparseMatrix& B, RowOf rowOf, ColumnOf columnOf) {
  std::vector<std::int32_t> targets(static_cast<std::size_t>(A.nonZeros()));
  for (Index r = 0; r < A.rows(); ++r) {
    const Index row = rowOf(r);
    for (Index e = A.outerIndexPtr()[r]; e < A.outerIndexPtr()[r + 1]; ++e) {
      targets[static_cast<std::size_t>(e)] = storedEntryIndex(B, row, columnOf(A.innerIndexPtr()[e]));
    }
  }
  return targets;
}

/// For each stored value of the compressed A, its position among A^T's stored values (the
/// gather that transposes values on a device).
std::vector<std::int32_t> transposeTargets(const SparseMatrix& A);

/// A's pattern with every stored value 1: products of such patterns have no cancellation,
/// so they hold every entry a product of the matrices can have.
SparseMatrix ones(const SparseMatrix& A);

}  // namespace plano::compute
