#include "projective/ScaledConstraintMatrix.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "core/Error.h"

namespace plano::projective {

ScaledConstraintMatrix::ScaledConstraintMatrix(Index rows, Index faces, Index scales, const std::vector<Term>& terms)
    : C_(rows, 4 * faces) {
  if (scales < 0 || scales >= std::numeric_limits<std::int32_t>::max()) {
    throwUsage("constraint matrix: " + std::to_string(scales) + " scales (0 to 2^31 - 2)");
  }
  scaling_.scaleCount = static_cast<std::int32_t>(scales);
  // The pattern from triplets whose values name their term and coefficient (id + 1, exact
  // in a double): setFromTriplets sums duplicates, which a count of stored entries reveals.
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(4 * terms.size());
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const Term& term = terms[t];
    if (term.row < 0 || term.row >= rows || term.face < 0 || term.face >= faces || term.scale < 0 ||
        term.scale >= scales) {
      throwUsage("constraint matrix: term " + std::to_string(t) + " (row " + std::to_string(term.row) + ", face " +
                 std::to_string(term.face) + ", scale " + std::to_string(term.scale) + ") lies outside a " +
                 std::to_string(rows) + "-row matrix on " + std::to_string(faces) + " faces with " +
                 std::to_string(scales) + " scales");
    }
    for (Index k = 0; k < 4; ++k) entries.emplace_back(term.row, 4 * term.face + k, static_cast<double>(4 * t + k + 1));
  }
  C_.setFromTriplets(entries.begin(), entries.end());
  C_.makeCompressed();
  if (static_cast<std::size_t>(C_.nonZeros()) != entries.size()) {
    throwUsage("constraint matrix: two terms on the same entry (a row with two corners of one face)");
  }
  scaling_.coefficients.resize(entries.size());
  scaling_.scaleOf.resize(entries.size());
  for (Eigen::Index e = 0; e < C_.nonZeros(); ++e) {
    const auto id = static_cast<std::size_t>(C_.valuePtr()[e]) - 1;
    const Term& term = terms[id / 4];
    scaling_.coefficients[e] = term.coefficients[static_cast<Eigen::Index>(id % 4)];
    scaling_.scaleOf[e] = static_cast<std::int32_t>(term.scale);
    C_.valuePtr()[e] = 0.0;
  }
}

const compute::SparseMatrix& ScaledConstraintMatrix::fill(std::span<const double> scales) {
  if (scales.size() != static_cast<std::size_t>(scaling_.scaleCount)) {
    throwUsage("constraint matrix: " + std::to_string(scales.size()) + " scales for terms that use " +
               std::to_string(scaling_.scaleCount));
  }
  compute::fillScaledValues(scaling_, scales, C_.valuePtr());
  return C_;
}

}  // namespace plano::projective
