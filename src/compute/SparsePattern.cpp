#include "compute/SparsePattern.h"

#include <algorithm>

namespace plano::compute {

std::int32_t storedEntryIndex(const SparseMatrix& A, Index row, Index column) {
  const int* begin = A.innerIndexPtr() + A.outerIndexPtr()[row];
  const int* end = A.innerIndexPtr() + A.outerIndexPtr()[row + 1];
  const int* found = std::lower_bound(begin, end, static_cast<int>(column));
  return found != end && *found == column ? static_cast<std::int32_t>(found - A.innerIndexPtr()) : -1;
}

std::vector<std::int32_t> transposeTargets(const SparseMatrix& A) {
  SparseMatrix positions = A;
  for (Eigen::Index e = 0; e < positions.nonZeros(); ++e) positions.valuePtr()[e] = static_cast<double>(e);
  SparseMatrix transposed = positions.transpose();
  transposed.makeCompressed();
  std::vector<std::int32_t> targets(static_cast<std::size_t>(A.nonZeros()));
  for (Eigen::Index t = 0; t < transposed.nonZeros(); ++t) {
    targets[static_cast<std::size_t>(transposed.valuePtr()[t])] = static_cast<std::int32_t>(t);
  }
  return targets;
}

SparseMatrix ones(const SparseMatrix& A) {
  SparseMatrix pattern = A;
  pattern.makeCompressed();
  for (Eigen::Index e = 0; e < pattern.nonZeros(); ++e) pattern.valuePtr()[e] = 1.0;
  return pattern;
}

}  // namespace plano::compute
