#include "compute/SparsePattern.h"

#include <algorithm>

namespace plano::compute {

std::int32_t storedEntryIndex(const SparseMatrix& A, Index row, Index column) {
  const int* begin = A.innerIndexPtr() + A.outerIndexPtr()[row];
  const int* end = A.innerIndexPtr() + A.outerIndexPtr()[row + 1];
  const int* found = std::lower_bound(begin, end, static_cast<int>(column));
  return found != end && *found == column ? static_cast<std::int32_t>(found - A.innerIndexPtr()) : -1;
}

}  // namespace plano::compute
