#pragma once
// Lookups in the fixed sparsity pattern of a compressed matrix: the places that assemble a
// matrix once and refill its values every iteration (planarizers, device kernels) keep the
// position of each value among the stored entries instead of searching again.
#include <cstdint>

#include "compute/Backend.h"

namespace plano::compute {

/// Position of entry (row, column) among the stored entries of the compressed A, or -1 when
/// that entry is not stored.
std::int32_t storedEntryIndex(const SparseMatrix& A, Index row, Index column);

}  // namespace plano::compute
